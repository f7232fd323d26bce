//! `octoray-testkit`: what octoray's tests, benches and accuracy example share (never
//! published). The seven seed problems and ulp arithmetic (here), the exact big-integer oracle
//! ([`oracle`]), accuracy measurements against it ([`accuracy`]), closed jittered meshes and the
//! crack test ([`mesh`]), proptest strategies ([`strategies`]), the icosphere generator
//! ([`icosphere`]) and the pinhole camera ([`camera`]) the demo and the scene benches use; the
//! case-count scale of the random tests ([`cases`]).
#![forbid(unsafe_code)]

pub mod accuracy;
pub mod camera;
pub mod cases;
pub mod icosphere;
pub mod mesh;
pub mod oracle;
pub mod rays;
pub mod spawn;
pub mod stored;
pub mod strategies;
pub mod trees;

use octoray::glam::Vec3;
use octoray::prim::{Ray, Sphere, VertexTriangle};

/// The ray every seed problem uses.
pub fn seed_ray() -> Ray {
    Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0))
}

/// The three seed triangles (problems.md, ray-triangle 1..3).
pub fn seed_triangles() -> [VertexTriangle; 3] {
    let v = Vec3::new;
    [
        VertexTriangle::new(v(0.0, 6.0, 7.0), v(-3.0, 1.0, 5.0), v(-2.0, 1.0, 4.0)),
        VertexTriangle::new(v(-2.0, 1.0, 2.0), v(-1.0, 1.0, 1.0), v(1.0, 6.0, 4.0)),
        VertexTriangle::new(v(0.0, 0.0, 0.0), v(2.0, 4.0, 6.0), v(1.0, 0.0, 0.0)),
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

/// Distance in f32 ulps between an f32 and an exact value given in f64: the distance from `a`
/// to the f32 nearest `exact`, plus one half-ulp step when `exact` is not representable.
pub fn ulp_err(a: f32, exact: f64) -> f64 {
    let near = exact as f32;
    let ulp = f32::from_bits(near.abs().to_bits() + 1) as f64 - near.abs() as f64;
    (a as f64 - exact).abs() / ulp
}

/// A small deterministic generator (SplitMix64) for fixed-seed sweeps whose counts are printed.
pub struct Rng(pub u64);

impl Rng {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        let u = (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * u
    }
    /// Uniform in [-h, h)³.
    pub fn vec3(&mut self, h: f32) -> Vec3 {
        Vec3::new(self.range(-h, h), self.range(-h, h), self.range(-h, h))
    }
}

/// Every `.rs` file under `dir`, recursively (for tests that read the sources).
pub fn rust_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).expect("read_dir") {
        let p = e.expect("entry").path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}
