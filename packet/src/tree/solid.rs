//! Exact crossing counts, containment and winding numbers of closed meshes: the walk of
//! [`all_hits_ray`] with the crossing rule ([`ExactCrossing`]), a page of hits at a time.

use super::all_hits::{all_hits_ray, each_hit};
#[cfg(feature = "alloc")]
use super::point::closest_point;
use octoray_core::bvh::Bvh8Ref;
#[cfg(feature = "alloc")]
use octoray_core::bvh::Solid;
use octoray_core::glam::Vec3;
use octoray_core::hit::Hit;
#[cfg(feature = "alloc")]
use octoray_core::kernels::triangle::crossing::crossing;
use octoray_core::kernels::ExactCrossing;
use octoray_core::lanes::Lanes;
use octoray_core::prim::{Ray, VertexTriangle};

/// Hits collected per walk: a ray crossing more walks the tree again from the last one.
pub(crate) const PAGE: usize = 32;

/// The direction containment casts in: any works (the answer does not depend on it); one off
/// the axes and diagonals keeps rays off the edges and faces of axis-aligned and grid meshes,
/// where ties cost exact arithmetic.
pub(crate) const CAST: Vec3 = Vec3::new(1.0, 0.371_3, 0.194_7);

/// Calls `f` once for every triangle the ray crosses under the crossing rule.
fn each_crossing<L: Lanes>(bvh: Bvh8Ref<'_, VertexTriangle>, ray: &Ray, f: impl FnMut(&Hit)) {
    each_hit::<PAGE>(
        |after, page| all_hits_ray::<L, ExactCrossing>(bvh, ray, after, page),
        f,
    );
}

/// How many triangles one ray crosses in `(t_min, t_max)` under the crossing rule
/// ([`ExactCrossing`]: exact, and a ray through a shared edge or vertex crosses one of the
/// triangles there, once), each primitive counted once. For a closed mesh (a [`Solid`]), the
/// count is even exactly when the ray's ends, perturbed as the rule perturbs its origin, are both
/// inside or both outside.
pub fn crossings_ray<L: Lanes>(bvh: Bvh8Ref<'_, VertexTriangle>, ray: &Ray) -> u32 {
    let mut n = 0u32;
    each_crossing::<L>(bvh, ray, |_| n += 1);
    n
}

/// The winding number of a closed mesh around `point`: how many times the surface wraps it,
/// counting a surface whose normals face out as +1 (a point inside a closed, outward-oriented
/// mesh is at 1, outside at 0, inside two nested shells at 2 or 0 by their orientations).
/// Exact: a point on the surface is treated as moved an infinitesimal step along `+x`, then
/// `+y`, then `+z` ([`octoray_core::kernels::triangle::crossing`]). A non-finite point is at 0.
///
/// # Limits
/// Exact for coordinates (the point's and the vertices') within ±2¹²⁶ (about 8.5e37), where
/// every crossing's exact `t` along the cast ray is below `f32::MAX`.
#[cfg(feature = "alloc")]
pub fn winding_number<L: Lanes>(solid: Solid<'_>, point: Vec3) -> i32 {
    let ray = Ray::new(point, CAST);
    let tris = solid.tris();
    let mut w = 0i32;
    each_crossing::<L>(solid.bvh(), &ray, |h| {
        let side = tris.get(h.prim as usize).and_then(|t| crossing(&ray, t));
        w += side.map_or(0, |s| s.winding());
    });
    w
}

/// Is `point` inside the closed mesh? The parity of the crossings of a ray from it, exact: `true`
/// where the winding number is odd (nested shells alternate), also where the surface turns
/// inside out. A point on the surface is classified as [`winding_number`] says; a non-finite
/// point is outside.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::{Bvh8, Solid}, glam::Vec3, prim::VertexTriangle};
/// use octoray_packet::{f32x8, tree::contains};
/// // A tetrahedron with its faces counter-clockwise seen from outside.
/// let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let tris: Vec<_> = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
///     .iter()
///     .map(|&[a, b, c]| VertexTriangle::new(p[a], p[b], p[c]))
///     .collect();
/// let bvh = Bvh8::build(&tris);
/// let solid = Solid::new(bvh.as_ref(), &tris)?;
/// assert!(contains::<f32x8>(solid, Vec3::splat(0.1)));
/// assert!(!contains::<f32x8>(solid, Vec3::splat(0.5)));
/// // On the face x = 0: moved to +x, so inside; on the slanted face: moved outside.
/// assert!(contains::<f32x8>(solid, Vec3::new(0.0, 0.2, 0.2)));
/// assert!(!contains::<f32x8>(solid, Vec3::new(0.5, 0.25, 0.25)));
/// # }
/// # Ok::<(), octoray_core::bvh::SolidError>(())
/// ```
#[cfg(feature = "alloc")]
pub fn contains<L: Lanes>(solid: Solid<'_>, point: Vec3) -> bool {
    crossings_ray::<L>(solid.bvh(), &Ray::new(point, CAST)) % 2 == 1
}

/// The signed distance from `point` to the closed mesh: the distance to its nearest point
/// ([`closest_point`]), negative where [`contains`] says the point is inside (exact, so the sign
/// is never wrong, also at distances below any rounding); `+0` or `−0` on the surface as
/// [`contains`] classifies it; `+inf` for a mesh with no triangle, NaN for a non-finite point.
#[cfg(feature = "alloc")]
pub fn signed_distance<L: Lanes>(solid: Solid<'_>, point: Vec3) -> f32 {
    if !point.is_finite() {
        return f32::NAN;
    }
    let d = closest_point(solid.bvh(), point, f32::INFINITY).map_or(f32::INFINITY, |h| h.dist);
    if contains::<L>(solid, point) {
        -d
    } else {
        d
    }
}
