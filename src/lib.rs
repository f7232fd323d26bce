//! octoray: SIMD packet ray-triangle and ray-sphere kernels with documented accuracy contracts.
//!
//! Every item has one path here; the modules are the chapters of the manual.
//!
//! | you need | where |
//! |---|---|
//! | rays, primitives, their SoA layouts | [`prim`] ([`prim::Ray`], [`prim::VertexTriangle`], [`prim::PackedTriangle`], [`prim::Sphere`], [`prim::PackedSphere`]) |
//! | a tier (accuracy against speed) and its contract | [`kernels`] ([`kernels::MollerTrumbore`], [`kernels::Watertight`], [`kernels::Exact`], [`kernels::StableSphere`]); the f64 tier is any of them at [`f64x4`]/[`f64x8`] |
//! | what a test answers | [`hit`] ([`hit::Hit`]) |
//! | a tree over one primitive slice: build, refit, store, validate | [`bvh`] ([`bvh::Bvh8`], [`bvh::Bvh8Ref`]) |
//! | rays against one tree | [`tree`] ([`tree::closest_ray`], [`tree::closest_packet`], [`tree::closest`], …, and `_with` forms taking a [`hit::HitFilter`]) |
//! | a renderer's scene: several meshes and sphere sets, instances, masks, IDs in the hit | [`scene::Scene`], [`scene::SceneRef`], [`scene::Transform`]; rays through it with [`scene::Trace`] |
//! | rays against a slice of primitives | [`closest`], [`closest_t`], [`occluded`] (slices), [`query`] (one packet), [`intersect`] (one ray) |
//! | lane types | [`f32x4`], [`f32x8`], [`f32x16`], [`f64x4`], [`f64x8`]; the trait [`lanes::Lanes`] |
//! | hit points, normals, spawned rays | [`shading`] |
//! | vertex and index buffers in, errors out | [`ingest`] |
//! | which tier a scene needs | [`recommend`] |
//! | the seed sheet's method, every intermediate | [`textbook`] |
//!
//! `octoray-core` (`no_std`, no `wide`) holds everything but the SIMD work; `octoray-packet`
//! (`no_std`, on `wide`) holds the slice calls, the walks of a tree and of a scene, and the lane
//! types. This crate
//! re-exports both, each item once, and adds [`parallel`] (feature `rayon`).
#![no_std]
#![forbid(unsafe_code)]

#[doc(inline)]
pub use octoray_core::intersect;
#[cfg(feature = "sphere")]
#[doc(inline)]
pub use octoray_core::intersect_sphere;
#[cfg(feature = "triangle")]
#[doc(inline)]
pub use octoray_core::intersect_triangle;
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[doc(inline)]
pub use octoray_core::shading;
#[doc(inline)]
pub use octoray_core::{bvh, glam, hit, ingest, kernels, lanes, prim, query, recommend, textbook};
#[doc(inline)]
pub use octoray_packet::{closest, closest_t, occluded, scene, tree};
#[doc(inline)]
pub use octoray_packet::{f32x16, f32x4, f32x8, f64x4, f64x8};

/// Threads for the BVH build (features `rayon` and `alloc`).
#[cfg(all(feature = "rayon", feature = "alloc"))]
pub mod parallel {
    /// rayon's `join` as a [`crate::bvh::Join`]: [`crate::bvh::Bvh8::try_build_on`] then
    /// runs the binary SAH build on rayon's thread pool. The tree is the same bit for bit as
    /// the single-threaded build's.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Rayon;

    impl crate::bvh::Join for Rayon {
        fn join<A: Send, B: Send>(
            &self,
            a: impl FnOnce() -> A + Send,
            b: impl FnOnce() -> B + Send,
        ) -> (A, B) {
            rayon::join(a, b)
        }
    }
}

/// The README's code blocks, compiled and run as doctests.
#[cfg(all(doctest, feature = "triangle", feature = "sphere", feature = "alloc"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
