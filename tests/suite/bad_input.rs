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
