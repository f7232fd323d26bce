//! The scene's walks: the top-level tree over instances, whose leaves carry the ray into each
//! instance's object space and walk its geometry's tree ([`Instances`], a [`Leaf`]).

use super::enter::{enter, Entered, Geometries};
use super::masks::{check_masks, Chunk, RayMasks};
use super::points::scene_points;
use super::region::scene_boxes;
use crate::tree::all_hits::{in_chunks, AllHits, Collect};
use crate::tree::batch::{closest_slice, occluded_slice};
use crate::tree::epilog::UNPLACED;
use crate::tree::epilog::{bound, Best, PacketBest};
use crate::tree::leaf::{Leaf, Members};
use crate::tree::packet::{packet_result, packet_walk, run_packet};
use crate::tree::point::{Best as PointBest, KNearest, Place, PointHit};
use crate::tree::single::trace_single;
use crate::tree::single::{run_prepared, run_single, Prepared};
use crate::tree::slab::BoxRay;
#[cfg(feature = "triangle")]
use crate::tree::{
    all_hits::each_hit,
    solid::{CAST, PAGE},
};
use arrayvec::ArrayVec;
use core::cell::OnceCell;
use octoray_core::bvh::Bvh8Ref;
use octoray_core::glam::Vec3;
use octoray_core::hit::{AcceptAll, Hit, HitFilter};
#[cfg(feature = "triangle")]
use octoray_core::kernels::ExactCrossing;
use octoray_core::kernels::Kernel;
use octoray_core::kernels::{MeetsBox, NearestPoint};
use octoray_core::lanes::{LaneMask, Lanes, MAX_LANES};
use octoray_core::prim::{Ray, RayLanes};
use octoray_core::query::ClosestHit;
use octoray_core::scene::{Instance, Level, SceneRef};
use wide::f32x8;

/// A level's leaves (the world's top-level tree, or a group's): its instances visited under
/// `mask` (the query's and the instances' above), their triangles tested with `KT` and their
/// spheres with `KS`, their hits numbered from instance path `path`.
struct Instances<'s, 'a, L: Lanes, KT: Kernel<L>, KS: Kernel<L>> {
    scene: &'s SceneRef<'a, KT::Prim, KS::Prim>,
    level: Level<'a>,
    mask: u32,
    path: u32,
}

impl<'s, 'a, L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Instances<'s, 'a, L, KT, KS> {
    /// The world's level of `scene` under the query's `mask`.
    fn world(scene: &'s SceneRef<'a, KT::Prim, KS::Prim>, mask: u32) -> Self {
        Self {
            scene,
            level: scene.world(),
            mask,
            path: 0,
        }
    }

    /// Instance `inst` under this level's mask and path ([`enter`]).
    #[cfg_attr(not(debug_assertions), inline(always))]
    #[allow(clippy::type_complexity)]
    fn enter(&self, inst: u32) -> Option<(&'a Instance, Entered<'a, KT::Prim, KS::Prim>)> {
        enter(self.scene, self.mask, self.path, inst)
    }

    /// The level below a group instance.
    fn below(&self, level: Level<'a>, mask: u32, path: u32) -> Self {
        Self {
            scene: self.scene,
            level,
            mask,
            path,
        }
    }

    /// One ray (in this level's space) through the part of instance `inst` that starts at
    /// `node` of its tree; a tree of triangles placed by the identity with the level's ray
    /// prepared once (`unmoved`). A call of its own, shared by the level's leaves, its unbounded
    /// instances and a lone world instance: inlined, each would carry its own copies of the
    /// trees' walks.
    #[inline(never)]
    fn single_instance<F: HitFilter, const ANY: bool>(
        &self,
        (inst, node): (u32, u32),
        world: &Ray,
        unmoved: &Unmoved<L, KT>,
        best: &mut Option<Best<L::Scalar>>,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let Some((i, entered)) = self.enter(inst) else {
            return false;
        };
        if let (Entered::Tree(Geometries::Triangles(b), place), true) =
            (&entered, i.transform.is_identity())
        {
            // The identity keeps the ray's bits: the level's ray, prepared once.
            let Some(p) = unmoved.get_or_init(|| Prepared::new(world)) else {
                return false;
            };
            let (b, place) = (*b, *place);
            return if place.2.members.is_empty() {
                run_prepared::<L, KT, F, ANY, false>(b, place, node, p, best, filter, ray_id)
            } else {
                run_prepared::<L, KT, F, ANY, true>(b, place, node, p, best, filter, ray_id)
            };
        }
        let ray = i.transform.apply(world);
        match entered {
            Entered::Tree(tree, place) => visit::<L, KT, KS, _>(
                tree,
                place,
                node,
                SingleWalk::<L, F, ANY> {
                    ray: &ray,
                    best,
                    filter,
                    ray_id,
                },
            ),
            Entered::Group(level, mask, path) => self
                .below(level, mask, path)
                .single_group::<F, ANY>(&ray, best, filter, ray_id),
        }
    }

    /// One ray (in this level's space) through the level: its tree, then its unbounded
    /// instances. Not inlined: a group's walk calls it again one level down.
    #[inline(never)]
    fn single_group<F: HitFilter, const ANY: bool>(
        &self,
        ray: &Ray,
        best: &mut Option<Best<L::Scalar>>,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        self.single_level::<F, ANY>(ray, best, filter, ray_id)
    }

    /// [`Instances::single_group`]'s body.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn single_level<F: HitFilter, const ANY: bool>(
        &self,
        ray: &Ray,
        best: &mut Option<Best<L::Scalar>>,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let br = BoxRay::with_slack(&RayLanes::<f32x8>::broadcast(ray), self.level.slack);
        // A ray that is not valid in one space is not valid in the next (a zero direction stays
        // zero, a non-finite component non-finite or NaN).
        if br.valid.none() {
            return false;
        }
        let top = self.level.top;
        let unmoved = Unmoved::new();
        if !top.nodes().is_empty()
            && trace_single::<L, _, F, ANY>(
                top.nodes(),
                self,
                &unmoved,
                &RayLanes::<L>::broadcast(ray),
                &br,
                (0, 0),
                best,
                filter,
                ray_id,
            )
            && ANY
        {
            return true;
        }
        for &inst in self.level.unbounded {
            if self.single_instance::<F, ANY>((inst, 0), ray, &unmoved, best, filter, ray_id) && ANY
            {
                return true;
            }
        }
        false
    }

    /// The lanes `live` of a packet (in this level's space) through the part of instance `inst`
    /// that starts at `node` of its tree. Inlined into the level's leaves, the hot path;
    /// [`Instances::packet_instance_outlined`] for the unbounded instances.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn packet_instance<F: HitFilter, const ANY: bool>(
        &self,
        (inst, node): (u32, u32),
        world: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let Some((i, entered)) = self.enter(inst) else {
            return;
        };
        // Each lane carried as its single ray is (the same bits; the identity keeps them).
        let rays = if i.transform.is_identity() {
            RayLanes {
                active: live,
                ..*world
            }
        } else {
            let lanes: ArrayVec<Ray, MAX_LANES> = (0..L::LANES)
                .map(|k| i.transform.apply(&world.ray(k)))
                .collect();
            RayLanes {
                active: live,
                ..RayLanes::<L>::load(&lanes)
            }
        };
        match entered {
            Entered::Tree(tree, place) => visit::<L, KT, KS, _>(
                tree,
                place,
                node,
                PacketWalk::<L, F, ANY> {
                    rays: &rays,
                    best,
                    filter,
                    ray_base,
                },
            ),
            Entered::Group(level, mask, path) => self
                .below(level, mask, path)
                .packet_group::<F, ANY>(&rays, best, filter, ray_base),
        }
    }

    /// [`Instances::packet_instance`] as a call of its own: inlined into the loop over a level's
    /// unbounded instances too, it would carry a second copy of the trees' walks.
    #[inline(never)]
    fn packet_instance_outlined<F: HitFilter, const ANY: bool>(
        &self,
        part: (u32, u32),
        world: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        self.packet_instance::<F, ANY>(part, world, live, best, filter, ray_base);
    }

    /// A packet (in this level's space, its live lanes `rays.active`) through the level: its
    /// tree, then its unbounded instances. Not inlined, as [`Instances::single_group`].
    #[inline(never)]
    fn packet_group<F: HitFilter, const ANY: bool>(
        &self,
        rays: &RayLanes<L>,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        self.packet_level::<F, ANY>(rays, best, filter, ray_base);
    }

    /// [`Instances::packet_group`]'s body.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn packet_level<F: HitFilter, const ANY: bool>(
        &self,
        rays: &RayLanes<L>,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let br = BoxRay::with_slack(rays, self.level.slack);
        if br.valid.none() {
            return;
        }
        packet_walk::<L, _, F, ANY>(
            self.level.top.nodes(),
            self,
            &Unmoved::new(),
            rays,
            &br,
            0,
            best,
            filter,
            ray_base,
        );
        for &inst in self.level.unbounded {
            let live = if ANY { br.valid & !best.mask } else { br.valid };
            if live.none() {
                break;
            }
            self.packet_instance_outlined::<F, ANY>((inst, 0), rays, live, best, filter, ray_base);
        }
    }
}

/// A walk of one instance's tree from one of its nodes, at the kernel of the tree's kind and with or
/// without the per-hit member lookup of a tree of several geometries ([`visit`] picks them).
trait TreeWalk<L: Lanes> {
    /// What the walk answers.
    type Out;
    /// Walks `bvh` from `node`, its hits reported as `place` says.
    fn walk<K: Kernel<L>, const MANY: bool>(
        self,
        bvh: Bvh8Ref<'_, K::Prim>,
        place: (u32, u32, Members<'_>),
        node: u32,
    ) -> Self::Out;
}

/// `w` through `tree` from `node`: triangles with `KT`, spheres with `KS`, the member lookup
/// only in a tree of several geometries.
#[cfg_attr(not(debug_assertions), inline(always))]
fn visit<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, W: TreeWalk<L>>(
    tree: Geometries<'_, KT::Prim, KS::Prim>,
    place: (u32, u32, Members<'_>),
    node: u32,
    w: W,
) -> W::Out {
    let many = !place.2.members.is_empty();
    match (tree, many) {
        (Geometries::Triangles(b), false) => w.walk::<KT, false>(b, place, node),
        (Geometries::Triangles(b), true) => w.walk::<KT, true>(b, place, node),
        (Geometries::Spheres(b), false) => w.walk::<KS, false>(b, place, node),
        (Geometries::Spheres(b), true) => w.walk::<KS, true>(b, place, node),
    }
}

/// One ray through a tree ([`run_single`]).
struct SingleWalk<'r, L: Lanes, F, const ANY: bool> {
    ray: &'r Ray,
    best: &'r mut Option<Best<L::Scalar>>,
    filter: &'r mut F,
    ray_id: u32,
}

impl<L: Lanes, F: HitFilter, const ANY: bool> TreeWalk<L> for SingleWalk<'_, L, F, ANY> {
    type Out = bool;
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn walk<K: Kernel<L>, const MANY: bool>(
        self,
        bvh: Bvh8Ref<'_, K::Prim>,
        place: (u32, u32, Members<'_>),
        node: u32,
    ) -> bool {
        run_single::<L, K, F, ANY, MANY>(
            bvh,
            place,
            node,
            self.ray,
            self.best,
            self.filter,
            self.ray_id,
        )
    }
}

/// A packet through a tree ([`run_packet`]).
struct PacketWalk<'r, L: Lanes, F, const ANY: bool> {
    rays: &'r RayLanes<L>,
    best: &'r mut PacketBest<L>,
    filter: &'r mut F,
    ray_base: u32,
}

impl<L: Lanes, F: HitFilter, const ANY: bool> TreeWalk<L> for PacketWalk<'_, L, F, ANY> {
    type Out = ();
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn walk<K: Kernel<L>, const MANY: bool>(
        self,
        bvh: Bvh8Ref<'_, K::Prim>,
        place: (u32, u32, Members<'_>),
        node: u32,
    ) {
        run_packet::<L, K, F, ANY, MANY>(
            bvh,
            place,
            node,
            self.rays,
            self.best,
            self.filter,
            self.ray_base,
        );
    }
}

/// A level's ray prepared once for the trees of triangles its instances place by the identity
/// (`None` inside: not valid), made at the first such entry.
type Unmoved<L, KT> = OnceCell<Option<Prepared<L, KT>>>;

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Leaf<L> for Instances<'_, '_, L, KT, KS> {
    type Pre = Unmoved<L, KT>;

    #[cfg_attr(not(debug_assertions), inline(always))]
    fn prepare(&self, _: &RayLanes<L>) -> Self::Pre {
        OnceCell::new()
    }

    fn single<F: HitFilter, const ANY: bool>(
        &self,
        unmoved: &Self::Pre,
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        t_bound: &mut L::Scalar,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let world = rl.ray(0);
        for slot in first..first + count {
            let Some(part) = self.level.part(slot) else {
                continue;
            };
            if self.single_instance::<F, ANY>(part, &world, unmoved, best, filter, ray_id) && ANY {
                return true;
            }
        }
        *t_bound = bound(rl.t_max.lane(0), best);
        false
    }

    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        _: &Self::Pre,
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        for slot in first..first + count {
            let Some(part) = self.level.part(slot) else {
                continue;
            };
            let live = if ANY { live & !best.mask } else { live };
            if live.none() {
                return;
            }
            self.packet_instance::<F, ANY>(part, rays, live, best, filter, ray_base);
        }
    }
}

/// The members of the tree at the end of instance path `path`, to find hits' geometries after
/// the walk.
fn members_of<'a, T, S>(scene: &SceneRef<'a, T, S>, path: u32) -> Members<'a>
where
    T: octoray_core::prim::Primitive,
    S: octoray_core::prim::Primitive,
{
    let members = scene
        .leaf_instance(path)
        .and_then(|k| scene.instances().get(k as usize))
        .map_or(&[][..], |i| scene.members(i.tree));
    Members {
        members,
        geoms: scene.geometries(),
        mask: u32::MAX,
        all_admitted: true,
    }
}

/// The best hit with its geometry found, if the walk left that for later.
fn placed<T, S, X: octoray_core::lanes::Scalar>(
    scene: &SceneRef<'_, T, S>,
    mut b: Best<X>,
) -> Best<X>
where
    T: octoray_core::prim::Primitive,
    S: octoray_core::prim::Primitive,
{
    if b.geom == UNPLACED {
        (b.geom, b.prim) = members_of(scene, b.inst).place(b.id).unwrap_or((0, b.id));
    }
    b
}

/// The packet's best hits with their geometries found, where the walk left that for later
/// (lanes of one instance, the usual case, share one lookup of its members).
fn placed_packet<L: Lanes, T, S>(scene: &SceneRef<'_, T, S>, b: &mut PacketBest<L>)
where
    T: octoray_core::prim::Primitive,
    S: octoray_core::prim::Primitive,
{
    let mut m = b.mask.bitmask();
    let mut cached: Option<(u32, Members<'_>)> = None;
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        if L::index_lane(b.geom, i) != UNPLACED {
            continue;
        }
        let inst = L::index_lane(b.inst, i);
        let members = match cached {
            Some((k, members)) if k == inst => members,
            _ => {
                let members = members_of(scene, inst);
                cached = Some((inst, members));
                members
            }
        };
        let id = L::index_lane(b.id, i);
        let (g, p) = members.place(id).unwrap_or((0, id));
        let lane = L::mask_from_bits(1 << i);
        b.geom = L::select_index(lane, L::splat_index(g), b.geom);
        b.prim = L::select_index(lane, L::splat_index(p), b.prim);
    }
}

/// One world ray through the scene.
fn scene_single<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: &SceneRef<'_, KT::Prim, KS::Prim>,
    ray: &Ray,
    mask: u32,
    filter: &mut F,
    ray_id: u32,
) -> (bool, Option<Best<L::Scalar>>) {
    let (any, best) = walk_single::<L, KT, KS, F, ANY>(scene, ray, mask, filter, ray_id);
    (any, best.map(|b| placed(scene, b)))
}

/// [`scene_single`]'s walk (geometries possibly left to find).
fn walk_single<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: &SceneRef<'_, KT::Prim, KS::Prim>,
    ray: &Ray,
    mask: u32,
    filter: &mut F,
    ray_id: u32,
) -> (bool, Option<Best<L::Scalar>>) {
    let mut best = None;
    let leaf = Instances::<L, KT, KS>::world(scene, mask);
    let any = if scene.world().instances.len() == 1 {
        // One world instance (a renderer's static world): no top level to walk; its tree's
        // root test is the only box test it needs.
        let unmoved = Unmoved::new();
        leaf.single_instance::<F, ANY>((0, 0), ray, &unmoved, &mut best, filter, ray_id)
    } else {
        leaf.single_level::<F, ANY>(ray, &mut best, filter, ray_id)
    };
    (any, best)
}

/// A world packet through the scene, lane `k` under mask `masks.at(ray_base + k)`: one walk
/// per distinct mask among the live lanes (one when they share it).
fn scene_packet<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: &SceneRef<'_, KT::Prim, KS::Prim>,
    rays: &RayLanes<L>,
    masks: impl RayMasks,
    filter: &mut F,
    ray_base: u32,
) -> PacketBest<L> {
    let mut best = PacketBest::new(rays.t_max);
    if let Some(mask) = masks.uniform() {
        walk_packet::<L, KT, KS, F, ANY>(scene, rays, mask, filter, ray_base, &mut best);
    } else {
        let base = ray_base as usize;
        let mut left = rays.active.bitmask();
        while left != 0 {
            let mask = masks.at(base + left.trailing_zeros() as usize);
            let mut same = left;
            for k in 0..L::LANES {
                if masks.at(base + k) != mask {
                    same &= !(1 << k);
                }
            }
            let lanes = RayLanes {
                active: rays.active & L::mask_from_bits(same),
                ..*rays
            };
            walk_packet::<L, KT, KS, F, ANY>(scene, &lanes, mask, filter, ray_base, &mut best);
            left &= !same;
        }
    }
    if !ANY && best.unplaced {
        placed_packet(scene, &mut best);
    }
    best
}

/// [`scene_packet`]'s walk (geometries possibly left to find).
fn walk_packet<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: &SceneRef<'_, KT::Prim, KS::Prim>,
    rays: &RayLanes<L>,
    mask: u32,
    filter: &mut F,
    ray_base: u32,
    best: &mut PacketBest<L>,
) {
    let leaf = Instances::<L, KT, KS>::world(scene, mask);
    if scene.world().instances.len() == 1 {
        // As in `scene_single`.
        leaf.packet_instance::<F, ANY>((0, 0), rays, rays.active, best, filter, ray_base);
    } else {
        leaf.packet_level::<F, ANY>(rays, best, filter, ray_base);
    }
}

/// The queries of a scene ([`SceneRef`]): closest hit and occlusion of one ray, a packet or a
/// slice of rays, triangles tested with kernel `KT` and spheres with `KS` at lane width `L`.
///
/// `mask` is the query's mask: an instance is visited only when its mask, its geometry's mask
/// and `mask` share a bit (tested before its subtree is entered). Packets and slices take a
/// [`RayMasks`]: one `u32` for every ray, or a `&[u32]` with one per lane or ray (a packet's
/// lanes that share a mask are walked together, one walk per distinct mask). Every answer equals brute
/// force over the instanced primitives under the scene contract
/// ([`octoray_core::scene`]); the hit's `geom` and `inst` name where it lies. The `_with` forms
/// take a [`HitFilter`] that sees every candidate with its geometry and instance.
pub trait Trace<T, S> {
    /// Closest hit of one ray.
    fn closest_ray<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        ray: &Ray,
        mask: u32,
    ) -> Option<Hit>;
    /// [`Trace::closest_ray`] counting only the hits `filter` accepts (the candidate's `ray` is
    /// 0).
    fn closest_ray_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        ray: &Ray,
        mask: u32,
        filter: &mut F,
    ) -> Option<Hit>;
    /// Does one ray hit anything in `[t_min, t_max]`?
    fn occluded_ray<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        ray: &Ray,
        mask: u32,
    ) -> bool;
    /// [`Trace::occluded_ray`] counting only the hits `filter` accepts.
    fn occluded_ray_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        ray: &Ray,
        mask: u32,
        filter: &mut F,
    ) -> bool;
    /// Every hit of one ray in `[t_min, t_max]` under `mask`, nearest first, into `out`, after
    /// the cursor `after`: as [`crate::tree::all_hits_ray`] (each primitive of each instance
    /// once, in [`crate::tree::hit_order`]; a full buffer's answer is not
    /// [`AllHits::complete`], and the next call continues after its last hit).
    fn all_hits_ray<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        ray: &Ray,
        mask: u32,
        after: Option<Hit>,
        out: &mut [Hit],
    ) -> AllHits {
        let mut collect = Collect::new(out, after);
        self.occluded_ray_with::<L, KT, KS, _>(ray, mask, &mut collect);
        collect.found()
    }
    /// How many triangles of the instances `mask` admits one ray crosses in `(t_min, t_max)`:
    /// as [`crate::tree::crossings_ray`] in each instance's object space (the crossing rule,
    /// [`ExactCrossing`], on the ray as the instance's map carries it there; each triangle of
    /// each instance once). Spheres are not counted (`KS` only walks them). For instances of
    /// closed meshes, each instance's crossings are even exactly when the ray's ends, as its
    /// map carries them (rounded to f32; bit for bit the world ray under the identity), are on
    /// the same side of its mesh.
    #[cfg(feature = "triangle")]
    fn crossings_ray<L: Lanes, KS: Kernel<L, Prim = S>>(&self, ray: &Ray, mask: u32) -> u32
    where
        ExactCrossing: Kernel<L, Prim = T>;
    /// Whether `point` is inside the instanced closed meshes `mask` admits: the parity of the
    /// crossings ([`Trace::crossings_ray`]) of a ray from it, so `true` inside an odd number of
    /// them (inside any one where they do not overlap). Exact for the point as each instance's
    /// map carries it into object space (rounded to f32; the point itself under the identity):
    /// a point on a surface is classified as [`crate::tree::contains`] does; a non-finite point
    /// is outside. Meaningful where every admitted triangle geometry is closed (check each with
    /// [`octoray_core::bvh::Solid::new`]); spheres do not count.
    #[cfg(feature = "triangle")]
    fn contains<L: Lanes, KS: Kernel<L, Prim = S>>(&self, point: Vec3, mask: u32) -> bool
    where
        ExactCrossing: Kernel<L, Prim = T>,
    {
        self.crossings_ray::<L, KS>(&Ray::new(point, CAST), mask) % 2 == 1
    }
    /// The signed distance from `point` to the admitted instances: the distance to the nearest
    /// primitive ([`Trace::closest_point`], spheres included), negative where
    /// [`Trace::contains`] says the point is inside (the sign exact for the point as each map
    /// carries it); `+inf` for a scene with nothing admitted, NaN for a non-finite point.
    #[cfg(feature = "triangle")]
    fn signed_distance<L: Lanes, KS: Kernel<L, Prim = S>>(&self, point: Vec3, mask: u32) -> f32
    where
        ExactCrossing: Kernel<L, Prim = T>,
        T: NearestPoint,
        S: NearestPoint,
    {
        if !point.is_finite() {
            return f32::NAN;
        }
        let d = self
            .closest_point(point, f32::INFINITY, mask)
            .map_or(f32::INFINITY, |h| h.dist);
        if self.contains::<L, KS>(point, mask) {
            -d
        } else {
            d
        }
    }
    /// The primitive nearest to `point` whose distance is at most `max_dist`, over every
    /// instance `mask` admits: as [`crate::tree::closest_point`] (the point on it, its
    /// barycentrics and distance; `None` when none is that near, for a non-finite point and for
    /// a NaN or negative `max_dist`), in world space, with the hit's `geom` and `inst` (its
    /// instance path) set. Ties in distance go to the lower (instance path, geometry,
    /// primitive).
    ///
    /// # Accuracy
    /// An instance's primitive is measured in world space: a triangle's corners carried there
    /// in f64 (the point and distance then within a few units of 2⁻⁵² of its extent), a sphere
    /// as the ellipsoid it becomes ([`octoray_core::kernels::NearestPoint::nearest_point_mapped`]).
    /// Its tree is walked in object space with the radius stretched by the map's largest
    /// singular value, so no primitive that could be nearer is skipped. An instance whose map
    /// is singular has no world image and is left out.
    fn closest_point(&self, point: Vec3, max_dist: f32, mask: u32) -> Option<PointHit>
    where
        T: NearestPoint,
        S: NearestPoint;
    /// The primitives of the instances `mask` admits that meet the closed world box `[lo, hi]`,
    /// as [`crate::tree::overlapping`] answers on one tree: where each lies ([`Place`]), in
    /// ascending order, each once, the first `out.len()` after `after` (`None`: from the start);
    /// `complete` is false when more follow (call again with `after = Some(out[stored − 1])`).
    /// Each candidate is tested in world space: a triangle's corners carried there in f64, a
    /// sphere as the ellipsoid its instance makes of it
    /// ([`octoray_core::kernels::MeetsBox::meets_box_mapped`]); exact but for primitives that
    /// touch or miss the box by a few units of 2⁻⁵⁰ of its coordinates. The box is carried into
    /// each level's and instance's space conservatively (its corners mapped, then widened past
    /// the roundings), so no primitive that meets it is skipped. A box with a NaN corner or
    /// `lo > hi` on an axis meets nothing; an instance whose map is singular is left out.
    fn overlapping(
        &self,
        lo: Vec3,
        hi: Vec3,
        mask: u32,
        after: Option<Place>,
        out: &mut [Place],
    ) -> AllHits
    where
        T: MeetsBox,
        S: MeetsBox;
    /// The `out.len()` primitives nearest to `point` within `radius` over every instance `mask`
    /// admits, as [`crate::tree::nearest_within`] reports them (in order of `dist`, then
    /// instance path, geometry and primitive), measured as [`Trace::closest_point`] measures.
    fn nearest_within(&self, point: Vec3, radius: f32, mask: u32, out: &mut [PointHit]) -> AllHits
    where
        T: NearestPoint,
        S: NearestPoint;
    /// Every hit of each ray under its mask: ray `i`'s first `out.len() / rays.len()` hits in
    /// hit order into that run of `out` (`out[i·cap..(i + 1)·cap]`), its count and completeness
    /// into `found[i]`; as [`Trace::all_hits_ray`] ray by ray (continue a ray whose answer is
    /// incomplete with it and its cursor), traced as packets where neighbouring rays share a
    /// direction octant.
    ///
    /// # Panics
    /// When `found.len() != rays.len()`, `out.len()` is not a multiple of `rays.len()`, or
    /// `mask` is a slice of other than `rays.len()` masks.
    #[track_caller]
    fn all_hits<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Hit],
        found: &mut [AllHits],
    ) {
        check_masks("all_hits", mask, rays.len());
        in_chunks(rays, out, found, |first, chunk, occluded, collect| {
            let masks = Chunk {
                masks: mask,
                first,
                len: chunk.len(),
            };
            self.occluded_with::<L, KT, KS, _>(chunk, masks, occluded, collect);
        });
    }
    /// Closest hit per lane of a packet (lane by lane equal to [`Trace::closest_ray`] under the
    /// lane's mask).
    ///
    /// # Panics
    /// When `mask` is a slice of other than `L::LANES` masks.
    #[track_caller]
    fn closest_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
    ) -> ClosestHit<L>;
    /// [`Trace::closest_packet`] counting only the hits `filter` accepts (the candidate's `ray`
    /// is its lane).
    ///
    /// # Panics
    /// When `mask` is a slice of other than `L::LANES` masks.
    #[track_caller]
    fn closest_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> ClosestHit<L>;
    /// Lanes of a packet that hit anything.
    ///
    /// # Panics
    /// When `mask` is a slice of other than `L::LANES` masks.
    #[track_caller]
    fn occluded_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
    ) -> L::Mask;
    /// [`Trace::occluded_packet`] counting only the hits `filter` accepts.
    ///
    /// # Panics
    /// When `mask` is a slice of other than `L::LANES` masks.
    #[track_caller]
    fn occluded_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> L::Mask;
    /// Closest hit of every ray (`out[i]` for `rays[i]`), packets where a chunk of `L::LANES`
    /// rays shares a direction octant, single rays elsewhere (the same answers).
    ///
    /// # Panics
    /// When `out.len() != rays.len()`, `mask` is a slice of other than `rays.len()` masks, or
    /// `rays.len() > u32::MAX`.
    #[track_caller]
    fn closest<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Option<Hit>],
    ) {
        self.closest_with::<L, KT, KS, _>(rays, mask, out, &mut AcceptAll);
    }
    /// [`Trace::closest`] counting only the hits `filter` accepts (the candidate's `ray` is the
    /// ray's index).
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    fn closest_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Option<Hit>],
        filter: &mut F,
    );
    /// Occlusion of every ray, packets or single rays as [`Trace::closest`] picks them.
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    fn occluded<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [bool],
    ) {
        self.occluded_with::<L, KT, KS, _>(rays, mask, out, &mut AcceptAll);
    }
    /// [`Trace::occluded`] counting only the hits `filter` accepts.
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    fn occluded_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [bool],
        filter: &mut F,
    );
}

impl<T: octoray_core::prim::Primitive, S: octoray_core::prim::Primitive> Trace<T, S>
    for SceneRef<'_, T, S>
{
    fn closest_ray<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        ray: &Ray,
        mask: u32,
    ) -> Option<Hit> {
        self.closest_ray_with::<L, KT, KS, _>(ray, mask, &mut AcceptAll)
    }

    #[cfg(feature = "triangle")]
    fn crossings_ray<L: Lanes, KS: Kernel<L, Prim = S>>(&self, ray: &Ray, mask: u32) -> u32
    where
        ExactCrossing: Kernel<L, Prim = T>,
    {
        let geoms = self.geometries();
        let mut n = 0u32;
        each_hit::<PAGE>(
            |after, page| self.all_hits_ray::<L, ExactCrossing, KS>(ray, mask, after, page),
            |h| {
                let kind = geoms.get(h.geom as usize).map(|g| g.kind);
                n += u32::from(kind == Some(octoray_core::scene::TRIANGLES));
            },
        );
        n
    }

    fn closest_ray_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        ray: &Ray,
        mask: u32,
        filter: &mut F,
    ) -> Option<Hit> {
        scene_single::<L, KT, KS, F, false>(self, ray, mask, filter, 0)
            .1
            .map(|b| b.hit())
    }

    fn occluded_ray<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        ray: &Ray,
        mask: u32,
    ) -> bool {
        self.occluded_ray_with::<L, KT, KS, _>(ray, mask, &mut AcceptAll)
    }

    fn occluded_ray_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        ray: &Ray,
        mask: u32,
        filter: &mut F,
    ) -> bool {
        scene_single::<L, KT, KS, F, true>(self, ray, mask, filter, 0).0
    }

    fn overlapping(
        &self,
        lo: Vec3,
        hi: Vec3,
        mask: u32,
        after: Option<Place>,
        out: &mut [Place],
    ) -> AllHits
    where
        T: MeetsBox,
        S: MeetsBox,
    {
        scene_boxes(self, (lo, hi), mask, after, out)
    }

    fn closest_point(&self, point: Vec3, max_dist: f32, mask: u32) -> Option<PointHit>
    where
        T: NearestPoint,
        S: NearestPoint,
    {
        if max_dist.is_nan() || max_dist < 0.0 {
            return None;
        }
        let mut best = PointBest::within(max_dist);
        scene_points(self, point, mask, &mut best);
        best.hit()
    }

    fn nearest_within(&self, point: Vec3, radius: f32, mask: u32, out: &mut [PointHit]) -> AllHits
    where
        T: NearestPoint,
        S: NearestPoint,
    {
        let mut sink = KNearest::new(out, radius);
        if radius >= 0.0 {
            scene_points(self, point, mask, &mut sink);
        }
        sink.found()
    }

    #[track_caller]
    fn closest_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
    ) -> ClosestHit<L> {
        self.closest_packet_with::<L, KT, KS, _>(rays, mask, &mut AcceptAll)
    }

    #[track_caller]
    fn closest_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> ClosestHit<L> {
        check_masks("closest_packet", mask, L::LANES);
        packet_result(&scene_packet::<L, KT, KS, F, false>(
            self, rays, mask, filter, 0,
        ))
    }

    #[track_caller]
    fn occluded_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
    ) -> L::Mask {
        self.occluded_packet_with::<L, KT, KS, _>(rays, mask, &mut AcceptAll)
    }

    #[track_caller]
    fn occluded_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> L::Mask {
        check_masks("occluded_packet", mask, L::LANES);
        scene_packet::<L, KT, KS, F, true>(self, rays, mask, filter, 0).mask
    }

    #[track_caller]
    fn closest_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Option<Hit>],
        filter: &mut F,
    ) {
        check_masks("closest", mask, rays.len());
        closest_slice::<L, F>(
            rays,
            out,
            filter,
            |r, f, base| scene_packet::<L, KT, KS, F, false>(self, r, mask, f, base),
            |r, f, id| {
                let m = mask.at(id as usize);
                scene_single::<L, KT, KS, F, false>(self, r, m, f, id).1
            },
        );
    }

    #[track_caller]
    fn occluded_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [bool],
        filter: &mut F,
    ) {
        check_masks("occluded", mask, rays.len());
        occluded_slice::<L, F>(
            rays,
            out,
            filter,
            |r, f, base| scene_packet::<L, KT, KS, F, true>(self, r, mask, f, base).mask,
            |r, f, id| scene_single::<L, KT, KS, F, true>(self, r, mask.at(id as usize), f, id).0,
        );
    }
}
