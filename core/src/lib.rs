//! `octoray-core`: the `no_std` scalar half of octoray.
//!
//! - [`textbook`]: the textbook method of the seed sheet (plane, then inside-outside test with
//!   cross products; the sphere quadratic), with every intermediate value observable.
//! - [`moller_trumbore`] (standard), [`watertight`], [`moller_trumbore_fast`] (fast),
//!   [`sphere_stable`], [`sphere_naive`]: the single generic body of each packet kernel, written
//!   against [`Lanes`]. Instantiated at `f32` they are the *scalar twins* of the packet kernels in
//!   `octoray-packet`, bit for bit (except the fast tier, whose contract is an error bound); at
//!   `f64`/`f64x4`/`f64x8` they are the f64 tier. [`kernel`] names the tiers.
//! - [`query`]: closest-hit and any-hit loops over slices, generic over width and tier.
//! - [`offset_ray_origin`]: spawn secondary rays without re-hitting the surface.
//!
//! Every kernel documents its accuracy contract. No `std`, no allocation, no `unsafe`.
//!
//! Cargo features: `triangle` and `sphere` (the primitives; a build with one has none of the
//! other's code) and `alloc` (`Vec`-returning ingest helpers), all on by default.
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_core::{glam::Vec3, textbook, Ray, Triangle};
//! let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
//! let tri = Triangle::new(
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

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod bvh;
pub mod hit;
pub mod ingest;
pub mod kernel;
pub mod lanes;
#[cfg(feature = "triangle")]
pub mod moller_trumbore;
#[cfg(feature = "triangle")]
pub mod moller_trumbore_fast;
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub mod offset;
pub mod prim;
pub mod query;
pub mod ray;
pub mod recommend;
#[cfg(feature = "sphere")]
pub mod sphere_naive;
#[cfg(feature = "sphere")]
pub mod sphere_stable;
#[cfg(feature = "triangle")]
pub mod surface;
pub mod textbook;
pub mod vec3;
#[cfg(feature = "triangle")]
pub mod watertight;

pub use glam;
#[cfg(feature = "triangle")]
pub use kernel::{Fast, Standard, StandardCulled, Watertight, WatertightCulled};
pub use kernel::{Kernel, LanesHit};
#[cfg(feature = "sphere")]
pub use kernel::{NaiveSphere, StableSphere};
pub use lanes::{FastLanes, LaneMask, Lanes, Scalar};
#[cfg(any(feature = "triangle", feature = "sphere"))]
pub use offset::offset_ray_origin;
pub use ray::{Hit, Ray, RayLanes};
#[cfg(feature = "sphere")]
pub use ray::{PackedSphere, Sphere};
#[cfg(feature = "triangle")]
pub use ray::{PackedTriangle, Triangle, VertexTriangle};
pub use vec3::V3;

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
/// triangle. `prim` is 0. Contract: [`moller_trumbore`].
#[cfg(feature = "triangle")]
pub fn intersect_triangle(ray: &Ray, tri: &PackedTriangle) -> Option<Hit> {
    intersect::<f32, Standard>(ray, tri)
}

/// Scalar twin of the packet sphere kernel (stable): one ray against one packed sphere. `u`, `v`,
/// `prim` are 0. Contract: [`sphere_stable`].
#[cfg(feature = "sphere")]
pub fn intersect_sphere(ray: &Ray, sphere: &PackedSphere) -> Option<Hit> {
    intersect::<f32, StableSphere>(ray, sphere)
}
