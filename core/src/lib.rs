//! `octoray-core`: the `no_std` half of octoray that needs no SIMD crate — the vocabulary (rays,
//! primitives, hits), the one generic body of every kernel, the BVH as data, and the scalar
//! twins. `octoray-packet` runs the same bodies on `wide`'s lanes.
//!
//! The modules are layers; each imports only from those listed before it:
//!
//! - [`lanes`]: the [`Lanes`] trait every body is written against (`f32`, `f64`;
//!   the `wide` types under the `wide` feature, which only `octoray-packet` turns on: the orphan
//!   rule keeps those impls beside the trait) and [`V3`](lanes::V3).
//! - [`prim`]: rays ([`Ray`], [`RayLanes`]) and primitive layouts
//!   read as lanes.
//! - [`hit`]: what a test answers ([`Hit`], [`LanesHit`](hit::LanesHit)) and the range
//!   checks.
//! - [`kernels`]: the tiers as kernel types, and one file per primitive × algorithm
//!   ([`kernels::triangle::moller_trumbore`] (standard tier), [`kernels::triangle::watertight`],
//!   [`kernels::triangle::exact`], [`kernels::sphere::stable`], [`kernels::sphere::naive`]), each
//!   the single generic body of its kernel with its accuracy contract. At `L = f32` a body is the
//!   *scalar twin* of the packet kernel, bit for bit; at `f64`/`f64x4`/`f64x8` it is the f64 tier.
//! - [`query`]: closest hit, closest `t` and occlusion of a packet over a slice; [`bvh`]: the
//!   8-wide BVH's layout, builder (under `alloc`) and validation of untrusted trees.
//! - [`shading`]: surface data and spawn points, [`ingest`], [`recommend`], and [`textbook`], the
//!   seed sheet's method with every intermediate value observable.
//!
//! No `std`, no allocation (but the builder and the `Vec` forms of ingest, under `alloc`), no
//! `unsafe`.
//!
//! Cargo features: `triangle` and `sphere` (the primitives; a build with one has none of the
//! other's code) and `alloc`, all on by default; `wide` (the `Lanes` impls of the wide types),
//! off by default: without it the crate has no `wide` in its dependency graph.
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_core::{glam::Vec3, prim::{Ray, VertexTriangle}, textbook};
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
pub mod scene;
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub mod shading;
pub mod textbook;

pub use glam;

use hit::Hit;
use kernels::Kernel;
#[cfg(feature = "triangle")]
use kernels::MollerTrumbore;
#[cfg(feature = "sphere")]
use kernels::StableSphere;
use lanes::{LaneMask, Lanes, Scalar};
#[cfg(feature = "sphere")]
use prim::PackedSphere;
#[cfg(feature = "triangle")]
use prim::PackedTriangle;
use prim::{Ray, RayLanes};

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
        geom: 0,
        inst: 0,
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
