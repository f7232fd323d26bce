//! octoray: SIMD packet ray-triangle and ray-sphere kernels with documented accuracy contracts.
//!
//! A thin facade: everything of `octoray-core` (scalar kernels, the textbook reference, the one
//! generic body of every kernel, the BVH) at the root, and [`packet`], `octoray-packet` (the
//! SIMD layer on `wide`: slices and packets of rays against primitives and scenes).
#![no_std]
#![forbid(unsafe_code)]

pub use octoray_core::*;
pub use octoray_packet as packet;

/// The README's code blocks, compiled and run as doctests.
#[cfg(all(doctest, feature = "triangle"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
