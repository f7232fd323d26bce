//! Bad input gets a defined answer: NaN or infinite components, zero directions, zero-area
//! triangles, bad radii are misses in every kernel, never a panic, never a non-finite t. Each case
//! starts from a configuration that hits, so every assertion can fail.
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray_testkit as testkit;

use octoray::glam::Vec3;
use octoray::kernels::{MollerTrumbore, StableSphere};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, Sphere, VertexTriangle};
use octoray::textbook::{self, InsideTest};
use octoray::{f32x16, f32x4, f32x8};
use testkit::*;

const BAD: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// Every ray made from the seed ray by poisoning one component of origin, direction or range,
/// plus the zero direction.
fn bad_rays() -> Vec<(String, Ray)> {
    let mut out = vec![];
    for k in 0..3 {
        for b in BAD {
            let mut r = seed_ray();
            r.origin[k] = b;
            out.push((format!("origin[{k}] = {b}"), r));
            let mut r = seed_ray();
            r.dir[k] = b;
            out.push((format!("dir[{k}] = {b}"), r));
        }
    }
    let mut r = seed_ray();
    r.dir = Vec3::ZERO;
    out.push(("zero direction".into(), r));
    for (name, t_min, t_max) in [
        ("t_min NaN", f32::NAN, f32::INFINITY),
        ("t_max NaN", 0.0, f32::NAN),
        ("empty range", 1.0, 0.0),
    ] {
        let mut r = seed_ray();
        (r.t_min, r.t_max) = (t_min, t_max);
        out.push((name.into(), r));
    }
    out
}

fn bad_triangles() -> Vec<(String, VertexTriangle)> {
    let good = seed_triangles()[0];
    let [v0, v1, v2] = good.vertices();
    let mut out = vec![
        (
            "collinear".to_string(),
            VertexTriangle::new(v0, v1, v0 * 2.0 - v1),
        ),
        (
            "repeated vertex".to_string(),
            VertexTriangle::new(v0, v0, v2),
        ),
        (
            "all vertices equal".to_string(),
            VertexTriangle::new(v0, v0, v0),
        ),
    ];
    for vi in 0..3 {
        for k in 0..3 {
            for b in BAD {
                let mut t = good;
                let v = match vi {
                    0 => &mut t.v0,
                    1 => &mut t.v1,
                    _ => &mut t.v2,
                };
                v[k] = b;
                out.push((format!("v{vi}[{k}] = {b}"), t));
            }
        }
    }
    out
}

fn bad_spheres() -> Vec<(String, Sphere)> {
    let good = seed_spheres()[1];
    let mut out = vec![];
    for r in [
        -1.0,
        0.0,
        -0.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1e30,
    ] {
        out.push((format!("radius {r}"), Sphere::new(good.center, r)));
    }
    for k in 0..3 {
        for b in BAD {
            let mut s = good;
            s.center[k] = b;
            out.push((format!("center[{k}] = {b}"), s));
        }
    }
    out
}

#[test]
fn the_base_configurations_hit() {
    let (ray, tri, sph) = (seed_ray(), seed_triangles()[0], seed_spheres()[1]);
    assert!(textbook::intersect_triangle(&ray, &tri, InsideTest::Full).is_some());
    assert!(textbook::intersect_sphere(&ray, &sph).is_some());
    assert!(octoray::intersect_triangle(&ray, &tri.into()).is_some());
    assert!(octoray::intersect_sphere(&ray, &sph.into()).is_some());
}

fn assert_triangle_miss(what: &str, ray: &Ray, tri: &VertexTriangle) {
    for test in [InsideTest::Full, InsideTest::DominantAxis] {
        assert_eq!(
            textbook::intersect_triangle(ray, tri, test),
            None,
            "textbook {test:?}: {what}"
        );
    }
    let packed = PackedTriangle::from(*tri);
    assert_eq!(
        octoray::intersect_triangle(ray, &packed),
        None,
        "MT twin: {what}"
    );
}

fn assert_sphere_miss(what: &str, ray: &Ray, s: &Sphere) {
    assert_eq!(
        textbook::intersect_sphere(ray, s),
        None,
        "textbook sphere: {what}"
    );
    let packed = PackedSphere::from(*s);
    assert_eq!(
        octoray::intersect_sphere(ray, &packed),
        None,
        "stable twin: {what}"
    );
}

#[test]
fn bad_rays_miss_everywhere() {
    let (tri, sph) = (seed_triangles()[0], seed_spheres()[1]);
    for (what, ray) in bad_rays() {
        assert_triangle_miss(&what, &ray, &tri);
        assert_sphere_miss(&what, &ray, &sph);
    }
}

#[test]
fn bad_triangles_miss_everywhere() {
    for (what, tri) in bad_triangles() {
        assert_triangle_miss(&what, &seed_ray(), &tri);
    }
}

#[test]
fn bad_spheres_miss_everywhere() {
    for (what, s) in bad_spheres() {
        assert_sphere_miss(&what, &seed_ray(), &s);
    }
}

#[test]
fn bad_radius_is_packed_as_nan() {
    for r in [-1.0, 0.0, f32::NAN, f32::INFINITY, 1e30] {
        assert!(
            PackedSphere::new(Vec3::ZERO, r).radius_sq.is_nan(),
            "radius {r}"
        );
    }
    assert_eq!(PackedSphere::new(Vec3::ZERO, 3.0).radius_sq, 9.0);
}

/// A packet whose lanes alternate good and bad rays: good lanes hit exactly as alone, bad lanes
/// miss: no lane poisons its neighbours.
fn no_poisoning<L: Lanes>() {
    let tris = [PackedTriangle::from(seed_triangles()[0])];
    let spheres = [PackedSphere::from(seed_spheres()[1])];
    let alone_t = octoray::intersect_triangle(&seed_ray(), &tris[0]).unwrap();
    let alone_s = octoray::intersect_sphere(&seed_ray(), &spheres[0]).unwrap();
    for (what, bad) in bad_rays() {
        let rays: Vec<Ray> = (0..L::LANES)
            .map(|i| if i % 2 == 0 { seed_ray() } else { bad })
            .collect();
        let p = RayLanes::<L>::load(&rays);
        let ht = octoray::query::closest::<_, MollerTrumbore>(&p, &tris);
        let hs = octoray::query::closest::<_, StableSphere>(&p, &spheres);
        let occ = octoray::query::occluded::<_, MollerTrumbore>(&p, &tris).bitmask();
        for i in 0..L::LANES {
            if i % 2 == 0 {
                assert_eq!(ht.lane(i), Some(alone_t), "{what}: lane {i}");
                assert_eq!(hs.lane(i), Some(alone_s), "{what}: lane {i}");
                assert_eq!((occ >> i) & 1, 1, "{what}: lane {i}");
            } else {
                assert_eq!(ht.lane(i), None, "{what}: lane {i}");
                assert_eq!(hs.lane(i), None, "{what}: lane {i}");
                assert_eq!((occ >> i) & 1, 0, "{what}: lane {i}");
            }
        }
    }
}

#[test]
fn bad_lanes_do_not_poison_neighbours_4() {
    no_poisoning::<f32x4>();
}

#[test]
fn bad_lanes_do_not_poison_neighbours_8() {
    no_poisoning::<f32x8>();
}

#[test]
fn bad_lanes_do_not_poison_neighbours_16() {
    no_poisoning::<f32x16>();
}

/// Every query that writes into a caller's buffer answers an empty one (one tree and a scene):
/// nothing stored, and complete exactly when there was nothing to store, never a panic.
#[test]
fn empty_output_buffers_are_answers_not_panics() {
    use octoray::bvh::Bvh8;
    use octoray::kernels::Watertight;
    use octoray::scene::{Scene, Trace, Transform};
    use octoray::tree::{all_hits, all_hits_ray, nearest_within, overlapping, AllHits};
    // Unit triangles in the planes x = 0, 1, …, 9.
    let tris: Vec<VertexTriangle> = (0..10)
        .map(|i| {
            let x = i as f32;
            VertexTriangle::new(
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x, 1.0, 0.0),
                Vec3::new(x, 0.0, 1.0),
            )
        })
        .collect();
    let tree = Bvh8::build(&tris);
    let b = tree.as_ref();
    let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
    let g = scene.add_triangles(&tris).expect("build");
    scene.add_instance(&[g], Transform::IDENTITY, 1);
    scene.commit().expect("commit");
    let s = scene.as_ref();
    let through = Ray::new(Vec3::new(-1.0, 0.2, 0.2), Vec3::X);
    let past = Ray::new(Vec3::new(-1.0, 5.0, 5.0), Vec3::X);
    let answer = |f: AllHits| (f.stored, f.complete);
    for (ray, meets) in [(through, true), (past, false)] {
        let want = (0, !meets);
        assert_eq!(
            answer(all_hits_ray::<f32x8, Watertight>(b, &ray, None, &mut [])),
            want
        );
        let mut found = [AllHits {
            stored: 9,
            complete: false,
        }; 2];
        all_hits::<f32x8, Watertight>(b, &[ray, ray], &mut [], &mut found);
        assert_eq!(found.map(answer), [want; 2]);
        let f = s.all_hits_ray::<f32x8, Watertight, StableSphere>(&ray, !0, None, &mut []);
        assert_eq!(answer(f), want);
        let mut found = [AllHits {
            stored: 9,
            complete: false,
        }; 2];
        s.all_hits::<f32x8, Watertight, StableSphere>(&[ray, ray], !0, &mut [], &mut found);
        assert_eq!(found.map(answer), [want; 2]);
    }
    for (p, radius, near) in [
        (Vec3::new(4.5, 0.2, 0.2), 1.0, true),
        (Vec3::splat(50.0), 1.0, false),
    ] {
        assert_eq!(answer(nearest_within(b, p, radius, &mut [])), (0, !near));
        assert_eq!(answer(s.nearest_within(p, radius, !0, &mut [])), (0, !near));
        let (lo, hi) = (p - Vec3::splat(0.6), p + Vec3::splat(0.6));
        assert_eq!(answer(overlapping(b, lo, hi, None, &mut [])), (0, !near));
        assert_eq!(answer(s.overlapping(lo, hi, !0, None, &mut [])), (0, !near));
    }
}
