//! `octoray-packet`: the SIMD layer a renderer calls — ray packets and ray slices against
//! primitive slices and scenes, at every tier and width, on `wide`.
//!
//! - Widths: [`f32x4`], [`f32x8`], [`f32x16`] for the f32 tiers, [`f64x4`], [`f64x8`] for the f64
//!   tier (re-exported, so you never need a matching `wide` version yourself).
//! - Tiers ([`tiers`]): [`MollerTrumbore`](tiers::MollerTrumbore) (the standard tier),
//!   [`Watertight`](tiers::Watertight), the culling variants,
//!   [`StableSphere`](tiers::StableSphere) and [`NaiveSphere`](tiers::NaiveSphere); at an f64
//!   width any of them is the f64 tier.
//! - One vocabulary: `closest` (nearest hit with barycentrics and primitive index), `closest_t`
//!   (nearest `t` only), `occluded` (any hit in range); the module or suffix says what they run
//!   over:
//!   - slices of rays against slices of primitives (brute force): [`closest`], [`closest_t`],
//!     [`occluded`];
//!   - one packet ([`RayLanes<L>`]) against a slice of primitives: [`query::closest`],
//!     [`query::closest_t`], [`query::occluded`];
//!   - against a scene ([`Bvh8`]/[`Bvh8Ref`]): [`scene::closest`], [`scene::occluded`] (slices
//!     of rays, packets or single rays as fits), `scene::*_packet` (one packet) and
//!     `scene::*_ray` (one ray).
//!
//! Every lane's answer is bit-identical to the scalar twin (`octoray_core::query` at `L = f32`),
//! on every build, for every tier.
//!
//! `wide` picks its instructions at compile time: build with `-C target-cpu=native` (or at least
//! `-C target-feature=+avx`) for one AVX register per `f32x8`, `+avx512f` for one zmm per
//! `f32x16`; the default x86-64 build runs every width on SSE2 halves.
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_packet::tiers::Watertight;
//! use octoray_packet::{closest, f32x8, glam::Vec3, Ray, VertexTriangle};
//! let tris = [VertexTriangle::new(
//!     Vec3::new(0.0, 6.0, 7.0),
//!     Vec3::new(-3.0, 1.0, 5.0),
//!     Vec3::new(-2.0, 1.0, 4.0),
//! )];
//! let rays = [Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0)); 3];
//! let mut hits = [None; 3];
//! closest::<f32x8, Watertight>(&rays, &tris, &mut hits);
//! // t = 2 on the seed sheet; the watertight tier is within its documented bound of it.
//! assert!(hits.iter().all(|h| h.is_some_and(|h| (h.t - 2.0).abs() < 1e-6)));
//! # }
//! ```
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "alloc")]
pub use octoray_core::bvh::{BuildStats, Bvh8};
pub use octoray_core::bvh::{Bvh8Node, Bvh8Ref, BvhError, BLOCK, PAD};
pub use octoray_core::query::{self, ClosestHit};
pub use octoray_core::{glam, Hit, LaneMask, Lanes, Ray, RayLanes};
#[cfg(feature = "sphere")]
pub use octoray_core::{PackedSphere, Sphere};
#[cfg(feature = "triangle")]
pub use octoray_core::{PackedTriangle, VertexTriangle};
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub use octoray_core::{Shade, Surface};
pub use wide::{f32x16, f32x4, f32x8, f64x4, f64x8};

/// The accuracy tiers (kernel types): pick one per call.
pub mod tiers {
    pub use octoray_core::kernels::Kernel;
    #[cfg(feature = "triangle")]
    pub use octoray_core::kernels::{
        Exact, ExactCulled, MollerTrumbore, MollerTrumboreCulled, Watertight, WatertightCulled,
    };
    #[cfg(feature = "sphere")]
    pub use octoray_core::kernels::{NaiveSphere, StableSphere};
}

use tiers::Kernel;

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
            *o = ((bits >> i) & 1 == 1).then(|| octoray_core::Scalar::to_f32(t.lane(i)));
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

/// The same calls against a scene ([`Bvh8`]/[`Bvh8Ref`]): answers equal the brute-force calls
/// above over the slice the tree was built from, bit for bit.
pub mod scene {
    pub use octoray_core::bvh::traverse::{
        closest, closest_packet, closest_ray, closest_t_packet, occluded, occluded_packet,
        occluded_ray,
    };
}
