//! octoray: SIMD packet ray-triangle and ray-sphere kernels with documented accuracy contracts.
//!
//! A thin facade: everything of `octoray-core` (scalar kernels, the textbook reference, the one
//! generic body of every kernel, the BVH) at the root, and [`packet`], `octoray-packet` (the
//! SIMD layer on `wide`: slices and packets of rays against primitives and scenes).
#![no_std]
#![forbid(unsafe_code)]

pub use octoray_core::*;
pub use octoray_packet as packet;

/// Threads for the BVH build (features `rayon` and `alloc`).
#[cfg(all(feature = "rayon", feature = "alloc"))]
pub mod parallel {
    /// rayon's `join` as a [`crate::bvh::Join`]: [`crate::bvh::Bvh8::try_build_with`] then
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
#[cfg(all(doctest, feature = "triangle"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
