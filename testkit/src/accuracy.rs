//! The accuracy harness shared by `tests/suite/accuracy.rs` and `examples/accuracy.rs`: tiers, case
//! sets, per-case error margins, and statistics against the exact oracle.

use crate::oracle::{self, SphereTruth};
use crate::Rng;
use glam::Vec3;
use octoray::hit::Hit;
use octoray::intersect;
use octoray::kernels::{Exact, MollerTrumbore, NaiveSphere, StableSphere, Watertight};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, Sphere, VertexTriangle};
use octoray::textbook::{self, InsideTest, TextbookHit};

/// f32 unit roundoff.
pub const EPS: f64 = 1.0 / 16_777_216.0;

/// A textbook hit as a `Hit` (the textbook reports t and the point, no barycentrics).
fn textbook_hit(h: TextbookHit) -> Hit {
    Hit {
        t: h.t,
        u: 0.0,
        v: 0.0,
        prim: 0,
        geom: 0,
        inst: 0,
    }
}

/// A ray and a triangle.
#[derive(Clone, Copy, Debug)]
pub struct TriCase {
    pub ray: Ray,
    pub v: [Vec3; 3],
}

impl TriCase {
    /// First-order condition of the hit/miss decision: how many f32 roundings of the inputs'
    /// scale one barycentric unit is worth. The barycentric error of every tier is about
    /// ε·|o − v0| / (h·|cos θ|) (h: the triangle's smallest height, θ: the ray's angle to the
    /// normal) plus ε·(|v0| / h) for translated triangles.
    pub fn condition(&self) -> f64 {
        let [a, b, c] = self.v.map(|v| v.as_dvec3());
        let (o, d) = (self.ray.origin.as_dvec3(), self.ray.dir.as_dvec3());
        let n = (b - a).cross(c - a);
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let h = n.length() / longest;
        let cos = (d.normalize().dot(n.normalize())).abs();
        let dist = (o - a).length() + longest + a.length().max(b.length()).max(c.length());
        dist / (h * cos)
    }
    /// The barycentric margin within which tiers may disagree with the exact answer.
    pub fn margin(&self) -> f64 {
        64.0 * EPS * self.condition()
    }

    /// The scale of t's rounding error: t = (s·n)/(d·n) loses ε relative to the larger of t and
    /// the origin's distance to the triangle (in units of |d|), amplified by 1/|cos θ|.
    pub fn t_scale(&self, t_exact: f64) -> f64 {
        let [a, b, c] = self.v.map(|v| v.as_dvec3());
        let (o, d) = (self.ray.origin.as_dvec3(), self.ray.dir.as_dvec3());
        let n = (b - a).cross(c - a).normalize();
        let cos = d.normalize().dot(n).abs();
        let reach = ((o - a).length() + (b - a).length() + (c - a).length()) / d.length();
        t_exact.abs().max(reach) / cos
    }

    /// How far the hit point `o + t·d` (formed exactly, from the reported f32 `t`) lies off the
    /// triangle's plane, in f32 steps at the point's largest coordinate: the error a renderer's
    /// next ray inherits when it spawns from the point (a plane error, not a `t` error, so it is
    /// comparable across triangles of any shape and rays of any angle).
    pub fn plane_ulps(&self, t: f32) -> f64 {
        let [a, b, c] = self.v.map(|v| v.as_dvec3());
        let (o, d) = (self.ray.origin.as_dvec3(), self.ray.dir.as_dvec3());
        let n = (b - a).cross(c - a).normalize();
        let p = o + d * f64::from(t);
        let off = (p - a).dot(n).abs();
        let big = p.abs().max_element().max(f64::from(f32::MIN_POSITIVE));
        // The f32 step at `big`: 2^(⌊log2 big⌋ − 23).
        let step = 2f64.powi(big.log2().floor() as i32 - 23);
        off / step
    }
}

/// A triangle tier as measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriTier {
    Textbook,
    Standard,
    Watertight,
    Exact,
    F64,
    F64Watertight,
}

impl TriTier {
    pub const ALL: [TriTier; 6] = [
        Self::Textbook,
        Self::Standard,
        Self::Watertight,
        Self::Exact,
        Self::F64,
        Self::F64Watertight,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Self::Textbook => "textbook (scalar)",
            Self::Standard => "standard (MT)",
            Self::Watertight => "watertight",
            Self::Exact => "exact",
            Self::F64 => "f64 (MT)",
            Self::F64Watertight => "f64 watertight",
        }
    }

    /// Whether the tier reads the packed (v0, e1, e2) form; else the vertices.
    pub fn packed(self) -> bool {
        matches!(self, Self::Standard | Self::F64)
    }

    /// The tier's answer for one case.
    pub fn run(self, c: &TriCase) -> Option<Hit> {
        let [a, b, v2] = c.v;
        let packed = PackedTriangle::new(a, b, v2);
        let verts = VertexTriangle::new(a, b, v2);
        match self {
            Self::Textbook => textbook::intersect_triangle(
                &c.ray,
                &VertexTriangle::new(a, b, v2),
                InsideTest::Full,
            )
            .map(textbook_hit),
            Self::Standard => intersect::<f32, MollerTrumbore>(&c.ray, &packed),
            Self::Watertight => intersect::<f32, Watertight>(&c.ray, &verts),
            Self::Exact => intersect::<f32, Exact>(&c.ray, &verts),
            Self::F64 => intersect::<f64, MollerTrumbore>(&c.ray, &packed),
            Self::F64Watertight => intersect::<f64, Watertight>(&c.ray, &verts),
        }
    }
}

/// Agreement statistics of one tier on one case set.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub cases: usize,
    /// Degenerate by contract (parallel, zero area, bad input): must be misses.
    pub degenerate: usize,
    pub exact_hits: usize,
    /// Hit/miss differs from the exact answer outside the margin.
    pub wrong: usize,
    /// Hit/miss differs inside the margin (allowed, counted).
    pub in_margin: usize,
    /// Reported hits whose t is not finite or outside [t_min, t_max] (must be 0).
    pub bad_t: usize,
    /// Hits on the wrong side of the origin (exact t < t_min) — counted separately.
    pub behind: usize,
    /// f32 steps between the reported and the exact t, for hits both agree on.
    pub ulps: Vec<u64>,
    /// |t − t_exact| / (ε · t_scale): the error relative to the problem's own scale.
    pub scaled: Vec<f64>,
    /// Distance of the hit point off the plane in f32 steps ([`TriCase::plane_ulps`]), for hits
    /// both agree on (empty for spheres).
    pub plane: Vec<f64>,
}

impl Stats {
    pub fn percentile(&self, p: f64) -> u64 {
        if self.ulps.is_empty() {
            return 0;
        }
        let mut v = self.ulps.clone();
        v.sort_unstable();
        v[((v.len() - 1) as f64 * p).round() as usize]
    }
    pub fn max_ulps(&self) -> u64 {
        self.ulps.iter().copied().max().unwrap_or(0)
    }
    pub fn max_scaled(&self) -> f64 {
        self.scaled.iter().copied().fold(0.0, f64::max)
    }
    /// Percentile `p` of the off-plane distances (0 when there are none).
    pub fn plane_percentile(&self, p: f64) -> f64 {
        if self.plane.is_empty() {
            return 0.0;
        }
        let mut v = self.plane.clone();
        v.sort_unstable_by(f64::total_cmp);
        v[((v.len() - 1) as f64 * p).round() as usize]
    }
    pub fn merge(&mut self, o: &Stats) {
        self.cases += o.cases;
        self.degenerate += o.degenerate;
        self.exact_hits += o.exact_hits;
        self.wrong += o.wrong;
        self.in_margin += o.in_margin;
        self.bad_t += o.bad_t;
        self.behind += o.behind;
        self.ulps.extend_from_slice(&o.ulps);
        self.scaled.extend_from_slice(&o.scaled);
        self.plane.extend_from_slice(&o.plane);
    }
}

/// Measures one tier on a case set against the exact oracle.
pub fn measure_triangles(tier: TriTier, cases: &[TriCase]) -> Stats {
    measure_triangles_with(|c| tier.run(c), tier.packed(), cases)
}

/// Measures any ray-triangle test (`run`) against the exact oracle for the packed (v0, e1, e2)
/// triangle (`packed`) or for the vertices.
pub fn measure_triangles_with(
    run: impl Fn(&TriCase) -> Option<Hit>,
    packed: bool,
    cases: &[TriCase],
) -> Stats {
    let mut s = Stats {
        cases: cases.len(),
        ..Stats::default()
    };
    for c in cases {
        let got = run(c);
        if let Some(h) = got {
            if !(h.t.is_finite() && h.t >= c.ray.t_min && h.t <= c.ray.t_max) {
                s.bad_t += 1;
            }
        }
        let truth = if packed {
            oracle::triangle_packed(&c.ray, c.v)
        } else {
            oracle::triangle(&c.ray, c.v)
        };
        if truth.degenerate {
            s.degenerate += 1;
            if got.is_some() {
                s.wrong += 1;
            }
            continue;
        }
        s.exact_hits += usize::from(truth.hit);
        if let Some(h) = got {
            if truth.t_cmp(c.ray.t_min.max(0.0)) == std::cmp::Ordering::Less && c.ray.t_min >= 0.0 {
                s.behind += 1;
            }
            if truth.hit {
                s.ulps.push(truth.t_ulps(h.t));
                s.scaled
                    .push((f64::from(h.t) - truth.t).abs() / (EPS * c.t_scale(truth.t)));
                s.plane.push(c.plane_ulps(h.t));
            }
        }
        if got.is_some() != truth.hit {
            if truth.edge_distance() > c.margin() {
                s.wrong += 1;
            } else {
                s.in_margin += 1;
            }
        }
    }
    s
}

/// A random triangle in [-1, 1]³ with edges ≥ 0.2 and no angle below ~3°.
fn good_triangle(rng: &mut Rng) -> [Vec3; 3] {
    loop {
        let v = [rng.vec3(1.0), rng.vec3(1.0), rng.vec3(1.0)];
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let n = e1.cross(e2).length();
        let l = [e1.length(), e2.length(), (v[2] - v[1]).length()];
        if l.iter().all(|&x| x > 0.2) && n > 0.05 * l[0] * l[1] {
            return v;
        }
    }
}

/// A point of the triangle's plane with barycentrics (u, v).
fn point(v: [Vec3; 3], u: f32, w: f32) -> Vec3 {
    v[0] + (v[1] - v[0]) * u + (v[2] - v[0]) * w
}

/// Random well-conditioned cases: origins in [-4, 4]³, aimed at barycentrics in [-0.25, 1.25].
pub fn random_cases(seed: u64, n: usize) -> Vec<TriCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let v = good_triangle(&mut rng);
            let o = rng.vec3(4.0);
            let target = point(v, rng.range(-0.25, 1.25), rng.range(-0.25, 1.25));
            TriCase {
                ray: Ray::new(o, target - o),
                v,
            }
        })
        .collect()
}

/// Rays aimed exactly at vertices and at points of edges (the adversarial half of hit/miss).
pub fn edge_cases(seed: u64, n: usize) -> Vec<TriCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let v = good_triangle(&mut rng);
            let o = rng.vec3(4.0);
            let k = (rng.next_u64() % 3) as usize;
            let target = if i % 2 == 0 {
                v[k]
            } else {
                v[k] + (v[(k + 1) % 3] - v[k]) * rng.range(0.0, 1.0)
            };
            TriCase {
                ray: Ray::new(o, target - o),
                v,
            }
        })
        .collect()
}

/// Grazing rays: at `angle` radians to the triangle's plane, aimed at barycentrics in
/// [-0.25, 1.25], at skinny (aspect up to 1:20) and regular triangles.
pub fn grazing_cases(seed: u64, n: usize, angle: f32) -> Vec<TriCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let skinny = if i % 2 == 0 { 0.05 } else { 1.0 };
            let v = [
                Vec3::new(-1.0, -skinny, 0.0),
                Vec3::new(1.0, -skinny, 0.0),
                Vec3::new(rng.range(-1.0, 1.0), skinny, 0.0),
            ];
            let target = point(v, rng.range(-0.25, 1.25), rng.range(-0.25, 1.25));
            let az = rng.range(0.0, std::f32::consts::TAU);
            let (ca, sa) = (libm::cosf(angle), libm::sinf(angle));
            let dir = Vec3::new(libm::cosf(az) * ca, libm::sinf(az) * ca, -sa);
            let o = target - dir * rng.range(0.5, 3.0);
            // A random rotation, so the plane is not axis-aligned and nothing is exact.
            let (axis, ang) = (rng.vec3(1.0).normalize(), rng.range(0.0, 3.0));
            let rot = |p: Vec3| rotate(p, axis, ang);
            let (v, o, target) = (v.map(rot), rot(o), rot(target));
            TriCase {
                ray: Ray::new(o, target - o),
                v,
            }
        })
        .collect()
}

/// Long thin triangles of aspect ratio `aspect` (longest edge over height), randomly rotated and
/// placed up to 1e3 from the origin, hit by rays from up to 10 lengths away aimed at random points
/// of the plane near the triangle, at its vertices, or at f32 points of its edges.
pub fn thin_cases(seed: u64, n: usize, aspect: f32) -> Vec<TriCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let len = rng.range(1.0, 100.0);
            let h = len / aspect;
            let v = [
                Vec3::ZERO,
                Vec3::new(len, 0.0, 0.0),
                Vec3::new(rng.range(-0.5, 1.5) * len, h, 0.0),
            ];
            let (axis, ang) = (rng.vec3(1.0).normalize(), rng.range(0.0, 3.0));
            let shift = rng.vec3(1000.0);
            let v = v.map(|p| rotate(p, axis, ang) + shift);
            let k = (rng.next_u64() % 3) as usize;
            let target = match i % 3 {
                0 => point(v, rng.range(-0.25, 1.25), rng.range(-0.25, 1.25)),
                1 => v[k],
                _ => v[k] + (v[(k + 1) % 3] - v[k]) * rng.range(0.0, 1.0),
            };
            let o = target + rng.vec3(10.0 * len);
            TriCase {
                ray: Ray::new(o, target - o),
                v,
            }
        })
        .collect()
}

/// Short rays at large triangles, as a renderer's spawned rays meet walls, floors and trim:
/// triangles with edges of 1…20 and aspect ratio `aspect` (longest edge over height; 1 for a
/// plain triangle) placed up to 20 from the world origin (axis-aligned, as architecture is, or
/// randomly rotated), origins 1e-4…1e-1 edge lengths off the plane above a point of the
/// triangle, aimed at a point of the plane within a few of those heights, so `t` is far smaller
/// than the distance to the vertices.
pub fn near_cases(seed: u64, n: usize, aspect: f32, axis_aligned: bool) -> Vec<TriCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let len = rng.range(1.0, 20.0);
            let v = [
                Vec3::ZERO,
                Vec3::new(len, rng.range(-0.3, 0.3) * len / aspect, 0.0),
                Vec3::new(rng.range(-0.3, 1.3) * len, len / aspect, 0.0),
            ];
            let (u, w) = (rng.range(0.05, 0.6), rng.range(0.05, 0.35));
            let foot = point(v, u, w);
            let h = len * 10f32.powf(rng.range(-4.0, -1.0));
            let side = if rng.next_u64().is_multiple_of(2) {
                1.0
            } else {
                -1.0
            };
            let o = foot + Vec3::new(0.0, 0.0, side * h);
            let target = foot + Vec3::new(rng.range(-3.0, 3.0) * h, rng.range(-3.0, 3.0) * h, 0.0);
            let (axis, ang) = if axis_aligned {
                // One of the axis-aligned orientations: the plane z = 0 turned onto x = 0 or y = 0.
                match rng.next_u64() % 3 {
                    0 => (Vec3::X, 0.0),
                    1 => (Vec3::X, core::f32::consts::FRAC_PI_2),
                    _ => (Vec3::Y, core::f32::consts::FRAC_PI_2),
                }
            } else {
                (rng.vec3(1.0).normalize(), rng.range(0.0, 3.0))
            };
            let shift = rng.vec3(20.0);
            let place = |p: Vec3| rotate(p, axis, ang) + shift;
            let (o, target) = (place(o), place(target));
            TriCase {
                ray: Ray::new(o, target - o),
                v: v.map(place),
            }
        })
        .collect()
}

/// Rodrigues' rotation of `p` about the unit `axis` by `angle`, in plain f32 arithmetic (glam's
/// `Quat` is SIMD-backed and fuses multiply-adds on FMA builds, which would make the generated
/// cases differ between builds).
fn rotate(p: Vec3, axis: Vec3, angle: f32) -> Vec3 {
    let (s, c) = (libm::sinf(angle), libm::cosf(angle));
    let dot = axis.x * p.x + axis.y * p.y + axis.z * p.z;
    let cross = Vec3::new(
        axis.y * p.z - axis.z * p.y,
        axis.z * p.x - axis.x * p.z,
        axis.x * p.y - axis.y * p.x,
    );
    p * c + cross * s + axis * (dot * (1.0 - c))
}

/// Random cases translated by `offset` along (1, 1, 1) with the scene scaled by `scale`.
pub fn translated_cases(seed: u64, n: usize, offset: f32, scale: f32) -> Vec<TriCase> {
    let shift = Vec3::splat(offset);
    random_cases(seed, n)
        .into_iter()
        .map(|c| {
            let map = |p: Vec3| p * scale + shift;
            let (o, target) = (map(c.ray.origin), map(c.ray.origin + c.ray.dir));
            TriCase {
                ray: Ray::new(o, target - o),
                v: c.v.map(map),
            }
        })
        .collect()
}

/// A ray and a sphere (centre, radius).
#[derive(Clone, Copy, Debug)]
pub struct SphereCase {
    pub ray: Ray,
    pub center: Vec3,
    pub radius: f32,
}

impl SphereCase {
    fn packed(&self) -> PackedSphere {
        PackedSphere::new(self.center, self.radius)
    }
    /// Margin on the relative discriminant Δ/(a r²): the stable form's first-order error,
    /// ε·(1 + |f|/r), times 64.
    pub fn margin(&self) -> f64 {
        let f = (self.ray.origin - self.center).length() as f64;
        64.0 * EPS * (1.0 + f / self.radius as f64)
    }

    /// The scale of t's rounding error: ε·(|f| + r)/|d|, amplified near tangency by
    /// 1/√(Δ/(a r²)) (the roots' sensitivity to the discriminant; `rel_disc` from the oracle).
    pub fn t_scale(&self, t_exact: f64, rel_disc: f64) -> f64 {
        let f = (self.ray.origin - self.center).as_dvec3().length();
        let d = self.ray.dir.as_dvec3().length();
        let r = f64::from(self.radius);
        t_exact.abs().max((f + r) / d) / rel_disc.abs().sqrt().min(1.0)
    }
}

/// A sphere tier as measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SphereTier {
    Textbook,
    Naive,
    Stable,
    F64,
}

impl SphereTier {
    pub const ALL: [SphereTier; 4] = [Self::Textbook, Self::Naive, Self::Stable, Self::F64];
    pub fn name(self) -> &'static str {
        match self {
            Self::Textbook => "textbook sphere (scalar)",
            Self::Naive => "naive sphere",
            Self::Stable => "stable sphere",
            Self::F64 => "f64 stable sphere",
        }
    }
    pub fn run(self, c: &SphereCase) -> Option<Hit> {
        let p = c.packed();
        match self {
            Self::Textbook => textbook::intersect_sphere(&c.ray, &Sphere::new(c.center, c.radius))
                .map(textbook_hit),
            Self::Naive => intersect::<f32, NaiveSphere>(&c.ray, &p),
            Self::Stable => intersect::<f32, StableSphere>(&c.ray, &p),
            Self::F64 => intersect::<f64, StableSphere>(&c.ray, &p),
        }
    }
}

/// Measures a sphere tier. A case's exact answer: the line meets the packed sphere and a root lies
/// in range; `wrong` counts hit/miss differences outside the margin on the discriminant.
pub fn measure_spheres(tier: SphereTier, cases: &[SphereCase]) -> Stats {
    let mut s = Stats {
        cases: cases.len(),
        ..Stats::default()
    };
    for c in cases {
        let got = tier.run(c);
        if let Some(h) = got {
            if !(h.t.is_finite() && h.t >= c.ray.t_min && h.t <= c.ray.t_max) {
                s.bad_t += 1;
            }
        }
        let truth: SphereTruth = oracle::sphere(&c.ray, c.center, c.packed().radius_sq);
        if truth.degenerate {
            s.degenerate += 1;
            s.wrong += usize::from(got.is_some());
            continue;
        }
        // The cases are built with t ranges [0, inf) and the near root clearly positive or the
        // origin clearly inside, so the exact answer is "the line meets the sphere ahead".
        let ahead = truth.roots[1] >= 0.0;
        let hit = truth.line_hits && ahead;
        s.exact_hits += usize::from(hit);
        if let (Some(h), true) = (got, hit) {
            if truth.rel_disc.abs() > c.margin() {
                s.ulps.push(truth.t_ulps(h.t));
                let t_exact = if truth.inside() {
                    truth.roots[1]
                } else {
                    truth.roots[0]
                };
                s.scaled.push(
                    (f64::from(h.t) - t_exact).abs() / (EPS * c.t_scale(t_exact, truth.rel_disc)),
                );
            }
        }
        if got.is_some() != hit {
            if truth.rel_disc.abs() > c.margin() {
                s.wrong += 1;
            } else {
                s.in_margin += 1;
            }
        }
    }
    s
}

/// Rays at spheres of radius `r` from `dist`·r away, aimed within ±1.5 r of the centre (about
/// half hit).
pub fn distant_sphere_cases(seed: u64, n: usize, dist: f32) -> Vec<SphereCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let r = rng.range(0.5, 2.0);
            let center = rng.vec3(10.0);
            let dir_out = rng.vec3(1.0).normalize();
            let o = center + dir_out * (dist * r);
            let target = center + rng.vec3(1.5 * r);
            SphereCase {
                ray: Ray::new(o, target - o),
                center,
                radius: r,
            }
        })
        .collect()
}

/// Rays from inside and near the surface of unit-ish spheres.
pub fn near_sphere_cases(seed: u64, n: usize) -> Vec<SphereCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let r = rng.range(0.5, 2.0);
            let center = rng.vec3(2.0);
            let o = center + rng.vec3(3.0 * r);
            SphereCase {
                ray: Ray::new(o, rng.vec3(1.0)),
                center,
                radius: r,
            }
        })
        .collect()
}

/// Rays at tiny spheres and with tiny directions, down to where `|d|·r` underflows: radii from
/// `PackedSphere::MIN_RADIUS` to 1e-3, `|d|` from 1.2e-19 to 1, origins 1 to 1e4 radii from
/// the centre, aimed within ±1.5 r of it, around centres at 0 to 1e3 radii from the origin.
pub fn tiny_sphere_cases(seed: u64, n: usize) -> Vec<SphereCase> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let r = libm::powf(10.0, rng.range(-18.9, -3.0)).max(PackedSphere::MIN_RADIUS);
            let (away, dist) = (
                libm::powf(10.0, rng.range(0.0, 3.0)),
                libm::powf(10.0, rng.range(0.0, 4.0)),
            );
            let center = rng.vec3(r * away);
            let o = center + rng.vec3(1.0).normalize() * (r * dist);
            let target = center + rng.vec3(1.5 * r);
            let len = libm::powf(10.0, rng.range(-18.9, 0.0));
            SphereCase {
                ray: Ray::new(o, (target - o).normalize() * len),
                center,
                radius: r,
            }
        })
        .collect()
}
