//! A renderer's scene as data: geometries (primitive slices, triangles or spheres, each with an
//! ID and a mask), bottom-level trees over sets of them, instances that place the trees in the
//! world with affine transforms and masks, and the top-level tree over the instances' world
//! boxes. The walks over it are `octoray-packet`'s `scene::Trace`.
//!
//! - [`Geometry`]: one geometry's kind, mask and length.
//! - [`SceneTree`] and [`Member`]: a BVH over one or more geometries of one kind (their
//!   primitives one after another), and where each member's primitives start in it. Static
//!   meshes share one tree (the cost of one tree); an instanced mesh has a tree of its own.
//! - [`Instance`]: a tree placed by a [`Transform`] (world → object), with a mask.
//! - A group ([`SceneTree`] of kind [`INSTANCES`]): a set of instances with a tree over their
//!   boxes, itself placed by instances (nested instancing, up to [`MAX_INSTANCE_LEVELS`]
//!   instances on a path from the world to a primitive).
//! - [`Level`]: the world's instances or a group's, with the tree over their boxes.
//! - [`SceneRef`]: the whole scene as borrowed slices, validated by [`SceneRef::new`]; traversal
//!   needs nothing else (no allocator, no `std`), so a scene written on a host can be traced on
//!   a target from `&'static` data.
//! - [`Scene`] (feature `alloc`): the owned scene: add geometries, place sets of them, commit.
//!
//! # Contract
//! A scene query's answer equals brute force over every instance path (a world instance, then
//! an instance of the group it places, and so on down to a tree of geometries), over every
//! geometry of the last tree whose mask shares a bit with the query's and every instance's on
//! the path: each path's primitives tested with the ray carried into its object space by
//! [`Transform::apply`] once per instance on the path, outermost first (the same f32 ray for
//! every primitive of that path), bit for bit (hit/miss, `t`, `u`, `v`, primitive, geometry,
//! instance path), with the tie rule: among hits of equal `t`, the lowest instance path, then
//! the lowest geometry, then the lowest primitive wins.
//!
//! A hit's `inst` numbers its instance path: the paths counted depth first in instance order
//! ([`Instance::path`]), so in a scene without groups it is the world instance's index, and
//! [`SceneRef::instance_path`] gives the instances back. `t` is measured along the world ray
//! (the transform keeps it), so hits of different instances compare by `t`. The transformed ray
//! is within 1 ulp of the exact map per component, which moves a hit's `t` by up to about
//! `κ·ε` relative (ε = 2⁻²⁴) for an instance whose transform has condition number `κ`, on top of
//! the tier's own `t` error; the identity keeps the ray's bits, so an instance placed there
//! answers exactly as its tree alone.
//!
//! Within one instance each tier keeps its contract (watertightness included: one ray, one
//! tree). Two instances that share an edge in the world see two differently rounded rays, so a
//! ray through that edge can pass between them by up to the transforms' rounding (about
//! `κ·ε·(‖o‖ + t‖d‖)`): a closed surface made of several instances is watertight only where
//! they share one transform; put a closed mesh in one geometry, or several in one tree.
//! A nested path rounds once per level: its `t` error adds up over the levels (the product of
//! their condition numbers bounds it), and so does each level's box slack.
//!
//! The top level's box tests are conservative for the rounded rays: each instance's world box is
//! grown by what the rounding into object space can move a hit ([`Transform::world_box`]), and
//! the top-level walk adds an origin slack for the largest condition number among the bounded
//! instances. A group's tree does the same in the group's space, and an instance of a group is
//! bounded by its group's boxes grown for the group's own slack, so the growth compounds
//! (about `κ` per level). An instance whose condition number exceeds [`MAX_CONDITION`] (nearly
//! singular) or whose box is not finite is not in its level's tree: every ray that reaches the
//! level visits it.
//!
//! The commit enters overlapping, level-spanning instances by parts ([`InstanceBox`]): the
//! subtrees below their top nodes, each with its own conservative world box, so the level's
//! tree orders and culls them among the other instances' (partial re-braiding) instead of
//! walking each whole tree in turn. The parts of an instance cover its tree once; the answer is
//! unchanged.
//!
//! # Untrusted scenes
//! [`SceneRef::new`] takes any slices: it answers `Ok` or a [`SceneError`], never panics, in time
//! linear in their total length and without an allocator. On a scene it accepts, every query is
//! total: no panic, each node visited and each leaf slot tested at most once per ray and
//! instance entry, every reported geometry, instance path and primitive in range, only
//! instances reached from the world traced (a group that no instance places contributes
//! nothing).
//!
//! # Work per ray
//! A ray enters an instance (carries itself into the instance's space and walks the tree it
//! places) at most once per slot that names the instance in its level's tree and per entry of
//! its level's unbounded list, at every visit of that level. The worst case over all rays, the
//! scene's *entry bound* ([`SceneRef::entries_within`]), counts those entries down every level,
//! as if every box were hit; each entry walks one tree, each node and leaf slot at most once.
//! Without groups the entry bound is at most the world's used tree slots plus its unbounded
//! entries; groups multiply it, level by level (a group of `n` instances placed `m` times costs
//! up to `n · m` entries).
//!
//! Validation refuses a scene whose entry bound exceeds a budget, with
//! [`SceneError::TooMuchWork`]: by default ([`SceneRef::new`], [`SceneRef::from_words`]) the
//! scene's length in 32-bit words ([`SceneParts::words`]), so a stored scene of `w` words makes
//! a ray enter at most `w` instances, each walking one tree of at most `w` words; a caller that
//! trusts the scene's source and wants deeper instancing sets its own budget with
//! [`SceneRef::new_bounded`] or [`SceneRef::from_words_bounded`]. Counting the bound stops at
//! the budget, so validation stays linear in the scene's length plus the budget. A scene
//! [`Scene`] built is not validated (its entry bound is what its instances make it).

#[cfg(feature = "alloc")]
mod braid;
#[cfg(feature = "alloc")]
mod build;
mod store;
mod transform;
mod validate;

#[cfg(feature = "alloc")]
pub use build::Scene;
pub use transform::{Transform, MAX_CONDITION};

use crate::bvh::{Bvh8Node, Bvh8Ref, BvhError, PAD, SLACK};
use crate::lanes::Lanes;
use crate::prim::{Aabb, Primitive, Words, BLOCK};

/// [`Geometry::kind`] of a triangle mesh (the scene's triangle layout).
pub const TRIANGLES: u32 = 0;
/// [`Geometry::kind`] of a set of spheres (the scene's sphere layout).
pub const SPHERES: u32 = 1;
/// [`SceneTree::kind`] of a group: a tree over instances.
pub const INSTANCES: u32 = 2;
/// Most instances on a path from the world to a primitive (a world instance and up to three
/// nested groups' below it).
pub const MAX_INSTANCE_LEVELS: u32 = 4;

/// One geometry of a scene: a primitive slice of one kind, with a mask.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Geometry {
    /// [`TRIANGLES`] or [`SPHERES`].
    pub kind: u32,
    /// ANDed with the instance's and the query's mask: no common bit, its hits do not count.
    pub mask: u32,
    /// Length of its primitive slice (a reported `prim` is below it).
    pub prims: u32,
}

/// One tree of a scene: a BVH over one or more geometries of one kind (their primitives one
/// after another, in the order of its members), or a group's tree over its instances' boxes;
/// and where it lies in the slices of its kind (nodes `first_node..first_node + nodes`, blocks
/// `first_block..first_block + blocks`; the trees of one kind follow one another there, the
/// groups' after the world's top-level tree).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SceneTree {
    /// [`TRIANGLES`], [`SPHERES`] or [`INSTANCES`].
    pub(crate) kind: u32,
    /// Its members' primitives together (a group: its instances).
    pub(crate) prims: u32,
    /// Its root's index in the nodes of its kind.
    pub(crate) first_node: u32,
    /// Its number of nodes (0: empty, never hit).
    pub(crate) nodes: u32,
    /// Its first block in the blocks of its kind.
    pub(crate) first_block: u32,
    /// Its number of blocks of [`BLOCK`] primitives.
    pub(crate) blocks: u32,
    /// Its first member in the scene's member list (a group: its first instance; a group's
    /// instances follow the world's and the previous group's).
    pub(crate) first_member: u32,
    /// Its number of members (geometries), at least 1 (a group: its instances, as `prims`).
    pub(crate) members: u32,
    /// The AND of its members' masks (a query sharing a bit with it admits every member, and
    /// the walk skips the per-hit mask test); a group: the OR of its instances' masks (a ray
    /// sharing no bit with it skips the group).
    pub(crate) mask: u32,
    /// Instance levels below an instance of it: 0 for geometries; for a group, one more than
    /// the deepest tree its instances place (below [`MAX_INSTANCE_LEVELS`]).
    pub(crate) levels: u32,
    /// Instance paths through one instance of it (the hit `inst` values it spans): 1 for
    /// geometries; for a group, the sum over its instances' trees.
    pub(crate) paths: u32,
    /// Relative origin slack of the box tests in it: [`SLACK`] for geometries; for a group,
    /// what its instances need ([`Transform::world_box_within`]), at least [`SLACK`].
    pub(crate) slack: f32,
    /// A group's first entry in the unbounded list (its instances outside its tree follow the
    /// world's and the previous group's there); 0 for geometries.
    pub(crate) first_unbounded: u32,
    /// A group's number of unbounded instances; 0 for geometries.
    pub(crate) unbounded: u32,
}

impl SceneTree {
    /// [`TRIANGLES`], [`SPHERES`] or [`INSTANCES`] (a group).
    pub const fn kind(&self) -> u32 {
        self.kind
    }

    /// Its members' primitives together (a group: its instances).
    pub const fn prims(&self) -> u32 {
        self.prims
    }

    /// The AND of its members' masks (a query sharing a bit with it admits every member); a
    /// group: the OR of its instances' masks (a ray sharing no bit with it skips the group).
    pub const fn mask(&self) -> u32 {
        self.mask
    }

    /// Instance paths through one instance of it (the hit `inst` values it spans): 1 for
    /// geometries; for a group, the sum over its instances' trees.
    pub const fn paths(&self) -> u32 {
        self.paths
    }
}

/// A geometry in a tree: its primitives are the tree's `first_prim..first_prim + prims`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Member {
    /// The geometry.
    pub geom: u32,
    /// Where its primitives start in the tree's primitive order.
    pub first_prim: u32,
}

/// A tree placed in the world or in a group: rays are carried into its object space by
/// `transform`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Instance {
    /// Its level's space (the world, or the group's) → object.
    pub transform: Transform,
    /// Index of the tree it places (an instance in a group places a tree of a lower index).
    pub tree: u32,
    /// ANDed with the query's mask and the masks above it before the tree is entered, and with
    /// each geometry's.
    pub mask: u32,
    /// Its first instance path within its level: the paths through its level's earlier
    /// instances (in the world, its index when no group is placed).
    pub path: u32,
}

/// The top-level tree's primitive: the world box ([`Transform::world_box_within`]) of a part of
/// an instance's tree, and the node that part starts at.
///
/// A part is the whole tree (`node` 0: its root) or a subtree the commit opened out of it: an
/// instance whose tree spans much of its level is entered by its parts, so that the level's
/// tree orders and culls them among the other instances' (partial re-braiding). The parts of
/// one instance cover its tree once; a group's instance is one part (`node` 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct InstanceBox {
    /// Smallest corner.
    pub lo: [f32; 3],
    /// Largest corner.
    pub hi: [f32; 3],
    /// The node of the instance's tree the part starts at.
    pub node: u32,
}

impl Primitive for InstanceBox {
    type Lanes<L: Lanes> = ();
    const TAG: u32 = u32::from_le_bytes(*b"IBox");
    // One instance per leaf: the node test is then each instance's own box test.
    const LEAF: usize = 1;
    #[inline(always)]
    fn from_words<L: Lanes, W: Words>(_: &W) -> Self::Lanes<L> {}
    fn bounds(&self) -> Option<Aabb> {
        let b = Aabb {
            lo: self.lo,
            hi: self.hi,
        };
        b.is_finite().then_some(b)
    }
}

/// A tree's three slices (see [`Bvh8Ref::new`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct TreeParts<'a> {
    /// Nodes.
    pub nodes: &'a [Bvh8Node],
    /// SoA block rows.
    pub blocks: &'a [[f32; BLOCK]],
    /// Caller's index per block slot.
    pub ids: &'a [u32],
}

/// A scene's slices: what [`SceneRef::new`] validates and [`SceneRef::parts`] gives back (each
/// slice is `bytemuck::Pod`, so a scene is stored as bytes and read back without a copy).
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneParts<'a> {
    /// The triangle trees' slices, one tree after another.
    pub triangles: TreeParts<'a>,
    /// The sphere trees' slices, one tree after another.
    pub spheres: TreeParts<'a>,
    /// The geometries.
    pub geometries: &'a [Geometry],
    /// The bottom-level trees.
    pub trees: &'a [SceneTree],
    /// The trees' members, tree after tree.
    pub members: &'a [Member],
    /// The instances.
    pub instances: &'a [Instance],
    /// The top-level tree over [`InstanceBox`]es, the parts of the instances (its ids are
    /// instance indices).
    pub top: TreeParts<'a>,
    /// Instances that are not in the top-level tree (every ray visits them).
    pub unbounded: &'a [u32],
}

/// Why a set of slices is not a valid scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneError {
    /// A geometry's or a tree's kind is neither [`TRIANGLES`] nor [`SPHERES`].
    BadKind {
        /// The geometry or tree.
        at: usize,
    },
    /// A tree's ranges do not follow the previous tree of its kind, or lie outside its kind's
    /// slices.
    BadRange {
        /// The tree.
        tree: usize,
    },
    /// A tree's members do not follow the previous tree's, name a geometry that does not exist
    /// or of another kind, are not in increasing geometry order, do not add up to its
    /// primitives, or its mask is not the AND of theirs.
    BadMembers {
        /// The tree.
        tree: usize,
    },
    /// A tree is not valid.
    Tree {
        /// The tree.
        tree: usize,
        /// What is wrong with it.
        error: BvhError,
    },
    /// Nodes, blocks or members that no tree holds.
    Unused {
        /// [`TRIANGLES`], [`SPHERES`] or [`INSTANCES`] (nodes or blocks), or 3 (members).
        kind: u32,
    },
    /// An instance names a tree that does not exist (or, in a group, a tree that does not come
    /// before the group), or its path is not the count of its level's earlier paths.
    BadInstance {
        /// The instance.
        inst: usize,
    },
    /// A group's instances, tree ranges or unbounded entries are out of place, or its levels,
    /// paths, mask or slack are not what its instances make them.
    BadGroup {
        /// The group's tree.
        tree: usize,
    },
    /// The top-level tree is not valid.
    Top(BvhError),
    /// A slot of a level's tree holds a part ([`InstanceBox::node`]) that is no node of its
    /// instance's tree (a group's instance: not its root).
    BadPart {
        /// The group's tree, or `None` for the world's level.
        level: Option<usize>,
        /// The slot.
        slot: usize,
    },
    /// An unbounded entry names an instance that does not exist.
    BadUnbounded {
        /// Its position in the list.
        at: usize,
    },
    /// More geometries, instances or instance paths than `u32` indices.
    TooMany,
    /// A ray could enter more instances than the budget allows ([`SceneRef::entries_within`]).
    TooMuchWork {
        /// The budget: most instance entries per ray allowed.
        budget: u64,
    },
    /// Stored words ([`SceneRef::from_words`]) are not laid out as a stored scene (the reason).
    BadWords(&'static str),
}

impl core::fmt::Display for SceneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SceneError::BadKind { at } => write!(f, "entry {at} has an unknown kind"),
            SceneError::BadRange { tree } => {
                write!(f, "tree {tree}'s nodes or blocks are out of place")
            }
            SceneError::BadMembers { tree } => write!(f, "tree {tree}'s members are not valid"),
            SceneError::Tree { tree, error } => write!(f, "tree {tree}: {error}"),
            SceneError::Unused { kind } => {
                write!(
                    f,
                    "nodes, blocks or members (kind {kind}) that no tree holds"
                )
            }
            SceneError::BadInstance { inst } => {
                write!(f, "instance {inst}'s tree or path is not valid")
            }
            SceneError::BadGroup { tree } => write!(f, "group {tree} is not valid"),
            SceneError::Top(e) => write!(f, "top-level tree: {e}"),
            SceneError::BadPart { level, slot } => match level {
                Some(g) => write!(
                    f,
                    "group {g}'s tree: slot {slot} names no node of its instance"
                ),
                None => write!(
                    f,
                    "top-level tree: slot {slot} names no node of its instance"
                ),
            },
            SceneError::BadUnbounded { at } => {
                write!(
                    f,
                    "unbounded entry {at} names an instance that does not exist"
                )
            }
            SceneError::TooMany => {
                write!(f, "more geometries, instances or paths than u32 indices")
            }
            SceneError::TooMuchWork { budget } => write!(
                f,
                "a ray could enter more than {budget} instances (the budget of per-ray work)"
            ),
            SceneError::BadWords(why) => write!(f, "stored scene words: {why}"),
        }
    }
}

impl core::error::Error for SceneError {}

/// The relative origin slack of a level's box tests over `instances` (placing `trees`): the
/// largest any bounded one needs, at least [`SLACK`].
fn origin_slack(instances: &[Instance], trees: &[SceneTree]) -> f32 {
    instances
        .iter()
        .filter_map(|i| {
            let inner = trees.get(i.tree as usize)?.slack;
            i.transform.origin_slack_within(inner)
        })
        .fold(SLACK, f32::max)
}

/// One level of instances, the world's or a group's: its instances, the tree over their boxes
/// and those outside it.
#[derive(Clone, Copy, Debug)]
pub struct Level<'a> {
    /// The tree over its bounded instances' parts ([`InstanceBox`]; its ids count from
    /// `first`).
    pub top: Bvh8Ref<'a, InstanceBox>,
    /// Its first instance in the scene's list.
    pub first: u32,
    /// Its instances, `first..first + instances.len()` in the scene's list.
    pub instances: &'a [Instance],
    /// Its instances that are not in `top` (scene indices): every ray reaching it visits them.
    pub unbounded: &'a [u32],
    /// The relative origin slack of `top`'s box tests (at least [`SLACK`]).
    pub slack: f32,
    /// The OR of its instances' masks (the world's: all ones): a ray sharing no bit with it
    /// finds nothing in the level.
    pub mask: u32,
}

impl Level<'_> {
    /// The part in slot `k` of the level's tree ([`InstanceBox`]): its instance (an index of the
    /// scene's list) and the node of the instance's tree it starts at; `None` on padding.
    ///
    /// # Panics
    /// When `k` is not a slot of the tree.
    #[inline(always)]
    pub fn part(&self, k: usize) -> Option<(u32, u32)> {
        let id = self.top.ids()[k];
        if id == PAD {
            return None;
        }
        Some((self.first.wrapping_add(id), part_node(&self.top, k)))
    }
}

/// [`InstanceBox::node`] of slot `k` of a level's tree, read alone from its block.
///
/// # Panics
/// When `k` is not a slot of the tree.
#[inline(always)]
pub(crate) fn part_node(top: &Bvh8Ref<'_, InstanceBox>, k: usize) -> u32 {
    const NODE: usize = core::mem::offset_of!(InstanceBox, node) / 4;
    top.block_of(k)[NODE][k % BLOCK].to_bits()
}

/// One tree of a scene, by kind, with its members.
#[derive(Debug)]
pub enum TreeRef<'a, T, S> {
    /// Over triangle geometries.
    Triangles(Bvh8Ref<'a, T>, &'a [Member]),
    /// Over sphere geometries.
    Spheres(Bvh8Ref<'a, S>, &'a [Member]),
    /// A group: a level of instances.
    Instances(Level<'a>),
}

impl<T, S> Clone for TreeRef<'_, T, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T, S> Copy for TreeRef<'_, T, S> {}

/// A scene as borrowed slices, validated: what the scene walks read. `Copy`, no allocation.
/// `T` and `S` are the triangle and sphere layouts of the tiers that will trace it.
#[derive(Debug)]
pub struct SceneRef<'a, T, S> {
    parts: SceneParts<'a>,
    root: Level<'a>,
    /// Whether any group is placed (instance paths are then not instance indices).
    nested: bool,
    /// The tree of the only instance, found once (a renderer's static world: every ray enters
    /// it).
    sole: Option<TreeRef<'a, T, S>>,
}

impl<T, S> Clone for SceneRef<'_, T, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T, S> Copy for SceneRef<'_, T, S> {}

/// The instances on an instance path, the world's first ([`SceneRef::instance_path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InstancePath {
    len: usize,
    insts: [u32; MAX_INSTANCE_LEVELS as usize],
}

impl InstancePath {
    /// The instances' indices in the scene's list, outermost first.
    pub fn as_slice(&self) -> &[u32] {
        &self.insts[..self.len]
    }

    /// The innermost instance (the one that places the hit's geometry).
    pub fn leaf(&self) -> u32 {
        self.insts[self.len - 1]
    }
}

/// The slices of tree `g` within its kind's slices (`words` rows per block), if its ranges lie
/// inside them.
fn sub_tree<'a>(parts: &TreeParts<'a>, g: &SceneTree, words: usize) -> Option<TreeParts<'a>> {
    let (n0, n) = (g.first_node as usize, g.nodes as usize);
    let (b0, b) = (g.first_block as usize, g.blocks as usize);
    Some(TreeParts {
        nodes: parts.nodes.get(n0..n0.checked_add(n)?)?,
        blocks: parts
            .blocks
            .get(b0.checked_mul(words)?..b0.checked_add(b)?.checked_mul(words)?)?,
        ids: parts
            .ids
            .get(b0.checked_mul(BLOCK)?..b0.checked_add(b)?.checked_mul(BLOCK)?)?,
    })
}

impl<'a, T: Primitive, S: Primitive> SceneRef<'a, T, S> {
    /// Validates and wraps a scene's slices, in time linear in their total length and without
    /// an allocator: every tree as [`Bvh8Ref::new`] checks it (the trees of a kind in order,
    /// together covering their kind's slices exactly), each tree's members, each group's
    /// instances (placing trees before the group, their paths, levels, mask and slack as they
    /// make them), every instance's tree in range, the world's top-level tree over its
    /// instances, every part's node in its instance's tree ([`InstanceBox::node`]), the
    /// unbounded lists in range; and the work per ray, within the default
    /// budget of [`SceneParts::words`] instance entries (see the module's "Work per ray").
    ///
    /// # Errors
    /// The first [`SceneError`] found.
    pub fn new(parts: SceneParts<'a>) -> Result<Self, SceneError> {
        Self::new_bounded(parts, parts.words())
    }

    /// [`SceneRef::new`] with the budget of per-ray work set by the caller: a scene whose rays
    /// could enter more than `max_entries` instances ([`SceneRef::entries_within`]) is refused
    /// with [`SceneError::TooMuchWork`]. Validation takes time linear in the slices' length plus
    /// `max_entries`.
    ///
    /// # Errors
    /// As [`SceneRef::new`].
    pub fn new_bounded(parts: SceneParts<'a>, max_entries: u64) -> Result<Self, SceneError> {
        let scene = Self::validate(parts)?;
        match scene.entries_within(max_entries) {
            Some(_) => Ok(scene),
            None => Err(SceneError::TooMuchWork {
                budget: max_entries,
            }),
        }
    }

    /// The scene, with the tree of its only instance found once (when the world's one instance
    /// is the scene's only instance: a group that holds the only instance but is placed nowhere
    /// is never traced).
    fn with_sole(parts: SceneParts<'a>, root: Level<'a>) -> Self {
        let mut s = Self {
            parts,
            root,
            nested: root.instances.len() != parts.instances.len()
                || parts.trees.iter().any(|t| t.kind == INSTANCES),
            sole: None,
        };
        if let ([only], [_]) = (parts.instances, root.instances) {
            s.sole = s.tree(only.tree);
        }
        s
    }

    /// The scene's entry bound (the most instance entries one ray can make: see the module's
    /// "Work per ray"), when it is at most `budget`; `None` when it exceeds `budget`. Takes
    /// time linear in `budget` (the count stops there).
    pub fn entries_within(&self, budget: u64) -> Option<u64> {
        let mut left = budget;
        self.level_entries(self.root, &mut left)
            .then(|| budget - left)
    }

    /// Counts `level`'s instance entries, and those below them, off `left`; false when they
    /// run out.
    fn level_entries(&self, level: Level<'a>, left: &mut u64) -> bool {
        let slots = level.top.ids().iter().filter(|&&k| k != PAD);
        for inst in slots
            .map(|&k| level.first.wrapping_add(k))
            .chain(level.unbounded.iter().copied())
        {
            let Some(rest) = left.checked_sub(1) else {
                return false;
            };
            *left = rest;
            let below = self
                .parts
                .instances
                .get(inst as usize)
                .and_then(|i| self.tree(i.tree));
            if let Some(TreeRef::Instances(group)) = below {
                if !self.level_entries(group, left) {
                    return false;
                }
            }
        }
        true
    }

    /// A scene [`Scene`] built (valid by construction: not validated again).
    #[cfg(feature = "alloc")]
    pub(crate) fn built(parts: SceneParts<'a>, root: Level<'a>) -> Self {
        Self::with_sole(parts, root)
    }

    /// The slices (to store the scene: `bytemuck::cast_slice` each to bytes).
    pub fn parts(&self) -> SceneParts<'a> {
        self.parts
    }

    /// The geometries.
    pub fn geometries(&self) -> &'a [Geometry] {
        self.parts.geometries
    }

    /// The trees (of geometries, and groups).
    pub fn trees(&self) -> &'a [SceneTree] {
        self.parts.trees
    }

    /// The instances: the world's, then each group's.
    pub fn instances(&self) -> &'a [Instance] {
        self.parts.instances
    }

    /// The world's level: its instances, the top-level tree over their boxes, those outside it.
    pub fn world(&self) -> Level<'a> {
        self.root
    }

    /// The number of instance paths (a hit's `inst` is below it): the world's instances when
    /// no group is placed; what instancing multiplies the trees into.
    pub fn paths(&self) -> u64 {
        self.root.instances.last().map_or(0, |i| {
            let below = self.parts.trees.get(i.tree as usize).map_or(0, |t| t.paths);
            u64::from(i.path) + u64::from(below)
        })
    }

    /// Instance `inst` and its tree (`None` when `inst` is out of range).
    #[inline]
    pub fn instance_tree(&self, inst: u32) -> Option<(&'a Instance, TreeRef<'a, T, S>)> {
        let i = self.parts.instances.get(inst as usize)?;
        match self.sole {
            Some(t) => Some((i, t)),
            None => Some((i, self.tree(i.tree)?)),
        }
    }

    /// The instances on instance path `path` (a hit's `inst`), the world's first; `None` when no
    /// path has that number.
    pub fn instance_path(&self, path: u32) -> Option<InstancePath> {
        let mut out = InstancePath {
            len: 0,
            insts: [0; MAX_INSTANCE_LEVELS as usize],
        };
        let mut level = self.root;
        let mut rest = path;
        loop {
            // Paths start at 0 and grow with the instances (validated): the last instance whose
            // first path is at or before `rest`.
            let k = level
                .instances
                .partition_point(|i| i.path <= rest)
                .checked_sub(1)?;
            let inst = &level.instances[k];
            *out.insts.get_mut(out.len)? = level.first + k as u32;
            out.len += 1;
            rest -= inst.path;
            match self.tree(inst.tree)? {
                TreeRef::Instances(l) => level = l,
                _ => return (rest == 0).then_some(out),
            }
        }
    }

    /// The instance that places the geometries of instance path `path`: the path's last (in a
    /// scene without groups, `path` itself).
    #[inline]
    pub fn leaf_instance(&self, path: u32) -> Option<u32> {
        if self.nested {
            self.instance_path(path).map(|p| p.leaf())
        } else {
            Some(path)
        }
    }

    /// Tree `t`'s members (empty when `t` is out of range or a group).
    #[inline]
    pub fn members(&self, t: u32) -> &'a [Member] {
        match self.tree(t) {
            Some(TreeRef::Triangles(_, m) | TreeRef::Spheres(_, m)) => m,
            _ => &[],
        }
    }

    /// Tree `t` with its members, or a group's level (`None` when `t` is out of range).
    #[inline]
    pub fn tree(&self, t: u32) -> Option<TreeRef<'a, T, S>> {
        let tr = self.parts.trees.get(t as usize)?;
        if tr.kind == INSTANCES {
            let p = sub_tree(&self.parts.top, tr, InstanceBox::WORDS)?;
            let first = tr.first_member as usize;
            let u0 = tr.first_unbounded as usize;
            return Some(TreeRef::Instances(Level {
                top: Bvh8Ref::trusted(p.nodes, p.blocks, p.ids, tr.prims),
                first: tr.first_member,
                instances: self
                    .parts
                    .instances
                    .get(first..first.checked_add(tr.members as usize)?)?,
                unbounded: self
                    .parts
                    .unbounded
                    .get(u0..u0.checked_add(tr.unbounded as usize)?)?,
                slack: tr.slack,
                mask: tr.mask,
            }));
        }
        let members = self
            .parts
            .members
            .get(tr.first_member as usize..)?
            .get(..tr.members as usize)?;
        Some(match tr.kind {
            TRIANGLES => {
                let p = sub_tree(&self.parts.triangles, tr, T::WORDS)?;
                TreeRef::Triangles(
                    Bvh8Ref::trusted(p.nodes, p.blocks, p.ids, tr.prims),
                    members,
                )
            }
            _ => {
                let p = sub_tree(&self.parts.spheres, tr, S::WORDS)?;
                TreeRef::Spheres(
                    Bvh8Ref::trusted(p.nodes, p.blocks, p.ids, tr.prims),
                    members,
                )
            }
        })
    }
}
