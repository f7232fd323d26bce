//! The 8-wide bounding volume hierarchy as data: its node layout, the builder and the
//! validation of untrusted trees. The walks over it are `octoray-packet`'s `scene` module.
//!
//! - [`Bvh8Node`]: one node, eight children's boxes in SoA (`lo[axis][child]`,
//!   `hi[axis][child]`, f32), their references and their visiting order for each ray-direction
//!   octant; 288 bytes, `bytemuck::Pod`.
//! - [`Bvh8`] (feature `alloc`): the owned tree, built by top-down binned SAH ([`Bvh8::build`]),
//!   optionally with spatial splits ([`BuildOptions::SPATIAL`], [`Bvh8::try_build_options`]).
//! - [`Bvh8Ref`]: the same tree as three borrowed slices (nodes, the primitives in leaf order in
//!   SoA blocks of [`BLOCK`], their indices in the caller's slice). Traversal needs nothing
//!   else: no allocator, no `std`.
//! - [`Solid`] (features `alloc`, `triangle`): a tree with the triangles it was built from,
//!   checked to be a closed surface: what exact containment needs. A tree built on a host can be written out with `bytemuck`
//!   and traversed on a target from `&'static` data, after [`Bvh8Ref::new`] has validated it.
//!
//! # Boxes
//! Every box is conservative: it holds its primitives exactly as the kernels read them, grown by
//! [`SLACK`] of its largest coordinate magnitude and one ulp, so that no kernel hit (whose
//! rounding may place it slightly outside the exact primitive) lies outside the box of its leaf,
//! and no box is entered after a hit a kernel reports on a primitive it holds whole (the kernels
//! raise a `t` that lies before the primitive's own box to that box's entry): a walk that culls
//! boxes entered after its best `t` finds what brute force finds.
//! Primitives with a non-finite coordinate are left out of the tree (no kernel can hit them).
//! A spatial split's box holds a part of a primitive ([`crate::prim::Primitive::clip`], rounded
//! outward) and takes the slack of the whole primitive, so a hit a kernel reports on that part
//! lies in it too; the parts of a primitive cover it. A part's box can be entered after a `t`
//! the kernel reports on that part where `t`'s error exceeds the slack (a float tier's `t` on a
//! grazing ray, `|cos θ|` ≲ 10⁻²): a walk of a tree with spatial splits can then miss that hit
//! in favour of a farther one (the exact tier's `t`, within an ulp, always finds it).
//! Primitive indices are `u32`, and a tree holds at most [`MAX_PRIMS`] primitives.
//!
//! # Untrusted trees
//! [`Bvh8Ref::new`] takes any bytes: it answers `Ok` or a [`BvhError`], never panics, in time
//! linear in the slices' length and without an allocator. A tree it accepts is a tree (every
//! node but the root has exactly one parent; no node is shared, none is unreachable), no deeper
//! than [`MAX_DEPTH`], whose leaves cover the blocks once and hold indices below the caller's
//! primitive count. On such a tree every walk runs without panicking or indexing out of bounds,
//! visits each node and tests each leaf slot at most once per ray, and reports only primitive
//! indices below [`Bvh8Ref::prims`]. Leaves may name a primitive more than once (a spatial
//! split's tree puts a primitive in each leaf its parts reach). The boxes are not checked against the primitives: a tree
//! with wrong boxes gives wrong answers (only the built or faithfully stored tree equals brute
//! force), never a crash or a long walk.

#[cfg(feature = "alloc")]
mod build;
#[cfg(feature = "alloc")]
mod collapse;
#[cfg(all(feature = "alloc", feature = "triangle"))]
mod solid;
#[cfg(all(feature = "alloc", feature = "triangle"))]
mod winding;

use crate::prim::{Primitive, BLOCK};

/// Children per node.
pub const WIDTH: usize = 8;

/// Largest number of primitives one tree holds (indices are `u32`; the top bit is reserved).
pub const MAX_PRIMS: usize = (1 << 31) - 1;

/// Deepest tree the traversal stack serves ([`Bvh8Ref::new`] rejects deeper ones; the builder
/// never makes one).
pub const MAX_DEPTH: usize = 64;

/// Relative slack of boxes and origins: 2⁻¹⁷ (≈ 128 ulp of f32) of the largest coordinate
/// magnitude. It covers every tier's hit/miss margin (≤ 64·ε of the distance from the origin to
/// the primitive's vertices, measured in the accuracy report), so no kernel hit lies outside a
/// box the traversal visits. A float tier's `t` can err by more than that on grazing rays; the
/// kernels raise such a `t` to the ray's entry into the primitive's own box (and miss where the
/// ray leaves it before `t_min`), so a box that holds the whole primitive is never entered after
/// a hit reported on it.
pub const SLACK: f32 = 1.0 / 131_072.0;

/// Traversal stack capacity: a depth-first walk holds at most `WIDTH − 1` siblings per level.
/// The validation and the walks share it (not part of the API).
#[doc(hidden)]
pub const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A child slot that holds nothing.
pub const EMPTY: u32 = u32::MAX;

/// The index of a padding slot in a leaf's last block (never reported: traversal masks it off).
pub const PAD: u32 = u32::MAX;

/// One node: the boxes of up to eight children in SoA, and what each child is.
///
/// Slot `i` is empty when `child[i] == EMPTY` (and `count[i] == 0`); an inner node when
/// `count[i] == 0` (`child[i]` is its index in the node slice, always greater than this
/// node's); a leaf of `count[i]` primitives starting at block slot `child[i]` (a multiple of
/// [`BLOCK`]) otherwise. Used slots come first. Boxes are already widened by the build slack.
///
/// `order` lists the slots near-first for each direction octant `o` (bit `k` of `o` set when
/// the direction's component `k` is negative): bits `3·o .. 3·o + 3` of `order[j]` hold the
/// slot visited `j`-th, a permutation of `0..8` per octant (empty slots last), bits 24–31 are
/// 0. It is a heuristic for speed ([`Bvh8Node::set_order`]); any permutation gives the same
/// answers.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Bvh8Node {
    /// Lower corners: `lo[axis][slot]`.
    pub lo: [[f32; WIDTH]; 3],
    /// Upper corners: `hi[axis][slot]`.
    pub hi: [[f32; WIDTH]; 3],
    /// Node index or first primitive, per slot.
    pub child: [u32; WIDTH],
    /// 0 for an inner node, else the leaf's primitive count, per slot.
    pub count: [u32; WIDTH],
    /// The slots' visiting order per direction octant, 3 bits each (above).
    pub order: [u32; WIDTH],
}

impl Bvh8Node {
    /// A node with every slot empty.
    pub const EMPTY: Self = Self {
        lo: [[f32::INFINITY; WIDTH]; 3],
        hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [EMPTY; WIDTH],
        count: [0; WIDTH],
        order: IDENTITY_ORDER,
    };

    /// Sets `order` from the boxes: for octant `o`, slots by the position of their box's centre
    /// along the octant's diagonal (the direction with component `k` negative where bit `k` of
    /// `o` is set, positive elsewhere), nearest first; ties in slot order, empty slots and NaN
    /// keys last.
    pub fn set_order(&mut self) {
        let mut order = [0u32; WIDTH];
        for o in 0..8 {
            let key = |s: usize| {
                let k: f32 = (0..3)
                    .map(|a| {
                        let c = self.lo[a][s] + self.hi[a][s];
                        if o >> a & 1 == 1 {
                            -c
                        } else {
                            c
                        }
                    })
                    .sum();
                let last = self.child[s] == EMPTY || k.is_nan();
                (last, if k.is_nan() { 0.0 } else { k })
            };
            let mut slots: [usize; WIDTH] = core::array::from_fn(|s| s);
            slots.sort_unstable_by(|&a, &b| {
                let ((la, ka), (lb, kb)) = (key(a), key(b));
                // No NaN key is compared: those are `last` and 0.
                la.cmp(&lb)
                    .then(ka.partial_cmp(&kb).unwrap_or(core::cmp::Ordering::Equal))
                    .then(a.cmp(&b))
            });
            for (j, &s) in slots.iter().enumerate() {
                order[j] |= (s as u32) << (3 * o);
            }
        }
        self.order = order;
    }

    /// True when `order` is a permutation of the slots for every octant, its top bits clear.
    fn order_is_valid(&self) -> bool {
        (0..8).all(|o| {
            let seen = self
                .order
                .iter()
                .fold(0u32, |m, &w| m | 1 << (w >> (3 * o) & 7));
            seen == 0xff
        }) && self.order.iter().all(|&w| w >> 24 == 0)
    }

    /// Number of used slots.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.child.iter().take_while(|&&c| c != EMPTY).count()
    }

    /// True when no slot is used.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.child[0] == EMPTY
    }
}

/// Every octant's order the identity (slot `j` visited `j`-th).
const IDENTITY_ORDER: [u32; WIDTH] = {
    let mut order = [0; WIDTH];
    let mut j = 0;
    while j < WIDTH {
        let mut o = 0;
        while o < 8 {
            order[j] |= (j as u32) << (3 * o);
            o += 1;
        }
        j += 1;
    }
    order
};

/// Why a set of slices is not a valid tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhError {
    /// `blocks` does not hold `WORDS` rows per [`BLOCK`] indices, or `ids` is not a whole number
    /// of blocks.
    LengthMismatch {
        /// Block rows.
        blocks: usize,
        /// Indices.
        ids: usize,
    },
    /// A slot refers to a node other than the next one in build order (a node named twice, a
    /// cycle, a node out of order or out of range), a used slot follows an empty one, or an
    /// empty slot has a non-zero count.
    BadNodeRef {
        /// The node holding the slot.
        node: usize,
    },
    /// A node's `order` is not a permutation of its slots for some octant, or has its top bits
    /// set.
    BadOrder {
        /// The node.
        node: usize,
    },
    /// A leaf's primitive range is not the next one in build order, or lies outside the blocks.
    BadLeaf {
        /// The node holding the slot.
        node: usize,
    },
    /// A leaf holds [`PAD`] or an index not below the caller's primitive count, or a padding slot
    /// holds anything but [`PAD`].
    BadIndex {
        /// The block slot.
        slot: usize,
    },
    /// A node that no slot reaches.
    Unreachable {
        /// The first such node.
        node: usize,
    },
    /// Block slots that no leaf holds.
    UnusedBlocks {
        /// The first such slot.
        slot: usize,
    },
    /// Deeper than [`MAX_DEPTH`].
    TooDeep,
    /// A scene's path from the world to a geometry would hold more instances than a scene
    /// allows (`MAX_INSTANCE_LEVELS` of the scene module).
    TooManyLevels,
    /// More primitives than [`MAX_PRIMS`].
    TooManyPrims(usize),
    /// A refit was given a slice of another length than the tree was built from.
    RefitLength {
        /// The length the tree was built from.
        built: usize,
        /// The length given.
        given: usize,
    },
    /// A refit was given a finite primitive that the build left out (it was not finite then),
    /// so no leaf holds it.
    RefitLeftOut {
        /// Its index in the slice.
        prim: usize,
    },
}

impl core::fmt::Display for BvhError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            BvhError::LengthMismatch { blocks, ids } => {
                write!(f, "{blocks} block rows do not hold {ids} indices")
            }
            BvhError::BadNodeRef { node } => write!(f, "node {node} refers to a bad child node"),
            BvhError::BadOrder { node } => {
                write!(
                    f,
                    "node {node} has a visiting order that is not a permutation"
                )
            }
            BvhError::BadLeaf { node } => {
                write!(
                    f,
                    "node {node} has a leaf outside the primitives or out of order"
                )
            }
            BvhError::BadIndex { slot } => {
                write!(f, "block slot {slot} holds a bad primitive index")
            }
            BvhError::Unreachable { node } => write!(f, "no slot refers to node {node}"),
            BvhError::UnusedBlocks { slot } => write!(f, "no leaf holds block slot {slot}"),
            BvhError::TooDeep => write!(f, "tree deeper than {MAX_DEPTH}"),
            BvhError::TooManyLevels => write!(
                f,
                "a path from the world would hold more instances than a scene allows"
            ),
            BvhError::TooManyPrims(n) => {
                write!(f, "{n} primitives; a tree holds at most {MAX_PRIMS}")
            }
            BvhError::RefitLength { built, given } => {
                write!(
                    f,
                    "refit with {given} primitives; the tree was built from {built}"
                )
            }
            BvhError::RefitLeftOut { prim } => write!(
                f,
                "primitive {prim} was left out of the build (not finite) and is finite now: rebuild"
            ),
        }
    }
}

impl core::error::Error for BvhError {}

/// A tree as borrowed slices: what traversal reads. `Copy`, no allocation.
#[derive(Debug)]
pub struct Bvh8Ref<'a, P> {
    nodes: &'a [Bvh8Node],
    blocks: &'a [[f32; BLOCK]],
    ids: &'a [u32],
    prims: usize,
    _prim: core::marker::PhantomData<P>,
}

impl<P> Clone for Bvh8Ref<'_, P> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<P> Copy for Bvh8Ref<'_, P> {}

impl<'a, P: Primitive> Bvh8Ref<'a, P> {
    /// Validates and wraps a tree's slices, in time linear in their length and without an
    /// allocator.
    ///
    /// - `nodes[0]` is the root (an empty node slice is an empty scene). Nodes are numbered in
    ///   build order: a depth-first expansion from the root that, on expanding a node, gives its
    ///   inner children the next free node indices in slot order, then expands the last one
    ///   numbered first (the order the builder writes). So every node but the root has
    ///   exactly one parent, a child's index is above its parent's, and every node is reached.
    /// - `blocks`: the primitives in leaf order, in SoA blocks of [`BLOCK`]: block slot `k` is
    ///   primitive `k % BLOCK` of block `k / BLOCK`, whose rows are
    ///   `blocks[(k / BLOCK)·WORDS ..][..WORDS]` (row `w` holds word `w` of the block's
    ///   primitives, [`Primitive::write_block`]). Leaves take block slots in build order, each
    ///   starting a block and padded to whole blocks, and cover every block.
    /// - `ids[k]`: the caller's index of slot `k`, below `prims` (the length of the caller's
    ///   primitive slice) inside a leaf, [`PAD`] on a leaf's padding.
    ///
    /// - Node indices are at most [`MAX_PRIMS`], like block slots: [`EMPTY`] is then the only
    ///   child reference with its top bit set, which the single-ray walk reads as "empty" for
    ///   eight slots at once.
    ///
    /// A validated tree guarantees: traversal never indexes out of bounds or panics, visits each
    /// node and tests each leaf slot at most once per ray (work linear in the tree's size), and
    /// every reported `prim` is below `prims`.
    pub fn new(
        nodes: &'a [Bvh8Node],
        blocks: &'a [[f32; BLOCK]],
        ids: &'a [u32],
        prims: usize,
    ) -> Result<Self, BvhError> {
        if !ids.len().is_multiple_of(BLOCK)
            || Some(blocks.len()) != (ids.len() / BLOCK).checked_mul(P::WORDS)
        {
            return Err(BvhError::LengthMismatch {
                blocks: blocks.len(),
                ids: ids.len(),
            });
        }
        if ids.len() > MAX_PRIMS {
            return Err(BvhError::TooManyPrims(ids.len()));
        }
        if prims > MAX_PRIMS {
            return Err(BvhError::TooManyPrims(prims));
        }
        // Replay the build order: each inner slot must name the next node, each leaf the next
        // block slot. Every node is then numbered once, so the walk visits it once; its stack
        // holds at most WIDTH − 1 siblings per level, the traversal's own bound.
        let (mut next_node, mut next_slot) = (1usize, 0usize);
        if !nodes.is_empty() {
            let mut stack = [(0u32, 0u32); STACK];
            let mut sp = 1;
            while sp > 0 {
                sp -= 1;
                let (n, d) = stack[sp];
                if d as usize >= MAX_DEPTH {
                    return Err(BvhError::TooDeep);
                }
                let node = &nodes[n as usize];
                let bad_node = BvhError::BadNodeRef { node: n as usize };
                let bad_leaf = BvhError::BadLeaf { node: n as usize };
                let used = node.len();
                if node.child[used..].iter().any(|&c| c != EMPTY)
                    || node.count[used..].iter().any(|&k| k != 0)
                {
                    return Err(bad_node);
                }
                if !node.order_is_valid() {
                    return Err(BvhError::BadOrder { node: n as usize });
                }
                for s in 0..used {
                    let (c, k) = (node.child[s] as usize, node.count[s] as usize);
                    if k == 0 {
                        if c != next_node || c >= nodes.len() || c > MAX_PRIMS {
                            return Err(bad_node);
                        }
                        if sp == STACK {
                            return Err(BvhError::TooDeep);
                        }
                        next_node += 1;
                        stack[sp] = (c as u32, d + 1);
                        sp += 1;
                        continue;
                    }
                    let end = c.checked_add(k).filter(|&e| e <= ids.len());
                    let Some(end) = end.filter(|_| c == next_slot) else {
                        return Err(bad_leaf);
                    };
                    let padded = end.next_multiple_of(BLOCK);
                    if let Some(i) = (c..end).find(|&i| ids[i] as usize >= prims) {
                        return Err(BvhError::BadIndex { slot: i });
                    }
                    if let Some(i) = (end..padded).find(|&i| ids[i] != PAD) {
                        return Err(BvhError::BadIndex { slot: i });
                    }
                    next_slot = padded;
                }
            }
        }
        if next_node < nodes.len() {
            return Err(BvhError::Unreachable { node: next_node });
        }
        if next_slot < ids.len() {
            return Err(BvhError::UnusedBlocks { slot: next_slot });
        }
        Ok(Self {
            nodes,
            blocks,
            ids,
            prims,
            _prim: core::marker::PhantomData,
        })
    }

    /// A part of a scene that [`crate::scene::SceneRef::new`] validated.
    pub(crate) fn trusted(
        nodes: &'a [Bvh8Node],
        blocks: &'a [[f32; BLOCK]],
        ids: &'a [u32],
        prims: u32,
    ) -> Self {
        Self {
            nodes,
            blocks,
            ids,
            prims: prims as usize,
            _prim: core::marker::PhantomData,
        }
    }

    /// The length of the caller's primitive slice: every reported `prim` is below it.
    pub fn prims(&self) -> usize {
        self.prims
    }

    /// The nodes (root first).
    pub fn nodes(&self) -> &'a [Bvh8Node] {
        self.nodes
    }

    /// The primitives in leaf order, in SoA blocks ([`Bvh8Ref::new`] gives the layout).
    pub fn blocks(&self) -> &'a [[f32; BLOCK]] {
        self.blocks
    }

    /// Rows of the block holding slot `k` (for the walks; not part of the API).
    #[doc(hidden)]
    #[inline(always)]
    pub fn block_of(&self, k: usize) -> &'a [[f32; BLOCK]] {
        let at = k / BLOCK * P::WORDS;
        &self.blocks[at..at + P::WORDS]
    }

    /// `ids()[k]`: the caller's index of the primitive in block slot `k` ([`PAD`] on padding).
    pub fn ids(&self) -> &'a [u32] {
        self.ids
    }
}

#[cfg(feature = "alloc")]
pub(crate) use build::refit_parts;
#[cfg(feature = "alloc")]
pub use build::{BuildOptions, BuildStats, Bvh8, Join, Sequential};
#[cfg(all(feature = "alloc", feature = "triangle"))]
pub use solid::{Solid, SolidError};
#[cfg(all(feature = "alloc", feature = "triangle"))]
pub use winding::WindingTree;
