//! Slices of rays against slices of primitives (brute force), a packet at a time.

use octoray_core::hit::Hit;
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{LaneMask, Lanes, Scalar};
use octoray_core::prim::{Ray, RayLanes};
use octoray_core::query;

/// Panics unless `out` has one entry per ray (the `copy_from_slice` convention: a length
/// mismatch is a caller bug, never silently truncated).
#[track_caller]
fn check_len(what: &str, rays: usize, out: usize) {
    assert_eq!(
        rays, out,
        "octoray {what}: {rays} rays but {out} output entries; they must be equal"
    );
}

/// Closest hit of every ray over `prims` with tier `K` at width `L`: `out[i]` for `rays[i]`
/// (`prim` is the index in `prims`).
///
/// # Panics
/// When `out.len() != rays.len()`, or `prims.len() > u32::MAX`.
pub fn closest<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim], out: &mut [Option<Hit>]) {
    check_len("closest", rays.len(), out.len());
    for (chunk, out) in rays.chunks(L::LANES).zip(out.chunks_mut(L::LANES)) {
        let h = query::closest::<L, K>(&RayLanes::load(chunk), prims);
        for (i, o) in out.iter_mut().enumerate() {
            *o = h.lane(i);
        }
    }
}

/// Nearest `t` of every ray (no barycentrics, no index): `out[i]` for `rays[i]`, equal to
/// [`closest`]'s `t` bit for bit.
///
/// # Panics
/// When `out.len() != rays.len()`.
pub fn closest_t<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim], out: &mut [Option<f32>]) {
    check_len("closest_t", rays.len(), out.len());
    for (chunk, out) in rays.chunks(L::LANES).zip(out.chunks_mut(L::LANES)) {
        let (m, t) = query::closest_t::<L, K>(&RayLanes::load(chunk), prims);
        let bits = m.bitmask();
        for (i, o) in out.iter_mut().enumerate() {
            *o = ((bits >> i) & 1 == 1).then(|| Scalar::to_f32(t.lane(i)));
        }
    }
}

/// Whether each ray hits anything in its `[t_min, t_max]` (shadow rays): `out[i]` for `rays[i]`.
///
/// # Panics
/// When `out.len() != rays.len()`.
pub fn occluded<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim], out: &mut [bool]) {
    check_len("occluded", rays.len(), out.len());
    for (chunk, out) in rays.chunks(L::LANES).zip(out.chunks_mut(L::LANES)) {
        let bits = query::occluded::<L, K>(&RayLanes::load(chunk), prims).bitmask();
        for (i, o) in out.iter_mut().enumerate() {
            *o = (bits >> i) & 1 == 1;
        }
    }
}
