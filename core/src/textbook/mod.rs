//! The textbook method of `shared/seed/textbook-solutions.md`, line by line.
//!
//! Each test has a `*_steps` function that returns every intermediate value the sheet shows, so
//! the golden tests check the working and not only the answer, and an `intersect_*` function that
//! returns just the hit. These are the readable reference, not the fast path: use the
//! [`crate::kernels::triangle::moller_trumbore`] and [`crate::kernels::sphere::stable`] kernels in a renderer.

#[cfg(feature = "sphere")]
pub mod sphere;
#[cfg(feature = "triangle")]
pub mod triangle;

#[cfg(feature = "sphere")]
pub use sphere::{intersect_sphere, sphere_steps, SphereOutcome, SphereSteps};
#[cfg(feature = "triangle")]
pub use triangle::{
    intersect_triangle, triangle_steps, InsideTest, TriangleOutcome, TriangleSteps,
};

use glam::Vec3;

/// A textbook hit: the ray parameter and the point `p = o + t·d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextbookHit {
    /// Ray parameter.
    pub t: f32,
    /// Hit point `o + t·d`.
    pub point: Vec3,
}
