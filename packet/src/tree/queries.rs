//! The calls: one ray, one packet, a slice of rays, with and without a hit filter.

use super::batch::{closest_slice, occluded_slice};
use super::epilog::{Best, PacketBest};
use super::leaf::Members;
use super::packet::{packet_result, run_packet};
use super::single::run_single;
use octoray_core::bvh::Bvh8Ref;
use octoray_core::hit::{AcceptAll, Hit, HitFilter};
use octoray_core::kernels::Kernel;
use octoray_core::lanes::Lanes;
use octoray_core::prim::{Ray, RayLanes};
use octoray_core::query::ClosestHit;

/// One ray through one tree from the root (geometry 0, instance 0).
fn single<L: Lanes, K: Kernel<L>, F: HitFilter, const ANY: bool>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
    ray_id: u32,
) -> (bool, Option<Best<L::Scalar>>) {
    let mut best = None;
    let any = run_single::<L, K, F, ANY, false>(
        bvh,
        (0, 0, Members::ONE),
        0,
        ray,
        &mut best,
        filter,
        ray_id,
    );
    (any, best)
}

/// Closest hit of one ray, leaves tested `L::LANES` primitives at a time with kernel `K`
/// (`L = f32x8` or `f32x16` for the f32 tiers, `f64x4`/`f64x8` for the f64 tier). `prim` is the
/// index in the slice the tree was built from.
pub fn closest_ray<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, ray: &Ray) -> Option<Hit> {
    closest_ray_with::<L, K, _>(bvh, ray, &mut AcceptAll)
}

/// [`closest_ray`] counting only the hits `filter` accepts (the candidate's `ray` is 0).
pub fn closest_ray_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
) -> Option<Hit> {
    single::<L, K, F, false>(bvh, ray, filter, 0)
        .1
        .map(|b| b.hit())
}

/// Does one ray hit anything in `[t_min, t_max]` (occlusion)? Stops at the first hit.
pub fn occluded_ray<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, ray: &Ray) -> bool {
    occluded_ray_with::<L, K, _>(bvh, ray, &mut AcceptAll)
}

/// [`occluded_ray`] counting only the hits `filter` accepts (any-hit with a filter: alpha-tested
/// shadows).
pub fn occluded_ray_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
) -> bool {
    single::<L, K, F, true>(bvh, ray, filter, 0).0
}

/// A packet through one tree from the root (geometry 0, instance 0).
fn packet<L: Lanes, K: Kernel<L>, F: HitFilter, const ANY: bool>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
    ray_base: u32,
) -> PacketBest<L> {
    let mut best = PacketBest::new(rays.t_max);
    run_packet::<L, K, F, ANY, false>(
        bvh,
        (0, 0, Members::ONE),
        0,
        rays,
        &mut best,
        filter,
        ray_base,
    );
    best
}

/// Closest hit per lane of a packet with kernel `K`. Lane by lane equal to
/// [`octoray_core::query::closest`] over the slice the tree was built from (the `prim` lanes are
/// indices into that slice). Lanes that miss hold `t = t_max` and zero barycentrics.
pub fn closest_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> ClosestHit<L> {
    closest_packet_with::<L, K, _>(bvh, rays, &mut AcceptAll)
}

/// [`closest_packet`] counting only the hits `filter` accepts (the candidate's `ray` is its
/// lane).
pub fn closest_packet_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
) -> ClosestHit<L> {
    packet_hits::<L, K, F>(bvh, rays, filter, 0)
}

fn packet_hits<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
    ray_base: u32,
) -> ClosestHit<L> {
    packet_result(&packet::<L, K, F, false>(bvh, rays, filter, ray_base))
}

/// Closest `t` per lane of a packet: the mask of lanes that hit and their nearest `t`, equal to
/// [`closest_packet`]'s.
pub fn closest_t_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> (L::Mask, L) {
    let b = packet::<L, K, AcceptAll, false>(bvh, rays, &mut AcceptAll, 0);
    (b.mask, b.t)
}

/// Lanes of a packet that hit anything in `[t_min, t_max]` (occlusion).
pub fn occluded_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> L::Mask {
    occluded_packet_with::<L, K, _>(bvh, rays, &mut AcceptAll)
}

/// [`occluded_packet`] counting only the hits `filter` accepts (the candidate's `ray` is its
/// lane).
pub fn occluded_packet_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
) -> L::Mask {
    packet::<L, K, F, true>(bvh, rays, filter, 0).mask
}

/// Closest hit of every ray: `out[i]` for `rays[i]`. Chunks of `L::LANES` rays that share a
/// direction octant are traced as packets, the others ray by ray; the answers are the same
/// either way.
///
/// # Panics
/// When `out.len() != rays.len()`.
#[track_caller]
pub fn closest<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [Option<Hit>],
) {
    closest_with::<L, K, _>(bvh, rays, out, &mut AcceptAll);
}

/// [`closest`] counting only the hits `filter` accepts (the candidate's `ray` is the ray's index
/// in `rays`).
///
/// # Panics
/// When `out.len() != rays.len()`, or `rays.len() > u32::MAX`.
#[track_caller]
pub fn closest_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [Option<Hit>],
    filter: &mut F,
) {
    closest_slice::<L, F>(
        rays,
        out,
        filter,
        |r, f, base| packet::<L, K, F, false>(bvh, r, f, base),
        |r, f, id| single::<L, K, F, false>(bvh, r, f, id).1,
    );
}

/// Occlusion of every ray: `out[i]` for `rays[i]`, packets or single rays as
/// [`closest`] picks them.
///
/// # Panics
/// When `out.len() != rays.len()`.
#[track_caller]
pub fn occluded<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray], out: &mut [bool]) {
    occluded_with::<L, K, _>(bvh, rays, out, &mut AcceptAll);
}

/// [`occluded`] counting only the hits `filter` accepts (the candidate's `ray` is the ray's
/// index in `rays`).
///
/// # Panics
/// When `out.len() != rays.len()`, or `rays.len() > u32::MAX`.
#[track_caller]
pub fn occluded_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [bool],
    filter: &mut F,
) {
    occluded_slice::<L, F>(
        rays,
        out,
        filter,
        |r, f, base| packet::<L, K, F, true>(bvh, r, f, base).mask,
        |r, f, id| single::<L, K, F, true>(bvh, r, f, id).0,
    );
}
