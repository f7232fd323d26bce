//! Slices of rays: packets where a packet's rays share a direction octant (coherent), single
//! rays elsewhere.

use super::epilog::{Best, PacketBest};
use super::packet::packet_result;
use octoray_core::hit::{Hit, HitFilter};
use octoray_core::lanes::{LaneMask, Lanes};
use octoray_core::prim::{Ray, RayLanes};

/// Do all rays of a chunk point into one octant (a coherent packet)?
pub(crate) fn coherent(rays: &[Ray]) -> bool {
    let octant = |r: &Ray| {
        (r.dir.x.is_sign_negative() as u8)
            | ((r.dir.y.is_sign_negative() as u8) << 1)
            | ((r.dir.z.is_sign_negative() as u8) << 2)
    };
    rays.iter().all(|r| octant(r) == octant(&rays[0]))
}

/// The closest-hit slice loop of a tree or a scene: chunks of `L::LANES` rays that share a
/// direction octant go to `packet`, the others ray by ray to `single` (each given the index of
/// its first ray).
#[track_caller]
pub(crate) fn closest_slice<L: Lanes, F: HitFilter>(
    rays: &[Ray],
    out: &mut [Option<Hit>],
    filter: &mut F,
    mut packet: impl FnMut(&RayLanes<L>, &mut F, u32) -> PacketBest<L>,
    mut single: impl FnMut(&Ray, &mut F, u32) -> Option<Best<L::Scalar>>,
) {
    check_len("closest", rays.len(), out.len());
    for (c, (chunk, out)) in rays
        .chunks(L::LANES)
        .zip(out.chunks_mut(L::LANES))
        .enumerate()
    {
        let base = (c * L::LANES) as u32;
        if chunk.len() > 1 && coherent(chunk) {
            let h = packet_result(&packet(&RayLanes::load(chunk), filter, base));
            for (i, o) in out.iter_mut().enumerate() {
                *o = h.lane(i);
            }
        } else {
            for (i, (r, o)) in chunk.iter().zip(out).enumerate() {
                *o = single(r, filter, base + i as u32).map(|b| b.hit());
            }
        }
    }
}

/// The occlusion slice loop of a tree or a scene, chunks picked as [`closest_slice`] picks
/// them.
#[track_caller]
pub(crate) fn occluded_slice<L: Lanes, F: HitFilter>(
    rays: &[Ray],
    out: &mut [bool],
    filter: &mut F,
    mut packet: impl FnMut(&RayLanes<L>, &mut F, u32) -> L::Mask,
    mut single: impl FnMut(&Ray, &mut F, u32) -> bool,
) {
    check_len("occluded", rays.len(), out.len());
    for (c, (chunk, out)) in rays
        .chunks(L::LANES)
        .zip(out.chunks_mut(L::LANES))
        .enumerate()
    {
        let base = (c * L::LANES) as u32;
        if chunk.len() > 1 && coherent(chunk) {
            let m = packet(&RayLanes::load(chunk), filter, base).bitmask();
            for (i, o) in out.iter_mut().enumerate() {
                *o = (m >> i) & 1 == 1;
            }
        } else {
            for (i, (r, o)) in chunk.iter().zip(out).enumerate() {
                *o = single(r, filter, base + i as u32);
            }
        }
    }
}

/// Panics unless `out` has one entry per ray and the rays can be numbered by `u32`.
#[track_caller]
pub(crate) fn check_len(what: &str, rays: usize, out: usize) {
    assert_eq!(
        out, rays,
        "octoray {what}: out has {out} entries for {rays} rays"
    );
    assert!(
        u32::try_from(rays).is_ok(),
        "octoray {what}: {rays} rays; rays are numbered by u32"
    );
}
