//! A renderer's scene as data: geometries (each a tree over one primitive slice, triangles or
//! spheres), instances that place them in the world with affine transforms and masks, and the
//! top-level tree over the instances' world boxes. The walks over it are `octoray-packet`'s
//! `scene::Trace`.
//!
//! - [`Geometry`]: one geometry's kind, mask and where its tree lies in the scene's slices.
//! - [`Instance`]: a geometry placed by a [`Transform`] (world → object), with a mask.
//! - [`SceneRef`]: the whole scene as borrowed slices, validated by [`SceneRef::new`]; traversal
//!   needs nothing else (no allocator, no `std`), so a scene written on a host can be traced on
//!   a target from `&'static` data.
//! - [`Scene`] (feature `alloc`): the owned scene, built geometry by geometry.
//!
//! # Contract
//! A scene query's answer equals brute force over every instance whose mask, its geometry's mask
//! and the query's mask share a bit: each instance's primitives tested with the ray carried into
//! its object space by [`Transform::apply`] (the same f32 ray for every primitive of that
//! instance), bit for bit (hit/miss, `t`, `u`, `v`, primitive, geometry, instance), with the tie
//! rule: among hits of equal `t`, the lowest instance index, then the lowest primitive index
//! wins. `t` is measured along the world ray (the transform keeps it), so hits of different
//! instances compare by `t`; each carries the transform's rounding (1 ulp of each ray
//! component), which moves its `t` by up to about `κ·ε` relative for an instance whose
//! transform has condition number `κ`, on top of the tier's own `t` error.
//!
//! Within one instance each tier keeps its contract (watertightness included: one ray, one
//! mesh). Two instances that share an edge in the world see two different rounded rays, so a
//! ray through that edge can pass between them by up to the transforms' rounding (about
//! `κ·ε·(‖o‖ + t‖d‖)`): a closed surface made of several instances is watertight only where its
//! instances share one transform. Instances are one level deep: an instance places a geometry,
//! not another scene.
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

/// One geometry of a scene: its kind, its mask, and where its tree lies in the slices of its
/// kind (nodes `first_node..first_node + nodes`, blocks `first_block..first_block + blocks`; the
/// geometries of one kind follow one another in those slices).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Geometry {
    /// [`TRIANGLES`] or [`SPHERES`].
    pub kind: u32,
    /// ANDed with the instance's and the query's mask: no common bit, not visited.
    pub mask: u32,
    /// Length of the primitive slice its tree was built from (reported `prim` is below it).
    pub prims: u32,
    /// Its root's index in the nodes of its kind.
    pub first_node: u32,
    /// Its number of nodes (0: an empty geometry, never hit).
    pub nodes: u32,
    /// Its first block in the blocks of its kind.
    pub first_block: u32,
    /// Its number of blocks of [`BLOCK`] primitives.
    pub blocks: u32,
}

/// A geometry placed in the world: rays are carried into its object space by `transform`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Instance {
    /// World → object.
    pub transform: Transform,
    /// Index of the geometry it places.
    pub geom: u32,
    /// ANDed with the geometry's and the query's mask: no common bit, not visited.
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
    /// The triangle geometries' trees, one after another.
    pub triangles: TreeParts<'a>,
    /// The sphere geometries' trees, one after another.
    pub spheres: TreeParts<'a>,
    /// The geometries.
    pub geometries: &'a [Geometry],
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
    /// A geometry's kind is neither [`TRIANGLES`] nor [`SPHERES`].
    BadKind {
        /// The geometry.
        geom: usize,
    },
    /// A geometry's ranges do not follow the previous geometry of its kind, or lie outside its
    /// kind's slices.
    BadRange {
        /// The geometry.
        geom: usize,
    },
    /// A geometry's tree is not valid.
    Geometry {
        /// The geometry.
        geom: usize,
        /// What is wrong with its tree.
        error: BvhError,
    },
    /// Nodes or blocks of a kind that no geometry holds.
    Unused {
        /// [`TRIANGLES`] or [`SPHERES`].
        kind: u32,
    },
    /// An instance names a geometry that does not exist.
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
}

impl core::fmt::Display for SceneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SceneError::BadKind { geom } => write!(f, "geometry {geom} has an unknown kind"),
            SceneError::BadRange { geom } => {
                write!(f, "geometry {geom}'s nodes or blocks are out of place")
            }
            SceneError::Geometry { geom, error } => write!(f, "geometry {geom}: {error}"),
            SceneError::Unused { kind } => {
                write!(f, "nodes or blocks of kind {kind} that no geometry holds")
            }
            SceneError::BadInstance { inst } => {
                write!(f, "instance {inst} names a geometry that does not exist")
            }
            SceneError::Top(e) => write!(f, "top-level tree: {e}"),
            SceneError::BadUnbounded { at } => {
                write!(
                    f,
                    "unbounded entry {at} names an instance that does not exist"
                )
            }
            SceneError::TooMany => write!(f, "more geometries or instances than u32 indices"),
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

/// One geometry's tree, by kind.
#[derive(Clone, Copy, Debug)]
pub enum GeomRef<'a, T, S> {
    /// A triangle mesh.
    Triangles(Bvh8Ref<'a, T>),
    /// A set of spheres.
    Spheres(Bvh8Ref<'a, S>),
}

/// A scene as borrowed slices, validated: what the scene walks read. `Copy`, no allocation.
/// `T` and `S` are the triangle and sphere layouts of the tiers that will trace it.
#[derive(Debug)]
pub struct SceneRef<'a, T, S> {
    parts: SceneParts<'a>,
    top: Bvh8Ref<'a, InstanceBox>,
    origin_slack: f32,
    _prim: core::marker::PhantomData<(T, S)>,
}

impl<T, S> Clone for SceneRef<'_, T, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T, S> Copy for SceneRef<'_, T, S> {}

/// The tree slices of geometry `g` within its kind's slices (`words` rows per block), if its
/// ranges lie inside them.
fn sub_tree<'a>(parts: &TreeParts<'a>, g: &Geometry, words: usize) -> Option<TreeParts<'a>> {
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
        {
            return Err(SceneError::TooMany);
        }
        let mut next = [(0u32, 0u32); 2];
        for (i, g) in parts.geometries.iter().enumerate() {
            let (tree, words) = match g.kind {
                TRIANGLES => (&parts.triangles, T::WORDS),
                SPHERES => (&parts.spheres, S::WORDS),
                _ => return Err(SceneError::BadKind { geom: i }),
            };
            let at = &mut next[g.kind as usize];
            if (g.first_node, g.first_block) != *at {
                return Err(SceneError::BadRange { geom: i });
            }
            let sub = sub_tree(tree, g, words).ok_or(SceneError::BadRange { geom: i })?;
            let err = |error| SceneError::Geometry { geom: i, error };
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
                .ok_or(SceneError::BadRange { geom: i })?;
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
        if let Some(i) = parts
            .instances
            .iter()
            .position(|inst| inst.geom as usize >= parts.geometries.len())
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
        Ok(Self {
            parts,
            top,
            origin_slack,
            _prim: core::marker::PhantomData,
        })
    }

    /// A scene [`Scene`] built (valid by construction: not validated again).
    #[cfg(feature = "alloc")]
    pub(crate) fn built(
        parts: SceneParts<'a>,
        top: Bvh8Ref<'a, InstanceBox>,
        origin_slack: f32,
    ) -> Self {
        Self {
            parts,
            top,
            origin_slack,
            _prim: core::marker::PhantomData,
        }
    }

    /// The slices (to store the scene: `bytemuck::cast_slice` each to bytes).
    pub fn parts(&self) -> SceneParts<'a> {
        self.parts
    }

    /// The geometries.
    pub fn geometries(&self) -> &'a [Geometry] {
        self.parts.geometries
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

    /// Geometry `g`'s tree (`None` when `g` is out of range).
    #[inline]
    pub fn geometry(&self, g: u32) -> Option<GeomRef<'a, T, S>> {
        let geo = self.parts.geometries.get(g as usize)?;
        Some(match geo.kind {
            TRIANGLES => {
                let t = sub_tree(&self.parts.triangles, geo, T::WORDS)?;
                GeomRef::Triangles(Bvh8Ref::trusted(t.nodes, t.blocks, t.ids, geo.prims))
            }
            _ => {
                let t = sub_tree(&self.parts.spheres, geo, S::WORDS)?;
                GeomRef::Spheres(Bvh8Ref::trusted(t.nodes, t.blocks, t.ids, geo.prims))
            }
        })
    }
}
