//! The owned scene: geometries added one by one, instances placing sets of them, the trees and
//! the top level built on [`Scene::commit`].

use super::braid::{open_parts, Part};
use super::{
    Geometry, Instance, InstanceBox, Level, Member, SceneParts, SceneRef, SceneTree, Transform,
    TreeParts, INSTANCES, MAX_INSTANCE_LEVELS, SPHERES, TRIANGLES,
};
use crate::bvh::{
    refit_parts, BuildOptions, Bvh8, Bvh8Node, Bvh8Ref, BvhError, Join, Sequential, PAD, SLACK,
};
use crate::prim::{Aabb, Primitive, BLOCK};
use alloc::vec::Vec;

/// One kind's trees, one after another.
#[derive(Clone, Debug, Default)]
struct Trees {
    nodes: Vec<Bvh8Node>,
    blocks: Vec<[f32; BLOCK]>,
    ids: Vec<u32>,
}

impl Trees {
    /// Appends a tree's slices.
    fn put<P: Primitive>(&mut self, tree: Bvh8<P>) {
        let (nodes, blocks, ids) = tree.into_parts();
        self.nodes.extend_from_slice(&nodes);
        self.blocks.extend_from_slice(&blocks);
        self.ids.extend_from_slice(&ids);
    }

    /// Appends a level's tree, its ids turned from parts into the level's instances.
    fn put_level(&mut self, level: &mut BuiltLevel) {
        let tree = core::mem::replace(&mut level.tree, Bvh8::build(&[]));
        let at = self.ids.len();
        self.put(tree);
        for id in &mut self.ids[at..] {
            if *id != PAD {
                *id = level.part_of[*id as usize];
            }
        }
    }

    fn parts(&self) -> TreeParts<'_> {
        TreeParts {
            nodes: &self.nodes,
            blocks: &self.blocks,
            ids: &self.ids,
        }
    }
}

/// A geometry's primitives, kept for the trees that hold it (builds and refits).
#[derive(Clone, Debug)]
enum Prims<T, S> {
    Triangles(Vec<T>),
    Spheres(Vec<S>),
}

/// What an instance places, as the scene is being built.
#[derive(Clone, Copy, Debug)]
enum Target {
    /// The tree over a set of geometries (an index of `Scene::sets`).
    Set(u32),
    /// A group.
    Group(u32),
}

/// An instance as the scene is being built.
#[derive(Clone, Copy, Debug)]
struct Placement {
    transform: Transform,
    target: Target,
    mask: u32,
}

/// Where a tree's hits can lie in its own space.
#[derive(Clone, Copy, Debug)]
enum Extent {
    /// Nothing to hit.
    Empty,
    /// Within a box.
    Box(Aabb),
    /// No finite box holds them.
    Unbounded,
}

/// One level of instances, built ([`Scene::commit_on`]).
struct BuiltLevel {
    instances: Vec<Instance>,
    /// The tree over the instances' parts ([`open_parts`]); its ids number the parts.
    tree: Bvh8<InstanceBox>,
    /// Each part's position in `instances`.
    part_of: Vec<u32>,
    /// Positions in `instances`.
    unbounded: Vec<u32>,
    levels: u32,
    paths: u32,
    mask: u32,
    slack: f32,
    extent: Extent,
}

/// An owned scene: geometries (triangle meshes in layout `T`, sphere sets in layout `S`), the
/// bottom-level trees over them, instances placing those trees, and the top-level tree.
///
/// Add geometries ([`Scene::add_triangles`], [`Scene::add_spheres`]) and place sets of them
/// ([`Scene::add_instance`]: one tree is built per distinct set, shared by every instance of
/// it; a renderer's static meshes go into one set, so one tree holds them all), then
/// [`Scene::commit`] (builds the new trees and the top level) before [`Scene::as_ref`]. After
/// moving instances ([`Scene::set_transform`]) or refitting a geometry
/// ([`Scene::refit_triangles`], [`Scene::refit_spheres`]: every tree holding it is refitted in
/// place), commit again: only the top level and the groups' trees are rebuilt.
///
/// Groups nest instancing: [`Scene::add_group`] makes one, [`Scene::add_to_group`] and
/// [`Scene::place_group`] fill it (with instances of geometries and of groups made before it),
/// and `place_group(None, …)` places it in the world, as many times as wanted. A hit's
/// `inst` numbers its instance path ([`SceneRef::instance_path`]). The scene keeps a copy of every
/// geometry's primitives (for the builds and refits of the trees that share it).
///
/// # Threads
/// `Scene` and [`SceneRef`] are `Send` and `Sync` (for `Send`/`Sync` layouts, as every layout
/// of the crate is): a committed scene is traced from any number of threads at once through
/// shared `SceneRef`s (queries take `&self` and allocate nothing); changing it takes `&mut`.
#[derive(Clone, Debug)]
pub struct Scene<T, S> {
    prims: Vec<Prims<T, S>>,
    geoms: Vec<Geometry>,
    /// Per tree: its members (sorted geometry indices); trees past `trees.len()` are not built.
    sets: Vec<Vec<u32>>,
    kinds: [Trees; 2],
    trees: Vec<SceneTree>,
    members: Vec<Member>,
    /// Per tree: the union of its root's boxes, and whether its build left primitives out.
    tree_boxes: Vec<Aabb>,
    skipped: Vec<bool>,
    /// The world's instances, and each group's, as added.
    world: Vec<Placement>,
    groups: Vec<Vec<Placement>>,
    /// Built on commit: the trees of sets and then the groups' records, the instances (the
    /// world's, then each group's), the world's tree and then each group's, the unbounded
    /// lists, and the world's level (its tree's nodes and blocks, unbounded entries, slack).
    stored_trees: Vec<SceneTree>,
    instances: Vec<Instance>,
    top: Trees,
    unbounded: Vec<u32>,
    world_top: (usize, usize),
    world_unbounded: usize,
    origin_slack: f32,
    committed: bool,
    /// How the trees of geometries are built.
    build: BuildOptions,
}

impl<T: Primitive + Sync, S: Primitive + Sync> Default for Scene<T, S> {
    fn default() -> Self {
        Self::new()
    }
}

/// The union of a root node's boxes.
fn root_box(nodes: &[Bvh8Node]) -> Aabb {
    nodes.first().map_or(Aabb::EMPTY, |n| {
        (0..n.len()).fold(Aabb::EMPTY, |a, s| {
            a.union(Aabb {
                lo: [n.lo[0][s], n.lo[1][s], n.lo[2][s]],
                hi: [n.hi[0][s], n.hi[1][s], n.hi[2][s]],
            })
        })
    })
}

/// `n` as a `u32` index of the scene's slices.
fn index(n: usize) -> Result<u32, BvhError> {
    u32::try_from(n).map_err(|_| BvhError::TooManyPrims(n))
}

impl<T: Primitive + Sync, S: Primitive + Sync> Scene<T, S> {
    /// An empty scene (committed: it can be traced as it is).
    pub fn new() -> Self {
        Self {
            prims: Vec::new(),
            geoms: Vec::new(),
            sets: Vec::new(),
            kinds: [Trees::default(), Trees::default()],
            trees: Vec::new(),
            members: Vec::new(),
            tree_boxes: Vec::new(),
            skipped: Vec::new(),
            world: Vec::new(),
            groups: Vec::new(),
            stored_trees: Vec::new(),
            instances: Vec::new(),
            top: Trees::default(),
            unbounded: Vec::new(),
            world_top: (0, 0),
            world_unbounded: 0,
            origin_slack: SLACK,
            committed: true,
            build: BuildOptions::BINNED,
        }
    }

    fn add(&mut self, kind: u32, prims: Prims<T, S>, n: usize) -> Result<u32, BvhError> {
        if n > crate::bvh::MAX_PRIMS {
            return Err(BvhError::TooManyPrims(n));
        }
        let id = index(self.geoms.len())?;
        self.geoms.push(Geometry {
            kind,
            mask: u32::MAX,
            prims: n as u32,
        });
        self.prims.push(prims);
        Ok(id)
    }

    /// How the trees of geometries built by later commits are built (the binned build unless
    /// set; [`BuildOptions::SPATIAL`] for spatial splits). Trees already built keep theirs; the
    /// instances' trees are always binned.
    pub fn set_build_options(&mut self, options: BuildOptions) {
        self.build = options;
    }

    /// Adds a triangle mesh (its indices become its hits' `prim`); returns its geometry index.
    /// Its mask is all ones. It is traced once an instance places it.
    ///
    /// # Errors
    /// [`BvhError::TooManyPrims`] when `prims` or the scene's indices outgrow `u32`.
    pub fn add_triangles(&mut self, prims: &[T]) -> Result<u32, BvhError> {
        self.add(TRIANGLES, Prims::Triangles(prims.to_vec()), prims.len())
    }

    /// Adds a set of spheres; returns its geometry index. As [`Scene::add_triangles`].
    ///
    /// # Errors
    /// As [`Scene::add_triangles`].
    pub fn add_spheres(&mut self, prims: &[S]) -> Result<u32, BvhError> {
        self.add(SPHERES, Prims::Spheres(prims.to_vec()), prims.len())
    }

    /// Sets geometry `geom`'s mask: its hits count only where it shares a bit with the query's
    /// and the instance's masks.
    ///
    /// # Panics
    /// When `geom` is not a geometry of the scene.
    #[track_caller]
    pub fn set_geometry_mask(&mut self, geom: u32, mask: u32) {
        let n = self.geoms.len();
        let Some(g) = self.geoms.get_mut(geom as usize) else {
            panic!("octoray Scene: geometry {geom} of {n}");
        };
        g.mask = mask;
        for (t, tree) in self.trees.iter_mut().enumerate() {
            if self.sets[t].contains(&geom) {
                tree.mask = self.sets[t]
                    .iter()
                    .fold(u32::MAX, |m, &g| m & self.geoms[g as usize].mask);
                if let Some(stored) = self.stored_trees.get_mut(t) {
                    stored.mask = tree.mask;
                }
            }
        }
    }

    /// Places the geometries `geoms` (one kind; one tree over all of them, shared with every
    /// other instance of the same set) in the world with `transform` (world → object;
    /// [`Transform::placing`] inverts a renderer's object → world matrix) and `mask`; returns
    /// the instance index.
    ///
    /// # Panics
    /// When `geoms` is empty, names a geometry the scene does not have, or mixes kinds; when the
    /// scene has `u32::MAX` instances.
    #[track_caller]
    pub fn add_instance(&mut self, geoms: &[u32], transform: Transform, mask: u32) -> u32 {
        let target = Target::Set(self.set_of(geoms));
        self.push(None, target, transform, mask)
    }

    /// A new, empty group; returns its index. Fill it with [`Scene::add_to_group`] and
    /// [`Scene::place_group`], place it with [`Scene::place_group`].
    ///
    /// # Panics
    /// When the scene has `u32::MAX` groups.
    #[track_caller]
    pub fn add_group(&mut self) -> u32 {
        assert!(
            self.groups.len() < u32::MAX as usize,
            "octoray Scene: too many groups"
        );
        self.groups.push(Vec::new());
        self.committed = false;
        self.groups.len() as u32 - 1
    }

    /// Places the geometries `geoms` in group `group` (its space → object by `transform`), as
    /// [`Scene::add_instance`] places them in the world; returns the instance's position in the
    /// group.
    ///
    /// # Panics
    /// As [`Scene::add_instance`]; when `group` is not a group of the scene.
    #[track_caller]
    pub fn add_to_group(
        &mut self,
        group: u32,
        geoms: &[u32],
        transform: Transform,
        mask: u32,
    ) -> u32 {
        self.group_len(group);
        let target = Target::Set(self.set_of(geoms));
        self.push(Some(group), target, transform, mask)
    }

    /// Places group `group` in the world (`parent` `None`) or in group `parent` (which must be
    /// made after it: a group holds only groups made before it), with `transform` (the
    /// parent's space → the group's) and `mask`; returns the instance's index in the world or
    /// its position in `parent`. A path from the world down to a geometry holds at most
    /// [`MAX_INSTANCE_LEVELS`] instances ([`Scene::commit_on`] checks).
    ///
    /// # Panics
    /// When `group` or `parent` is not a group of the scene, or `parent` is not made after
    /// `group`; when the level has `u32::MAX` instances.
    #[track_caller]
    pub fn place_group(
        &mut self,
        parent: Option<u32>,
        group: u32,
        transform: Transform,
        mask: u32,
    ) -> u32 {
        self.group_len(group);
        if let Some(p) = parent {
            self.group_len(p);
            assert!(
                group < p,
                "octoray Scene: group {p} cannot hold group {group} (a group holds groups made \
                 before it)"
            );
        }
        self.push(parent, Target::Group(group), transform, mask)
    }

    /// Group `g`'s number of instances.
    #[track_caller]
    fn group_len(&self, g: u32) -> usize {
        match self.groups.get(g as usize) {
            Some(list) => list.len(),
            None => panic!("octoray Scene: group {g} of {}", self.groups.len()),
        }
    }

    /// The tree index of the set `geoms` (one kind), a new one when no tree holds that set.
    #[track_caller]
    fn set_of(&mut self, geoms: &[u32]) -> u32 {
        let mut set = geoms.to_vec();
        set.sort_unstable();
        set.dedup();
        assert!(!set.is_empty(), "octoray Scene: an instance of no geometry");
        let n = self.geoms.len();
        if let Some(&g) = set.iter().find(|&&g| g as usize >= n) {
            panic!("octoray Scene: geometry {g} of {n}");
        }
        let k = self.geoms[set[0] as usize].kind;
        assert!(
            set.iter().all(|&g| self.geoms[g as usize].kind == k),
            "octoray Scene: an instance places geometries of one kind"
        );
        let tree = match self.sets.iter().position(|s| *s == set) {
            Some(t) => t,
            None => {
                self.sets.push(set);
                self.sets.len() - 1
            }
        };
        tree as u32
    }

    /// Adds an instance to the world (`None`) or a group; returns its position there.
    #[track_caller]
    fn push(&mut self, level: Option<u32>, target: Target, transform: Transform, mask: u32) -> u32 {
        let list = match level {
            None => &mut self.world,
            Some(g) => &mut self.groups[g as usize],
        };
        assert!(
            list.len() < u32::MAX as usize,
            "octoray Scene: too many instances"
        );
        list.push(Placement {
            transform,
            target,
            mask,
        });
        self.committed = false;
        list.len() as u32 - 1
    }

    /// Moves world instance `inst` (commit before tracing again).
    ///
    /// # Panics
    /// When `inst` is not an instance of the world.
    #[track_caller]
    pub fn set_transform(&mut self, inst: u32, transform: Transform) {
        self.placement_mut(None, inst).transform = transform;
        self.committed = false;
    }

    /// Moves instance `k` of group `group` (commit before tracing again).
    ///
    /// # Panics
    /// When `group` is not a group of the scene or has no instance `k`.
    #[track_caller]
    pub fn set_group_transform(&mut self, group: u32, k: u32, transform: Transform) {
        self.group_len(group);
        self.placement_mut(Some(group), k).transform = transform;
        self.committed = false;
    }

    /// Sets world instance `inst`'s mask (it holds at once, without a commit).
    ///
    /// # Panics
    /// When `inst` is not an instance of the world.
    #[track_caller]
    pub fn set_instance_mask(&mut self, inst: u32, mask: u32) {
        self.placement_mut(None, inst).mask = mask;
        // The world's instances come first in the stored list, in the order they were added.
        if let Some(i) = self.instances.get_mut(inst as usize) {
            i.mask = mask;
        }
    }

    #[track_caller]
    fn placement_mut(&mut self, level: Option<u32>, inst: u32) -> &mut Placement {
        let list = match level {
            None => &mut self.world,
            Some(g) => &mut self.groups[g as usize],
        };
        let n = list.len();
        match list.get_mut(inst as usize) {
            Some(p) => p,
            None => panic!("octoray Scene: instance {inst} of {n}"),
        }
    }

    /// The primitives of tree `t`'s members, one after another.
    fn tree_prims<P: Primitive>(&self, t: usize, pick: impl Fn(&Prims<T, S>) -> &[P]) -> Vec<P> {
        self.sets[t]
            .iter()
            .flat_map(|&g| pick(&self.prims[g as usize]).iter().copied())
            .collect()
    }

    /// Builds tree `t` (the next one) over its members and appends it to its kind's slices.
    fn build_tree<P: Primitive, J: Join>(
        &mut self,
        t: usize,
        kind: u32,
        prims: &[P],
        join: &J,
    ) -> Result<(), BvhError> {
        let tree = Bvh8::try_build_options(prims, self.build, join)?;
        let skipped = tree.stats().skipped > 0;
        let (nodes, blocks, ids) = tree.into_parts();
        let trees = &mut self.kinds[kind as usize];
        let record = SceneTree {
            kind,
            prims: index(prims.len())?,
            first_node: index(trees.nodes.len())?,
            nodes: index(nodes.len())?,
            first_block: index(trees.ids.len() / BLOCK)?,
            blocks: index(ids.len() / BLOCK)?,
            first_member: index(self.members.len())?,
            members: index(self.sets[t].len())?,
            mask: self.sets[t]
                .iter()
                .fold(u32::MAX, |m, &g| m & self.geoms[g as usize].mask),
            levels: 0,
            paths: 1,
            slack: SLACK,
            first_unbounded: 0,
            unbounded: 0,
        };
        index(trees.nodes.len() + nodes.len())?;
        index(trees.ids.len() / BLOCK + ids.len() / BLOCK)?;
        let mut first_prim = 0u32;
        for &g in &self.sets[t] {
            self.members.push(Member {
                geom: g,
                first_prim,
            });
            first_prim += self.geoms[g as usize].prims;
        }
        self.tree_boxes.push(root_box(&nodes));
        trees.nodes.extend_from_slice(&nodes);
        trees.blocks.extend_from_slice(&blocks);
        trees.ids.extend_from_slice(&ids);
        self.skipped.push(skipped);
        self.trees.push(record);
        Ok(())
    }

    /// Refits tree `t` in place to its members' current primitives.
    fn refit_tree<P: Primitive + Sync, J: Join>(
        &mut self,
        t: usize,
        prims: &[P],
        join: &J,
    ) -> Result<(), BvhError> {
        let g = self.trees[t];
        let trees = &mut self.kinds[g.kind as usize];
        let (n0, n1) = (g.first_node as usize, (g.first_node + g.nodes) as usize);
        let (b0, b1) = (g.first_block as usize, (g.first_block + g.blocks) as usize);
        let nodes = &mut trees.nodes[n0..n1];
        refit_parts(
            nodes,
            &mut trees.blocks[b0 * P::WORDS..b1 * P::WORDS],
            &trees.ids[b0 * BLOCK..b1 * BLOCK],
            prims,
            self.skipped[t],
            join,
        )?;
        self.tree_boxes[t] = root_box(nodes);
        Ok(())
    }

    /// Replaces geometry `geom`'s primitives and refits every built tree that holds it.
    #[track_caller]
    fn refit<J: Join>(&mut self, geom: u32, new: Prims<T, S>, join: &J) -> Result<(), BvhError> {
        let n = self.geoms.len();
        let Some(&g) = self.geoms.get(geom as usize) else {
            panic!("octoray Scene: geometry {geom} of {n}");
        };
        let len = match &new {
            Prims::Triangles(p) => (g.kind == TRIANGLES).then_some(p.len()),
            Prims::Spheres(p) => (g.kind == SPHERES).then_some(p.len()),
        };
        let Some(len) = len else {
            panic!("octoray Scene: geometry {geom} is of the other kind");
        };
        if len != g.prims as usize {
            return Err(BvhError::RefitLength {
                built: g.prims as usize,
                given: len,
            });
        }
        let old = core::mem::replace(&mut self.prims[geom as usize], new);
        let holding: Vec<usize> = (0..self.trees.len())
            .filter(|&t| self.sets[t].contains(&geom))
            .collect();
        let mut done = Vec::new();
        for &t in &holding {
            if let Err(e) = self.refit_holding(t, g.kind, join) {
                // Back to the old primitives, and the trees refitted so far with them (which
                // succeeded before, so they succeed again).
                self.prims[geom as usize] = old;
                for &d in &done {
                    let _ = self.refit_holding(d, g.kind, join);
                }
                return Err(e);
            }
            done.push(t);
        }
        self.committed = false;
        Ok(())
    }

    /// Refits tree `t` (of `kind`) to its members' current primitives.
    fn refit_holding<J: Join>(&mut self, t: usize, kind: u32, join: &J) -> Result<(), BvhError> {
        if kind == TRIANGLES {
            let p = self.tree_prims(t, |p| match p {
                Prims::Triangles(v) => v,
                Prims::Spheres(_) => &[],
            });
            self.refit_tree(t, &p, join)
        } else {
            let p = self.tree_prims(t, |p| match p {
                Prims::Spheres(v) => v,
                Prims::Triangles(_) => &[],
            });
            self.refit_tree(t, &p, join)
        }
    }

    /// Refits triangle geometry `geom` to `prims` after its vertices moved (same slice length
    /// and order): every tree holding it is refitted in place, as [`Bvh8::refit`] (commit
    /// before tracing again).
    ///
    /// # Errors
    /// As [`Bvh8::refit`].
    ///
    /// # Panics
    /// When `geom` is not a triangle geometry of the scene.
    #[track_caller]
    pub fn refit_triangles(&mut self, geom: u32, prims: &[T]) -> Result<(), BvhError> {
        self.refit(geom, Prims::Triangles(prims.to_vec()), &Sequential)
    }

    /// [`Scene::refit_triangles`] with the blocks rewritten on `join`'s threads (the same trees).
    ///
    /// # Errors
    /// As [`Bvh8::refit`].
    ///
    /// # Panics
    /// As [`Scene::refit_triangles`].
    #[track_caller]
    pub fn refit_triangles_on<J: Join>(
        &mut self,
        geom: u32,
        prims: &[T],
        join: &J,
    ) -> Result<(), BvhError> {
        self.refit(geom, Prims::Triangles(prims.to_vec()), join)
    }

    /// Former name of [`Scene::refit_triangles_on`].
    #[deprecated(
        since = "0.1.0",
        note = "renamed `refit_triangles_on`: `_with` names the hit-filter forms"
    )]
    pub fn refit_triangles_with<J: Join>(
        &mut self,
        geom: u32,
        prims: &[T],
        join: &J,
    ) -> Result<(), BvhError> {
        self.refit_triangles_on(geom, prims, join)
    }

    /// Refits sphere geometry `geom`: as [`Scene::refit_triangles`].
    ///
    /// # Errors
    /// As [`Bvh8::refit`].
    ///
    /// # Panics
    /// When `geom` is not a sphere geometry of the scene.
    #[track_caller]
    pub fn refit_spheres(&mut self, geom: u32, prims: &[S]) -> Result<(), BvhError> {
        self.refit(geom, Prims::Spheres(prims.to_vec()), &Sequential)
    }

    /// [`Scene::commit`] with the new trees built on `join`'s threads (the same scene).
    ///
    /// # Errors
    /// [`BvhError::TooManyLevels`] when a path from the world would hold more than
    /// [`MAX_INSTANCE_LEVELS`] instances; [`BvhError::TooManyPrims`] when a tree or the scene's
    /// slices would outgrow `u32` indices. The scene is then not committed.
    pub fn commit_on<J: Join>(&mut self, join: &J) -> Result<(), BvhError> {
        for t in self.trees.len()..self.sets.len() {
            let kind = self.geoms[self.sets[t][0] as usize].kind;
            if kind == TRIANGLES {
                let p = self.tree_prims(t, |p| match p {
                    Prims::Triangles(v) => v,
                    Prims::Spheres(_) => &[],
                });
                self.build_tree(t, kind, &p, join)?;
            } else {
                let p = self.tree_prims(t, |p| match p {
                    Prims::Spheres(v) => v,
                    Prims::Triangles(_) => &[],
                });
                self.build_tree(t, kind, &p, join)?;
            }
        }
        // Groups first (a group holds groups made before it, so their records are ready), then
        // the world; stored as the world, then each group in turn.
        let geo = self.trees.len();
        let mut records = self.trees.clone();
        let mut extents: Vec<Extent> = (0..geo)
            .map(|t| {
                if self.trees[t].nodes == 0 {
                    Extent::Empty
                } else {
                    Extent::Box(self.tree_boxes[t])
                }
            })
            .collect();
        let mut built = Vec::with_capacity(self.groups.len());
        for g in 0..self.groups.len() {
            let level = self.build_level(&self.groups[g], geo, &records, &extents, join)?;
            if level.levels + 1 >= MAX_INSTANCE_LEVELS {
                return Err(BvhError::TooManyLevels);
            }
            records.push(SceneTree {
                kind: INSTANCES,
                prims: index(level.instances.len())?,
                members: index(level.instances.len())?,
                mask: level.mask,
                levels: level.levels + 1,
                paths: level.paths,
                slack: level.slack,
                unbounded: index(level.unbounded.len())?,
                ..<SceneTree as bytemuck::Zeroable>::zeroed()
            });
            extents.push(level.extent);
            built.push(level);
        }
        let mut world = self.build_level(&self.world, geo, &records, &extents, join)?;
        let mut top = Trees::default();
        self.origin_slack = world.slack;
        self.world_unbounded = world.unbounded.len();
        top.put_level(&mut world);
        let mut instances = world.instances;
        let mut unbounded = world.unbounded;
        self.world_top = (top.nodes.len(), top.ids.len() / BLOCK);
        for (g, mut level) in built.into_iter().enumerate() {
            let r = &mut records[geo + g];
            r.first_node = index(top.nodes.len())?;
            r.first_block = index(top.ids.len() / BLOCK)?;
            r.first_member = index(instances.len())?;
            r.first_unbounded = index(unbounded.len())?;
            let first = r.first_member;
            top.put_level(&mut level);
            let r = &mut records[geo + g];
            r.nodes = index(top.nodes.len())? - r.first_node;
            r.blocks = index(top.ids.len() / BLOCK)? - r.first_block;
            unbounded.extend(level.unbounded.iter().map(|&k| first + k));
            instances.extend_from_slice(&level.instances);
        }
        index(instances.len())?;
        self.stored_trees = records;
        self.instances = instances;
        self.top = top;
        self.unbounded = unbounded;
        self.committed = true;
        Ok(())
    }

    /// Former name of [`Scene::commit_on`].
    #[deprecated(
        since = "0.1.0",
        note = "renamed `commit_on`: `_with` names the hit-filter forms"
    )]
    pub fn commit_with<J: Join>(&mut self, join: &J) -> Result<(), BvhError> {
        self.commit_on(join)
    }

    /// The instances `placements` of one level (trees `0..geo` are the sets', then the
    /// groups'), the tree over their boxes, and what the level's record says of them.
    fn build_level<J: Join>(
        &self,
        placements: &[Placement],
        geo: usize,
        records: &[SceneTree],
        extents: &[Extent],
        join: &J,
    ) -> Result<BuiltLevel, BvhError> {
        let mut out = BuiltLevel {
            instances: Vec::with_capacity(placements.len()),
            tree: Bvh8::build(&[]),
            part_of: Vec::new(),
            unbounded: Vec::new(),
            levels: 0,
            paths: 0,
            mask: 0,
            slack: SLACK,
            extent: Extent::Empty,
        };
        let mut parts = Vec::with_capacity(placements.len());
        for (k, p) in placements.iter().enumerate() {
            let t = match p.target {
                Target::Set(s) => s as usize,
                Target::Group(g) => geo + g as usize,
            };
            let child = &records[t];
            // An empty tree is never hit; a tree whose boxes reach infinity (coordinates near
            // f32::MAX widened), a nearly singular transform or an unbounded group has no
            // finite box: every ray reaching the level visits it.
            let placed = match extents[t] {
                Extent::Empty => None,
                Extent::Box(b) => match p.transform.world_box_within(&b, child.slack) {
                    Some(w) => Some(w),
                    None => {
                        out.unbounded.push(index(k)?);
                        None
                    }
                },
                Extent::Unbounded => {
                    out.unbounded.push(index(k)?);
                    None
                }
            };
            out.extent = match (out.extent, placed, extents[t]) {
                (Extent::Unbounded, _, _) | (_, None, Extent::Box(_) | Extent::Unbounded) => {
                    Extent::Unbounded
                }
                (Extent::Empty, Some(w), _) => Extent::Box(w),
                (Extent::Box(a), Some(w), _) => Extent::Box(a.union(w)),
                (e, None, Extent::Empty) => e,
            };
            if let Some(world) = placed {
                parts.push(Part {
                    k: index(k)?,
                    world,
                    node: 0,
                });
            }
            out.instances.push(Instance {
                transform: p.transform,
                tree: index(t)?,
                mask: p.mask,
                path: out.paths,
            });
            out.paths = out
                .paths
                .checked_add(child.paths)
                .ok_or(BvhError::TooManyPrims(usize::MAX))?;
            out.levels = out.levels.max(child.levels);
            out.mask |= p.mask;
        }
        open_parts(&mut parts, |k| {
            let p = &placements[k as usize];
            let Target::Set(t) = p.target else {
                return None;
            };
            let r = &records[t as usize];
            let nodes = &self.kinds[r.kind as usize].nodes;
            let first = r.first_node as usize;
            Some((
                &nodes[first..first + r.nodes as usize],
                &p.transform,
                r.slack,
            ))
        });
        let boxes: Vec<InstanceBox> = parts
            .iter()
            .map(|p| InstanceBox {
                lo: p.world.lo,
                hi: p.world.hi,
                node: p.node,
            })
            .collect();
        out.tree = Bvh8::try_build_on(&boxes, join)?;
        out.part_of = parts.iter().map(|p| p.k).collect();
        out.slack = super::origin_slack(&out.instances, records);
        Ok(out)
    }

    /// Builds the trees of the sets no tree holds yet, then each group's tree and the world's
    /// top level over their instances' boxes ([`Transform::world_box_within`]), overlapping
    /// instances of trees that span much of their level entered by parts ([`InstanceBox`]); the instances
    /// without one (nearly singular, boxes that reach infinity, groups holding such) go on their
    /// level's unbounded list (every ray reaching the level visits them), those of empty trees
    /// nowhere.
    ///
    /// # Errors
    /// As [`Scene::commit_on`].
    pub fn commit(&mut self) -> Result<(), BvhError> {
        self.commit_on(&Sequential)
    }

    /// Whether the scene can be traced: nothing changed since the last [`Scene::commit`].
    pub fn is_committed(&self) -> bool {
        self.committed
    }

    /// The scene as borrowed slices, for tracing: constant time and no validation, but not free
    /// (a few dozen slice bounds and the world's level assembled), so a loop over rays takes it
    /// once, outside the loop (or keeps a `Tracer` made from it, in `octoray::scene`).
    ///
    /// # Panics
    /// When instances or geometries changed since the last [`Scene::commit`].
    #[track_caller]
    pub fn as_ref(&self) -> SceneRef<'_, T, S> {
        assert!(
            self.committed,
            "octoray Scene::as_ref: the scene changed since its last commit"
        );
        let parts = self.slices();
        let (nodes, blocks) = self.world_top;
        let roots = self.world.len();
        let world = Level {
            top: Bvh8Ref::trusted(
                &parts.top.nodes[..nodes],
                &parts.top.blocks[..blocks * <InstanceBox as Primitive>::WORDS],
                &parts.top.ids[..blocks * BLOCK],
                roots as u32,
            ),
            first: 0,
            instances: &parts.instances[..roots],
            unbounded: &parts.unbounded[..self.world_unbounded],
            slack: self.origin_slack,
            mask: u32::MAX,
        };
        SceneRef::built(parts, world)
    }

    /// The slices (to store the scene; [`SceneRef::new`] reads them back).
    ///
    /// # Panics
    /// When instances or geometries changed since the last [`Scene::commit`] (the top level
    /// would be stale), as [`Scene::as_ref`].
    #[track_caller]
    pub fn parts(&self) -> SceneParts<'_> {
        assert!(
            self.committed,
            "octoray Scene::parts: the scene changed since its last commit"
        );
        self.slices()
    }

    /// The slices as they are.
    fn slices(&self) -> SceneParts<'_> {
        SceneParts {
            triangles: self.kinds[TRIANGLES as usize].parts(),
            spheres: self.kinds[SPHERES as usize].parts(),
            geometries: &self.geoms,
            trees: &self.stored_trees,
            members: &self.members,
            instances: &self.instances,
            top: self.top.parts(),
            unbounded: &self.unbounded,
        }
    }

    /// The geometries.
    pub fn geometries(&self) -> &[Geometry] {
        &self.geoms
    }

    /// The instances as last committed (empty before the first [`Scene::commit`]): the
    /// world's, in the order added (the indices [`Scene::add_instance`] returned), then each
    /// group's.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }
}
