//! Spawning secondary rays without re-hitting the surface they leave (pbrt-v4 §6.8.6).
//!
//! A hit point computed in floating point is off the true surface by up to its error bound; a
//! ray spawned from it with `t_min = 0` can hit its own triangle again ("shadow acne"). The fix is
//! to move the origin along the geometric normal by at least the error bound's projection onto
//! the normal, to the side the new ray leaves towards, and to round that point away from `p`.

#[cfg(feature = "triangle")]
use crate::prim::VertexTriangle;
use glam::Vec3;

/// `γ(n) = n·u / (1 − n·u)` for f32 (u = 2⁻²⁴).
fn gamma(n: f32) -> f32 {
    let u = f32::EPSILON * 0.5;
    n * u / (1.0 - n * u)
}

/// The hit point of `ray` at parameter `t` on the sphere (`center`, `radius`), and the error bound
/// to hand to [`offset_ray_origin`].
///
/// `o + t·d` inherits the error of `t`, which scales with the ray's whole length (the eye's
/// distance) and grows near the silhouette; so the point is re-projected onto the sphere,
/// `c + r·(p − c)/|p − c|` (as pbrt-v4 does), after which it is off the surface by a few ulps of
/// `|c| + r` only. The bound returned is `γ8·(|p| + |c| + r)` per component, which also covers the
/// sphere kernels' rounding of `f·f − r²` for an origin just outside (tested: zero re-hits).
#[cfg(feature = "sphere")]
pub fn sphere_hit_point(ray: &crate::prim::Ray, t: f32, center: Vec3, radius: f32) -> (Vec3, Vec3) {
    let (p, err, _) = sphere_hit(ray, t, center, radius);
    (p, err)
}

/// [`sphere_hit_point`] and the outward direction from the centre to the f64 point before it is
/// rounded: far from the origin (`|c| ≫ r`) the f32 point resolves the sphere coarsely, and a
/// normal from `p − c` in f32 would be off by up to `ulp(|c|)/r` radians.
#[cfg(feature = "sphere")]
pub(crate) fn sphere_hit(
    ray: &crate::prim::Ray,
    t: f32,
    center: Vec3,
    radius: f32,
) -> (Vec3, Vec3, [f64; 3]) {
    use super::wide::{add, length, narrow, of, scale, sub};
    let p = ray.at(t);
    // In f64: |p − c|² of a tiny sphere (r ≲ 1e-19) underflows in f32 and would give NaN, and
    // o + t·d of a huge direction can overflow f32 before the point is projected back.
    let cd = of(center);
    let diff = sub(add(of(ray.origin), scale(of(ray.dir), f64::from(t))), cd);
    let len = length(diff);
    let q = narrow(add(cd, scale(diff, f64::from(radius) / len)));
    // Re-project only where that is a finite point (not for p == c or a non-finite input).
    let p = if len > 0.0 && q.is_finite() { q } else { p };
    let err = (p.abs() + center.abs() + Vec3::splat(radius)) * gamma(8.0);
    (p, err, diff)
}

/// The point with barycentrics `(u, v)` (weights of `v1`, `v2`) on `tri`, and the componentwise
/// error bound to hand to [`offset_ray_origin`].
///
/// `p = b0·v0 + b1·v1 + b2·v2` with `b0 = 1 − u − v` is off the surface by at most `γ7·Σ|bᵢ·vᵢ|`
/// (pbrt-v4's bound, which also covers a few ulp of error in the barycentrics). A spawned ray is
/// then tested by a kernel with its own rounding: the standard tier's plane test `(o − v0)·Ng` is
/// uncertain by about `γ5·|o − v0|·|Ng|`, and it tests the packed triangle, whose edges are
/// rounded to f32 (half an ulp of each edge). The bound returned adds `γ8·(|e1| + |e2|)` to every
/// component to cover both, so the offset origin lies beyond the surface *as every tier computes
/// it* (tested: zero re-hits for the standard, watertight and f64 tiers at scales 1 to 1e6).
#[cfg(feature = "triangle")]
pub fn triangle_hit_point(tri: &VertexTriangle, u: f32, v: f32) -> (Vec3, Vec3) {
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let b0 = 1.0 - u - v;
    let p = v0 * b0 + v1 * u + v2 * v;
    let point_err = ((v0 * b0).abs() + (v1 * u).abs() + (v2 * v).abs()) * gamma(7.0);
    // Edge lengths in f64: in f32 their squares overflow past ~1.8e19 and underflow below ~1e-19.
    use super::wide::{length, of, sub};
    let edges = length(sub(of(v1), of(v0))) + length(sub(of(v2), of(v0)));
    let kernel_err = (f64::from(gamma(8.0)) * edges) as f32;
    (p, point_err + Vec3::splat(kernel_err))
}

/// Next representable f32 towards +∞ (−0 treated as +0; ∞ and NaN unchanged).
fn next_up(x: f32) -> f32 {
    if x.is_infinite() && x > 0.0 || x.is_nan() {
        return x;
    }
    let x = if x == 0.0 { 0.0 } else { x };
    let b = x.to_bits();
    f32::from_bits(if x >= 0.0 { b + 1 } else { b - 1 })
}

/// Next representable f32 towards −∞.
fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// The origin for a ray leaving the surface at `p` (with componentwise error bound `p_error`,
/// geometric normal `n`, any length) in direction `w`: `p` pushed along `±n` by
/// `Σ|n̂ᵢ|·p_errorᵢ` to the side `w` points to, each component then rounded one ulp further
/// away from `p`. With `p_error` from [`triangle_hit_point`], the result lies on `w`'s side of
/// the surface as the kernels compute it, so a ray from it with `t_min = 0` does not re-hit the
/// surface it left. Directions within ~1e-6 rad of the tangent plane are the exception: there
/// the sign of `d·Ng` itself is within rounding.
///
/// Returns `p` unchanged when `n` is zero or not finite (there is no side to pick).
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let n = super::unit_vector(super::wide::of(n));
    if n == Vec3::ZERO {
        return p;
    }
    let d = n.abs().dot(p_error);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_down(po[i]);
        }
        // A point at ±f32::MAX pushed further would become infinite: stay finite where the input
        // is (such a point cannot be moved off the surface in f32 anyway).
        if p[i].is_finite() && !po[i].is_finite() {
            po[i] = p[i];
        }
    }
    po
}
