//! Point queries on a scene: each level's tree walked by box distance in that level's space,
//! each instance's tree in its object space with the search radius stretched by the map, and
//! each candidate measured in world space (its primitive carried there in f64).

use super::enter::{enter, Entered, Geometries};
use crate::tree::leaf::Members;
use crate::tree::point::{cull_of, point_walk, Place, PointLeaves, PrimLeaves, Sink};
use octoray_core::bvh::Bvh8Ref;
use octoray_core::glam::Vec3;
use octoray_core::kernels::{Nearest, NearestPoint};
use octoray_core::lanes::{Lanes, V3};
use octoray_core::prim::{Affine64, Primitive};
use octoray_core::scene::{Level, SceneRef, Transform};
use wide::f32x8;

/// One space a walk passes through (the world, a group's, an instance's object space): the maps
/// between it and the world, and the query point in it.
#[derive(Clone, Copy)]
struct Space {
    /// This space → world.
    to_world: Affine64,
    /// World → this space.
    to_here: Affine64,
    /// The query point here, rounded to f32 (what the box tests read).
    q: V3<f32x8>,
    /// How far a world distance can stretch here, and the slack for the point's rounding (0 and
    /// 1 in the world: a world bound is used as it is).
    stretch: f64,
    slack: f64,
}

impl Space {
    /// The world, with the query point `p`.
    fn world(p: Vec3) -> Self {
        Self {
            to_world: Affine64::IDENTITY,
            to_here: Affine64::IDENTITY,
            q: V3::splat(p.to_array()),
            stretch: 1.0,
            slack: 0.0,
        }
    }

    /// The space an instance with transform `t` (from this space into its own) leads to, for
    /// the world point `p`; `None` when its map is singular (its primitives have no world
    /// image: such an instance is left out).
    fn enter(&self, t: &Transform, p: [f64; 3]) -> Option<Self> {
        let a = t.to_f64();
        let to_here = self.to_here.then(&a);
        let to_world = a.inverse()?.then(&self.to_world);
        let here = to_here.apply(p);
        if !here.iter().all(|x| x.is_finite()) {
            return None;
        }
        let stretch = to_here.stretch();
        // The point's rounding to f32 (half an ulp per coordinate, √3 of them, taken as 2),
        // and the f64 map's own (a few units of 2⁻⁵² of its terms, taken as 2⁻⁴⁰).
        let big = here.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let terms = stretch * p.iter().fold(0.0f64, |m, x| m.max(x.abs()))
            + to_here.t.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let slack = big / 8_388_608.0 + terms / 1_099_511_627_776.0;
        Some(Self {
            to_world,
            to_here,
            q: V3::splat(here.map(|x| x as f32)),
            stretch,
            slack,
        })
    }

    /// A world cull (an f32 bound on squared distance) in this space: its radius stretched,
    /// plus the slack.
    fn cull(&self, world: f32) -> f32 {
        if self.slack == 0.0 && self.stretch == 1.0 {
            return world;
        }
        let r = self.stretch * Lanes::sqrt(f64::from(world)) + self.slack;
        cull_of(r * r)
    }
}

/// A sink in an instance's space: its cull stretched, its candidates named by the instance
/// path, geometry and primitive before `inner` sees them.
struct Placed<'a, 'k, K> {
    inner: &'k mut K,
    space: &'k Space,
    /// The geometry of a one-geometry tree, the instance path and the members (or
    /// [`Members::ONE`]).
    geom: u32,
    path: u32,
    members: Members<'a>,
}

impl<K: Sink> Sink for Placed<'_, '_, K> {
    fn cull(&self) -> f32 {
        self.space.cull(self.inner.cull())
    }

    fn offer(&mut self, n: Nearest, at: Place) {
        let Some((geom, prim)) = self.members.locate(self.geom, at.prim) else {
            return;
        };
        let inst = self.path;
        self.inner.offer(n, Place { inst, geom, prim });
    }
}

/// A level's leaves (instances) for a point walk under `mask`, paths from `path`.
struct LevelLeaves<'s, 'a, 'k, T, S, K> {
    scene: &'s SceneRef<'a, T, S>,
    level: Level<'a>,
    mask: u32,
    path: u32,
    space: Space,
    p: [f64; 3],
    sink: &'k mut K,
}

impl<T: NearestPoint, S: NearestPoint, K: Sink> LevelLeaves<'_, '_, '_, T, S, K> {
    /// The level's tree, then its unbounded instances.
    fn walk(&mut self) {
        point_walk(self.level.top.nodes(), 0, self);
        for &inst in self.level.unbounded {
            self.instance((inst, 0));
        }
    }

    /// The part of instance `inst` of the level that starts at `node` of its tree, when the
    /// masks admit it and its map is invertible.
    fn instance(&mut self, (inst, node): (u32, u32)) {
        let Some((i, entered)) = enter(self.scene, self.mask, self.path, inst) else {
            return;
        };
        let Some(space) = self.space.enter(&i.transform, self.p) else {
            return;
        };
        match entered {
            Entered::Tree(Geometries::Triangles(b), place) => self.tree(b, place, node, &space),
            Entered::Tree(Geometries::Spheres(b), place) => self.tree(b, place, node, &space),
            Entered::Group(level, mask, path) => LevelLeaves {
                scene: self.scene,
                level,
                mask,
                path,
                space,
                p: self.p,
                sink: &mut *self.sink,
            }
            .walk(),
        }
    }

    /// An instance's tree `bvh` from `node`, in `space`.
    fn tree<P: NearestPoint>(
        &mut self,
        bvh: Bvh8Ref<'_, P>,
        (geom, path, members): (u32, u32, Members<'_>),
        node: u32,
        space: &Space,
    ) {
        let mut placed = Placed {
            inner: &mut *self.sink,
            space,
            geom,
            path,
            members,
        };
        let identity = space.to_world == Affine64::IDENTITY;
        let mut leaves = PrimLeaves {
            bvh,
            p: self.p,
            q: space.q,
            to_world: (!identity).then_some(&space.to_world),
            sink: &mut placed,
        };
        point_walk(bvh.nodes(), node, &mut leaves);
    }
}

impl<T: NearestPoint, S: NearestPoint, K: Sink> PointLeaves for LevelLeaves<'_, '_, '_, T, S, K> {
    fn point(&self) -> V3<f32x8> {
        self.space.q
    }

    fn cull(&self) -> f32 {
        self.space.cull(self.sink.cull())
    }

    fn leaf(&mut self, first: u32, count: u32) {
        let (first, count) = (first as usize, count as usize);
        for slot in first..first + count {
            if let Some(part) = self.level.part(slot) {
                self.instance(part);
            }
        }
    }
}

/// Offers `sink` every primitive of `scene` under `mask` that may be near enough to `point`.
pub(super) fn scene_points<T, S, K>(
    scene: &SceneRef<'_, T, S>,
    point: Vec3,
    mask: u32,
    sink: &mut K,
) where
    T: NearestPoint + Primitive,
    S: NearestPoint + Primitive,
    K: Sink,
{
    if !point.is_finite() {
        return;
    }
    LevelLeaves {
        scene,
        level: scene.world(),
        mask,
        path: 0,
        space: Space::world(point),
        p: point.to_array().map(f64::from),
        sink,
    }
    .walk();
}
