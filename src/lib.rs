//! octoray: SIMD packet ray-triangle and ray-sphere kernels with documented accuracy contracts.
//!
//! A thin facade: [`core`] is `octoray-core` (scalar kernels, the textbook reference, and the one
//! generic body of every kernel), [`packet`] is `octoray-packet` (SoA ray packets on `wide`).
#![no_std]
#![forbid(unsafe_code)]

pub use octoray_core as core;
pub use octoray_packet as packet;

pub use octoray_core::{glam, Hit, Ray};
#[cfg(feature = "sphere")]
pub use octoray_core::{PackedSphere, Sphere};
#[cfg(feature = "triangle")]
pub use octoray_core::{PackedTriangle, Triangle, VertexTriangle};

/// The README's code blocks, compiled and run as doctests.
#[cfg(all(doctest, feature = "triangle"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
