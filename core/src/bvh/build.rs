//! Top-down binned SAH build (Wald 2007, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies"; 32 bins like Embree), a binary tree collapsed into 8-wide nodes.
//!
//! Deterministic: plain f32 arithmetic in a fixed order, no hashing, ties broken by primitive
//! index, so the same input gives the same tree bit for bit on every build; with threads
//! ([`Bvh8::try_build_on`]) too, since each half of a split only touches its own items.

use super::collapse::{collapse, widen, Wide};
use super::{Bvh8Node, Bvh8Ref, BvhError, MAX_DEPTH, MAX_PRIMS, PAD};
use crate::prim::{Aabb, Primitive, BLOCK};
use alloc::vec;
use alloc::vec::Vec;

/// Number of SAH bins per axis (at most; small nodes use fewer, [`bins_for`]).
const BINS: usize = 32;

/// Bins for a node of `n` items: 32 from 128 items up, fewer below (4 at the least): the sweep
/// over the bins then costs no more than the pass over the items.
#[inline]
fn bins_for(n: usize) -> usize {
    (n / 4).clamp(4, BINS)
}
/// Where a node lies in the binary build: its depth, and the largest leaf of the layout
/// ([`Primitive::LEAF`]).
#[derive(Clone, Copy)]
struct Level {
    depth: usize,
    max_leaf: usize,
}

impl Level {
    fn down(self) -> Self {
        Self {
            depth: self.depth + 1,
            ..self
        }
    }
}
/// SAH cost of visiting a node, relative to testing one block of [`BLOCK`] primitives (one ray
/// against a node's eight boxes costs about what it costs against eight triangles at once).
const TRAVERSAL_COST: f32 = 1.0;
/// SAH cost of testing one block.
const BLOCK_COST: f32 = 1.0;

/// SAH cost of testing `n` primitives: whole blocks.
#[inline]
fn leaf_cost(n: usize) -> f32 {
    n.div_ceil(BLOCK) as f32 * BLOCK_COST
}
/// Binary depth from which splits are by count (balanced), so the tree stays within
/// [`MAX_DEPTH`] whatever the input.
const BALANCED_FROM: usize = MAX_DEPTH - 34;

/// The owned tree: nodes, primitives in leaf order (SoA blocks of [`BLOCK`], each leaf padded to
/// whole blocks), and their indices in the caller's slice.
#[derive(Clone, Debug)]
pub struct Bvh8<P> {
    nodes: Vec<Bvh8Node>,
    blocks: Vec<[f32; BLOCK]>,
    ids: Vec<u32>,
    /// Length of the slice the tree was built from.
    prims: usize,
    stats: BuildStats,
    _prim: core::marker::PhantomData<P>,
}

/// How a tree is built: the plain binned SAH build, or with spatial splits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// How many extra leaf references spatial splits may add, as a share of the primitives
    /// (0: no spatial splits; at most 1). Each split leaves what it did not spend to its halves
    /// in proportion to their items (and below the join's size, what the left half leaves to
    /// the right one), so the build stays deterministic under any join.
    pub split_budget: f32,
}

impl BuildOptions {
    /// The binned SAH build: fastest to build, every primitive in one leaf.
    pub const BINNED: Self = Self { split_budget: 0.0 };
    /// Spatial splits with up to as many leaf references again as primitives: slower to build
    /// and larger, far fewer primitive tests and node visits where primitives are long or large
    /// against their neighbours (a primitive may then sit in several leaves).
    pub const SPATIAL: Self = Self { split_budget: 1.0 };

    /// Extra references for `n` items.
    fn budget(&self, n: usize) -> usize {
        let share = if self.split_budget.is_finite() {
            self.split_budget.clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((n as f64 * share as f64) as usize).min(MAX_PRIMS.saturating_sub(n))
    }
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self::BINNED
    }
}

/// Figures of a built tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildStats {
    /// Primitives in the tree (those with finite bounds).
    pub prims: usize,
    /// Primitives left out (a non-finite coordinate: no kernel can hit them).
    pub skipped: usize,
    /// Leaf references: `prims`, plus one for each extra leaf a spatial split put a primitive in.
    pub references: usize,
    /// Nodes.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Depth in nodes (the root is 1).
    pub depth: usize,
    /// SAH cost of the 8-wide tree with the conventional unit costs: `Σ area(node)/area(root) +
    /// Σ area(leaf)/area(root)·count` (one per node visit, one per primitive test; comparable
    /// across libraries).
    pub sah_cost: f32,
    /// Bytes of nodes + primitive blocks (leaves padded to whole blocks) + indices per primitive.
    pub bytes_per_prim: f32,
    /// Share of block slots that hold a primitive (the rest is leaf padding).
    pub block_fill: f32,
}

/// Runs two closures and returns both results: how a build runs the two halves of a split.
/// [`Sequential`] runs them one after the other; a thread pool's join may run them at once (the
/// facade's `rayon` feature provides one). Every join gives the same tree.
pub trait Join: Sync {
    /// Runs `a` and `b`, in any order or at once.
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B);
}

/// One after the other, on the calling thread (no threads: `no_std` targets).
#[derive(Clone, Copy, Debug, Default)]
pub struct Sequential;

impl Join for Sequential {
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B) {
        (a(), b())
    }
}

/// A node of the binary tree the build splits into (collapsed into 8-wide nodes after).
pub(super) struct BinNode {
    /// Its items' union box.
    pub(super) bounds: Aabb,
    /// The largest magnitude of its items' whole primitives ([`Item::m`]).
    pub(super) m: f32,
    /// Inner: children; leaf: `usize::MAX`, with `start..start + count` in the items.
    pub(super) left: usize,
    /// Inner: the right child.
    pub(super) right: usize,
    /// Leaf: its first item.
    pub(super) start: usize,
    /// Leaf: its item count.
    pub(super) count: usize,
}

impl<P: Primitive> Bvh8<P> {
    /// Builds the tree over `prims` (their slice indices become the reported primitive indices).
    ///
    /// # Panics
    /// When `prims.len() > MAX_PRIMS` (indices are `u32`): use [`Bvh8::try_build`] to get an error
    /// instead.
    pub fn build(prims: &[P]) -> Self {
        match Self::try_build(prims) {
            Ok(b) => b,
            Err(e) => panic!("octoray Bvh8::build: {e}"),
        }
    }

    /// Builds the tree, or says why not (too many primitives).
    pub fn try_build(prims: &[P]) -> Result<Self, BvhError> {
        Self::try_build_on(prims, &Sequential)
    }

    /// [`Bvh8::try_build`] with the two halves of every large split handed to `join`: with a
    /// thread pool's join (the facade's `rayon` feature: `octoray::parallel::Rayon`) the binary
    /// build runs on its threads. The tree is the same bit for bit as [`Bvh8::try_build`]'s,
    /// whatever the join and the number of threads (each half only reads and reorders its own
    /// items; the halves are joined in order). The collapse into 8-wide nodes stays on the
    /// calling thread.
    pub fn try_build_on<J: Join>(prims: &[P], join: &J) -> Result<Self, BvhError> {
        Self::try_build_options(prims, BuildOptions::BINNED, join)
    }

    /// Former name of [`Bvh8::try_build_on`].
    #[deprecated(
        since = "0.1.0",
        note = "renamed `try_build_on`: `_with` names the hit-filter forms"
    )]
    pub fn try_build_with<J: Join>(prims: &[P], join: &J) -> Result<Self, BvhError> {
        Self::try_build_on(prims, join)
    }

    /// [`Bvh8::try_build_on`] as `options` say: [`BuildOptions::SPATIAL`] for a tree with
    /// spatial splits (slower to build, faster to trace where primitives are long or large
    /// against their neighbours). The same input, options and primitives give the same tree bit
    /// for bit, whatever the join.
    pub fn try_build_options<J: Join>(
        prims: &[P],
        options: BuildOptions,
        join: &J,
    ) -> Result<Self, BvhError> {
        if prims.len() > MAX_PRIMS {
            return Err(BvhError::TooManyPrims(prims.len()));
        }
        let mut boxes = Vec::with_capacity(prims.len());
        let mut refs = Vec::with_capacity(prims.len());
        for (i, p) in prims.iter().enumerate() {
            if let Some(b) = p.bounds() {
                boxes.push(b);
                refs.push(i as u32);
            }
        }
        let skipped = prims.len() - refs.len();
        let (bin, items) = binary(prims, &boxes, &refs, options, join);
        let mut stats = BuildStats {
            prims: refs.len(),
            skipped,
            references: items.len(),
            ..BuildStats::default()
        };
        let Wide {
            nodes, blocks, ids, ..
        } = collapse(&bin, &items, &refs, prims, &mut stats);
        if ids.len() > MAX_PRIMS {
            // Leaf padding took the block slots past u32 indices.
            return Err(BvhError::TooManyPrims(ids.len()));
        }
        stats.nodes = nodes.len();
        let bytes = nodes.len() * core::mem::size_of::<Bvh8Node>()
            + blocks.len() * core::mem::size_of::<[f32; BLOCK]>()
            + ids.len() * 4;
        if !refs.is_empty() {
            stats.bytes_per_prim = bytes as f32 / refs.len() as f32;
            stats.block_fill = stats.references as f32 / ids.len() as f32;
        }
        debug_assert!(stats.depth <= MAX_DEPTH);
        Ok(Self {
            nodes,
            blocks,
            ids,
            prims: prims.len(),
            stats,
            _prim: core::marker::PhantomData,
        })
    }

    /// The tree as borrowed slices, for traversal.
    pub fn as_ref(&self) -> Bvh8Ref<'_, P> {
        Bvh8Ref {
            nodes: &self.nodes,
            blocks: &self.blocks,
            ids: &self.ids,
            prims: self.prims,
            _prim: core::marker::PhantomData,
        }
    }

    /// The nodes, root first (`bytemuck::cast_slice` them to bytes to store the tree).
    pub fn nodes(&self) -> &[Bvh8Node] {
        &self.nodes
    }

    /// The primitives in leaf order, in SoA blocks (see [`Bvh8Ref::new`] for the layout;
    /// `bytemuck::cast_slice` them to bytes to store the tree).
    pub fn blocks(&self) -> &[[f32; BLOCK]] {
        &self.blocks
    }

    /// `ids()[k]`: the caller's index of the primitive in block slot `k` ([`PAD`] on padding).
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// Figures of the tree as built (a refit keeps them).
    pub fn stats(&self) -> BuildStats {
        self.stats
    }

    /// Refits the tree in place to `prims` after their coordinates moved: the same slice (same
    /// length and order), the topology kept, every leaf block rewritten from `prims` and every
    /// box recomputed bottom up. Linear in the tree's size, one scratch box per node and block.
    ///
    /// Each box is the one the binned builder would compute for the same topology (the exact
    /// union of its primitives' whole bounds, widened by [`super::SLACK`]; a spatial split's
    /// parts grow back to whole primitives), so every walk's answer equals brute force over
    /// `prims`, bit for bit, under the same contract as a built tree; a primitive that
    /// became non-finite is never hit (its box is left out, and a box of only such primitives is
    /// never entered). Traversal cost grows as the topology fits the new positions worse.
    ///
    /// # Errors
    /// [`BvhError::RefitLength`] when `prims` is not as long as the slice the tree was built
    /// from; [`BvhError::RefitLeftOut`] when a primitive the build left out (a non-finite
    /// coordinate) is now finite, since it is in no leaf: rebuild then. On error the tree is
    /// unchanged.
    pub fn refit(&mut self, prims: &[P]) -> Result<(), BvhError>
    where
        P: Sync,
    {
        self.refit_on(prims, &Sequential)
    }

    /// [`Bvh8::refit`] with the blocks rewritten on `join`'s threads (the facade's
    /// `octoray::parallel::Rayon`); the tree is the same bit for bit whatever the join.
    ///
    /// # Errors
    /// As [`Bvh8::refit`].
    pub fn refit_on<J: Join>(&mut self, prims: &[P], join: &J) -> Result<(), BvhError>
    where
        P: Sync,
    {
        if prims.len() != self.prims {
            return Err(BvhError::RefitLength {
                built: self.prims,
                given: prims.len(),
            });
        }
        refit_parts(
            &mut self.nodes,
            &mut self.blocks,
            &self.ids,
            prims,
            self.stats.skipped > 0,
            join,
        )
    }

    /// Former name of [`Bvh8::refit_on`].
    #[deprecated(
        since = "0.1.0",
        note = "renamed `refit_on`: `_with` names the hit-filter forms"
    )]
    pub fn refit_with<J: Join>(&mut self, prims: &[P], join: &J) -> Result<(), BvhError>
    where
        P: Sync,
    {
        self.refit_on(prims, join)
    }

    /// The owned slices: nodes, blocks, ids (for a scene's storage).
    pub(crate) fn into_parts(self) -> (Vec<Bvh8Node>, Vec<[f32; BLOCK]>, Vec<u32>) {
        (self.nodes, self.blocks, self.ids)
    }
}

/// The refit of a tree held as slices (a [`Bvh8`]'s, or one geometry's within a scene's):
/// `check_left_out` when the build may have left primitives out.
pub(crate) fn refit_parts<P: Primitive + Sync, J: Join>(
    nodes: &mut [Bvh8Node],
    blocks: &mut [[f32; BLOCK]],
    ids: &[u32],
    prims: &[P],
    check_left_out: bool,
    join: &J,
) -> Result<(), BvhError> {
    if check_left_out {
        let mut held = vec![false; prims.len()];
        for &id in ids.iter().filter(|&&id| id != PAD) {
            held[id as usize] = true;
        }
        if let Some(k) = (0..prims.len()).find(|&k| !held[k] && prims[k].bounds().is_some()) {
            return Err(BvhError::RefitLeftOut { prim: k });
        }
    }
    // Every block rewritten from its primitives, with their union box: independent work.
    let mut boxes = vec![Aabb::EMPTY; ids.len() / BLOCK];
    refit_blocks(blocks, ids, &mut boxes, prims, join);
    // Then the nodes. Children have larger indices than their parents: one pass from the
    // last node up sees every child's union before its parent needs it.
    let mut raw = vec![Aabb::EMPTY; nodes.len()];
    for n in (0..nodes.len()).rev() {
        let mut node = nodes[n];
        let mut all = Aabb::EMPTY;
        for s in 0..node.len() {
            let (child, count) = (node.child[s] as usize, node.count[s] as usize);
            let bx = if count == 0 {
                raw[child]
            } else {
                boxes[child / BLOCK..(child + count).div_ceil(BLOCK)]
                    .iter()
                    .fold(Aabb::EMPTY, |a, &b| a.union(b))
            };
            // A box of only non-finite primitives is inverted, as an empty slot's is.
            let (lo, hi) = if bx.is_finite() {
                widen(bx, 0.0)
            } else {
                (Aabb::EMPTY.lo, Aabb::EMPTY.hi)
            };
            for a in 0..3 {
                node.lo[a][s] = lo[a];
                node.hi[a][s] = hi[a];
            }
            all = all.union(bx);
        }
        raw[n] = all;
        node.set_order();
        nodes[n] = node;
    }
    Ok(())
}

/// Blocks at which a refit splits its block work between the join's two sides.
const REFIT_SPLIT: usize = 1024;

/// Rewrites each block of `blocks` (its primitives' indices in `ids`, [`PAD`] after them) from
/// `prims`, and puts the union of their bounds in `boxes`; halves go to `join`.
fn refit_blocks<P: Primitive + Sync, J: Join>(
    blocks: &mut [[f32; BLOCK]],
    ids: &[u32],
    boxes: &mut [Aabb],
    prims: &[P],
    join: &J,
) {
    if boxes.len() > REFIT_SPLIT {
        let h = boxes.len() / 2;
        let (b0, b1) = blocks.split_at_mut(h * P::WORDS);
        let (i0, i1) = ids.split_at(h * BLOCK);
        let (x0, x1) = boxes.split_at_mut(h);
        join.join(
            || refit_blocks(b0, i0, x0, prims, join),
            || refit_blocks(b1, i1, x1, prims, join),
        );
        return;
    }
    for (k, bx) in boxes.iter_mut().enumerate() {
        let ids = &ids[k * BLOCK..][..BLOCK];
        let n = ids.iter().take_while(|&&i| i != PAD).count();
        let mut chunk = [P::zeroed(); BLOCK];
        for (c, &i) in chunk.iter_mut().zip(&ids[..n]) {
            *c = prims[i as usize];
        }
        P::write_block(&chunk[..n], &mut blocks[k * P::WORDS..][..P::WORDS]);
        *bx = chunk[..n]
            .iter()
            .filter_map(Primitive::bounds)
            .fold(Aabb::EMPTY, Aabb::union);
    }
}

/// The binary tree over the primitives with finite `boxes` (`refs`: their indices in `prims`),
/// root first, and its items in leaf order (more than `refs` when spatial splits place a
/// primitive in several leaves).
fn binary<P: Primitive, J: Join>(
    prims: &[P],
    boxes: &[Aabb],
    refs: &[u32],
    options: BuildOptions,
    join: &J,
) -> (Vec<BinNode>, Vec<Item>) {
    // `refs` holds slice indices; each item carries its box and centre (so the build's passes
    // read memory in order) and `local`, its index in `refs`.
    let mut items: Vec<Item> = boxes
        .iter()
        .enumerate()
        .map(|(k, b)| Item {
            bx: *b,
            c: b.center(),
            local: k as u32,
            m: b.magnitude(),
        })
        .collect();
    let level = Level {
        depth: 0,
        max_leaf: P::LEAF.clamp(1, BLOCK),
    };
    let budget = options.budget(items.len());
    let bin = if items.is_empty() {
        Vec::new()
    } else if budget == 0 {
        subtree(&mut items, 0, level, join)
    } else {
        let spatial = Spatial {
            prims,
            refs,
            root_area: boxes
                .iter()
                .fold(Aabb::EMPTY, |a, &b| a.union_finite(b))
                .half_area(),
        };
        let (bin, placed, _) = spatial.subtree(core::mem::take(&mut items), budget, level, join);
        items = placed;
        bin
    };
    (bin, items)
}

/// A primitive's box and centre during the build, and its index in `refs`. With spatial splits
/// an item is a reference: the box of the part of its primitive in a node, and `m`, the largest
/// coordinate magnitude of the whole primitive (what the box slack scales with).
#[derive(Clone, Copy)]
pub(super) struct Item {
    bx: Aabb,
    c: [f32; 3],
    /// Its primitive's index in `refs`.
    pub(super) local: u32,
    m: f32,
}

/// Below this many items a subtree is built in one task: the join's overhead would outweigh
/// the work.
const PARALLEL_MIN: usize = 8192;

/// The binary subtree over `items` (the node's items, reordered in place), nodes in preorder
/// with the root first; `base` is the position of `items[0]` among all items. The two halves of
/// a split go to `join`; the tree is the same whether it runs them one after the other or at
/// once (each half only reads and reorders its own items).
fn subtree<J: Join>(items: &mut [Item], base: usize, level: Level, join: &J) -> Vec<BinNode> {
    let mut scratch = Vec::new();
    let mut out = Vec::new();
    if items.len() < PARALLEL_MIN {
        split(&mut out, items, &mut scratch, base, 0, items.len(), level);
        return out;
    }
    let (bounds, m, mid) = decide(items, &mut scratch, level);
    drop(scratch);
    out.push(BinNode {
        bounds,
        m,
        left: usize::MAX,
        right: usize::MAX,
        start: base,
        count: items.len(),
    });
    let Some(mid) = mid else {
        return out;
    };
    let (l, r) = items.split_at_mut(mid);
    let (left, right) = join.join(
        || subtree(l, base, level.down(), join),
        || subtree(r, base + mid, level.down(), join),
    );
    link(&mut out, left, right, 0);
    out
}

/// Appends the preorder subtrees `left` and `right` after the root `out[0]` and links them to
/// it; the right subtree's item ranges move by `right_items`.
fn link(out: &mut Vec<BinNode>, left: Vec<BinNode>, right: Vec<BinNode>, right_items: usize) {
    let mut append = |part: Vec<BinNode>, shift: usize| {
        let at = out.len();
        out.extend(part.into_iter().map(|mut n| {
            if n.left != usize::MAX {
                n.left += at;
                n.right += at;
            }
            n.start += shift;
            n
        }));
        at
    };
    let (l, r) = (append(left, 0), append(right, right_items));
    (out[0].left, out[0].right) = (l, r);
}

/// Builds the binary node for `all[start..end]` and its subtree, one task; returns its index
/// in `out`. Node ranges are offset by `base`.
fn split(
    out: &mut Vec<BinNode>,
    all: &mut [Item],
    scratch: &mut Vec<Item>,
    base: usize,
    start: usize,
    end: usize,
    level: Level,
) -> usize {
    let (bounds, m, mid) = decide(&mut all[start..end], scratch, level);
    let me = out.len();
    out.push(BinNode {
        bounds,
        m,
        left: usize::MAX,
        right: usize::MAX,
        start: base + start,
        count: end - start,
    });
    if let Some(mid) = mid {
        let left = split(out, all, scratch, base, start, start + mid, level.down());
        let right = split(out, all, scratch, base, start + mid, end, level.down());
        out[me].left = left;
        out[me].right = right;
    }
    me
}

/// A node's items as binned by their centres: their box, centres' box, slack magnitude and
/// best object split.
struct Binned {
    bounds: Aabb,
    m: f32,
    cb: Aabb,
    /// Bins per axis.
    nb: usize,
    /// (cost, axis, bins on the left).
    best: Option<(f32, usize, usize)>,
}

/// Bins `items` by their centres and finds the best object split (none from
/// [`BALANCED_FROM`] down).
fn bin_objects(items: &[Item], depth: usize) -> Binned {
    let n = items.len();
    let (bounds, m) = items.iter().fold((Aabb::EMPTY, 0.0f32), |(b, m), i| {
        (b.union_finite(i.bx), m.max(i.m))
    });
    let cb = items.iter().fold(Aabb::EMPTY, |b, i| b.grow(i.c));
    let nb = bins_for(n);
    let mut best: Option<(f32, usize, usize)> = None;
    if n == 1 || depth >= BALANCED_FROM {
        return Binned {
            bounds,
            m,
            cb,
            nb,
            best,
        };
    }
    let area = bounds.half_area();
    // Bin all three axes in one pass over the items (the pass is memory-bound).
    let scale: [f32; 3] = core::array::from_fn(|a| nb as f32 / (cb.hi[a] - cb.lo[a]));
    let mut bb = [[Aabb::EMPTY; BINS]; 3];
    let mut cnt = [[0usize; BINS]; 3];
    for &Item { bx, c, .. } in items {
        for a in 0..3 {
            // A flat axis (hi ≤ lo: centres are finite) is skipped below; its bins unused.
            let b = bin_of(c[a], cb.lo[a], scale[a], nb);
            bb[a][b] = bb[a][b].union_finite(bx);
            cnt[a][b] += 1;
        }
    }
    for axis in 0..3 {
        if cb.hi[axis] <= cb.lo[axis] {
            continue;
        }
        let (bb, cnt) = (&bb[axis], &cnt[axis]);
        // Right-to-left sweep of areas·counts, then left to right.
        let mut right = [0.0f32; BINS];
        let (mut acc, mut c) = (Aabb::EMPTY, 0usize);
        for b in (1..nb).rev() {
            acc = acc.union_finite(bb[b]);
            c += cnt[b];
            right[b] = acc.half_area() * leaf_cost(c);
        }
        let (mut acc, mut c) = (Aabb::EMPTY, 0usize);
        for b in 0..nb - 1 {
            acc = acc.union_finite(bb[b]);
            c += cnt[b];
            if c == 0 || c == n {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (acc.half_area() * leaf_cost(c) + right[b + 1]) / area.max(f32::MIN_POSITIVE);
            if best.is_none_or(|(bc, _, _)| cost < bc) {
                best = Some((cost, axis, b + 1));
            }
        }
    }
    Binned {
        bounds,
        m,
        cb,
        nb,
        best,
    }
}

/// The box and slack magnitude of `all`'s items and where to split them (`Some(k)`: `all[..k]`
/// and `all[k..]`, after reordering), or `None` for a leaf.
fn decide(all: &mut [Item], scratch: &mut Vec<Item>, level: Level) -> (Aabb, f32, Option<usize>) {
    let binned = bin_objects(all, level.depth);
    let mid = object_split(all, scratch, level, &binned);
    (binned.bounds, binned.m, mid)
}

/// Reorders `all` for its best object split and returns the left half's length, or `None` for
/// a leaf. Without an SAH split (every centre in one bin, or too deep) the split is by count
/// along the widest centre axis, so the tree stays balanced.
fn object_split(
    all: &mut [Item],
    scratch: &mut Vec<Item>,
    level: Level,
    binned: &Binned,
) -> Option<usize> {
    let Level { depth, max_leaf } = level;
    let n = all.len();
    if n == 1 {
        return None;
    }
    let Binned { cb, nb, best, .. } = *binned;
    let mid = match best {
        Some((cost, _, _)) if n <= max_leaf && cost >= leaf_cost(n) => return None,
        Some((_, axis, left_bins)) => {
            let (lo, hi) = (cb.lo[axis], cb.hi[axis]);
            let scale = nb as f32 / (hi - lo);
            partition(all, scratch, |i| {
                bin_of(i.c[axis], lo, scale, nb) < left_bins
            })
        }
        None if n <= max_leaf && depth < BALANCED_FROM => return None,
        None => {
            // Ties by index.
            let axis = (0..3)
                .max_by(|&a, &b| {
                    (cb.hi[a] - cb.lo[a])
                        .total_cmp(&(cb.hi[b] - cb.lo[b]))
                        .then(b.cmp(&a))
                })
                .unwrap_or(0);
            all.sort_by(|a, b| a.c[axis].total_cmp(&b.c[axis]).then(a.local.cmp(&b.local)));
            if n <= max_leaf {
                return None;
            }
            n / 2
        }
    };
    Some(mid)
}

/// Spatial splits (Stich, Friedrich and Dietrich 2009, "Spatial Splits in Bounding Volume
/// Hierarchies"): a node may cut its space at a plane instead of its list of primitives, and a
/// primitive crossing the plane then goes to both sides, each with the box of its own part
/// ([`Primitive::clip`]). Tried where the best object split's halves overlap by more than
/// [`SPATIAL_OVERLAP`] of the root's area, and taken where its SAH cost is lower and the node's
/// budget of extra references allows.
struct Spatial<'a, P> {
    prims: &'a [P],
    refs: &'a [u32],
    root_area: f32,
}

/// Overlap of an object split's halves, relative to the root's area, from which a spatial split
/// is tried (Stich et al.'s α; tinybvh's `BuildHQ` tries from the same share).
const SPATIAL_OVERLAP: f32 = 1e-4;

/// Bins a spatial split is sought among (at most; fewer where the node's object binning has
/// fewer): each primitive long against the node is clipped to every bin it spans, so this is
/// most of the sweep's cost. Fewer were measured worse where spatial splits matter most: on
/// the city of needles, 8 (tinybvh `BuildHQ`'s) cost 4–5 % more instructions per ray and 16
/// up to 18 % (its planes fall badly on the city's grid), for half the build time.
const SPATIAL_BINS: usize = 32;

/// The bins of a spatial split at a node whose object binning has `nb`.
#[inline]
fn spatial_bins(nb: usize) -> usize {
    nb.min(SPATIAL_BINS)
}

impl<P: Primitive> Spatial<'_, P> {
    /// A box of the part of `it` (its primitive's part in `it.bx`) with `lo ≤ x[axis] ≤ hi`.
    fn clip(&self, it: &Item, axis: usize, lo: f32, hi: f32) -> Option<Aabb> {
        let prim = &self.prims[self.refs[it.local as usize] as usize];
        prim.clip(axis, lo, hi)?.intersect(it.bx)
    }

    /// [`Spatial::clip`] to each slab between consecutive `planes`, into `out`
    /// ([`Primitive::clip_slabs`]).
    fn clip_slabs(&self, it: &Item, axis: usize, planes: &[f32], out: &mut [Option<Aabb>]) {
        let prim = &self.prims[self.refs[it.local as usize] as usize];
        prim.clip_slabs(axis, planes, out);
        for o in out {
            *o = o.and_then(|b| b.intersect(it.bx));
        }
    }

    /// The binary subtree over `items` with up to `budget` extra references, nodes in preorder
    /// with the root first, its items in leaf order (leaf ranges index them), and the budget it
    /// left unspent.
    fn subtree<J: Join>(
        &self,
        mut items: Vec<Item>,
        budget: usize,
        level: Level,
        join: &J,
    ) -> (Vec<BinNode>, Vec<Item>, usize) {
        let mut scratch = Vec::new();
        let n = items.len();
        if budget == 0 {
            // The plain binned build from here on.
            let mut out = Vec::new();
            if n < PARALLEL_MIN {
                split(&mut out, &mut items, &mut scratch, 0, 0, n, level);
            } else {
                out = subtree(&mut items, 0, level, join);
            }
            return (out, items, 0);
        }
        let binned = bin_objects(&items, level.depth);
        let mut out = vec![BinNode {
            bounds: binned.bounds,
            m: binned.m,
            left: usize::MAX,
            right: usize::MAX,
            start: 0,
            count: n,
        }];
        let spatial = (level.depth < BALANCED_FROM)
            .then(|| self.best_split(&items, &binned, budget))
            .flatten()
            .filter(|&(cost, _, _)| n > level.max_leaf || cost < leaf_cost(n))
            .and_then(|(_, axis, s)| self.divide(&items, &binned, axis, s));
        let (l, r) = match spatial {
            Some(halves) => halves,
            None => match object_split(&mut items, &mut scratch, level, &binned) {
                None => return (out, items, budget),
                Some(mid) => {
                    let r = items.split_off(mid);
                    (items, r)
                }
            },
        };
        drop(scratch);
        // What the split did not spend goes to the halves in proportion to their items; below
        // the size handed to the join, what the left half leaves goes on to the right one (the
        // halves run one after the other there whatever the join, so the tree stays the same).
        let rest = budget - (l.len() + r.len() - n);
        let lb = (rest as u64 * l.len() as u64 / (l.len() + r.len()) as u64) as usize;
        let rb = rest - lb;
        let ((ln, li, l_left), (rn, ri, r_left)) = if n >= PARALLEL_MIN {
            join.join(
                || self.subtree(l, lb, level.down(), join),
                || self.subtree(r, rb, level.down(), join),
            )
        } else {
            let left = self.subtree(l, lb, level.down(), join);
            let carry = left.2;
            (
                (left.0, left.1, 0),
                self.subtree(r, rb + carry, level.down(), join),
            )
        };
        link(&mut out, ln, rn, li.len());
        let mut items = li;
        items.extend(ri);
        (out, items, l_left + r_left)
    }

    /// The best spatial split of `items` cheaper than `binned`'s object split and within
    /// `budget` extra references: (cost, axis, bins on the left), bins of equal width over the
    /// node's box.
    fn best_split(
        &self,
        items: &[Item],
        binned: &Binned,
        budget: usize,
    ) -> Option<(f32, usize, usize)> {
        let n = items.len();
        let (bounds, nb) = (binned.bounds, binned.nb);
        let area = bounds.half_area();
        if n < 2 || area <= 0.0 || !area.is_finite() {
            return None;
        }
        let mut best = binned.best;
        if let Some((_, axis, left_bins)) = binned.best {
            // Only where the object split's halves overlap.
            let (lo, hi) = (binned.cb.lo[axis], binned.cb.hi[axis]);
            let scale = nb as f32 / (hi - lo);
            let (mut lb, mut rb) = (Aabb::EMPTY, Aabb::EMPTY);
            for i in items {
                if bin_of(i.c[axis], lo, scale, nb) < left_bins {
                    lb = lb.union_finite(i.bx);
                } else {
                    rb = rb.union_finite(i.bx);
                }
            }
            let overlap = lb.intersect(rb).map_or(0.0, |o| o.half_area());
            if overlap <= SPATIAL_OVERLAP * self.root_area {
                return None;
            }
        }
        let mut found = None;
        let nb = spatial_bins(nb);
        for axis in 0..3 {
            let (lo, hi) = (bounds.lo[axis], bounds.hi[axis]);
            if hi <= lo || !(hi - lo).is_finite() {
                continue;
            }
            let scale = nb as f32 / (hi - lo);
            let width = (hi - lo) / nb as f32;
            let mut bb = [Aabb::EMPTY; BINS];
            let mut enter = [0usize; BINS];
            let mut exit = [0usize; BINS];
            for it in items {
                let b0 = bin_of(it.bx.lo[axis], lo, scale, nb);
                let b1 = bin_of(it.bx.hi[axis], lo, scale, nb).max(b0);
                enter[b0] += 1;
                exit[b1] += 1;
                if b0 == b1 {
                    bb[b0] = bb[b0].union_finite(it.bx);
                    continue;
                }
                // The part in each bin it spans: for an item long against the node, the
                // primitive clipped to the bin's slab and cut to the item's box (which holds the
                // item's part); for a short one, just its box cut to the slab (a looser bound,
                // for the cost estimate only: clipping would tighten it little and costs more
                // than the rest of the sweep).
                let long = it.bx.hi[axis] - it.bx.lo[axis] > (hi - lo) * 0.25;
                if long {
                    // The slabs' planes: the item's box's ends and the bin planes between.
                    let mut planes = [0.0f32; BINS + 1];
                    planes[0] = it.bx.lo[axis];
                    for b in b0 + 1..=b1 {
                        planes[b - b0] = lo + b as f32 * width;
                    }
                    planes[b1 - b0 + 1] = it.bx.hi[axis];
                    let mut parts = [None; BINS];
                    self.clip_slabs(it, axis, &planes[..=b1 - b0 + 1], &mut parts[..=b1 - b0]);
                    for (bin, part) in bb[b0..=b1].iter_mut().zip(parts) {
                        if let Some(part) = part {
                            *bin = bin.union_finite(part);
                        }
                    }
                    continue;
                }
                for (b, bin) in bb.iter_mut().enumerate().take(b1 + 1).skip(b0) {
                    let s_lo = if b > b0 {
                        lo + b as f32 * width
                    } else {
                        it.bx.lo[axis]
                    };
                    let s_hi = if b < b1 {
                        lo + (b + 1) as f32 * width
                    } else {
                        it.bx.hi[axis]
                    };
                    let mut cut = it.bx;
                    cut.lo[axis] = s_lo.max(cut.lo[axis]);
                    cut.hi[axis] = s_hi.min(cut.hi[axis]);
                    *bin = bin.union_finite(cut);
                }
            }
            let mut right = [0.0f32; BINS];
            let (mut acc, mut c) = (Aabb::EMPTY, 0usize);
            for b in (1..nb).rev() {
                acc = acc.union_finite(bb[b]);
                c += exit[b];
                right[b] = acc.half_area() * leaf_cost(c);
            }
            let (mut acc, mut left, mut exited) = (Aabb::EMPTY, 0usize, 0usize);
            for b in 0..nb - 1 {
                acc = acc.union_finite(bb[b]);
                left += enter[b];
                exited += exit[b];
                let right_n = n - exited;
                if left == 0 || right_n == 0 || left + right_n - n > budget {
                    continue;
                }
                let cost =
                    TRAVERSAL_COST + (acc.half_area() * leaf_cost(left) + right[b + 1]) / area;
                if best.is_none_or(|(bc, _, _)| cost < bc) {
                    best = Some((cost, axis, b + 1));
                    found = best;
                }
            }
        }
        found
    }

    /// The two halves of a spatial split at the left edge of bin `s` on `axis`: items wholly on
    /// one side go there, items across it go to both with the boxes of their parts; `None` when
    /// a half comes out empty.
    fn divide(
        &self,
        items: &[Item],
        binned: &Binned,
        axis: usize,
        s: usize,
    ) -> Option<(Vec<Item>, Vec<Item>)> {
        let (bounds, nb) = (binned.bounds, spatial_bins(binned.nb));
        let (lo, hi) = (bounds.lo[axis], bounds.hi[axis]);
        let scale = nb as f32 / (hi - lo);
        let plane = lo + s as f32 * ((hi - lo) / nb as f32);
        let (mut l, mut r) = (Vec::new(), Vec::new());
        let part = |it: &Item, bx: Aabb| Item {
            bx,
            c: bx.center(),
            ..*it
        };
        for it in items {
            let b0 = bin_of(it.bx.lo[axis], lo, scale, nb);
            let b1 = bin_of(it.bx.hi[axis], lo, scale, nb).max(b0);
            if b1 < s {
                l.push(*it);
            } else if b0 >= s {
                r.push(*it);
            } else {
                // The two slabs cover the item's box whatever `plane` is, so its parts hold
                // every point of the primitive the item held.
                let (x_lo, x_hi) = (it.bx.lo[axis], it.bx.hi[axis]);
                let left = self.clip(it, axis, x_lo, plane.min(x_hi));
                let right = self.clip(it, axis, plane.max(x_lo), x_hi);
                match (left, right) {
                    (None, None) => l.push(*it),
                    (a, b) => {
                        l.extend(a.map(|a| part(it, a)));
                        r.extend(b.map(|b| part(it, b)));
                    }
                }
            }
        }
        (!l.is_empty() && !r.is_empty()).then_some((l, r))
    }
}

fn bin_of(c: f32, lo: f32, scale: f32, bins: usize) -> usize {
    (((c - lo) * scale) as usize).min(bins - 1)
}

/// Stable partition: the items where `left` holds first; returns their count.
fn partition(items: &mut [Item], scratch: &mut Vec<Item>, left: impl Fn(&Item) -> bool) -> usize {
    scratch.clear();
    let mut k = 0;
    for i in 0..items.len() {
        let it = items[i];
        if left(&it) {
            items[k] = it;
            k += 1;
        } else {
            scratch.push(it);
        }
    }
    items[k..].copy_from_slice(scratch);
    k
}
