//! `octoray-packet`: structure-of-arrays ray packets against triangles and spheres, on `wide`.
//!
//! A [`RayPacket<L>`] holds `L::LANES` rays (4, 8 or 16 on `wide::f32x4`, [`f32x8`], `f32x16`;
//! 8 is the default) and an active-lane mask. Triangles and spheres are stored precomputed as
//! [`PackedTriangle`] (`v0, e1, e2`) and [`PackedSphere`] (centre, radius²), broadcast to every
//! lane. The kernels are the single generic bodies of `octoray-core`; each lane's answer is
//! bit-identical to the scalar twin ([`octoray_core::intersect_triangle`],
//! [`octoray_core::intersect_sphere`], and the `query` functions at `L = f32`), on every build.
//!
//! `wide` picks its instructions at compile time: build with `-C target-cpu=native` (or at least
//! `-C target-feature=+avx`) for one AVX register per `f32x8`, `+avx512f` for one zmm per
//! `f32x16`; the default x86-64 build runs every width on SSE2 halves.
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_packet::{closest_triangles, glam::Vec3, PackedTriangle, Ray};
//! let tris = [PackedTriangle::new(
//!     Vec3::new(0.0, 6.0, 7.0),
//!     Vec3::new(-3.0, 1.0, 5.0),
//!     Vec3::new(-2.0, 1.0, 4.0),
//! )];
//! let rays = [Ray::new(Vec3::new(-4.0, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0)); 3];
//! let mut hits = [None; 3];
//! closest_triangles::<octoray_packet::f32x8>(&rays, &tris, &mut hits);
//! assert!(hits.iter().all(|h| h.map(|h| h.t) == Some(2.0)));
//! # }
//! ```
#![no_std]
#![forbid(unsafe_code)]

pub use octoray_core::query::ClosestHit;
pub use octoray_core::{glam, query, Hit, LaneMask, Lanes, Ray};
#[cfg(feature = "triangle")]
pub use octoray_core::{moller_trumbore, PackedTriangle, Triangle};
#[cfg(feature = "sphere")]
pub use octoray_core::{sphere_stable, PackedSphere, Sphere};
pub use wide::{f32x16, f32x4, f32x8};

/// `L::LANES` rays in SoA form with an active-lane mask (see [`octoray_core::RayLanes`]).
pub type RayPacket<L = f32x8> = octoray_core::RayLanes<L>;
/// A 4-lane packet (`wide::f32x4`: one SSE register).
pub type RayPacket4 = RayPacket<f32x4>;
/// An 8-lane packet (`wide::f32x8`: one AVX register, or two SSE halves without `avx`).
pub type RayPacket8 = RayPacket<f32x8>;
/// A 16-lane packet (`wide::f32x16`: one zmm register with `avx512f`, else two `f32x8`).
pub type RayPacket16 = RayPacket<f32x16>;

/// Splits a slice of rays of any length into packets; the last one is partial and masked.
pub fn packets<L: Lanes + 'static>(rays: &[Ray]) -> impl Iterator<Item = RayPacket<L>> + '_ {
    rays.chunks(L::LANES).map(RayPacket::<L>::load)
}

/// Closest triangle packet query: lane by lane equal to
/// [`octoray_core::query::closest_triangle`] at `L = f32`.
#[cfg(feature = "triangle")]
pub fn closest_triangle<L: Lanes>(packet: &RayPacket<L>, tris: &[PackedTriangle]) -> ClosestHit<L> {
    query::closest_triangle(packet, tris)
}

/// Occlusion packet query against triangles (stops when every active lane is occluded).
#[cfg(feature = "triangle")]
pub fn any_triangle<L: Lanes>(packet: &RayPacket<L>, tris: &[PackedTriangle]) -> L::Mask {
    query::any_triangle(packet, tris)
}

/// Closest sphere packet query.
#[cfg(feature = "sphere")]
pub fn closest_sphere<L: Lanes>(packet: &RayPacket<L>, spheres: &[PackedSphere]) -> ClosestHit<L> {
    query::closest_sphere(packet, spheres)
}

/// Occlusion packet query against spheres.
#[cfg(feature = "sphere")]
pub fn any_sphere<L: Lanes>(packet: &RayPacket<L>, spheres: &[PackedSphere]) -> L::Mask {
    query::any_sphere(packet, spheres)
}

/// Traces `rays` in packets of `L::LANES` and writes each ray's closest triangle hit to `out`
/// (`out[i]` for `rays[i]`; extra entries of `out` are left alone, missing ones are not written).
#[cfg(feature = "triangle")]
pub fn closest_triangles<L: Lanes>(rays: &[Ray], tris: &[PackedTriangle], out: &mut [Option<Hit>]) {
    batch(
        rays,
        out,
        |p| closest_triangle::<L>(p, tris),
        ClosestHit::lane,
    );
}

/// Traces `rays` in packets and writes each ray's closest sphere hit to `out`.
#[cfg(feature = "sphere")]
pub fn closest_spheres<L: Lanes>(rays: &[Ray], spheres: &[PackedSphere], out: &mut [Option<Hit>]) {
    batch(
        rays,
        out,
        |p| closest_sphere::<L>(p, spheres),
        ClosestHit::lane,
    );
}

/// Traces `rays` in packets and writes whether each is occluded by a triangle to `out`.
#[cfg(feature = "triangle")]
pub fn occluded_triangles<L: Lanes>(rays: &[Ray], tris: &[PackedTriangle], out: &mut [bool]) {
    batch(
        rays,
        out,
        |p| any_triangle::<L>(p, tris),
        |m, i| (m.bitmask() >> i) & 1 == 1,
    );
}

/// Traces `rays` in packets and writes whether each is occluded by a sphere to `out`.
#[cfg(feature = "sphere")]
pub fn occluded_spheres<L: Lanes>(rays: &[Ray], spheres: &[PackedSphere], out: &mut [bool]) {
    batch(
        rays,
        out,
        |p| any_sphere::<L>(p, spheres),
        |m, i| (m.bitmask() >> i) & 1 == 1,
    );
}

/// Runs `query` on each packet of `rays` and scatters lane `i`'s answer (via `lane`) to `out`.
#[cfg(any(feature = "triangle", feature = "sphere"))]
fn batch<L: Lanes, R, T>(
    rays: &[Ray],
    out: &mut [T],
    mut query: impl FnMut(&RayPacket<L>) -> R,
    lane: impl Fn(&R, usize) -> T,
) {
    for (chunk, out) in rays.chunks(L::LANES).zip(out.chunks_mut(L::LANES)) {
        let r = query(&RayPacket::<L>::load(chunk));
        for (i, o) in out.iter_mut().take(chunk.len()).enumerate() {
            *o = lane(&r, i);
        }
    }
}
