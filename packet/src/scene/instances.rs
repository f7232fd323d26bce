//! The scene's walks: the top-level tree over instances, whose leaves carry the ray into each
//! instance's object space and walk its geometry's tree ([`Instances`], a [`Leaf`]).

use super::epilog::{Best, PacketBest};
use super::slab::BoxRay;
use super::walk::{
    closest_slice, occluded_slice, packet_result, packet_walk, run_packet, run_single,
    trace_single, Leaf,
};
use arrayvec::ArrayVec;
use octoray_core::hit::{AcceptAll, Hit, HitFilter};
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{LaneMask, Lanes, MAX_LANES};
use octoray_core::prim::{Ray, RayLanes};
use octoray_core::query::ClosestHit;
use octoray_core::scene::{GeomRef, SceneRef};
use wide::f32x8;

/// The top level's leaves: instances of `scene` visited under the query's `mask`, their
/// triangles tested with `KT` and their spheres with `KS`.
struct Instances<'a, L: Lanes, KT: Kernel<L>, KS: Kernel<L>> {
    scene: SceneRef<'a, KT::Prim, KS::Prim>,
    mask: u32,
}

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Instances<'_, L, KT, KS> {
    /// The instance's geometry and the ray's interval, when its mask admits the query.
    #[inline(always)]
    fn enter(&self, inst: u32) -> Option<(&octoray_core::scene::Instance, u32)> {
        let i = self.scene.instances().get(inst as usize)?;
        let g = self.scene.geometries().get(i.geom as usize)?;
        (i.mask & g.mask & self.mask != 0).then_some((i, i.geom))
    }

    /// One world ray through instance `inst`.
    #[inline(always)]
    fn single_instance<F: HitFilter, const ANY: bool>(
        &self,
        inst: u32,
        world: &Ray,
        best: &mut Option<Best<L::Scalar>>,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let Some((i, geom)) = self.enter(inst) else {
            return false;
        };
        let ray = i.transform.apply(world);
        match self.scene.geometry(geom) {
            Some(GeomRef::Triangles(b)) => {
                run_single::<L, KT, F, ANY>(b, (geom, inst), &ray, best, filter, ray_id)
            }
            Some(GeomRef::Spheres(b)) => {
                run_single::<L, KS, F, ANY>(b, (geom, inst), &ray, best, filter, ray_id)
            }
            None => false,
        }
    }

    /// The lanes `live` of a world packet through instance `inst`.
    #[inline(always)]
    fn packet_instance<F: HitFilter, const ANY: bool>(
        &self,
        inst: u32,
        world: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let Some((i, geom)) = self.enter(inst) else {
            return;
        };
        // Each lane carried as its single ray is (the same bits).
        let lanes: ArrayVec<Ray, MAX_LANES> = (0..L::LANES)
            .map(|k| i.transform.apply(&world.ray(k)))
            .collect();
        let mut rays = RayLanes::<L>::load(&lanes);
        rays.active = live;
        match self.scene.geometry(geom) {
            Some(GeomRef::Triangles(b)) => {
                run_packet::<L, KT, F, ANY>(b, (geom, inst), &rays, best, filter, ray_base)
            }
            Some(GeomRef::Spheres(b)) => {
                run_packet::<L, KS, F, ANY>(b, (geom, inst), &rays, best, filter, ray_base)
            }
            None => {}
        }
    }
}

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Leaf<L> for Instances<'_, L, KT, KS> {
    type Pre = ();

    #[inline(always)]
    fn prepare(&self, _: &RayLanes<L>) {}

    fn single<F: HitFilter, const ANY: bool>(
        &self,
        _: &(),
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let world = rl.ray(0);
        let ids = self.scene.top().ids();
        for &inst in &ids[first..first + count] {
            if self.single_instance::<F, ANY>(inst, &world, best, filter, ray_id) && ANY {
                return true;
            }
        }
        false
    }

    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        _: &(),
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let ids = self.scene.top().ids();
        for &inst in &ids[first..first + count] {
            let live = if ANY { live & !best.mask } else { live };
            if live.none() {
                return;
            }
            self.packet_instance::<F, ANY>(inst, rays, live, best, filter, ray_base);
        }
    }
}

/// One world ray through the scene.
fn scene_single<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: SceneRef<'_, KT::Prim, KS::Prim>,
    ray: &Ray,
    mask: u32,
    filter: &mut F,
    ray_id: u32,
) -> (bool, Option<Best<L::Scalar>>) {
    let mut best = None;
    let leaf = Instances::<L, KT, KS> { scene, mask };
    let rl = RayLanes::<L>::broadcast(ray);
    let br = BoxRay::with_slack(&RayLanes::<f32x8>::broadcast(ray), scene.origin_slack());
    // A ray that is not valid in the world is not valid in any object space (a zero direction
    // stays zero, a non-finite component non-finite or NaN).
    if br.valid.none() {
        return (false, best);
    }
    let top = scene.top();
    if !top.nodes().is_empty()
        && trace_single::<L, _, F, ANY>(
            top.nodes(),
            &leaf,
            &(),
            &rl,
            &br,
            (0, 0),
            &mut best,
            filter,
            ray_id,
        )
        && ANY
    {
        return (true, best);
    }
    for &inst in scene.unbounded() {
        if leaf.single_instance::<F, ANY>(inst, ray, &mut best, filter, ray_id) && ANY {
            return (true, best);
        }
    }
    (false, best)
}

/// A world packet through the scene.
fn scene_packet<L: Lanes, KT: Kernel<L>, KS: Kernel<L>, F: HitFilter, const ANY: bool>(
    scene: SceneRef<'_, KT::Prim, KS::Prim>,
    rays: &RayLanes<L>,
    mask: u32,
    filter: &mut F,
    ray_base: u32,
) -> PacketBest<L> {
    let mut best = PacketBest::new(rays.t_max);
    let leaf = Instances::<L, KT, KS> { scene, mask };
    let br = BoxRay::with_slack(rays, scene.origin_slack());
    if br.valid.none() {
        return best;
    }
    packet_walk::<L, _, F, ANY>(
        scene.top().nodes(),
        &leaf,
        &(),
        rays,
        &br,
        &mut best,
        filter,
        ray_base,
    );
    for &inst in scene.unbounded() {
        let live = if ANY { br.valid & !best.mask } else { br.valid };
        if live.none() {
            break;
        }
        leaf.packet_instance::<F, ANY>(inst, rays, live, &mut best, filter, ray_base);
    }
    best
}

/// The queries of a scene ([`SceneRef`]): closest hit and occlusion of one ray, a packet or a
/// slice of rays, triangles tested with kernel `KT` and spheres with `KS` at lane width `L`.
///
/// `mask` is the query's mask: an instance is visited only when its mask, its geometry's mask
/// and `mask` share a bit (tested before its subtree is entered). Every answer equals brute
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
    /// Closest hit per lane of a packet (lane by lane equal to [`Trace::closest_ray`]).
    fn closest_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> ClosestHit<L>;
    /// [`Trace::closest_packet`] counting only the hits `filter` accepts (the candidate's `ray`
    /// is its lane).
    fn closest_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
        filter: &mut F,
    ) -> ClosestHit<L>;
    /// Lanes of a packet that hit anything.
    fn occluded_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> L::Mask;
    /// [`Trace::occluded_packet`] counting only the hits `filter` accepts.
    fn occluded_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
        filter: &mut F,
    ) -> L::Mask;
    /// Closest hit of every ray (`out[i]` for `rays[i]`), packets where a chunk of `L::LANES`
    /// rays shares a direction octant, single rays elsewhere (the same answers).
    ///
    /// # Panics
    /// When `out.len() != rays.len()` or `rays.len() > u32::MAX`.
    #[track_caller]
    fn closest<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &[Ray],
        mask: u32,
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
        mask: u32,
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
        mask: u32,
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
        mask: u32,
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
        scene_single::<L, KT, KS, F, false>(*self, ray, mask, filter, 0)
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
        scene_single::<L, KT, KS, F, true>(*self, ray, mask, filter, 0).0
    }

    fn closest_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> ClosestHit<L> {
        self.closest_packet_with::<L, KT, KS, _>(rays, mask, &mut AcceptAll)
    }

    fn closest_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
        filter: &mut F,
    ) -> ClosestHit<L> {
        packet_result(&scene_packet::<L, KT, KS, F, false>(
            *self, rays, mask, filter, 0,
        ))
    }

    fn occluded_packet<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>>(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> L::Mask {
        self.occluded_packet_with::<L, KT, KS, _>(rays, mask, &mut AcceptAll)
    }

    fn occluded_packet_with<
        L: Lanes,
        KT: Kernel<L, Prim = T>,
        KS: Kernel<L, Prim = S>,
        F: HitFilter,
    >(
        &self,
        rays: &RayLanes<L>,
        mask: u32,
        filter: &mut F,
    ) -> L::Mask {
        scene_packet::<L, KT, KS, F, true>(*self, rays, mask, filter, 0).mask
    }

    #[track_caller]
    fn closest_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: u32,
        out: &mut [Option<Hit>],
        filter: &mut F,
    ) {
        closest_slice::<L, F>(
            rays,
            out,
            filter,
            |r, f, base| scene_packet::<L, KT, KS, F, false>(*self, r, mask, f, base),
            |r, f, id| scene_single::<L, KT, KS, F, false>(*self, r, mask, f, id).1,
        );
    }

    #[track_caller]
    fn occluded_with<L: Lanes, KT: Kernel<L, Prim = T>, KS: Kernel<L, Prim = S>, F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: u32,
        out: &mut [bool],
        filter: &mut F,
    ) {
        occluded_slice::<L, F>(
            rays,
            out,
            filter,
            |r, f, base| scene_packet::<L, KT, KS, F, true>(*self, r, mask, f, base).mask,
            |r, f, id| scene_single::<L, KT, KS, F, true>(*self, r, mask, f, id).0,
        );
    }
}
