//! The seven worked problems of `shared/seed/problems.md`: exact where the sheet's values are
//! integers, within a stated f32 bound where they are irrational. Intermediates are checked, not
//! only answers, through the textbook `*_steps` API; the packet kernels must agree.
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray_testkit as testkit;

use octoray::glam::Vec3;
use octoray::lanes::Lanes;
use octoray::prim::{PackedSphere, PackedTriangle};
use octoray::textbook::{self, InsideTest, SphereOutcome, TextbookHit, TriangleOutcome};
use octoray::{f32x16, f32x4, f32x8};
use testkit::*;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

#[test]
fn triangle_1_hits_at_minus2_2_5_with_sheet_intermediates() {
    let s = textbook::triangle_steps(&seed_ray(), &seed_triangles()[0], InsideTest::Full);
    assert_eq!(s.n, v(5.0, -5.0, 5.0));
    assert_eq!(s.d_dot_n, 10.0);
    assert_eq!(s.o_dot_n, -20.0);
    assert_eq!(s.t, 2.0);
    assert_eq!(s.p, v(-2.0, 2.0, 5.0));
    assert_eq!(
        s.to_vertices,
        [v(2.0, 4.0, 2.0), v(-1.0, -1.0, 0.0), v(0.0, -1.0, -1.0)]
    );
    assert_eq!(
        s.edge_cross,
        [v(2.0, -2.0, 2.0), v(1.0, -1.0, 1.0), v(2.0, -2.0, 2.0)]
    );
    assert_eq!(s.edge_tests, [30.0, 15.0, 30.0]);
    assert_eq!(s.dominant_axis, 0);
    // The sheet's x components.
    assert_eq!(s.edge_tests_dominant, [2.0, 1.0, 2.0]);
    assert_eq!(
        s.outcome,
        TriangleOutcome::Hit(TextbookHit {
            t: 2.0,
            point: v(-2.0, 2.0, 5.0)
        })
    );
}

#[test]
fn triangle_2_misses_with_mixed_edge_signs_and_corrected_intermediates() {
    let s = textbook::triangle_steps(&seed_ray(), &seed_triangles()[1], InsideTest::Full);
    assert_eq!(s.n, v(5.0, -5.0, 5.0));
    assert_eq!(s.d_dot_n, 10.0);
    assert_eq!(s.o_dot_n, -10.0);
    assert_eq!(s.t, 1.0);
    assert_eq!(s.p, v(-3.0, 0.0, 2.0));
    // The sheet prints p a1 = [-3, -5, -6] etc.: misprints (problems.md). These are correct.
    assert_eq!(
        s.to_vertices,
        [v(1.0, 1.0, 0.0), v(2.0, 1.0, -1.0), v(4.0, 6.0, 2.0)]
    );
    assert_eq!(s.edge_tests, [-15.0, 120.0, -30.0]);
    assert_eq!(s.edge_tests_dominant, [-1.0, 8.0, -2.0]);
    assert_eq!(s.outcome, TriangleOutcome::Outside);
}

#[test]
fn triangle_3_is_parallel_and_not_in_the_plane() {
    let s = textbook::triangle_steps(&seed_ray(), &seed_triangles()[2], InsideTest::Full);
    assert_eq!(s.n, v(0.0, 6.0, -4.0));
    assert_eq!(s.d_dot_n, 0.0);
    assert_eq!(s.o_dot_n, -8.0);
    assert_eq!(s.dominant_axis, 1);
    assert!(s.t.is_nan());
    assert_eq!(s.outcome, TriangleOutcome::Parallel);
}

#[test]
fn dominant_axis_shortcut_decides_the_three_triangles_like_the_full_test() {
    let ray = seed_ray();
    let expected = [true, false, false];
    for (tri, want) in seed_triangles().iter().zip(expected) {
        let full = textbook::intersect_triangle(&ray, tri, InsideTest::Full);
        let short = textbook::intersect_triangle(&ray, tri, InsideTest::DominantAxis);
        assert_eq!(full, short);
        assert_eq!(full.is_some(), want);
    }
}

/// Bound for the irrational sphere answers: `t = (−B ± √disc)/2A` with exact integer A, B, disc
/// takes three correctly rounded operations (√, ±, ÷), so `t` is within 1.5 ulp of the exact
/// root (we assert 2). Each `p_i = o_i + t·d_i` adds |d_i|·err(t) and two roundings: we assert
/// `|p_i − exact| ≤ 2·|d_i|·ulp(t) + ulp(p_i)`.
const T_ULP_BOUND: f64 = 2.0;

fn check_point(p: Vec3, t_exact: f64) {
    let ray = seed_ray();
    let ulp_t = f64::from(f32::EPSILON) * t_exact.abs();
    for k in 0..3 {
        let exact = f64::from(ray.origin[k]) + t_exact * f64::from(ray.dir[k]);
        let ulp_p = f64::from(f32::EPSILON) * exact.abs().max(f64::from(f32::MIN_POSITIVE));
        let bound = 2.0 * f64::from(ray.dir[k]).abs() * ulp_t + ulp_p;
        assert!(
            (f64::from(p[k]) - exact).abs() <= bound,
            "p[{k}] = {} vs exact {exact} (bound {bound})",
            p[k]
        );
    }
}

#[test]
fn sphere_1_origin_inside_takes_the_far_root() {
    let s = textbook::sphere_steps(&seed_ray(), &seed_spheres()[0]);
    assert_eq!(s.f, v(-4.0, -2.0, -1.0));
    assert_eq!((s.a, s.b, s.c, s.disc), (14.0, -22.0, -79.0, 4908.0));
    assert!(s.t_near < 0.0 && s.t_far > 0.0);
    let SphereOutcome::Hit { hit, inside } = s.outcome else {
        panic!("expected a hit, got {:?}", s.outcome)
    };
    assert!(inside);
    let t_exact = seed_sphere_t_exact()[0];
    assert!(ulp_err(hit.t, t_exact) <= T_ULP_BOUND, "t = {}", hit.t);
    assert!((f64::from(hit.t) - 3.287_754_269_7).abs() < 1e-6);
    check_point(hit.point, t_exact);
}

#[test]
fn sphere_2_two_positive_roots_takes_the_near_one() {
    let s = textbook::sphere_steps(&seed_ray(), &seed_spheres()[1]);
    assert_eq!(s.f, v(-1.0, -2.0, -3.0));
    assert_eq!((s.a, s.b, s.c, s.disc), (14.0, -28.0, 13.0, 56.0));
    let SphereOutcome::Hit { hit, inside } = s.outcome else {
        panic!("expected a hit, got {:?}", s.outcome)
    };
    assert!(!inside);
    let t_exact = seed_sphere_t_exact()[1];
    assert!(ulp_err(hit.t, t_exact) <= T_ULP_BOUND, "t = {}", hit.t);
    assert!((f64::from(hit.t) - 0.732_738_758_1).abs() < 1e-6);
    check_point(hit.point, t_exact);
}

#[test]
fn sphere_3_both_roots_negative_is_a_miss() {
    let s = textbook::sphere_steps(&seed_ray(), &seed_spheres()[2]);
    assert_eq!(s.f, v(1.0, 4.0, 6.0));
    assert_eq!((s.a, s.b, s.c, s.disc), (14.0, 54.0, 49.0, 172.0));
    assert!(s.t_near < 0.0 && s.t_far < 0.0);
    assert_eq!(s.outcome, SphereOutcome::OutOfRange);
}

#[test]
fn sphere_4_negative_discriminant_is_a_miss() {
    let s = textbook::sphere_steps(&seed_ray(), &seed_spheres()[3]);
    assert_eq!(s.f, v(-4.0, -2.0, 0.0));
    assert_eq!((s.a, s.b, s.c, s.disc), (14.0, -16.0, 11.0, -360.0));
    assert_eq!(s.outcome, SphereOutcome::NoRealRoot);
}

/// The seven problems through the kernels: the scalar twins, one lane each in a packet, and all
/// of them in one packet per width. Triangle t is exact (2); sphere t within 2 ulp of the exact
/// root (the stable form: √ of an exact Δ/4, one add, one divide, all correctly rounded here).
fn check_kernels<L: Lanes>() {
    let ray = seed_ray();
    let tris: Vec<PackedTriangle> = seed_triangles().iter().map(|&t| t.into()).collect();
    let spheres: Vec<PackedSphere> = seed_spheres().iter().map(|&s| s.into()).collect();
    let want_tri = [Some(2.0f64), None, None];
    let t_exact = seed_sphere_t_exact();
    let want_sph = [Some(t_exact[0]), Some(t_exact[1]), None, None];

    for (tri, want) in tris.iter().zip(want_tri) {
        let twin = octoray::intersect_triangle(&ray, tri).map(|h| f64::from(h.t));
        assert_eq!(twin, want);
        let p = octoray::query::closest::<L, octoray::kernels::MollerTrumbore>(
            &octoray::prim::RayLanes::<L>::load(&[ray]),
            std::slice::from_ref(tri),
        );
        assert_eq!(p.lane(0).map(|h| f64::from(h.t)), want);
        for i in 1..L::LANES {
            assert_eq!(p.lane(i), None, "inactive lane {i} must not hit");
        }
    }
    for (s, want) in spheres.iter().zip(want_sph) {
        let twin = octoray::intersect_sphere(&ray, s);
        let p = octoray::query::closest::<L, octoray::kernels::StableSphere>(
            &octoray::prim::RayLanes::<L>::load(&[ray]),
            std::slice::from_ref(s),
        );
        assert_eq!(twin, p.lane(0));
        match want {
            Some(t) => assert!(ulp_err(twin.unwrap().t, t) <= T_ULP_BOUND),
            None => assert_eq!(twin, None),
        }
    }

    // One packet carrying the seed ray in min(7, LANES) lanes (partial and masked for 16), solved
    // against each problem's primitive: every lane must give that problem's answer.
    let rays = vec![ray; L::LANES.min(7)];
    let mut hits = vec![None; rays.len()];
    for (k, tri) in tris.iter().enumerate() {
        octoray::closest::<L, octoray::kernels::MollerTrumbore>(
            &rays,
            std::slice::from_ref(tri),
            &mut hits,
        );
        for h in &hits {
            assert_eq!(h.map(|h| f64::from(h.t)), want_tri[k]);
        }
    }
    for (k, s) in spheres.iter().enumerate() {
        octoray::closest::<L, octoray::kernels::StableSphere>(
            &rays,
            std::slice::from_ref(s),
            &mut hits,
        );
        for h in &hits {
            assert_eq!(h.is_some(), want_sph[k].is_some());
        }
    }
    // And all primitives at once: triangle 1 (t = 2) is nearer than nothing else; sphere 2's
    // near root (~0.733) is the closest sphere.
    octoray::closest::<L, octoray::kernels::MollerTrumbore>(&rays, &tris, &mut hits);
    assert!(hits
        .iter()
        .all(|h| h.map(|h| (h.t, h.prim)) == Some((2.0, 0))));
    octoray::closest::<L, octoray::kernels::StableSphere>(&rays, &spheres, &mut hits);
    assert!(hits.iter().all(|h| h.is_some_and(|h| h.prim == 1)));
}

#[test]
fn seed_problems_through_kernels_width_1() {
    check_kernels::<f32>();
}

#[test]
fn seed_problems_through_kernels_width_4() {
    check_kernels::<f32x4>();
}

#[test]
fn seed_problems_through_kernels_width_8() {
    check_kernels::<f32x8>();
}

#[test]
fn seed_problems_through_kernels_width_16() {
    check_kernels::<f32x16>();
}

#[test]
fn textbook_and_kernel_points_agree_on_triangle_1() {
    let ray = seed_ray();
    let h = octoray::intersect_triangle(&ray, &seed_triangles()[0].into()).unwrap();
    assert_eq!(ray.at(h.t), v(-2.0, 2.0, 5.0));
    // Barycentrics: p − v0 = (−2, −4, −2) = 0.4·(−3, −5, −2) + 0.4·(−2, −5, −3), and the kernel
    // forms them as −8/−20 and −8/−20 from exact integers: one rounding each.
    assert_eq!((h.u, h.v), (0.4, 0.4));
}
