//! `octoray-core`: the `no_std` scalar half of octoray, and the one generic body of every kernel.
//!
//! The modules are layers; each imports only from those listed before it:
//!
//! - [`lanes`]: the [`Lanes`] trait every body is written against (`f32`, `f64`; the `wide`
//!   types under the `wide` feature, which only `octoray-packet` turns on) and [`V3`].
//! - [`prim`]: rays ([`Ray`], [`RayLanes`]) and primitive layouts read as lanes.
//! - [`hit`]: what a test answers ([`Hit`], [`LanesHit`]) and the range checks.
//! - [`kernels`]: one file per primitive × algorithm —
//!   [`kernels::triangle::moller_trumbore`] (standard tier), [`kernels::triangle::watertight`],
//!   [`kernels::sphere::stable`],
//!   [`kernels::sphere::naive`] — each the single generic body of its kernel, and the tier types
//!   over them ([`Kernel`]). At `L = f32` a body is the *scalar twin* of the packet kernel, bit
//!   for bit; at `f64`/`f64x4`/`f64x8`
//!   it is the f64 tier.
//! - [`query`]: closest hit, closest `t` and occlusion of a packet over a slice; [`bvh`]: the
//!   8-wide BVH over any primitive slice (build under `alloc`, traversal under `wide`).
//! - [`shading`]: surface data and spawn points ([`Shade`]), [`ingest`], [`recommend`], and
//!   [`textbook`], the seed sheet's method with every intermediate value observable.
//!
//! Every kernel documents its accuracy contract. No `std`, no allocation, no `unsafe`.
//!
//! Cargo features: `triangle` and `sphere` (the primitives; a build with one has none of the
//! other's code) and `alloc` (`Vec`-returning ingest helpers, the BVH builder), all on by
//! default; `wide` (the SIMD lane types and BVH traversal), off by default: without it the crate
//! has no `wide` in its dependency graph.
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_core::{glam::Vec3, textbook, Ray, VertexTriangle};
//! let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
//! let tri = VertexTriangle::new(
//!     Vec3::new(0.0, 6.0, 7.0),
//!     Vec3::new(-3.0, 1.0, 5.0),
//!     Vec3::new(-2.0, 1.0, 4.0),
//! );
//! let hit = textbook::intersect_triangle(&ray, &tri, textbook::InsideTest::Full).unwrap();
//! assert_eq!((hit.t, hit.point), (2.0, Vec3::new(-2.0, 2.0, 5.0)));
//! # }
//! ```
#![no_std]
#![forbid(unsafe_code)]
// A build with neither primitive (`--no-default-features`) keeps the shared helpers the
// primitives would use; it exists to prove the scalar core builds without `wide` and features.
#![cfg_attr(
    not(any(feature = "triangle", feature = "sphere")),
    allow(dead_code, unused_imports)
)]

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod bvh;
pub mod hit;
pub mod ingest;
pub mod kernels;
pub mod lanes;
pub mod prim;
pub mod query;
pub mod recommend;
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub mod shading;
pub mod textbook;

pub use glam;
pub use hit::{Hit, LanesHit};
pub use kernels::Kernel;
#[cfg(feature = "triangle")]
pub use kernels::{
    Exact, ExactCulled, MollerTrumbore, MollerTrumboreCulled, Watertight, WatertightCulled,
};
#[cfg(feature = "sphere")]
pub use kernels::{NaiveSphere, StableSphere};
pub use lanes::{LaneMask, Lanes, Scalar, V3};
#[cfg(feature = "sphere")]
pub use prim::{PackedSphere, Sphere};
#[cfg(feature = "triangle")]
pub use prim::{PackedTriangle, VertexTriangle};
pub use prim::{Ray, RayLanes};
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub use shading::offset::offset_ray_origin;
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub use shading::{Shade, Surface};

/// One ray against one primitive with kernel `K` in one lane of `L` (`f32` for the scalar twin,
/// `f64` for the f64 tier). `prim` is 0; f64 results are rounded to f32.
pub fn intersect<L: Lanes, K: Kernel<L>>(ray: &Ray, prim: &K::Prim) -> Option<Hit> {
    let r = RayLanes::<L>::single(ray);
    let h = K::intersect(&r, &K::prepare(&r), prim);
    let (u, v) = h.barycentrics();
    (h.mask.bitmask() & 1 == 1).then(|| Hit {
        t: h.t.lane(0).to_f32(),
        u: u.lane(0).to_f32(),
        v: v.lane(0).to_f32(),
        prim: 0,
    })
}

/// Scalar twin of the packet Möller-Trumbore kernel (standard tier): one ray against one packed
/// triangle. `prim` is 0. Contract: [`kernels::triangle::moller_trumbore`].
#[cfg(feature = "triangle")]
pub fn intersect_triangle(ray: &Ray, tri: &PackedTriangle) -> Option<Hit> {
    intersect::<f32, MollerTrumbore>(ray, tri)
}

/// Scalar twin of the packet sphere kernel (stable): one ray against one packed sphere. `u`, `v`,
/// `prim` are 0. Contract: [`kernels::sphere::stable`].
#[cfg(feature = "sphere")]
pub fn intersect_sphere(ray: &Ray, sphere: &PackedSphere) -> Option<Hit> {
    intersect::<f32, StableSphere>(ray, sphere)
}
