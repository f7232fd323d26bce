//! A scene with its tiers and lane width chosen once: [`Tracer`].

use super::instances::Trace;
use super::masks::RayMasks;
use crate::tree::point::Place;
use crate::tree::{AllHits, PointHit};
use core::marker::PhantomData;
use octoray_core::glam::Vec3;
use octoray_core::hit::{Hit, HitFilter};
#[cfg(feature = "triangle")]
use octoray_core::kernels::ExactCrossing;
use octoray_core::kernels::Kernel;
use octoray_core::kernels::{MeetsBox, NearestPoint};
use octoray_core::lanes::Lanes;
use octoray_core::prim::{Ray, RayLanes};
use octoray_core::query::ClosestHit;
use octoray_core::scene::SceneRef;

/// A scene's queries with the lane width `L`, the triangle tier `KT` and the sphere tier `KS`
/// fixed once, so that each call names none of them: the [`Trace`] methods of a [`SceneRef`],
/// with the same answers and panics.
///
/// `Copy` and as cheap to keep as the `SceneRef` it holds: make one per frame (or per committed
/// scene) and trace every ray through it.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))] {
/// use octoray_core::glam::Vec3;
/// use octoray_core::kernels::{StableSphere, Watertight};
/// use octoray_core::prim::{PackedSphere, Ray, VertexTriangle};
/// use octoray_packet::f32x8;
/// use octoray_packet::scene::{Scene, Tracer, Transform};
///
/// let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
/// let ball = scene.add_spheres(&[PackedSphere::new(Vec3::ZERO, 1.0)])?;
/// scene.add_instance(&[ball], Transform::IDENTITY, !0);
/// scene.commit()?;
/// let tracer = Tracer::<f32x8, Watertight, StableSphere>::new(scene.as_ref());
/// let hit = tracer.closest_ray(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z), !0);
/// assert_eq!(hit.map(|h| h.t), Some(4.0));
/// # }
/// # Ok::<(), octoray_core::bvh::BvhError>(())
/// ```
pub struct Tracer<'a, L: Lanes, KT: Kernel<L>, KS: Kernel<L>> {
    scene: SceneRef<'a, KT::Prim, KS::Prim>,
    tiers: Tiers<L, KT, KS>,
}

/// The width and tiers a [`Tracer`] names, held without owning any (`Send + Sync` whatever they
/// are).
type Tiers<L, KT, KS> = PhantomData<fn() -> (L, KT, KS)>;

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Clone for Tracer<'_, L, KT, KS> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Copy for Tracer<'_, L, KT, KS> {}

impl<L: Lanes, KT: Kernel<L>, KS: Kernel<L>> core::fmt::Debug for Tracer<'_, L, KT, KS> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Tracer")
            .field("lanes", &L::LANES)
            .field("instances", &self.scene.instances().len())
            .finish_non_exhaustive()
    }
}

impl<'a, L: Lanes, KT: Kernel<L>, KS: Kernel<L>> Tracer<'a, L, KT, KS> {
    /// The queries of `scene` at width `L` with tiers `KT` and `KS`.
    pub fn new(scene: SceneRef<'a, KT::Prim, KS::Prim>) -> Self {
        Self {
            scene,
            tiers: PhantomData,
        }
    }

    /// The scene traced.
    pub fn scene(&self) -> SceneRef<'a, KT::Prim, KS::Prim> {
        self.scene
    }

    /// [`Trace::closest_ray`].
    pub fn closest_ray(&self, ray: &Ray, mask: u32) -> Option<Hit> {
        self.scene.closest_ray::<L, KT, KS>(ray, mask)
    }

    /// [`Trace::closest_ray_with`].
    pub fn closest_ray_with<F: HitFilter>(
        &self,
        ray: &Ray,
        mask: u32,
        filter: &mut F,
    ) -> Option<Hit> {
        self.scene
            .closest_ray_with::<L, KT, KS, F>(ray, mask, filter)
    }

    /// [`Trace::occluded_ray`].
    pub fn occluded_ray(&self, ray: &Ray, mask: u32) -> bool {
        self.scene.occluded_ray::<L, KT, KS>(ray, mask)
    }

    /// [`Trace::occluded_ray_with`].
    pub fn occluded_ray_with<F: HitFilter>(&self, ray: &Ray, mask: u32, filter: &mut F) -> bool {
        self.scene
            .occluded_ray_with::<L, KT, KS, F>(ray, mask, filter)
    }

    /// [`Trace::all_hits_ray`].
    pub fn all_hits_ray(
        &self,
        ray: &Ray,
        mask: u32,
        after: Option<Hit>,
        out: &mut [Hit],
    ) -> AllHits {
        self.scene.all_hits_ray::<L, KT, KS>(ray, mask, after, out)
    }

    /// [`Trace::all_hits`].
    ///
    /// # Panics
    /// As [`Trace::all_hits`].
    #[track_caller]
    pub fn all_hits(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Hit],
        found: &mut [AllHits],
    ) {
        self.scene.all_hits::<L, KT, KS>(rays, mask, out, found);
    }

    /// [`Trace::crossings_ray`]: triangles by the crossing rule whatever `KT` is, spheres by
    /// `KS`.
    #[cfg(feature = "triangle")]
    pub fn crossings_ray(&self, ray: &Ray, mask: u32) -> u32
    where
        ExactCrossing: Kernel<L, Prim = KT::Prim>,
    {
        self.scene.crossings_ray::<L, KS>(ray, mask)
    }

    /// [`Trace::contains`].
    #[cfg(feature = "triangle")]
    pub fn contains(&self, point: Vec3, mask: u32) -> bool
    where
        ExactCrossing: Kernel<L, Prim = KT::Prim>,
    {
        self.scene.contains::<L, KS>(point, mask)
    }

    /// [`Trace::signed_distance`].
    #[cfg(feature = "triangle")]
    pub fn signed_distance(&self, point: Vec3, mask: u32) -> f32
    where
        ExactCrossing: Kernel<L, Prim = KT::Prim>,
        KT::Prim: NearestPoint,
        KS::Prim: NearestPoint,
    {
        self.scene.signed_distance::<L, KS>(point, mask)
    }

    /// [`Trace::overlapping`].
    pub fn overlapping(
        &self,
        lo: Vec3,
        hi: Vec3,
        mask: u32,
        after: Option<Place>,
        out: &mut [Place],
    ) -> AllHits
    where
        KT::Prim: MeetsBox,
        KS::Prim: MeetsBox,
    {
        self.scene.overlapping(lo, hi, mask, after, out)
    }

    /// [`Trace::closest_point`].
    pub fn closest_point(&self, point: Vec3, max_dist: f32, mask: u32) -> Option<PointHit>
    where
        KT::Prim: NearestPoint,
        KS::Prim: NearestPoint,
    {
        self.scene.closest_point(point, max_dist, mask)
    }

    /// [`Trace::nearest_within`].
    pub fn nearest_within(
        &self,
        point: Vec3,
        radius: f32,
        mask: u32,
        out: &mut [PointHit],
    ) -> AllHits
    where
        KT::Prim: NearestPoint,
        KS::Prim: NearestPoint,
    {
        self.scene.nearest_within(point, radius, mask, out)
    }

    /// [`Trace::closest_packet`].
    ///
    /// # Panics
    /// As [`Trace::closest_packet`].
    #[track_caller]
    pub fn closest_packet(&self, rays: &RayLanes<L>, mask: impl RayMasks) -> ClosestHit<L> {
        self.scene.closest_packet::<L, KT, KS>(rays, mask)
    }

    /// [`Trace::closest_packet_with`].
    ///
    /// # Panics
    /// As [`Trace::closest_packet`].
    #[track_caller]
    pub fn closest_packet_with<F: HitFilter>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> ClosestHit<L> {
        self.scene
            .closest_packet_with::<L, KT, KS, F>(rays, mask, filter)
    }

    /// [`Trace::occluded_packet`].
    ///
    /// # Panics
    /// As [`Trace::occluded_packet`].
    #[track_caller]
    pub fn occluded_packet(&self, rays: &RayLanes<L>, mask: impl RayMasks) -> L::Mask {
        self.scene.occluded_packet::<L, KT, KS>(rays, mask)
    }

    /// [`Trace::occluded_packet_with`].
    ///
    /// # Panics
    /// As [`Trace::occluded_packet`].
    #[track_caller]
    pub fn occluded_packet_with<F: HitFilter>(
        &self,
        rays: &RayLanes<L>,
        mask: impl RayMasks,
        filter: &mut F,
    ) -> L::Mask {
        self.scene
            .occluded_packet_with::<L, KT, KS, F>(rays, mask, filter)
    }

    /// [`Trace::closest`].
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    pub fn closest(&self, rays: &[Ray], mask: impl RayMasks, out: &mut [Option<Hit>]) {
        self.scene.closest::<L, KT, KS>(rays, mask, out);
    }

    /// [`Trace::closest_with`].
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    pub fn closest_with<F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [Option<Hit>],
        filter: &mut F,
    ) {
        self.scene
            .closest_with::<L, KT, KS, F>(rays, mask, out, filter);
    }

    /// [`Trace::occluded`].
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    pub fn occluded(&self, rays: &[Ray], mask: impl RayMasks, out: &mut [bool]) {
        self.scene.occluded::<L, KT, KS>(rays, mask, out);
    }

    /// [`Trace::occluded_with`].
    ///
    /// # Panics
    /// As [`Trace::closest`].
    #[track_caller]
    pub fn occluded_with<F: HitFilter>(
        &self,
        rays: &[Ray],
        mask: impl RayMasks,
        out: &mut [bool],
        filter: &mut F,
    ) {
        self.scene
            .occluded_with::<L, KT, KS, F>(rays, mask, out, filter);
    }
}
