//! Partial re-braiding: a level's instances whose trees span much of the level are entered by
//! parts of their trees (subtrees with their own world boxes), so that the level's tree orders
//! and culls those parts among the other instances' ([`open_parts`]).

use super::Transform;
use crate::bvh::{Bvh8Node, EMPTY};
use crate::prim::Aabb;
use alloc::collections::BinaryHeap;
use alloc::vec::Vec;

/// A part of a level's instance `k`: its world box and the node its subtree starts at (0: the
/// root).
#[derive(Clone, Copy, Debug)]
pub(super) struct Part {
    pub k: u32,
    pub world: Aabb,
    pub node: u32,
}

/// What a part's instance places, when its tree can be opened: the tree's nodes, the instance's
/// transform and the tree's box slack.
pub(super) type Opened<'a> = Option<(&'a [Bvh8Node], &'a Transform, f32)>;

/// A part is opened while its box's half area is above this share of the level's box's.
const LARGE: f32 = 1.0 / 64.0;

/// An instance is opened when the boxes of others cover at least this share of its box's half
/// area (summed over them).
const OVERLAPPED: f32 = 0.5;

/// Most pairs of boxes [`overlapped`] compares (beyond, the rest count as apart).
const PAIRS: usize = 1 << 22;

/// At most this many parts per instance of the level, on average.
const PARTS_PER_INSTANCE: usize = 16;

/// Opens the largest parts of `parts` (each instance's whole tree at first) into their node's
/// children (when every child is a node: parts are subtrees, never leaves), largest world box
/// first, while the largest is above [`LARGE`] of the level's box and the parts stay within
/// [`PARTS_PER_INSTANCE`] per instance; only instances that others overlap ([`overlapped`]) are
/// opened. A ray then enters the parts of overlapping, level-spanning trees in the level's
/// order, culled by its best hit, instead of each whole tree in turn; instances that lie apart
/// stay whole (one entry each, as an entry costs a ray's setup). `tree(k)` tells what instance
/// `k` places (`None`: a group, never opened). A child slot whose world box cannot be formed
/// keeps its parent whole. Deterministic: the same parts give the same result.
pub(super) fn open_parts<'a>(parts: &mut Vec<Part>, tree: impl Fn(u32) -> Opened<'a>) {
    if parts.len() < 2 {
        return;
    }
    let level = parts.iter().fold(Aabb::EMPTY, |a, p| a.union(p.world));
    let large = level.half_area() * LARGE;
    if !(large > 0.0 && large.is_finite()) {
        return;
    }
    let open = overlapped(parts);
    let budget = parts.len().saturating_mul(PARTS_PER_INSTANCE);
    // Largest first; among equal areas the earlier part (the key is the area's bits: areas are
    // finite and non-negative, so their bits order as they do).
    let key = |i: usize, p: &Part| (p.world.half_area().to_bits(), usize::MAX - i);
    let mut heap: BinaryHeap<(u32, usize)> = parts
        .iter()
        .enumerate()
        .filter(|&(i, p)| open[i] && p.world.half_area() > large)
        .map(|(i, p)| key(i, p))
        .collect();
    while let Some((_, i)) = heap.pop() {
        let i = usize::MAX - i;
        if parts.len() + 7 > budget {
            break;
        }
        let p = parts[i];
        let Some((nodes, transform, slack)) = tree(p.k) else {
            continue;
        };
        let Some(children) = nodes
            .get(p.node as usize)
            .and_then(|n| children(n, transform, slack))
        else {
            continue;
        };
        let mut new = children.into_iter().map(|(world, node)| Part {
            k: p.k,
            world,
            node,
        });
        let Some(first) = new.next() else {
            continue;
        };
        parts[i] = first;
        let at = parts.len();
        parts.extend(new);
        for j in core::iter::once(i).chain(at..parts.len()) {
            let q = &parts[j];
            if q.world.half_area() > large {
                heap.push(key(j, q));
            }
        }
    }
}

/// The used slots of `node` as (world box, node), or `None` when a slot is a leaf or its world
/// box cannot be formed.
fn children(node: &Bvh8Node, transform: &Transform, slack: f32) -> Option<Vec<(Aabb, u32)>> {
    (0..node.child.len())
        .filter(|&s| node.child[s] != EMPTY)
        .map(|s| {
            if node.count[s] != 0 {
                return None;
            }
            let obj = Aabb {
                lo: [node.lo[0][s], node.lo[1][s], node.lo[2][s]],
                hi: [node.hi[0][s], node.hi[1][s], node.hi[2][s]],
            };
            let world = transform.world_box_within(&obj, slack)?;
            Some((world, node.child[s]))
        })
        .collect()
}

/// Per part (one per instance, before opening): whether the other parts' boxes cover at least
/// [`OVERLAPPED`] of its half area, summing the half areas of the intersections (boxes that
/// only touch do not count). A sweep along
/// x compares only boxes whose x ranges meet, at most [`PAIRS`] pairs.
fn overlapped(parts: &[Part]) -> Vec<bool> {
    let mut by_x: Vec<usize> = (0..parts.len()).collect();
    by_x.sort_by(|&a, &b| parts[a].world.lo[0].total_cmp(&parts[b].world.lo[0]));
    let mut covered = alloc::vec![0.0f32; parts.len()];
    let mut pairs = 0;
    'sweep: for (n, &a) in by_x.iter().enumerate() {
        let wa = parts[a].world;
        for &b in &by_x[n + 1..] {
            let wb = parts[b].world;
            if wb.lo[0] > wa.hi[0] {
                break;
            }
            pairs += 1;
            if pairs > PAIRS {
                break 'sweep;
            }
            let lo = core::array::from_fn(|k| wa.lo[k].max(wb.lo[k]));
            let hi = core::array::from_fn(|k| wa.hi[k].min(wb.hi[k]));
            // Boxes that only touch (a face, an edge) do not overlap; two flat boxes in one
            // plane do.
            let meet = |k: usize| lo[k] < hi[k] || (lo[k] == hi[k] && wa.lo[k] == wa.hi[k]);
            if (0..3).all(meet) {
                let shared = Aabb { lo, hi }.half_area();
                covered[a] += shared;
                covered[b] += shared;
            }
        }
    }
    parts
        .iter()
        .zip(covered)
        .map(|(p, c)| c >= OVERLAPPED * p.world.half_area())
        .collect()
}
