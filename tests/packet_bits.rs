//! Packet kernels == scalar twins, bit for bit, lane by lane, at widths 4, 8 and 16, on random
//! and adversarial inputs and on packets of every partial length. Run on the default build and
//! with `-C target-cpu=native` (see `.ci/run`).
mod common;

use common::strategies::*;
use octoray::core::{moller_trumbore, query, sphere_stable, RayLanes};
use octoray::glam::Vec3;
use octoray::packet::{f32x16, f32x4, f32x8, LaneMask, Lanes};
use octoray::{Hit, PackedSphere, PackedTriangle, Ray};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.prim))
}

fn lane_bit<M: LaneMask>(m: M, i: usize) -> bool {
    (m.bitmask() >> i) & 1 == 1
}

/// Every packet of `rays` (the last partial) against every triangle, and the closest/any
/// queries, compared with the `f32` twin.
fn check_triangles<L: Lanes>(rays: &[Ray], tris: &[PackedTriangle]) -> Result<(), TestCaseError> {
    for chunk in rays.chunks(L::LANES) {
        let p = RayLanes::<L>::load(chunk);
        for (k, tri) in tris.iter().enumerate() {
            let h = moller_trumbore::intersect(&p, tri);
            for i in 0..L::LANES {
                let twin = chunk
                    .get(i)
                    .and_then(|r| octoray::core::intersect_triangle(r, tri));
                let lane = lane_bit(h.mask, i).then(|| Hit {
                    t: h.t.lane(i),
                    u: h.u.lane(i),
                    v: h.v.lane(i),
                    prim: 0,
                });
                prop_assert_eq!(
                    bits(lane),
                    bits(twin),
                    "lane {} tri {} ray {:?}",
                    i,
                    k,
                    chunk.get(i)
                );
                if let Some(l) = lane {
                    let r = &chunk[i];
                    prop_assert!(
                        l.t.is_finite() && l.t >= r.t_min && l.t <= r.t_max,
                        "bad t {:?}",
                        l
                    );
                }
            }
        }
        let closest = query::closest_triangle(&p, tris);
        let any = query::any_triangle(&p, tris);
        for i in 0..L::LANES {
            let twin = chunk
                .get(i)
                .map(|r| query::closest_triangle(&RayLanes::single(r), tris));
            let twin_hit = twin.and_then(|t| t.lane(0));
            prop_assert_eq!(bits(closest.lane(i)), bits(twin_hit), "closest lane {}", i);
            let twin_any = chunk
                .get(i)
                .is_some_and(|r| query::any_triangle(&RayLanes::single(r), tris));
            prop_assert_eq!(lane_bit(any, i), twin_any, "any lane {}", i);
            // What any-hit reports must agree with closest-hit.
            prop_assert_eq!(lane_bit(any, i), closest.lane(i).is_some());
        }
    }
    Ok(())
}

fn check_spheres<L: Lanes>(rays: &[Ray], spheres: &[PackedSphere]) -> Result<(), TestCaseError> {
    for chunk in rays.chunks(L::LANES) {
        let p = RayLanes::<L>::load(chunk);
        for (k, s) in spheres.iter().enumerate() {
            let h = sphere_stable::intersect(&p, s);
            for i in 0..L::LANES {
                let twin = chunk
                    .get(i)
                    .and_then(|r| octoray::core::intersect_sphere(r, s));
                let lane = lane_bit(h.mask, i).then(|| Hit {
                    t: h.t.lane(i),
                    u: 0.0,
                    v: 0.0,
                    prim: 0,
                });
                prop_assert_eq!(
                    bits(lane),
                    bits(twin),
                    "lane {} sphere {} ray {:?}",
                    i,
                    k,
                    chunk.get(i)
                );
                if let Some(l) = lane {
                    let r = &chunk[i];
                    prop_assert!(
                        l.t.is_finite() && l.t >= r.t_min && l.t <= r.t_max,
                        "bad t {:?}",
                        l
                    );
                }
            }
        }
        let closest = query::closest_sphere(&p, spheres);
        let any = query::any_sphere(&p, spheres);
        for i in 0..L::LANES {
            let twin = chunk
                .get(i)
                .and_then(|r| query::closest_sphere(&RayLanes::single(r), spheres).lane(0));
            prop_assert_eq!(bits(closest.lane(i)), bits(twin), "closest lane {}", i);
            let twin_any = chunk
                .get(i)
                .is_some_and(|r| query::any_sphere(&RayLanes::single(r), spheres));
            prop_assert_eq!(lane_bit(any, i), twin_any, "any lane {}", i);
            prop_assert_eq!(lane_bit(any, i), closest.lane(i).is_some());
        }
    }
    Ok(())
}

/// All widths on the same rays, plus every partial packet length 1..=16 of them.
fn check_all_widths_triangles(rays: &[Ray], tris: &[PackedTriangle]) -> Result<(), TestCaseError> {
    check_triangles::<f32x4>(rays, tris)?;
    check_triangles::<f32x8>(rays, tris)?;
    check_triangles::<f32x16>(rays, tris)?;
    for n in 1..=rays.len().min(16) {
        check_triangles::<f32x16>(&rays[..n], tris)?;
        check_triangles::<f32x8>(&rays[..n.min(8)], tris)?;
        check_triangles::<f32x4>(&rays[..n.min(4)], tris)?;
    }
    Ok(())
}

fn check_all_widths_spheres(rays: &[Ray], spheres: &[PackedSphere]) -> Result<(), TestCaseError> {
    check_spheres::<f32x4>(rays, spheres)?;
    check_spheres::<f32x8>(rays, spheres)?;
    check_spheres::<f32x16>(rays, spheres)?;
    for n in 1..=rays.len().min(16) {
        check_spheres::<f32x16>(&rays[..n], spheres)?;
        check_spheres::<f32x8>(&rays[..n.min(8)], spheres)?;
        check_spheres::<f32x4>(&rays[..n.min(4)], spheres)?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Adversarial triangles and rays aimed at their vertices, edges, interiors, grazing, or
    /// anywhere; scenes scaled to huge and tiny coordinates; NaN/Inf sprinkled in.
    #[test]
    fn triangle_packets_equal_scalar_twin_bitwise(
        tris in prop::collection::vec(triangle(), 1..6),
        specs in prop::collection::vec(ray_spec(), 1..40),
        s in scale(),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|sp| aim_at_triangle(sp, &tris, s)).collect();
        check_all_widths_triangles(&rays, &pack_triangles(&tris))?;
    }

    /// Plain random rays and triangles in a box (the common case).
    #[test]
    fn triangle_packets_equal_scalar_twin_bitwise_random(
        tris in prop::collection::vec((tame(), tame(), tame()).prop_map(|(a, b, c)| [a, b, c]), 1..12),
        rays in prop::collection::vec((tame(), tame()).prop_map(|(o, d)| Ray::new(o, d)), 1..40),
    ) {
        check_all_widths_triangles(&rays, &pack_triangles(&tris))?;
    }

    /// Spheres near, far (1e2..1e6 radii away), huge, tiny and invalid; origins on the surface,
    /// rays skimming the rim.
    #[test]
    fn sphere_packets_equal_scalar_twin_bitwise(
        spheres in prop::collection::vec(sphere(), 1..6),
        specs in prop::collection::vec(sphere_ray_spec(), 1..40),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|sp| aim_at_sphere(sp, &spheres)).collect();
        check_all_widths_spheres(&rays, &pack_spheres(&spheres))?;
    }
}

/// Hand-picked cases the generators only reach by chance: exact vertex and edge hits on a shared
/// edge, a ray in the plane, t exactly at t_max and t_min.
#[test]
fn named_edge_cases_equal_scalar_twin() {
    let v = Vec3::new;
    let tris = [
        [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
        [v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)],
    ];
    let rays = vec![
        Ray::new(v(0.5, 0.5, 1.0), v(0.0, 0.0, -1.0)), // shared edge
        Ray::new(v(0.0, 0.0, 1.0), v(0.0, 0.0, -1.0)), // vertex
        Ray::new(v(1.0, 0.0, 1.0), v(0.0, 0.0, -1.0)), // shared vertex
        Ray::new(v(-1.0, 0.2, 0.0), v(1.0, 0.0, 0.0)), // in the plane
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 0.0, 1.0), // t == t_max
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 1.0, 2.0), // t == t_min
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 0.0, 0.99999994), // just short
        Ray::new(v(0.2, 0.2, 0.0), v(0.0, 0.0, -1.0)), // origin on the surface
    ];
    let packed = pack_triangles(&tris);
    check_all_widths_triangles(&rays, &packed).unwrap();
    // And the expected answers, so this test is not only self-consistency.
    let h: Vec<Option<Hit>> = rays
        .iter()
        .map(|r| query::closest_triangle(&RayLanes::single(r), &packed).lane(0))
        .collect();
    assert_eq!(h[0].map(|h| h.t), Some(1.0));
    assert_eq!(h[1].map(|h| (h.t, h.prim)), Some((1.0, 0)));
    assert_eq!(
        h[2].map(|h| (h.t, h.prim)),
        Some((1.0, 0)),
        "tie goes to the lower index"
    );
    assert_eq!(h[3], None, "a ray in the plane is a miss");
    assert_eq!(
        h[4].map(|h| h.t),
        Some(1.0),
        "t == t_max is inside the closed range"
    );
    assert_eq!(
        h[5].map(|h| h.t),
        Some(1.0),
        "t == t_min is inside the closed range"
    );
    assert_eq!(h[6], None);
    assert_eq!(h[7].map(|h| h.t), Some(0.0));
}
