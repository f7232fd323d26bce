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
//! - [`SceneRef`]: the whole scene as borrowed slices, validated by [`SceneRef::new`]; traversal
//!   needs nothing else (no allocator, no `std`), so a scene written on a host can be traced on
//!   a target from `&'static` data.
//! - [`Scene`] (feature `alloc`): the owned scene: add geometries, place sets of them, commit.
//!
//! # Contract
//! A scene query's answer equals brute force over every instance, over every geometry of its
//! tree whose mask shares a bit with the instance's and the query's: each instance's primitives
//! tested with the ray carried into its object space by [`Transform::apply`] (the same f32 ray
//! for every primitive of that instance), bit for bit (hit/miss, `t`, `u`, `v`, primitive,
//! geometry, instance), with the tie rule: among hits of equal `t`, the lowest instance index,
//! then the lowest geometry, then the lowest primitive wins. `t` is measured along the world ray
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
//! Instances are one level deep: an instance places a tree of geometries, not another scene.
//!
//! The top level's box tests are conservative for the rounded rays: each instance's world box is
//! grown by what the rounding into object space can move a hit ([`Transform::world_box`]), and
//! the top-level walk adds an origin slack for the largest condition number among the bounded
//! instances. An instance whose condition number exceeds [`MAX_CONDITION`] (nearly singular) or
//! whose world box is not finite is not in the top-level tree: every ray visits it.
//!
//! # Untrusted scenes
//! [`SceneRef::new`] takes any slices: it answers `Ok` or a [`SceneError`], never panics, in time
//! linear in their total length and without an allocator. On a scene it accepts, every query is
//! total: no panic, each node visited and each primitive tested at most once per ray and
//! instance visit, every reported geometry, instance and primitive in range.

#[cfg(feature = "alloc")]
mod build;
mod store;
mod transform;

#[cfg(feature = "alloc")]
pub use build::Scene;
pub use transform::{Transform, MAX_CONDITION};

use crate::bvh::{Bvh8Node, Bvh8Ref, BvhError, SLACK};
use crate::lanes::Lanes;
use crate::prim::{Aabb, Primitive, Words, BLOCK};

/// [`Geometry::kind`] of a triangle mesh (the scene's triangle layout).
pub const TRIANGLES: u32 = 0;
/// [`Geometry::kind`] of a set of spheres (the scene's sphere layout).
pub const SPHERES: u32 = 1;

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

/// One bottom-level tree of a scene: a BVH over one or more geometries of one kind (their
/// primitives one after another, in the order of its members), and where it lies in the slices
/// of its kind (nodes `first_node..first_node + nodes`, blocks `first_block..first_block +
/// blocks`; the trees of one kind follow one another there).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SceneTree {
    /// [`TRIANGLES`] or [`SPHERES`].
    pub kind: u32,
    /// Its members' primitives together.
    pub prims: u32,
    /// Its root's index in the nodes of its kind.
    pub first_node: u32,
    /// Its number of nodes (0: empty, never hit).
    pub nodes: u32,
    /// Its first block in the blocks of its kind.
    pub first_block: u32,
    /// Its number of blocks of [`BLOCK`] primitives.
    pub blocks: u32,
    /// Its first member in the scene's member list.
    pub first_member: u32,
    /// Its number of members (geometries), at least 1.
    pub members: u32,
    /// The AND of its members' masks (a query sharing a bit with it admits every member, and
    /// the walk skips the per-hit mask test).
    pub mask: u32,
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

/// A tree placed in the world: rays are carried into its object space by `transform`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Instance {
    /// World → object.
    pub transform: Transform,
    /// Index of the tree it places.
    pub tree: u32,
    /// ANDed with the query's mask before the tree is entered, and with each geometry's.
    pub mask: u32,
}

/// The top-level tree's primitive: an instance's world box ([`Transform::world_box`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct InstanceBox {
    /// Smallest corner.
    pub lo: [f32; 3],
    /// Largest corner.
    pub hi: [f32; 3],
}

impl Primitive for InstanceBox {
    type Lanes<L: Lanes> = ();
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
    /// The top-level tree over [`InstanceBox`]es (its ids are instance indices).
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
        /// [`TRIANGLES`] or [`SPHERES`] (nodes or blocks), or 2 (members).
        kind: u32,
    },
    /// An instance names a tree that does not exist.
    BadInstance {
        /// The instance.
        inst: usize,
    },
    /// The top-level tree is not valid.
    Top(BvhError),
    /// An unbounded entry names an instance that does not exist.
    BadUnbounded {
        /// Its position in the list.
        at: usize,
    },
    /// More geometries or instances than `u32` indices.
    TooMany,
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
                write!(f, "instance {inst} names a tree that does not exist")
            }
            SceneError::Top(e) => write!(f, "top-level tree: {e}"),
            SceneError::BadUnbounded { at } => {
                write!(
                    f,
                    "unbounded entry {at} names an instance that does not exist"
                )
            }
            SceneError::TooMany => write!(f, "more geometries or instances than u32 indices"),
            SceneError::BadWords(why) => write!(f, "stored scene words: {why}"),
        }
    }
}

impl core::error::Error for SceneError {}

/// The top level's relative origin slack for `instances`: the largest any bounded one needs,
/// at least [`SLACK`].
fn origin_slack(instances: &[Instance]) -> f32 {
    instances
        .iter()
        .filter_map(|i| i.transform.origin_slack())
        .fold(SLACK, f32::max)
}

/// One bottom-level tree, by kind, with its members.
#[derive(Debug)]
pub enum TreeRef<'a, T, S> {
    /// Over triangle geometries.
    Triangles(Bvh8Ref<'a, T>, &'a [Member]),
    /// Over sphere geometries.
    Spheres(Bvh8Ref<'a, S>, &'a [Member]),
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
    top: Bvh8Ref<'a, InstanceBox>,
    origin_slack: f32,
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
    /// an allocator: every geometry's tree as [`Bvh8Ref::new`] checks it (the geometries of a
    /// kind in order, together covering their kind's slices exactly), every instance's geometry
    /// in range, the top-level tree over the instances, the unbounded list in range.
    pub fn new(parts: SceneParts<'a>) -> Result<Self, SceneError> {
        if u32::try_from(parts.geometries.len()).is_err()
            || u32::try_from(parts.instances.len()).is_err()
            || u32::try_from(parts.trees.len()).is_err()
        {
            return Err(SceneError::TooMany);
        }
        if let Some(at) = parts
            .geometries
            .iter()
            .position(|g| g.kind != TRIANGLES && g.kind != SPHERES)
        {
            return Err(SceneError::BadKind { at });
        }
        let mut next = [(0u32, 0u32); 2];
        let mut next_member = 0usize;
        for (i, g) in parts.trees.iter().enumerate() {
            let (tree, words) = match g.kind {
                TRIANGLES => (&parts.triangles, T::WORDS),
                SPHERES => (&parts.spheres, S::WORDS),
                _ => return Err(SceneError::BadKind { at: i }),
            };
            let at = &mut next[g.kind as usize];
            let bad_range = SceneError::BadRange { tree: i };
            if (g.first_node, g.first_block) != *at {
                return Err(bad_range);
            }
            let sub = sub_tree(tree, g, words).ok_or(bad_range)?;
            let err = |error| SceneError::Tree { tree: i, error };
            let prims = g.prims as usize;
            match g.kind {
                TRIANGLES => Bvh8Ref::<T>::new(sub.nodes, sub.blocks, sub.ids, prims).map(drop),
                _ => Bvh8Ref::<S>::new(sub.nodes, sub.blocks, sub.ids, prims).map(drop),
            }
            .map_err(err)?;
            *at = g
                .first_node
                .checked_add(g.nodes)
                .zip(g.first_block.checked_add(g.blocks))
                .ok_or(bad_range)?;
            // Members: the next ones in the list, geometries of this kind in increasing order,
            // their primitives one after another adding up to the tree's.
            let bad_members = SceneError::BadMembers { tree: i };
            let members = (g.first_member as usize == next_member)
                .then(|| {
                    parts
                        .members
                        .get(next_member..next_member.checked_add(g.members as usize)?)
                })
                .flatten()
                .filter(|m| !m.is_empty())
                .ok_or(bad_members)?;
            next_member += members.len();
            let mut sum = 0u64;
            let mut last = None;
            let mut mask = u32::MAX;
            for m in members {
                let geo = parts.geometries.get(m.geom as usize).ok_or(bad_members)?;
                if geo.kind != g.kind || u64::from(m.first_prim) != sum || last >= Some(m.geom) {
                    return Err(bad_members);
                }
                last = Some(m.geom);
                sum += u64::from(geo.prims);
                mask &= geo.mask;
            }
            if sum != u64::from(g.prims) || mask != g.mask {
                return Err(bad_members);
            }
        }
        for (kind, tree, words) in [
            (TRIANGLES, &parts.triangles, T::WORDS),
            (SPHERES, &parts.spheres, S::WORDS),
        ] {
            let (n, b) = next[kind as usize];
            if n as usize != tree.nodes.len()
                || b as usize * BLOCK != tree.ids.len()
                || Some(tree.blocks.len()) != (b as usize).checked_mul(words)
            {
                return Err(SceneError::Unused { kind });
            }
        }
        if next_member != parts.members.len() {
            return Err(SceneError::Unused { kind: 2 });
        }
        if let Some(i) = parts
            .instances
            .iter()
            .position(|inst| inst.tree as usize >= parts.trees.len())
        {
            return Err(SceneError::BadInstance { inst: i });
        }
        let origin_slack = origin_slack(parts.instances);
        let top = Bvh8Ref::<InstanceBox>::new(
            parts.top.nodes,
            parts.top.blocks,
            parts.top.ids,
            parts.instances.len(),
        )
        .map_err(SceneError::Top)?;
        if let Some(at) = parts
            .unbounded
            .iter()
            .position(|&i| i as usize >= parts.instances.len())
        {
            return Err(SceneError::BadUnbounded { at });
        }
        Ok(Self::with_sole(parts, top, origin_slack))
    }

    /// The scene, with the only instance's tree found once.
    fn with_sole(parts: SceneParts<'a>, top: Bvh8Ref<'a, InstanceBox>, origin_slack: f32) -> Self {
        let mut s = Self {
            parts,
            top,
            origin_slack,
            sole: None,
        };
        if let [only] = parts.instances {
            s.sole = s.tree(only.tree);
        }
        s
    }

    /// A scene [`Scene`] built (valid by construction: not validated again).
    #[cfg(feature = "alloc")]
    pub(crate) fn built(
        parts: SceneParts<'a>,
        top: Bvh8Ref<'a, InstanceBox>,
        origin_slack: f32,
    ) -> Self {
        Self::with_sole(parts, top, origin_slack)
    }

    /// The slices (to store the scene: `bytemuck::cast_slice` each to bytes).
    pub fn parts(&self) -> SceneParts<'a> {
        self.parts
    }

    /// The geometries.
    pub fn geometries(&self) -> &'a [Geometry] {
        self.parts.geometries
    }

    /// The bottom-level trees.
    pub fn trees(&self) -> &'a [SceneTree] {
        self.parts.trees
    }

    /// The instances.
    pub fn instances(&self) -> &'a [Instance] {
        self.parts.instances
    }

    /// The top-level tree over the bounded instances.
    pub fn top(&self) -> Bvh8Ref<'a, InstanceBox> {
        self.top
    }

    /// The instances every ray visits (not in the top-level tree).
    pub fn unbounded(&self) -> &'a [u32] {
        self.parts.unbounded
    }

    /// The relative origin slack of the top level's box tests (at least [`SLACK`]).
    pub fn origin_slack(&self) -> f32 {
        self.origin_slack
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

    /// Tree `t`'s members (empty when `t` is out of range).
    #[inline]
    pub fn members(&self, t: u32) -> &'a [Member] {
        self.parts
            .trees
            .get(t as usize)
            .and_then(|tr| {
                self.parts
                    .members
                    .get(tr.first_member as usize..)?
                    .get(..tr.members as usize)
            })
            .unwrap_or(&[])
    }

    /// Tree `t` with its members (`None` when `t` is out of range).
    #[inline]
    pub fn tree(&self, t: u32) -> Option<TreeRef<'a, T, S>> {
        let tr = self.parts.trees.get(t as usize)?;
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
