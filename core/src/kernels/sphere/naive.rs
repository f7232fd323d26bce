//! Naive ray-sphere: the textbook quadratic `b² − 4ac` as a lane kernel, kept so the
//! speed-accuracy trade against [`crate::kernels::sphere::stable`] is visible.
//!
//! # Guarantees
//! - **Same bits** across widths and builds (same exact operations as the other standard
//!   kernels).
//! - Reported hits always have finite `t ∈ [t_min, t_max]`; bad input is a miss, and so is an
//!   overflowed `b² − 4ac` or `2a` (`|f|·|d|` or `|d|·r` beyond ~1e19). A root before the ray's
//!   entry into the sphere's bounding box is raised to that entry, and a ray that leaves that box
//!   before `t_min` is a miss, as in the stable kernel.
//!
//! # Limits
//! - **Not sound far from the sphere**: `c = f·f − r²` and `b² − 4ac` cancel when the distance
//!   is large compared to the radius, so hit/miss can be wrong for small distant spheres
//!   (measured in the accuracy report at 1e2…1e6 radii) and the near root cancels in `−b + √Δ`.

use crate::hit::{nearest_root_in_range, LanesHit};
use crate::lanes::{LaneMask, Lanes, Scalar};
use crate::prim::{PackedSphere, RayLanes};
use crate::prim::{Primitive, SphereLanes};

/// Tests every lane of `ray` against one sphere.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect<L: Lanes>(ray: &RayLanes<L>, sphere: &PackedSphere) -> LanesHit<L> {
    intersect_lanes(ray, &sphere.splat())
}

/// Tests lane `i` of `ray` against lane `i` of `sphere`.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_lanes<L: Lanes>(ray: &RayLanes<L>, sphere: &SphereLanes<L>) -> LanesHit<L> {
    let zero = L::zero();
    let d = ray.dir;
    let f = ray.origin - sphere.center;
    // a t² + b t + c = 0 with a = d·d, b = 2 f·d, c = f·f − r²; roots (−b ± √(b² − 4ac)) / 2a.
    let a = d.dot(d);
    let b = L::splat(2.0) * f.dot(d);
    let c = f.dot(f) - sphere.radius_sq;
    let disc = b * b - L::splat(4.0) * a * c;
    let two_a = L::splat(2.0) * a;
    // An overflowed discriminant or 2a makes the roots meaningless (a finite b over an infinite
    // 2a would give a false hit at t = 0): a miss.
    // A squared radius below f32's normal range is no sphere (as `PackedSphere::new` and the
    // BVH's boxes have it), and a subnormal `a` no direction.
    let normal = L::splat_scalar(L::Scalar::from_f64(L::Scalar::MIN_NORMAL));
    let mask = ray.active
        & a.ge(normal)
        & sphere.radius_sq.ge(L::splat(f32::MIN_POSITIVE))
        & two_a.is_finite()
        & disc.ge(zero)
        & disc.is_finite();
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let sq = disc.sqrt();
    let near = (-b - sq) / two_a;
    let far = (-b + sq) / two_a;
    nearest_root_in_range(ray, mask, (near, far), f, sphere.radius_sq)
}
