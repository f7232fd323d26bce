//! Layouts that store more per triangle than the standard tier's [`PackedTriangle`], measured in
//! the trade report as candidates for a tier that is faster and honest about its error.
//!
//! [`PlaneTriangle`] stores three planes (12 floats): the triangle's own, and the two whose values
//! at a point of that plane are the point's barycentric weights of `v1` and `v2`. Two published
//! tests read them:
//! - [`havel_herout`]: Havel & Herout 2010, "Yet Faster Ray-Triangle Intersection (Using
//!   SSE4)": the hit point scaled by the determinant, then the two planes at it; decisions before
//!   the division.
//! - [`baldwin_weber`]: Baldwin & Weber 2016, "Fast Ray-Triangle Intersections by Coordinate
//!   Transformation" (JCGT 5(3)), in its general 12-float form: the three planes are the rows of
//!   an affine map taking the triangle to the unit triangle in `z = 0`; origin and direction are
//!   mapped, `t` divided first, the barycentrics formed from it.
//!
//! - [`baldwin_weber_v0`]: the same on [`FrameTriangle`], relative to `v0` (its rounding then
//!   scales with `|o − v0|`, as Möller-Trumbore's does, not with `|o|` and `|v0|`).
//!
//! All are generic over octoray's lanes (`L = f32` is the scalar twin the accuracy columns use)
//! and keep what the tiers' contract asks of every hit: an active lane, `t` finite and in
//! `[t_min, t_max]`, a miss on a zero-area triangle (its planes are NaN). Neither has the standard
//! tier's determinant-noise bound, so rays within rounding of the plane can report hits.
//!
//! [`PackedTriangle`]: octoray::prim::PackedTriangle

use glam::Vec3;
use octoray::hit::{t_in_range, LanesHit};
use octoray::lanes::{LaneMask, Lanes, V3};
use octoray::prim::{Ray, RayLanes};

/// A triangle as three planes `(a, b, c, w)`, each evaluated at `p` as `a·x + b·y + c·z + w`:
/// the triangle's plane (the unit normal, `w = −n·v0`), then the planes giving the barycentric
/// weights of `v1` and `v2` (the rows of the inverse of `[e1 e2 n]`). Formed in f64 from the
/// vertices and rounded once; all NaN for a triangle of zero area or with a non-finite vertex.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlaneTriangle {
    /// The triangle's plane: unit normal and offset.
    pub n: [f32; 4],
    /// Barycentric weight of `v1` as a plane: `(e2 × n)/|n|²` and offset.
    pub b1: [f32; 4],
    /// Barycentric weight of `v2` as a plane: `(n × e1)/|n|²` and offset.
    pub b2: [f32; 4],
}

impl PlaneTriangle {
    /// The three planes of triangle `v`.
    pub fn new(v: [Vec3; 3]) -> Self {
        let w = |p: Vec3| V3::<f64>::new(p.x.into(), p.y.into(), p.z.into());
        let (v0, e1, e2) = (w(v[0]), w(v[1]) - w(v[0]), w(v[2]) - w(v[0]));
        let n = e1.cross(e2);
        let q = n.dot(n);
        if !(q > 0.0 && q.is_finite()) {
            return Self {
                n: [f32::NAN; 4],
                b1: [f32::NAN; 4],
                b2: [f32::NAN; 4],
            };
        }
        // For p = v0 + a·e1 + b·e2 + c·n: (e2 × n)·p' = a·(e2 × n)·e1 = a·|n|², likewise b.
        let plane = |r: V3<f64>, scale: f64| {
            let r = V3::new(r.x * scale, r.y * scale, r.z * scale);
            [r.x, r.y, r.z, -r.dot(v0)].map(|x| x as f32)
        };
        Self {
            n: plane(n, 1.0 / q.sqrt()),
            b1: plane(e2.cross(n), 1.0 / q),
            b2: plane(n.cross(e1), 1.0 / q),
        }
    }

    /// The planes as lanes.
    #[inline(always)]
    fn lanes<L: Lanes>(&self) -> [(V3<L>, L); 3] {
        let plane = |p: &[f32; 4]| {
            (
                V3::new(L::splat(p[0]), L::splat(p[1]), L::splat(p[2])),
                L::splat(p[3]),
            )
        };
        [plane(&self.n), plane(&self.b1), plane(&self.b2)]
    }
}

/// A triangle as `v0` and three directions (12 floats): the unit normal and the two vectors
/// whose dot products with `p − v0` are the barycentric weights of `v1` and `v2` at a point `p`
/// of the plane (the rows of `[e1 e2 n]⁻¹`). [`PlaneTriangle`]'s planes with their offsets left
/// out: evaluated at `o − v0`, not at `o`, so their rounding is relative to the triangle.
/// Formed in f64 and rounded once; all NaN for a degenerate triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// Unit normal.
    pub n: [f32; 3],
    /// `(e2 × n)/|n|²`.
    pub b1: [f32; 3],
    /// `(n × e1)/|n|²`.
    pub b2: [f32; 3],
}

impl From<[Vec3; 3]> for FrameTriangle {
    fn from(v: [Vec3; 3]) -> Self {
        let p = PlaneTriangle::new(v);
        let xyz = |r: [f32; 4]| [r[0], r[1], r[2]];
        let nan = p.n[0].is_nan();
        Self {
            v0: if nan { [f32::NAN; 3] } else { v[0].to_array() },
            n: xyz(p.n),
            b1: xyz(p.b1),
            b2: xyz(p.b2),
        }
    }
}

impl From<[Vec3; 3]> for PlaneTriangle {
    fn from(v: [Vec3; 3]) -> Self {
        Self::new(v)
    }
}

/// Havel-Herout: every lane of `ray` against `tri`, decided before one division.
#[inline(always)]
pub fn havel_herout<L: Lanes>(ray: &RayLanes<L>, tri: &PlaneTriangle) -> LanesHit<L> {
    let [(n, nw), (b1, b1w), (b2, b2w)] = tri.lanes::<L>();
    let (o, d) = (ray.origin, ray.dir);
    // With det = n·d and tn = −(n·o + nw) = t·det, the hit point times det is
    // det·o + tn·d, and each barycentric plane at it, times det, is b·(det·o + tn·d) + det·w.
    let det = n.dot(d);
    let tn = -(n.dot(o) + nw);
    let p = V3::new(
        det * o.x + tn * d.x,
        det * o.y + tn * d.y,
        det * o.z + tn * d.z,
    );
    let u = b1.dot(p) + det * b1w;
    let v = b2.dot(p) + det * b2w;
    // Signs flipped by det's (exact), so 0 ≤ u, 0 ≤ v, u + v ≤ 1 and the range need no division.
    let abs_det = det.abs();
    let (u_s, v_s, t_s) = (u.xor_sign(det), v.xor_sign(det), tn.xor_sign(det));
    let zero = L::zero();
    let mask = ray.active
        & det.ne(zero)
        & u_s.ge(zero)
        & v_s.ge(zero)
        & (u_s + v_s).le(abs_det)
        & t_s.ge(ray.t_min * abs_det)
        & t_s.le(ray.t_max * abs_det);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let t = tn / det + zero;
    LanesHit {
        mask: mask & t_in_range(ray, t),
        t,
        u,
        v,
        scale: det,
    }
}

/// Baldwin-Weber: every lane of `ray` against `tri`, the division first.
#[inline(always)]
pub fn baldwin_weber<L: Lanes>(ray: &RayLanes<L>, tri: &PlaneTriangle) -> LanesHit<L> {
    let [(n, nw), (b1, b1w), (b2, b2w)] = tri.lanes::<L>();
    let (o, d) = (ray.origin, ray.dir);
    // In the triangle's frame the ray is o' + t·d'; it meets z = 0 at t = −o'z/d'z, where
    // the barycentrics are o'x + t·d'x and o'y + t·d'y.
    let t = -(n.dot(o) + nw) / n.dot(d) + L::zero();
    let mask = ray.active & t_in_range(ray, t);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let u = b1.dot(o) + b1w + t * b1.dot(d);
    let v = b2.dot(o) + b2w + t * b2.dot(d);
    let zero = L::zero();
    LanesHit {
        mask: mask & u.ge(zero) & v.ge(zero) & (u + v).le(L::splat(1.0)),
        t,
        u,
        v,
        scale: L::splat(1.0),
    }
}

/// Baldwin-Weber relative to `v0`: the same steps on `o − v0`, three subtractions more.
#[inline(always)]
pub fn baldwin_weber_v0<L: Lanes>(ray: &RayLanes<L>, tri: &FrameTriangle) -> LanesHit<L> {
    let v3 = |p: [f32; 3]| V3::<L>::new(L::splat(p[0]), L::splat(p[1]), L::splat(p[2]));
    let (v0, n, b1, b2) = (v3(tri.v0), v3(tri.n), v3(tri.b1), v3(tri.b2));
    let (s, d) = (ray.origin - v0, ray.dir);
    let t = -n.dot(s) / n.dot(d) + L::zero();
    let mask = ray.active & t_in_range(ray, t);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let u = b1.dot(s) + t * b1.dot(d);
    let v = b2.dot(s) + t * b2.dot(d);
    let zero = L::zero();
    LanesHit {
        mask: mask & u.ge(zero) & v.ge(zero) & (u + v).le(L::splat(1.0)),
        t,
        u,
        v,
        scale: L::splat(1.0),
    }
}

/// A candidate's test of the lanes of a ray against one triangle of layout `P`.
pub type Test<L, P> = fn(&RayLanes<L>, &P) -> LanesHit<L>;

/// The nearest `t` per lane over `tris` with `test` (`octoray::query::closest_t`'s loop: the
/// running best lowers `t_max` to its loosened `t`). Returns the lanes that hit and their `t`.
#[inline(always)]
pub fn closest_t<L: Lanes, P>(ray: &RayLanes<L>, tris: &[P], test: Test<L, P>) -> (L::Mask, L) {
    let t_max = ray.t_max;
    let mut ray = *ray;
    let mut found = L::first_lanes(0);
    let mut t = ray.t_max;
    for tri in tris {
        let h = test(&ray, tri);
        if h.mask.any() {
            let m = h.mask & (!found | h.t.lt(t));
            t = L::select(m, h.t, t);
            ray.t_max = L::select(m, h.t.loosen(t_max), ray.t_max);
            found = found | h.mask;
        }
    }
    (found, t)
}

/// Rays that hit, over packets of `L::LANES` rays, closest `t` only: what the speed entries time.
pub fn count_closest<L: Lanes, P>(rays: &[Ray], tris: &[P], test: Test<L, P>) -> u32 {
    rays.chunks(L::LANES)
        .map(|c| {
            closest_t(&RayLanes::<L>::load(c), tris, test)
                .0
                .bitmask()
                .count_ones()
        })
        .sum()
}

/// One ray against one triangle with `test` at `L = f32`: `t` of a hit (for the oracle).
pub fn single<P: From<[Vec3; 3]>>(ray: &Ray, tri: [Vec3; 3], test: Test<f32, P>) -> Option<f32> {
    let h = test(&RayLanes::<f32>::single(ray), &P::from(tri));
    h.mask.then_some(h.t)
}
