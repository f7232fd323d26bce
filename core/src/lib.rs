//! `octoray-core`: the `no_std` scalar half of octoray.
//!
//! - [`textbook`]: the textbook method of the seed sheet (plane, then inside-outside test with
//!   cross products; the sphere quadratic), with every intermediate value observable.
//! - [`moller_trumbore`], [`sphere_stable`]: the single generic body of each packet kernel,
//!   written against [`Lanes`]. Instantiated at `f32` they are the *scalar twins* of the packet
//!   kernels in `octoray-packet`, bit for bit.
//! - [`query`]: closest-hit and any-hit loops over slices, generic the same way.
//!
//! Every kernel documents its accuracy contract. No `std`, no allocation, no `unsafe`.
//!
//! ```
//! use octoray_core::{glam::Vec3, textbook, Ray, Triangle};
//! let ray = Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
//! let tri = Triangle::new(
//!     Vec3::new(0.0, 6.0, 7.0),
//!     Vec3::new(-3.0, 1.0, 5.0),
//!     Vec3::new(-2.0, 1.0, 4.0),
//! );
//! let hit = textbook::intersect_triangle(&ray, &tri, textbook::InsideTest::Full).unwrap();
//! assert_eq!((hit.t, hit.point), (2.0, Vec3::new(-2.0, 2.0, 5.0)));
//! ```
#![no_std]
#![forbid(unsafe_code)]

pub mod lanes;
pub mod moller_trumbore;
pub mod query;
pub mod ray;
pub mod sphere_stable;
pub mod textbook;
pub mod vec3;

pub use glam;
pub use lanes::{LaneMask, Lanes};
pub use ray::{Hit, PackedSphere, PackedTriangle, Ray, RayLanes, Sphere, Triangle};
pub use vec3::V3;

/// Scalar twin of the packet Möller-Trumbore kernel: one ray against one packed triangle.
/// `prim` is 0. Contract: [`moller_trumbore`].
pub fn intersect_triangle(ray: &Ray, tri: &PackedTriangle) -> Option<Hit> {
    let h = moller_trumbore::intersect(&RayLanes::single(ray), tri);
    h.mask.then_some(Hit {
        t: h.t,
        u: h.u,
        v: h.v,
        prim: 0,
    })
}

/// Scalar twin of the packet sphere kernel: one ray against one packed sphere. `u`, `v`, `prim`
/// are 0. Contract: [`sphere_stable`].
pub fn intersect_sphere(ray: &Ray, sphere: &PackedSphere) -> Option<Hit> {
    let h = sphere_stable::intersect(&RayLanes::single(ray), sphere);
    h.mask.then_some(Hit {
        t: h.t,
        u: 0.0,
        v: 0.0,
        prim: 0,
    })
}
