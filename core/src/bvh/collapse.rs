//! The binary build's tree collapsed into 8-wide nodes, parents before children: each wide node
//! opens its binary node's largest inner children until it has eight, and each leaf's
//! primitives go out in whole SoA blocks as the leaf is placed.

use super::build::{BinNode, BuildStats, Item};
use super::{Bvh8Node, PAD, WIDTH};
use crate::prim::{Aabb, Primitive, BLOCK};
use alloc::vec;
use alloc::vec::Vec;

/// The wide tree's slices, as [`collapse`] writes them.
pub(super) struct Wide<P> {
    /// Nodes, the root first.
    pub nodes: Vec<Bvh8Node>,
    /// Primitive blocks in leaf order.
    pub blocks: Vec<[f32; BLOCK]>,
    /// The caller's index per block slot ([`PAD`] in a leaf's last block's empty slots).
    pub ids: Vec<u32>,
    /// One block's primitives, reused.
    chunk: Vec<P>,
}

/// Collapses `bin` (root first; its leaves' items are `items`, whose `local` indexes `refs`,
/// the indices in `prims`), counting nodes, leaves, depth and SAH cost into `stats`.
pub(super) fn collapse<P: Primitive>(
    bin: &[BinNode],
    items: &[Item],
    refs: &[u32],
    prims: &[P],
    stats: &mut BuildStats,
) -> Wide<P> {
    let mut w = Wide {
        nodes: Vec::new(),
        blocks: Vec::new(),
        ids: Vec::new(),
        chunk: Vec::with_capacity(BLOCK),
    };
    let Some(root) = bin.first() else {
        return w;
    };
    let root_area = root.bounds.half_area().max(f32::MIN_POSITIVE);
    // Work list: (binary node to expand into a wide node, wide node slot to fill, depth).
    w.nodes.push(Bvh8Node::EMPTY);
    let mut work = vec![(0usize, 0usize, 1usize)];
    stats.sah_cost += 1.0;
    while let Some((b, slot, depth)) = work.pop() {
        stats.depth = stats.depth.max(depth);
        let mut node = Bvh8Node::EMPTY;
        for (s, &k) in open(bin, b).iter().enumerate() {
            let (lo, hi) = widen(bin[k].bounds, bin[k].m);
            for a in 0..3 {
                node.lo[a][s] = lo[a];
                node.hi[a][s] = hi[a];
            }
            let area = bin[k].bounds.half_area() / root_area;
            if bin[k].left == usize::MAX {
                let (start, count) = (bin[k].start, bin[k].count);
                node.child[s] = w.ids.len() as u32;
                node.count[s] = count as u32;
                w.leaf(&items[start..start + count], refs, prims);
                stats.leaves += 1;
                stats.sah_cost += area * count as f32;
            } else {
                node.child[s] = w.nodes.len() as u32;
                node.count[s] = 0;
                stats.sah_cost += area;
                w.nodes.push(Bvh8Node::EMPTY);
                work.push((k, w.nodes.len() - 1, depth + 1));
            }
        }
        node.set_order();
        w.nodes[slot] = node;
    }
    w
}

/// The children of the wide node over binary node `b`: its two children, then the inner
/// child with the largest area opened in place until there are eight (a lone leaf under the
/// root is its own child).
fn open(bin: &[BinNode], b: usize) -> Vec<usize> {
    let mut kids: Vec<usize> = if bin[b].left == usize::MAX {
        vec![b]
    } else {
        vec![bin[b].left, bin[b].right]
    };
    while kids.len() < WIDTH {
        let pick = kids
            .iter()
            .enumerate()
            .filter(|(_, &k)| bin[k].left != usize::MAX)
            .max_by(|a, c| {
                let (x, y) = (bin[*a.1].bounds.half_area(), bin[*c.1].bounds.half_area());
                // Larger area first; on ties the earlier slot (max_by keeps the last).
                x.total_cmp(&y).then(c.0.cmp(&a.0))
            })
            .map(|(i, _)| i);
        let Some(i) = pick else { break };
        let k = kids.remove(i);
        kids.insert(i, bin[k].right);
        kids.insert(i, bin[k].left);
    }
    kids
}

impl<P: Primitive> Wide<P> {
    /// Writes one leaf's primitives (`leaf`, indices into `refs`) as whole blocks, padding the
    /// last block's ids with [`PAD`].
    fn leaf(&mut self, leaf: &[Item], refs: &[u32], prims: &[P]) {
        for part in leaf.chunks(BLOCK) {
            self.chunk.clear();
            self.chunk
                .extend(part.iter().map(|i| prims[refs[i.local as usize] as usize]));
            let at = self.blocks.len();
            self.blocks.resize(at + P::WORDS, [0.0; BLOCK]);
            P::write_block(&self.chunk, &mut self.blocks[at..]);
            self.ids.extend(part.iter().map(|i| refs[i.local as usize]));
            self.ids.resize(self.ids.len().next_multiple_of(BLOCK), PAD);
        }
    }
}

/// The box slack of a box at build time: `lo`, `hi` moved outward by [`super::SLACK`] of the
/// largest coordinate magnitude of the box and of `m` (its primitives' whole boxes, when a
/// spatial split clipped them: a kernel's margin scales with the primitive, not the part),
/// then by one ulp.
pub(super) fn widen(bx: Aabb, m: f32) -> ([f32; 3], [f32; 3]) {
    let (lo, hi) = (bx.lo, bx.hi);
    let delta = bx.magnitude().max(m) * super::SLACK;
    (
        core::array::from_fn(|k| (lo[k] - delta).next_down()),
        core::array::from_fn(|k| (hi[k] + delta).next_up()),
    )
}
