//! Shared test data and helpers: the seven seed problems and ulp arithmetic.
#![allow(dead_code)]

pub mod strategies;

use octoray::glam::Vec3;
use octoray::{Ray, Sphere, Triangle};

/// The ray every seed problem uses.
pub fn seed_ray() -> Ray {
    Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0))
}

/// The three seed triangles (problems.md, ray-triangle 1..3).
pub fn seed_triangles() -> [Triangle; 3] {
    let v = Vec3::new;
    [
        Triangle::new(v(0.0, 6.0, 7.0), v(-3.0, 1.0, 5.0), v(-2.0, 1.0, 4.0)),
        Triangle::new(v(-2.0, 1.0, 2.0), v(-1.0, 1.0, 1.0), v(1.0, 6.0, 4.0)),
        Triangle::new(v(0.0, 0.0, 0.0), v(2.0, 4.0, 6.0), v(1.0, 0.0, 0.0)),
    ]
}

/// The four seed spheres (problems.md, ray-sphere 1..4).
pub fn seed_spheres() -> [Sphere; 4] {
    let v = Vec3::new;
    [
        Sphere::new(v(0.0, 0.0, 0.0), 10.0),
        Sphere::new(v(-3.0, 0.0, 2.0), 1.0),
        Sphere::new(v(-5.0, -6.0, -7.0), 2.0),
        Sphere::new(v(0.0, 0.0, -1.0), 3.0),
    ]
}

/// Exact (to f64 precision, far below an f32 ulp) answers of the two sphere hits.
pub fn seed_sphere_t_exact() -> [f64; 2] {
    [(22.0 + 4908f64.sqrt()) / 28.0, 1.0 - 1.0 / 14f64.sqrt()]
}

/// Maps f32 bits to a monotone integer line (+0 and −0 both map to 0).
pub fn ordered(x: f32) -> i64 {
    let b = x.to_bits() as i32;
    if b < 0 {
        -((b & 0x7fff_ffff) as i64)
    } else {
        b as i64
    }
}

/// Distance in f32 ulps between two finite floats.
pub fn ulp_diff(a: f32, b: f32) -> u64 {
    (ordered(a) - ordered(b)).unsigned_abs()
}

/// Distance in f32 ulps between an f32 and an exact value given in f64: the distance from `a`
/// to the f32 nearest `exact`, plus one half-ulp step when `exact` is not representable.
pub fn ulp_err(a: f32, exact: f64) -> f64 {
    let near = exact as f32;
    let ulp = f32::from_bits(near.abs().to_bits() + 1) as f64 - near.abs() as f64;
    (a as f64 - exact).abs() / ulp
}
