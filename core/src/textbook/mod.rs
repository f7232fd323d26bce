//! The textbook method of the seed sheet (the seven worked problems the golden tests check), line
//! by line.
//!
//! Each test has a `*_steps` function that returns every intermediate value the sheet shows, so
//! the golden tests check the working and not only the answer, and an `intersect_*` function that
//! returns just the hit. These are the readable reference, not the fast path: use the
//! [`crate::kernels::triangle::moller_trumbore`] and [`crate::kernels::sphere::stable`] kernels in a renderer.
//!
//! # Triangle: the plane, then the inside-outside test with cross products
//! Accuracy: `n`, `d·n` and the numerator are each a few roundings of the inputs; with small
//! integer inputs (as on the sheet) every one of them is exact. `t` is one correctly rounded
//! division of those, `p` two more roundings per component. The inside-outside decision is not
//! robust: points within rounding of an edge can be decided either way, and neighbouring
//! triangles can both miss (cracks). The packet kernels and the accuracy tiers address that.
//!
//! # Sphere: the quadratic `A t² + B t + C = 0` with `f = o − c`
//! Accuracy: with small integer inputs (as on the sheet) `A`, `B`, `C` and the discriminant are
//! exact and each root is within 2 ulp (one rounding each for `√disc`, `−B ± √disc` and the
//! division by `2A`). In general the form is not sound: `C = f·f − r²` and `B² − 4AC` cancel for
//! small distant spheres, so hit/miss can be wrong; see [`crate::kernels::sphere::stable`].

#[cfg(feature = "sphere")]
mod sphere;
#[cfg(feature = "triangle")]
mod triangle;

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
