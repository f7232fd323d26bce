//! `octoray-packet`: the SIMD layer a renderer calls — slices of rays against slices of
//! primitives, against one tree and against scenes, at every tier and lane width, on `wide`.
//!
//! `octoray-core` holds the vocabulary (rays, primitives, hits, the tiers' kernels, the BVH as
//! data) and every kernel's one generic body; this crate runs them on SIMD lanes:
//!
//! - Widths: [`f32x4`], [`f32x8`], [`f32x16`] for the f32 tiers, [`f64x4`], [`f64x8`] for the f64
//!   tier (re-exported, so you never need a matching `wide` version yourself).
//! - One vocabulary: `closest` (nearest hit with barycentrics and primitive index), `closest_t`
//!   (nearest `t` only), `occluded` (any hit in range); the module or suffix says what they run
//!   over:
//!   - slices of rays against slices of primitives (brute force): [`closest`], [`closest_t`],
//!     [`occluded`];
//!   - one packet against a slice of primitives: `octoray_core::query`;
//!   - against one tree (`Bvh8`/`Bvh8Ref`): [`tree::closest`], [`tree::occluded`] (slices of
//!     rays, packets or single rays as fits), `tree::*_packet` (one packet) and `tree::*_ray`
//!     (one ray);
//!   - against a scene of geometries and instances: the same names as methods of
//!     [`scene::Trace`].
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
//! use octoray_core::{glam::Vec3, kernels::Watertight, prim::{Ray, VertexTriangle}};
//! use octoray_packet::{closest, f32x8};
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

// The walks (`tree::{single, packet, leaf}`, `scene::{instances, enter}`) carry
// `#[cfg_attr(not(debug_assertions), inline(always))]`: forced into their callers in optimised
// builds, left to the compiler where debug assertions are on (tests, dev builds), whose compile
// time forced copies of these large bodies dominate (docs/build-flags.md); the kernel bodies in
// `octoray_core::kernels` follow the same rule. The per-node helpers (slab test, epilog, masks)
// are small and always forced.

pub mod scene;
mod slices;
pub mod tree;

pub use slices::{closest, closest_t, occluded};
pub use wide::{f32x16, f32x4, f32x8, f64x4, f64x8};
