//! Benchmark workloads: rays through a window against stacks of primitives, with the fraction
//! of ray-primitive tests that hit geometrically chosen (0 %, ~50 %, 100 %).

use glam::Vec3;
use octoray::prim::{PackedSphere, PackedTriangle, Ray, VertexTriangle};

/// Deterministic generator (an LCG) so every run and every peer sees the same data.
pub struct Lcg(pub u64);
impl Lcg {
    /// Uniform in [-1, 1).
    pub fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

/// Fraction of ray-primitive tests that hit geometrically.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitRate {
    /// Every primitive lies outside the bundle of rays.
    None,
    /// Each primitive covers about half of the bundle.
    Half,
    /// Every primitive covers the whole bundle.
    All,
}

impl HitRate {
    /// Every rate, lowest first.
    pub const ALL: [HitRate; 3] = [HitRate::None, HitRate::Half, HitRate::All];
    /// The benchmark id's suffix.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "hit0",
            Self::Half => "hit50",
            Self::All => "hit100",
        }
    }
}

/// Rays and primitives for one benchmark.
pub struct Workload {
    /// The rays.
    pub rays: Vec<Ray>,
    /// The triangles, as vertices.
    pub tris: Vec<[Vec3; 3]>,
    /// The spheres: centre, radius.
    pub spheres: Vec<(Vec3, f32)>,
}

impl Workload {
    /// `n_rays` rays from near (0, 0, −5) through the window [-1, 1]² at z = 0, against
    /// `n_prims` triangles and spheres stacked at depths 1…3 in random order.
    pub fn new(rate: HitRate, n_rays: usize, n_prims: usize, seed: u64) -> Self {
        let mut r = Lcg(seed);
        let rays = (0..n_rays)
            .map(|_| {
                let o = Vec3::new(0.05 * r.f(), 0.05 * r.f(), -5.0);
                let through = Vec3::new(r.f(), r.f(), 0.0);
                Ray::new(o, through - o)
            })
            .collect();
        let mut tris = Vec::with_capacity(n_prims);
        let mut spheres = Vec::with_capacity(n_prims);
        for _ in 0..n_prims {
            let z = 2.0 + r.f();
            // The bundle's half-width at depth z: the window [-1, 1] scaled by (z + 5)/5.
            let w = (z + 5.0) / 5.0;
            let tri = match rate {
                HitRate::All => [
                    Vec3::new(-4.0 * w, -4.0 * w, z),
                    Vec3::new(8.0 * w, -4.0 * w, z),
                    Vec3::new(-4.0 * w, 8.0 * w, z),
                ],
                HitRate::None => [
                    Vec3::new(3.0 * w, 3.0 * w, z),
                    Vec3::new(4.0 * w, 3.0 * w, z),
                    Vec3::new(3.0 * w, 4.0 * w, z),
                ],
                HitRate::Half => {
                    // A big triangle with one edge through the bundle's axis at a random angle.
                    let a = std::f32::consts::PI * r.f();
                    let (s, c) = a.sin_cos();
                    let (along, across) = (
                        Vec3::new(c, s, 0.0) * (10.0 * w),
                        Vec3::new(-s, c, 0.0) * (10.0 * w),
                    );
                    let base = Vec3::new(0.0, 0.0, z);
                    [base - along, base + along, base + across]
                }
            };
            tris.push(tri);
            let sphere = match rate {
                HitRate::All => (Vec3::new(0.0, 0.0, z + 10.0 * w), 10.0 * w + 0.5),
                HitRate::None => (Vec3::new(4.0 * w, 4.0 * w, z), 0.5 * w),
                HitRate::Half => (Vec3::new(0.0, 0.0, z), 0.8 * w),
            };
            spheres.push(sphere);
        }
        Self {
            rays,
            tris,
            spheres,
        }
    }

    /// The triangles in the standard tier's layout.
    pub fn packed(&self) -> Vec<PackedTriangle> {
        self.tris
            .iter()
            .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
            .collect()
    }
    /// The triangles as vertices.
    pub fn vertex(&self) -> Vec<VertexTriangle> {
        self.tris
            .iter()
            .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
            .collect()
    }
    /// The spheres in the kernels' layout.
    pub fn packed_spheres(&self) -> Vec<PackedSphere> {
        self.spheres
            .iter()
            .map(|&(c, r)| PackedSphere::new(c, r))
            .collect()
    }
    /// Number of ray-primitive tests in one pass over the workload.
    pub fn tests(&self) -> u64 {
        (self.rays.len() * self.tris.len()) as u64
    }
}
