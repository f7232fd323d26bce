//! The owned scene: geometries added one by one (each built into its tree), instances placed,
//! the top level built on [`Scene::commit`].

use super::{
    Geometry, Instance, InstanceBox, SceneParts, SceneRef, Transform, TreeParts, SPHERES, TRIANGLES,
};
use crate::bvh::{refit_parts, Bvh8, Bvh8Node, BvhError, Join, Sequential};
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

/// An owned scene: geometries (triangle meshes in layout `T`, sphere sets in layout `S`),
/// instances, and the top-level tree.
///
/// Add geometries ([`Scene::add_triangles`], [`Scene::add_spheres`]), place them
/// ([`Scene::add_instance`]), then [`Scene::commit`] (builds the top level) before
/// [`Scene::as_ref`]. After moving instances ([`Scene::set_transform`]) or refitting a geometry
/// ([`Scene::refit_triangles`], [`Scene::refit_spheres`]), commit again: only the top level is
/// rebuilt.
#[derive(Clone, Debug)]
pub struct Scene<T, S> {
    kinds: [Trees; 2],
    geoms: Vec<Geometry>,
    /// Per geometry: the union of its root's boxes (its object box; empty for an empty one).
    boxes: Vec<Aabb>,
    /// Per geometry: whether its build left primitives out.
    skipped: Vec<bool>,
    instances: Vec<Instance>,
    top: Bvh8<InstanceBox>,
    unbounded: Vec<u32>,
    origin_slack: f32,
    committed: bool,
    _prim: core::marker::PhantomData<(T, S)>,
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

impl<T: Primitive + Sync, S: Primitive + Sync> Scene<T, S> {
    /// An empty scene (committed: it can be traced as it is).
    pub fn new() -> Self {
        Self {
            kinds: [Trees::default(), Trees::default()],
            geoms: Vec::new(),
            boxes: Vec::new(),
            skipped: Vec::new(),
            instances: Vec::new(),
            top: Bvh8::build(&[]),
            unbounded: Vec::new(),
            origin_slack: crate::bvh::SLACK,
            committed: true,
            _prim: core::marker::PhantomData,
        }
    }

    fn add<P: Primitive, J: Join>(
        &mut self,
        kind: u32,
        prims: &[P],
        join: &J,
    ) -> Result<u32, BvhError> {
        if self.geoms.len() >= u32::MAX as usize {
            return Err(BvhError::TooManyPrims(self.geoms.len()));
        }
        let tree = Bvh8::try_build_with(prims, join)?;
        let skipped = tree.stats().skipped > 0;
        let (nodes, blocks, ids) = tree.into_parts();
        let trees = &mut self.kinds[kind as usize];
        let count = |n: usize| u32::try_from(n).map_err(|_| BvhError::TooManyPrims(n));
        let geom = Geometry {
            kind,
            mask: u32::MAX,
            prims: count(prims.len())?,
            first_node: count(trees.nodes.len())?,
            nodes: count(nodes.len())?,
            first_block: count(trees.ids.len() / BLOCK)?,
            blocks: count(ids.len() / BLOCK)?,
        };
        count(trees.nodes.len() + nodes.len())?;
        count(trees.ids.len() / BLOCK + ids.len() / BLOCK)?;
        self.boxes.push(root_box(&nodes));
        trees.nodes.extend_from_slice(&nodes);
        trees.blocks.extend_from_slice(&blocks);
        trees.ids.extend_from_slice(&ids);
        self.skipped.push(skipped);
        self.geoms.push(geom);
        Ok(self.geoms.len() as u32 - 1)
    }

    /// Adds a triangle mesh (its tree built from `prims`, whose indices become its hits'
    /// `prim`); returns its geometry index. Its mask is all ones.
    ///
    /// # Errors
    /// As [`Bvh8::try_build`], and when the scene's slices would outgrow `u32` indices.
    pub fn add_triangles(&mut self, prims: &[T]) -> Result<u32, BvhError> {
        self.add(TRIANGLES, prims, &Sequential)
    }

    /// [`Scene::add_triangles`] built on `join`'s threads (the same tree).
    ///
    /// # Errors
    /// As [`Scene::add_triangles`].
    pub fn add_triangles_with<J: Join>(&mut self, prims: &[T], join: &J) -> Result<u32, BvhError> {
        self.add(TRIANGLES, prims, join)
    }

    /// Adds a set of spheres; returns its geometry index. As [`Scene::add_triangles`].
    ///
    /// # Errors
    /// As [`Scene::add_triangles`].
    pub fn add_spheres(&mut self, prims: &[S]) -> Result<u32, BvhError> {
        self.add(SPHERES, prims, &Sequential)
    }

    /// Sets geometry `geom`'s mask.
    ///
    /// # Panics
    /// When `geom` is not a geometry of the scene.
    #[track_caller]
    pub fn set_geometry_mask(&mut self, geom: u32, mask: u32) {
        self.geom_mut(geom).mask = mask;
    }

    #[track_caller]
    fn geom_mut(&mut self, geom: u32) -> &mut Geometry {
        let n = self.geoms.len();
        self.geoms
            .get_mut(geom as usize)
            .unwrap_or_else(|| panic!("octoray Scene: geometry {geom} of {n}"))
    }

    /// Places geometry `geom` with `transform` (world → object; [`Transform::placing`] inverts
    /// a renderer's object → world matrix) and `mask`; returns its instance index.
    ///
    /// # Panics
    /// When `geom` is not a geometry of the scene, or the scene has `u32::MAX` instances.
    #[track_caller]
    pub fn add_instance(&mut self, geom: u32, transform: Transform, mask: u32) -> u32 {
        self.geom_mut(geom);
        assert!(
            self.instances.len() < u32::MAX as usize,
            "octoray Scene: too many instances"
        );
        self.instances.push(Instance {
            transform,
            geom,
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
        let n = self.instances.len();
        self.instances
            .get_mut(inst as usize)
            .unwrap_or_else(|| panic!("octoray Scene: instance {inst} of {n}"))
            .transform = transform;
        self.committed = false;
    }

    /// Sets instance `inst`'s mask.
    ///
    /// # Panics
    /// When `inst` is not an instance of the scene.
    #[track_caller]
    pub fn set_instance_mask(&mut self, inst: u32, mask: u32) {
        let n = self.instances.len();
        self.instances
            .get_mut(inst as usize)
            .unwrap_or_else(|| panic!("octoray Scene: instance {inst} of {n}"))
            .mask = mask;
    }

    fn refit<P: Primitive + Sync, J: Join>(
        &mut self,
        kind: u32,
        geom: u32,
        prims: &[P],
        join: &J,
    ) -> Result<(), BvhError> {
        let g = *self.geom_mut(geom);
        assert!(
            g.kind == kind,
            "octoray Scene: geometry {geom} is of the other kind"
        );
        if prims.len() != g.prims as usize {
            return Err(BvhError::RefitLength {
                built: g.prims as usize,
                given: prims.len(),
            });
        }
        let trees = &mut self.kinds[kind as usize];
        let (n0, n1) = (g.first_node as usize, (g.first_node + g.nodes) as usize);
        let (b0, b1) = (g.first_block as usize, (g.first_block + g.blocks) as usize);
        let nodes = &mut trees.nodes[n0..n1];
        refit_parts(
            nodes,
            &mut trees.blocks[b0 * P::WORDS..b1 * P::WORDS],
            &trees.ids[b0 * BLOCK..b1 * BLOCK],
            prims,
            self.skipped[geom as usize],
            join,
        )?;
        self.boxes[geom as usize] = root_box(nodes);
        self.committed = false;
        Ok(())
    }

    /// Refits triangle geometry `geom` to `prims` after its vertices moved (same slice length
    /// and order): as [`Bvh8::refit`], in place (commit before tracing again).
    ///
    /// # Errors
    /// As [`Bvh8::refit`].
    ///
    /// # Panics
    /// When `geom` is not a triangle geometry of the scene.
    #[track_caller]
    pub fn refit_triangles(&mut self, geom: u32, prims: &[T]) -> Result<(), BvhError> {
        self.refit(TRIANGLES, geom, prims, &Sequential)
    }

    /// [`Scene::refit_triangles`] with the blocks rewritten on `join`'s threads (the same tree).
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
        self.refit(TRIANGLES, geom, prims, join)
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
        self.refit(SPHERES, geom, prims, &Sequential)
    }

    /// Builds the top level over the instances' world boxes ([`Transform::world_box`]); the
    /// instances without one go on the unbounded list (every ray visits them), those of empty
    /// geometries nowhere. Linear in the instances plus the top build (`O(n log n)`).
    pub fn commit(&mut self) {
        let mut unbounded = Vec::new();
        let boxes: Vec<InstanceBox> = self
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let obj = &self.boxes[inst.geom as usize];
                let world = if obj.is_finite() {
                    let w = inst.transform.world_box(obj);
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
        self.top = Bvh8::build(&boxes);
        self.unbounded = unbounded;
        self.origin_slack = super::origin_slack(&self.instances);
        self.committed = true;
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

    /// The slices (to store the scene; [`SceneRef::new`] reads them back).
    pub fn parts(&self) -> SceneParts<'_> {
        SceneParts {
            triangles: self.kinds[TRIANGLES as usize].parts(),
            spheres: self.kinds[SPHERES as usize].parts(),
            geometries: &self.geoms,
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
