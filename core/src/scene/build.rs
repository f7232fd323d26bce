//! The owned scene: geometries added one by one, instances placing sets of them, the trees and
//! the top level built on [`Scene::commit`].

use super::{
    Geometry, Instance, InstanceBox, Member, SceneParts, SceneRef, SceneTree, Transform, TreeParts,
    SPHERES, TRIANGLES,
};
use crate::bvh::{refit_parts, Bvh8, Bvh8Node, BvhError, Join, Sequential, SLACK};
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

/// An owned scene: geometries (triangle meshes in layout `T`, sphere sets in layout `S`), the
/// bottom-level trees over them, instances placing those trees, and the top-level tree.
///
/// Add geometries ([`Scene::add_triangles`], [`Scene::add_spheres`]) and place sets of them
/// ([`Scene::add_instance`]: one tree is built per distinct set, shared by every instance of
/// it; a renderer's static meshes go into one set, so one tree holds them all), then
/// [`Scene::commit`] (builds the new trees and the top level) before [`Scene::as_ref`]. After
/// moving instances ([`Scene::set_transform`]) or refitting a geometry
/// ([`Scene::refit_triangles`], [`Scene::refit_spheres`]: every tree holding it is refitted in
/// place), commit again: only the top level is rebuilt. The scene keeps a copy of every
/// geometry's primitives (for the builds and refits of the trees that share it).
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
    instances: Vec<Instance>,
    top: Bvh8<InstanceBox>,
    unbounded: Vec<u32>,
    origin_slack: f32,
    committed: bool,
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
            instances: Vec::new(),
            top: Bvh8::build(&[]),
            unbounded: Vec::new(),
            origin_slack: SLACK,
            committed: true,
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
        self.geoms
            .get_mut(geom as usize)
            .unwrap_or_else(|| panic!("octoray Scene: geometry {geom} of {n}"))
            .mask = mask;
        for (t, tree) in self.trees.iter_mut().enumerate() {
            if self.sets[t].contains(&geom) {
                tree.mask = self.sets[t]
                    .iter()
                    .fold(u32::MAX, |m, &g| m & self.geoms[g as usize].mask);
            }
        }
    }

    /// Places the geometries `geoms` (one kind; one tree over all of them, shared with every
    /// other instance of the same set) with `transform` (world → object;
    /// [`Transform::placing`] inverts a renderer's object → world matrix) and `mask`; returns
    /// the instance index.
    ///
    /// # Panics
    /// When `geoms` is empty, names a geometry the scene does not have, or mixes kinds; when the
    /// scene has `u32::MAX` instances.
    #[track_caller]
    pub fn add_instance(&mut self, geoms: &[u32], transform: Transform, mask: u32) -> u32 {
        let mut set = geoms.to_vec();
        set.sort_unstable();
        set.dedup();
        assert!(!set.is_empty(), "octoray Scene: an instance of no geometry");
        let kind = |g: u32| {
            self.geoms
                .get(g as usize)
                .unwrap_or_else(|| panic!("octoray Scene: geometry {g} of {}", self.geoms.len()))
                .kind
        };
        let k = kind(set[0]);
        assert!(
            set.iter().all(|&g| kind(g) == k),
            "octoray Scene: an instance places geometries of one kind"
        );
        assert!(
            self.instances.len() < u32::MAX as usize,
            "octoray Scene: too many instances"
        );
        let tree = match self.sets.iter().position(|s| *s == set) {
            Some(t) => t,
            None => {
                self.sets.push(set);
                self.sets.len() - 1
            }
        };
        self.instances.push(Instance {
            transform,
            tree: tree as u32,
            mask,
        });
        self.committed = false;
        self.instances.len() as u32 - 1
    }

    /// Moves instance `inst` (commit before tracing again).
    ///
    /// # Panics
    /// When `inst` is not an instance of the scene.
    #[track_caller]
    pub fn set_transform(&mut self, inst: u32, transform: Transform) {
        self.instance_mut(inst).transform = transform;
        self.committed = false;
    }

    /// Sets instance `inst`'s mask.
    ///
    /// # Panics
    /// When `inst` is not an instance of the scene.
    #[track_caller]
    pub fn set_instance_mask(&mut self, inst: u32, mask: u32) {
        self.instance_mut(inst).mask = mask;
    }

    #[track_caller]
    fn instance_mut(&mut self, inst: u32) -> &mut Instance {
        let n = self.instances.len();
        self.instances
            .get_mut(inst as usize)
            .unwrap_or_else(|| panic!("octoray Scene: instance {inst} of {n}"))
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
        let tree = Bvh8::try_build_with(prims, join)?;
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
        let g = *self
            .geoms
            .get(geom as usize)
            .unwrap_or_else(|| panic!("octoray Scene: geometry {geom} of {n}"));
        let len = match &new {
            Prims::Triangles(p) => (g.kind == TRIANGLES).then_some(p.len()),
            Prims::Spheres(p) => (g.kind == SPHERES).then_some(p.len()),
        };
        let len =
            len.unwrap_or_else(|| panic!("octoray Scene: geometry {geom} is of the other kind"));
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
    pub fn refit_triangles_with<J: Join>(
        &mut self,
        geom: u32,
        prims: &[T],
        join: &J,
    ) -> Result<(), BvhError> {
        self.refit(geom, Prims::Triangles(prims.to_vec()), join)
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
    /// When a tree or the scene's slices would outgrow `u32` indices.
    pub fn commit_with<J: Join>(&mut self, join: &J) -> Result<(), BvhError> {
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
        let mut unbounded = Vec::new();
        let boxes: Vec<InstanceBox> = self
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let t = inst.tree as usize;
                // An empty tree is never hit; a tree whose boxes reach infinity (coordinates
                // near f32::MAX widened) has no finite world box: every ray visits it.
                let world = if self.trees[t].nodes > 0 {
                    let w = inst.transform.world_box(&self.tree_boxes[t]);
                    if w.is_none() {
                        unbounded.push(i as u32);
                    }
                    w
                } else {
                    None
                };
                // A non-finite box leaves the instance out of the top tree.
                let w = world.unwrap_or(Aabb::EMPTY);
                InstanceBox { lo: w.lo, hi: w.hi }
            })
            .collect();
        self.top = Bvh8::try_build_with(&boxes, join)?;
        self.unbounded = unbounded;
        self.origin_slack = super::origin_slack(&self.instances);
        self.committed = true;
        Ok(())
    }

    /// Builds the trees of the sets no tree holds yet, then the top level over the instances'
    /// world boxes ([`Transform::world_box`]); the instances without one (nearly singular, or
    /// boxes that reach infinity) go on the unbounded list (every ray visits them), those of
    /// empty trees nowhere.
    ///
    /// # Panics
    /// When a tree or the scene's slices would outgrow `u32` indices (use
    /// [`Scene::commit_with`] for an error instead).
    #[track_caller]
    pub fn commit(&mut self) {
        if let Err(e) = self.commit_with(&Sequential) {
            panic!("octoray Scene::commit: {e}");
        }
    }

    /// Whether the scene can be traced: nothing changed since the last [`Scene::commit`].
    pub fn is_committed(&self) -> bool {
        self.committed
    }

    /// The scene as borrowed slices, for tracing.
    ///
    /// # Panics
    /// When instances or geometries changed since the last [`Scene::commit`].
    #[track_caller]
    pub fn as_ref(&self) -> SceneRef<'_, T, S> {
        assert!(
            self.committed,
            "octoray Scene::as_ref: the scene changed since its last commit"
        );
        SceneRef::built(self.parts(), self.top.as_ref(), self.origin_slack)
    }

    /// The slices (to store the scene; [`SceneRef::new`] reads them back). Call after
    /// [`Scene::commit`].
    pub fn parts(&self) -> SceneParts<'_> {
        SceneParts {
            triangles: self.kinds[TRIANGLES as usize].parts(),
            spheres: self.kinds[SPHERES as usize].parts(),
            geometries: &self.geoms,
            trees: &self.trees,
            members: &self.members,
            instances: &self.instances,
            top: TreeParts {
                nodes: self.top.nodes(),
                blocks: self.top.blocks(),
                ids: self.top.ids(),
            },
            unbounded: &self.unbounded,
        }
    }

    /// The geometries.
    pub fn geometries(&self) -> &[Geometry] {
        &self.geoms
    }

    /// The instances.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }
}
