//! The bodies of the trace calls: one ray, an array of rays and one 8- or 16-ray packet, each
//! written once for both questions (closest hit, occlusion) and dispatched over the scene's
//! layout and tier.
use octoray::f32x8;
use octoray::hit::Hit;
use octoray::kernels::{Exact, Kernel, MollerTrumbore, StableSphere, Watertight};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, VertexTriangle};
use octoray::scene::Trace;

use crate::{
    null_check, put, run, scene_ref, slice, slice_mut, OctorayHit, OctorayHits, OctorayPlace,
    OctorayPointHit, OctorayRay, OctorayRays, OctorayScene, OctorayStatus, OctorayTier, View,
};
use octoray::glam::Vec3;

/// Dispatches `$body` over the view's layout and the scene's tier: `$s` is the scene, `$KT`
/// the triangle kernel.
macro_rules! traced {
    ($scene:expr, $view:expr, |$s:ident, $KT:ident| $body:expr) => {
        match ($view, $scene.tier) {
            (View::Packed($s), _) => {
                type $KT = MollerTrumbore;
                $body
            }
            (View::Vertex($s), OctorayTier::Exact) => {
                type $KT = Exact;
                $body
            }
            (View::Vertex($s), _) => {
                type $KT = Watertight;
                $body
            }
        }
    };
}

/// What a trace call asks of each ray, and how C receives the answer.
pub(crate) trait Query {
    /// The answer for one ray.
    type Answer: Copy;
    /// What C receives for one ray.
    type Out: From<Self::Answer>;
    /// What C receives for an `N`-ray packet.
    type Packet<const N: usize>;
    /// The placeholder an answer buffer starts with.
    const NONE: Self::Answer;
    /// The name of a one-ray call's output parameter, for error messages.
    const ONE: &'static str;
    /// The name of an array or packet call's output parameter.
    const MANY: &'static str;

    /// One ray's answer, single-ray walk at 8 lanes.
    fn ray<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        ray: &Ray,
        mask: u32,
    ) -> Self::Answer;

    /// The answers of `rays` (`got[i]` for `rays[i]`), packet-traced at 8 lanes.
    fn rays<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &[Ray],
        mask: u32,
        got: &mut [Self::Answer],
    );

    /// One packet's answer at `L` lanes.
    fn packet<T, L: Lanes, KT: Kernel<L, Prim = T>, const N: usize>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> Self::Packet<N>
    where
        StableSphere: Kernel<L, Prim = PackedSphere>;
}

/// The closest hit: an [`OctorayHit`] per ray.
pub(crate) enum Closest {}

impl Query for Closest {
    type Answer = Option<octoray::hit::Hit>;
    type Out = OctorayHit;
    type Packet<const N: usize> = OctorayHits<N>;
    const NONE: Self::Answer = None;
    const ONE: &'static str = "hit";
    const MANY: &'static str = "hits";

    fn ray<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        ray: &Ray,
        mask: u32,
    ) -> Self::Answer {
        scene.closest_ray::<f32x8, KT, StableSphere>(ray, mask)
    }

    fn rays<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &[Ray],
        mask: u32,
        got: &mut [Self::Answer],
    ) {
        scene.closest::<f32x8, KT, StableSphere>(rays, mask, got);
    }

    fn packet<T, L: Lanes, KT: Kernel<L, Prim = T>, const N: usize>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> Self::Packet<N>
    where
        StableSphere: Kernel<L, Prim = PackedSphere>,
    {
        let h = scene.closest_packet::<L, KT, StableSphere>(rays, mask);
        OctorayHits::from(core::array::from_fn::<_, N, _>(|i| {
            OctorayHit::from(h.lane(i))
        }))
    }
}

/// Occlusion: a byte (1 or 0) per ray, one bit per lane for a packet.
pub(crate) enum Occluded {}

impl Query for Occluded {
    type Answer = bool;
    type Out = u8;
    type Packet<const N: usize> = u32;
    const NONE: Self::Answer = false;
    const ONE: &'static str = "occluded";
    const MANY: &'static str = "occluded";

    fn ray<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        ray: &Ray,
        mask: u32,
    ) -> Self::Answer {
        scene.occluded_ray::<f32x8, KT, StableSphere>(ray, mask)
    }

    fn rays<T, KT: Kernel<f32x8, Prim = T>>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &[Ray],
        mask: u32,
        got: &mut [Self::Answer],
    ) {
        scene.occluded::<f32x8, KT, StableSphere>(rays, mask, got);
    }

    fn packet<T, L: Lanes, KT: Kernel<L, Prim = T>, const N: usize>(
        scene: &impl Trace<T, PackedSphere>,
        rays: &RayLanes<L>,
        mask: u32,
    ) -> Self::Packet<N>
    where
        StableSphere: Kernel<L, Prim = PackedSphere>,
    {
        scene
            .occluded_packet::<L, KT, StableSphere>(rays, mask)
            .bitmask()
    }
}

/// The body of a one-ray call: `*out` answers `*ray`.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading, `out` for
/// writing.
pub(crate) unsafe fn one<Q: Query>(
    call: &str,
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    out: *mut Q::Out,
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let r = unsafe { slice(ray, 1, call, "ray") }?;
        let out = null_check(out, call, Q::ONE)?;
        let r = Ray::from(&r[0]);
        let a = traced!(s, s.view(call)?, |sc, KT| Q::ray::<_, KT>(&sc, &r, mask));
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, Q::Out::from(a)) };
        Ok(())
    })
}

/// The body of an array call: `out[i]` answers `rays[i]`, in chunks of 256 rays.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading `count` rays,
/// `out` for writing `count` answers.
pub(crate) unsafe fn many<Q: Query>(
    call: &str,
    scene: *const OctorayScene,
    rays: *const OctorayRay,
    count: usize,
    mask: u32,
    out: *mut Q::Out,
) -> OctorayStatus {
    const CHUNK: usize = 256;
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let rays = unsafe { slice(rays, count, call, "rays") }?;
        // SAFETY: the caller's contract.
        let out = unsafe { slice_mut(out, count, call, Q::MANY) }?;
        let view = s.view(call)?;
        let mut got = vec![Q::NONE; CHUNK.min(count)];
        for (rs, os) in rays.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let rs: Vec<Ray> = rs.iter().map(Ray::from).collect();
            let got = &mut got[..rs.len()];
            traced!(s, &view, |sc, KT| Q::rays::<_, KT>(sc, &rs, mask, got));
            for (o, g) in os.iter_mut().zip(got.iter()) {
                *o = Q::Out::from(*g);
            }
        }
        Ok(())
    })
}

/// The body of an `N`-ray packet call at `L` lanes: `*out` answers the packet `*rays`.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
/// `out` for writing one answer.
pub(crate) unsafe fn packet<Q: Query, L: Lanes, const N: usize>(
    call: &str,
    scene: *const OctorayScene,
    rays: *const OctorayRays<N>,
    mask: u32,
    out: *mut Q::Packet<N>,
) -> OctorayStatus
where
    MollerTrumbore: Kernel<L, Prim = PackedTriangle>,
    Watertight: Kernel<L, Prim = VertexTriangle>,
    Exact: Kernel<L, Prim = VertexTriangle>,
    StableSphere: Kernel<L, Prim = PackedSphere>,
{
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let p = unsafe { slice(rays, 1, call, "rays") }?;
        let out = null_check(out, call, Q::MANY)?;
        let rays: [Ray; N] = core::array::from_fn(|i| p[0].ray(i));
        let lanes = RayLanes::<L>::load(&rays);
        let a = traced!(s, s.view(call)?, |sc, KT| Q::packet::<_, L, KT, N>(
            &sc, &lanes, mask
        ));
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, a) };
        Ok(())
    })
}

/// Hits collected per walk by [`all_hits`]: a buffer larger than this fills in several walks.
const ALL_HITS_PAGE: usize = 64;

/// The body of the all-hits call: the first `out.len()` hits of `*ray` after `after`, in hit
/// order; returns how many were written and whether they are all of them.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `after` is null
/// or valid for reading; `out` is valid for writing `capacity` hits; `stored` and `complete`
/// for writing.
#[allow(clippy::too_many_arguments)] // the C call's parameters, passed on once
pub(crate) unsafe fn all_hits(
    call: &str,
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    after: *const OctorayHit,
    out: *mut OctorayHit,
    capacity: usize,
    (stored, complete): (*mut usize, *mut u8),
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let r = Ray::from(&unsafe { slice(ray, 1, call, "ray") }?[0]);
        let after = if after.is_null() {
            None
        } else {
            // SAFETY: non-null and, by the contract, valid for reading.
            Some(Hit::from(unsafe { *after }))
        };
        // SAFETY: the caller's contract.
        let out = unsafe { slice_mut(out, capacity, call, "hits") }?;
        let stored = null_check(stored, call, "stored")?;
        let complete = null_check(complete, call, "complete")?;
        let view = s.view(call)?;
        let mut page = [Hit::default(); ALL_HITS_PAGE];
        let (mut n, mut cursor) = (0, after);
        let all = loop {
            let room = (out.len() - n).min(ALL_HITS_PAGE);
            let page = &mut page[..room];
            let found = traced!(s, &view, |sc, KT| sc
                .all_hits_ray::<f32x8, KT, StableSphere>(&r, mask, cursor, page));
            for (o, h) in out[n..].iter_mut().zip(&page[..found.stored]) {
                *o = OctorayHit::from(Some(*h));
            }
            n += found.stored;
            if found.complete || n == out.len() {
                break found.complete;
            }
            cursor = Some(page[found.stored - 1]);
        };
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe {
            put(stored, n);
            put(complete, u8::from(all));
        }
        Ok(())
    })
}

/// `octoray_closest_point1`: the primitive nearest to `point` within `max_dist` into `*out`
/// (a miss: `prim == OCTORAY_NO_HIT`).
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` for writing one answer.
pub(crate) unsafe fn closest_point(
    call: &str,
    scene: *const OctorayScene,
    point: *const f32,
    max_dist: f32,
    mask: u32,
    out: *mut OctorayPointHit,
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let p = unsafe { slice(point, 3, call, "point") }?;
        let out = null_check(out, call, "out")?;
        let view = s.view(call)?;
        let p = octoray::glam::Vec3::new(p[0], p[1], p[2]);
        let found = match view {
            View::Packed(sc) => sc.closest_point(p, max_dist, mask),
            View::Vertex(sc) => sc.closest_point(p, max_dist, mask),
        };
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, OctorayPointHit::from(found)) };
        Ok(())
    })
}

/// `octoray_crossings1`: how many triangles `*ray` crosses under the crossing rule into
/// `*out`; an `InvalidArgument` error for a standard-tier scene, whose layout
/// has no crossing rule.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `out` for writing
/// one `u32`.
pub(crate) unsafe fn crossings(
    call: &str,
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    out: *mut u32,
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let r = Ray::from(&unsafe { slice(ray, 1, call, "ray") }?[0]);
        let out = null_check(out, call, "out")?;
        let n = vertex_view(s, call)?.crossings_ray::<f32x8, StableSphere>(&r, mask);
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, n) };
        Ok(())
    })
}

/// `octoray_contains1`: whether `point` is inside the scene's closed meshes (the parity of the
/// crossings of a ray from it) into `*out` as 1 or 0; an `InvalidArgument` error for a
/// standard-tier scene.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` for writing one byte.
pub(crate) unsafe fn contains(
    call: &str,
    scene: *const OctorayScene,
    point: *const f32,
    mask: u32,
    out: *mut u8,
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let p = unsafe { slice(point, 3, call, "point") }?;
        let out = null_check(out, call, "out")?;
        let p = octoray::glam::Vec3::new(p[0], p[1], p[2]);
        let inside = vertex_view(s, call)?.contains::<f32x8, StableSphere>(p, mask);
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, u8::from(inside)) };
        Ok(())
    })
}

/// `octoray_signed_distance1`: the distance from `point` to the nearest primitive, negative
/// inside the scene's closed meshes, into `*out`; an `InvalidArgument` error for a
/// standard-tier scene.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` for writing one float.
pub(crate) unsafe fn signed_distance(
    call: &str,
    scene: *const OctorayScene,
    point: *const f32,
    mask: u32,
    out: *mut f32,
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let p = Vec3::from_slice(unsafe { slice(point, 3, call, "point") }?);
        let out = null_check(out, call, "out")?;
        let d = vertex_view(s, call)?.signed_distance::<f32x8, StableSphere>(p, mask);
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, d) };
        Ok(())
    })
}

/// The scene as vertex triangles (the watertight and exact tiers' layout), or the error a
/// crossing query on a standard-tier scene gets.
fn vertex_view<'s>(
    s: &'s OctorayScene,
    call: &str,
) -> Result<octoray::scene::SceneRef<'s, VertexTriangle, PackedSphere>, OctorayStatus> {
    match s.view(call)? {
        View::Vertex(sc) => Ok(sc),
        View::Packed(_) => Err(crate::fail(
            OctorayStatus::InvalidArgument,
            format!("{call}: a standard-tier scene has no crossing rule (use the watertight or exact tier)"),
        )),
    }
}

/// `octoray_overlapping1`: the first `capacity` places after `after` of the primitives that meet
/// the world box `[lo, hi]`, ascending; returns how many were written and whether they are all.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `lo` and `hi` are valid for reading three
/// floats; `after` is null or valid for reading; `places` is valid for writing `capacity`
/// places; `stored` and `complete` for writing.
pub(crate) unsafe fn overlapping(
    call: &str,
    scene: *const OctorayScene,
    (lo, hi): (*const f32, *const f32),
    mask: u32,
    after: *const OctorayPlace,
    (places, capacity): (*mut OctorayPlace, usize),
    (stored, complete): (*mut usize, *mut u8),
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let (lo, hi) = unsafe { (slice(lo, 3, call, "lo")?, slice(hi, 3, call, "hi")?) };
        let after = if after.is_null() {
            None
        } else {
            // SAFETY: non-null and, by the contract, valid for reading.
            Some(octoray::scene::Place::from(unsafe { *after }))
        };
        // SAFETY: the caller's contract.
        let out = unsafe { slice_mut(places, capacity, call, "places") }?;
        let stored = null_check(stored, call, "stored")?;
        let complete = null_check(complete, call, "complete")?;
        let (lo, hi) = (Vec3::from_slice(lo), Vec3::from_slice(hi));
        let view = s.view(call)?;
        // A page at a time into the caller's buffer, as the all-hits call does.
        let mut page = [octoray::scene::Place::default(); ALL_HITS_PAGE];
        let (mut n, mut cursor) = (0, after);
        let all = loop {
            let page = &mut page[..(out.len() - n).min(ALL_HITS_PAGE)];
            let f = match &view {
                View::Packed(sc) => sc.overlapping(lo, hi, mask, cursor, page),
                View::Vertex(sc) => sc.overlapping(lo, hi, mask, cursor, page),
            };
            for (o, p) in out[n..].iter_mut().zip(&page[..f.stored]) {
                *o = OctorayPlace::from(*p);
            }
            n += f.stored;
            if f.complete || n == out.len() {
                break f.complete;
            }
            cursor = Some(page[f.stored - 1]);
        };
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe {
            put(stored, n);
            put(complete, u8::from(all));
        }
        Ok(())
    })
}

/// `octoray_nearest_within1`: the `capacity` primitives nearest to `point` within `radius`, in
/// order of distance; returns how many were written and whether that is all of them.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `near` for writing `capacity` answers; `stored` and `complete` for writing.
pub(crate) unsafe fn nearest_within(
    call: &str,
    scene: *const OctorayScene,
    (point, radius, mask): (*const f32, f32, u32),
    (near, capacity): (*mut OctorayPointHit, usize),
    (stored, complete): (*mut usize, *mut u8),
) -> OctorayStatus {
    run(|| {
        // SAFETY: the caller's contract.
        let s = unsafe { scene_ref(scene, call) }?;
        // SAFETY: the caller's contract.
        let p = Vec3::from_slice(unsafe { slice(point, 3, call, "point") }?);
        // SAFETY: the caller's contract.
        let out = unsafe { slice_mut(near, capacity, call, "near") }?;
        let stored = null_check(stored, call, "stored")?;
        let complete = null_check(complete, call, "complete")?;
        let mut found = vec![octoray::tree::PointHit::default(); out.len()];
        let f = match s.view(call)? {
            View::Packed(sc) => sc.nearest_within(p, radius, mask, &mut found),
            View::Vertex(sc) => sc.nearest_within(p, radius, mask, &mut found),
        };
        for (o, h) in out.iter_mut().zip(&found[..f.stored]) {
            *o = OctorayPointHit::from(Some(*h));
        }
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe {
            put(stored, f.stored);
            put(complete, u8::from(f.complete));
        }
        Ok(())
    })
}
