//! Box queries on one tree: [`overlapping`], the primitives that meet an axis-aligned box.

use super::all_hits::{insert_sorted, AllHits};
use arrayvec::ArrayVec;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref, PAD, STACK};
use octoray_core::glam::Vec3;
use octoray_core::kernels::MeetsBox;
use octoray_core::prim::{BlockLane, BLOCK};
use wide::f32x8;

/// The primitives of `bvh` that meet the closed box `[lo, hi]`
/// ([`octoray_core::kernels::MeetsBox`]: triangles exactly but for touching within about 2⁻⁵⁰
/// of their coordinates, spheres as balls), by index: the first `out.len()` indices above
/// `after` (`None`: from the start), ascending, each once. `complete` is false when more
/// follow: call again with `after = Some(out[stored - 1])`. A box with a NaN corner or `lo > hi`
/// on an axis meets nothing.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::Bvh8, glam::Vec3, prim::VertexTriangle};
/// use octoray_packet::tree::overlapping;
/// let tris: Vec<_> = (0..10)
///     .map(|i| {
///         let x = i as f32;
///         VertexTriangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0))
///     })
///     .collect();
/// let bvh = Bvh8::build(&tris);
/// let mut out = [0u32; 8];
/// let found = overlapping(bvh.as_ref(), Vec3::new(2.5, 0.0, 0.0), Vec3::new(5.0, 1.0, 1.0), None, &mut out);
/// assert_eq!((found.stored, found.complete, &out[..3]), (3, true, &[3, 4, 5][..]));
/// # }
/// ```
pub fn overlapping<P: MeetsBox>(
    bvh: Bvh8Ref<'_, P>,
    lo: Vec3,
    hi: Vec3,
    after: Option<u32>,
    out: &mut [u32],
) -> AllHits {
    let mut found = AllHits {
        stored: 0,
        complete: true,
    };
    if !(lo.cmple(hi).all()) || bvh.nodes().is_empty() {
        return found;
    }
    let (lo64, hi64) = (lo.to_array().map(f64::from), hi.to_array().map(f64::from));
    box_walk(
        bvh.nodes(),
        0,
        lo.to_array(),
        hi.to_array(),
        |first, count| {
            let first = first as usize;
            let end = first.saturating_add(count as usize).min(bvh.ids().len());
            for slot in first..end {
                let id = bvh.ids()[slot];
                if id == PAD || after.is_some_and(|a| id <= a) {
                    continue;
                }
                let words = BlockLane::new::<P>(bvh.block_of(slot), slot % BLOCK);
                if P::meets_box(&words, lo64, hi64) {
                    insert_sorted(out, &mut found, id, u32::cmp);
                }
            }
        },
    );
    found
}

/// The walk of a tree of `nodes` from node `start` (0: the root) for the box `[lo, hi]`: `leaf`
/// gets the slots `(first, count)` of every leaf whose (conservative) box meets it.
pub(crate) fn box_walk(
    nodes: &[Bvh8Node],
    start: u32,
    lo: [f32; 3],
    hi: [f32; 3],
    mut leaf: impl FnMut(u32, u32),
) {
    if nodes.is_empty() {
        return;
    }
    let mut stack = ArrayVec::<(u32, u32), STACK>::new();
    stack.push((start, 0));
    while let Some((child, count)) = stack.pop() {
        if count > 0 {
            leaf(child, count);
            continue;
        }
        let Some(node) = nodes.get(child as usize) else {
            continue;
        };
        // The children whose boxes meet the query box, on every axis.
        let meets = (0..3).fold(u32::MAX, |m, a| {
            let (clo, chi) = (f32x8::from(node.lo[a]), f32x8::from(node.hi[a]));
            let ok = clo.simd_le(f32x8::splat(hi[a])) & chi.simd_ge(f32x8::splat(lo[a]));
            m & ok.to_bitmask()
        });
        let mut near = meets & 0xff;
        while near != 0 {
            let s = near.trailing_zeros() as usize;
            near &= near - 1;
            // A validated tree is at most MAX_DEPTH deep, so the stack never fills.
            let _ = stack.try_push((node.child[s], node.count[s]));
        }
    }
}
