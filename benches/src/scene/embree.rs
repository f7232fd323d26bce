//! Embree 3 as a benchmark peer, through its C API loaded at run time (`libembree3.so.3`, Debian's
//! `libembree-dev`), so that a machine without it builds and runs every benchmark and reports the
//! Embree rows as skipped.
//!
//! The shim declares the handful of entry points and the ray structures of `rtcore_ray.h` for
//! `RTC_MAX_INSTANCE_LEVEL_COUNT = 1` and `RTC_MIN_WIDTH = 0` (Debian's build). The scene is a
//! triangle soup (vertex buffer of `3n` points, index buffer `3i, 3i + 1, 3i + 2`), built on a
//! device with `threads=1`; robust mode is `RTC_SCENE_FLAG_ROBUST`.
#![allow(unsafe_code)] // FFI into the peer; the library crates forbid unsafe code.

use crate::scene::row::{Query, Traversal};
use crate::scene::trace::Traces;
use glam::Vec3;
use octoray::prim::Ray;
use std::ffi::{c_char, c_int, c_uint, c_void};
use std::time::{Duration, Instant};

type Device = *mut c_void;
type Scene = *mut c_void;
type Geometry = *mut c_void;

#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: c_uint,
    id: c_uint,
    flags: c_uint,
}

#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: c_uint,
    geom_id: c_uint,
    inst_id: [c_uint; 1],
}

#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct RtcRay8 {
    org: [[f32; 8]; 3],
    tnear: [f32; 8],
    dir: [[f32; 8]; 3],
    time: [f32; 8],
    tfar: [f32; 8],
    mask: [c_uint; 8],
    id: [c_uint; 8],
    flags: [c_uint; 8],
}

#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct RtcHit8 {
    ng: [[f32; 8]; 3],
    u: [f32; 8],
    v: [f32; 8],
    prim_id: [c_uint; 8],
    geom_id: [c_uint; 8],
    inst_id: [[c_uint; 8]; 1],
}

#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayHit8 {
    ray: RtcRay8,
    hit: RtcHit8,
}

#[repr(C)]
struct Context {
    flags: c_uint,
    filter: *const c_void,
    inst_id: [c_uint; 1],
}

const INVALID_ID: c_uint = u32::MAX;
const CONTEXT_COHERENT: c_uint = 1;
const GEOMETRY_TRIANGLE: c_int = 0;
const BUFFER_INDEX: c_int = 0;
const BUFFER_VERTEX: c_int = 1;
const FORMAT_UINT3: c_int = 0x5003;
const FORMAT_FLOAT3: c_int = 0x9003;
const SCENE_FLAG_ROBUST: c_int = 1 << 2;
const GEOMETRY_INSTANCE: c_int = 121;
const FORMAT_FLOAT3X4_COLUMN_MAJOR: c_int = 0x9234;
const SCENE_FLAG_CONTEXT_FILTER_FUNCTION: c_int = 1 << 3;

/// `RTCPointQuery`.
#[repr(C, align(16))]
struct RtcPointQuery {
    p: [f32; 3],
    time: f32,
    radius: f32,
}

/// `RTCPointQueryContext`, zeroed (an empty instance stack at any instance level count).
#[repr(C, align(16))]
struct PointQueryContext([u8; 1024]);

/// `RTCPointQueryFunctionArguments`.
#[repr(C)]
struct PointQueryArgs {
    query: *mut RtcPointQuery,
    user: *mut c_void,
    prim_id: c_uint,
    geom_id: c_uint,
    context: *mut PointQueryContext,
    similarity_scale: f32,
}

type PointQueryFn = unsafe extern "C" fn(*mut PointQueryArgs) -> bool;

/// `RTCFilterFunctionNArguments`.
#[repr(C)]
struct FilterArgs {
    valid: *mut c_int,
    geometry_user: *mut c_void,
    context: *mut Context,
    ray: *mut f32,
    hit: *mut f32,
    n: c_uint,
}

/// An intersection context with the hits its filter collects behind it (Embree passes the
/// context pointer through to the filter).
#[repr(C)]
struct CollectingContext {
    ctx: Context,
    hits: Vec<(f32, u32)>,
}

/// The loaded library's entry points.
struct Api {
    _lib: libloading::Library,
    new_device: unsafe extern "C" fn(*const c_char) -> Device,
    release_device: unsafe extern "C" fn(Device),
    new_scene: unsafe extern "C" fn(Device) -> Scene,
    release_scene: unsafe extern "C" fn(Scene),
    set_scene_flags: unsafe extern "C" fn(Scene, c_int),
    new_geometry: unsafe extern "C" fn(Device, c_int) -> Geometry,
    set_new_buffer:
        unsafe extern "C" fn(Geometry, c_int, c_uint, c_int, usize, usize) -> *mut c_void,
    commit_geometry: unsafe extern "C" fn(Geometry),
    attach_geometry: unsafe extern "C" fn(Scene, Geometry) -> c_uint,
    release_geometry: unsafe extern "C" fn(Geometry),
    commit_scene: unsafe extern "C" fn(Scene),
    set_instanced_scene: unsafe extern "C" fn(Geometry, Scene),
    set_transform: unsafe extern "C" fn(Geometry, c_uint, c_int, *const c_void),
    intersect1: unsafe extern "C" fn(Scene, *mut Context, *mut RtcRayHit),
    occluded1: unsafe extern "C" fn(Scene, *mut Context, *mut RtcRay),
    intersect8: unsafe extern "C" fn(*const c_int, Scene, *mut Context, *mut RtcRayHit8),
    occluded8: unsafe extern "C" fn(*const c_int, Scene, *mut Context, *mut RtcRay8),
    point_query: unsafe extern "C" fn(
        Scene,
        *mut RtcPointQuery,
        *mut PointQueryContext,
        PointQueryFn,
        *mut c_void,
    ) -> bool,
}

impl Api {
    fn load() -> Result<Self, String> {
        // SAFETY: loading a shared library runs its initialisers; Embree's are plain C++ statics.
        let lib = unsafe { libloading::Library::new("libembree3.so.3") }
            .map_err(|e| format!("Embree 3 not found ({e}); install libembree-dev"))?;
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the symbol's type is the prototype in Embree 3's headers.
                *unsafe { lib.get($name) }.map_err(|e| format!("Embree 3: {e}"))?
            };
        }
        Ok(Self {
            new_device: sym!(b"rtcNewDevice\0"),
            release_device: sym!(b"rtcReleaseDevice\0"),
            new_scene: sym!(b"rtcNewScene\0"),
            release_scene: sym!(b"rtcReleaseScene\0"),
            set_scene_flags: sym!(b"rtcSetSceneFlags\0"),
            new_geometry: sym!(b"rtcNewGeometry\0"),
            set_new_buffer: sym!(b"rtcSetNewGeometryBuffer\0"),
            commit_geometry: sym!(b"rtcCommitGeometry\0"),
            attach_geometry: sym!(b"rtcAttachGeometry\0"),
            release_geometry: sym!(b"rtcReleaseGeometry\0"),
            commit_scene: sym!(b"rtcCommitScene\0"),
            set_instanced_scene: sym!(b"rtcSetGeometryInstancedScene\0"),
            set_transform: sym!(b"rtcSetGeometryTransform\0"),
            intersect1: sym!(b"rtcIntersect1\0"),
            occluded1: sym!(b"rtcOccluded1\0"),
            intersect8: sym!(b"rtcIntersect8\0"),
            occluded8: sym!(b"rtcOccluded8\0"),
            point_query: sym!(b"rtcPointQuery\0"),
            _lib: lib,
        })
    }
}

/// The library, loaded once and never unloaded: Embree's task threads outlive its devices, and
/// unloading the code under them crashes the process.
static API: std::sync::OnceLock<Result<Api, String>> = std::sync::OnceLock::new();

/// An Embree device (one thread) and a committed triangle scene (or a scene of instances of
/// one committed triangle scene, `mesh`).
pub struct EmbreeScene {
    api: &'static Api,
    device: Device,
    scene: Scene,
    /// The scenes its instances place.
    inner: Vec<Scene>,
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: handles created by this library and released once.
        unsafe {
            (self.api.release_scene)(self.scene);
            for &m in &self.inner {
                (self.api.release_scene)(m);
            }
            (self.api.release_device)(self.device);
        }
    }
}

fn context(coherent: bool) -> Context {
    Context {
        flags: if coherent { CONTEXT_COHERENT } else { 0 },
        filter: std::ptr::null(),
        inst_id: [INVALID_ID],
    }
}

fn rtc_ray(r: &Ray) -> RtcRay {
    RtcRay {
        org: r.origin.to_array(),
        tnear: r.t_min,
        dir: r.dir.to_array(),
        time: 0.0,
        tfar: r.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// A packet's valid mask (−1 on active lanes), aligned as Embree requires.
#[repr(C, align(32))]
struct Valid([c_int; 8]);

fn rtc_ray8(rays: &[Ray]) -> (RtcRay8, Valid) {
    let mut p = RtcRay8 {
        org: [[0.0; 8]; 3],
        tnear: [0.0; 8],
        dir: [[0.0; 8]; 3],
        time: [0.0; 8],
        tfar: [f32::NEG_INFINITY; 8],
        mask: [u32::MAX; 8],
        id: [0; 8],
        flags: [0; 8],
    };
    let mut valid = Valid([0; 8]);
    for (i, r) in rays.iter().enumerate().take(8) {
        for k in 0..3 {
            p.org[k][i] = r.origin[k];
            p.dir[k][i] = r.dir[k];
        }
        p.tnear[i] = r.t_min;
        p.tfar[i] = r.t_max;
        valid.0[i] = -1;
    }
    (p, valid)
}

impl EmbreeScene {
    /// Loads Embree and builds a scene on one thread (robust mode when `robust`); returns the
    /// scene and the build's wall time (`rtcCommitScene`), or why Embree is unavailable.
    pub fn build(tris: &[[Vec3; 3]], robust: bool) -> Result<(Self, Duration), String> {
        let api = API.get_or_init(Api::load).as_ref().map_err(Clone::clone)?;
        let device = Self::device(api)?;
        // SAFETY: a device from `Self::device`.
        let flags = if robust { SCENE_FLAG_ROBUST } else { 0 };
        let (scene, built) = unsafe { Self::mesh_scene(api, device, tris, flags) };
        Ok((
            Self {
                api,
                device,
                scene,
                inner: Vec::new(),
            },
            built,
        ))
    }

    /// A robust scene whose intersection contexts may carry a filter: what
    /// [`EmbreeScene::all_hits1`] needs.
    pub fn build_collecting(tris: &[[Vec3; 3]]) -> Result<Self, String> {
        let api = API.get_or_init(Api::load).as_ref().map_err(Clone::clone)?;
        let device = Self::device(api)?;
        let flags = SCENE_FLAG_ROBUST | SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
        // SAFETY: a device from `Self::device`.
        let (scene, _) = unsafe { Self::mesh_scene(api, device, tris, flags) };
        Ok(Self {
            api,
            device,
            scene,
            inner: Vec::new(),
        })
    }

    /// A scene of `places.len()` instances (`RTC_GEOMETRY_TYPE_INSTANCE`) of one triangle mesh,
    /// each placed by its object → world matrix; the wall time covers the mesh's and the top
    /// level's commit.
    pub fn build_instanced(
        mesh: &[[Vec3; 3]],
        places: &[glam::Affine3A],
        robust: bool,
    ) -> Result<(Self, Duration), String> {
        let api = API.get_or_init(Api::load).as_ref().map_err(Clone::clone)?;
        let device = Self::device(api)?;
        // SAFETY: Embree's instancing API: a committed mesh scene, one instance geometry per
        // placement with its 3×4 column-major transform (12 floats read during the call), each
        // committed, attached and released (the scene keeps it).
        unsafe {
            let flags = if robust { SCENE_FLAG_ROBUST } else { 0 };
            let (inner, built) = Self::mesh_scene(api, device, mesh, flags);
            let scene = (api.new_scene)(device);
            if robust {
                (api.set_scene_flags)(scene, SCENE_FLAG_ROBUST);
            }
            for a in places {
                Self::attach_instance(api, device, scene, inner, a);
            }
            let start = Instant::now();
            (api.commit_scene)(scene);
            Ok((
                Self {
                    api,
                    device,
                    scene,
                    inner: vec![inner],
                },
                built + start.elapsed(),
            ))
        }
    }

    /// Each of `meshes` in a scene of its own, placed once by an identity instance (a renderer's
    /// meshes as instances); the commits' wall time.
    pub fn build_meshes_instanced(
        meshes: &[&[[Vec3; 3]]],
        robust: bool,
    ) -> Result<(Self, Duration), String> {
        let api = API.get_or_init(Api::load).as_ref().map_err(Clone::clone)?;
        let device = Self::device(api)?;
        // SAFETY: as `build_instanced`, one committed mesh scene per instance geometry.
        unsafe {
            let flags = if robust { SCENE_FLAG_ROBUST } else { 0 };
            let scene = (api.new_scene)(device);
            (api.set_scene_flags)(scene, flags);
            let mut inner = Vec::with_capacity(meshes.len());
            let mut built = Duration::ZERO;
            for mesh in meshes {
                let (m, t) = Self::mesh_scene(api, device, mesh, flags);
                built += t;
                Self::attach_instance(api, device, scene, m, &glam::Affine3A::IDENTITY);
                inner.push(m);
            }
            let start = Instant::now();
            (api.commit_scene)(scene);
            Ok((
                Self {
                    api,
                    device,
                    scene,
                    inner,
                },
                built + start.elapsed(),
            ))
        }
    }

    /// Places the committed scene `inner` in `scene` by one instance geometry with transform `a`
    /// (committed, attached and released: the scene keeps it).
    ///
    /// # Safety
    /// `device` is a live device of `api`, `scene` and `inner` live scenes of it.
    unsafe fn attach_instance(
        api: &Api,
        device: Device,
        scene: Scene,
        inner: Scene,
        a: &glam::Affine3A,
    ) {
        let cols = a.to_cols_array();
        // SAFETY: Embree's instancing API; the 12 floats of `cols` are read during the call.
        unsafe {
            let geom = (api.new_geometry)(device, GEOMETRY_INSTANCE);
            (api.set_instanced_scene)(geom, inner);
            (api.set_transform)(
                geom,
                0,
                FORMAT_FLOAT3X4_COLUMN_MAJOR,
                cols.as_ptr() as *const c_void,
            );
            (api.commit_geometry)(geom);
            (api.attach_geometry)(scene, geom);
            (api.release_geometry)(geom);
        }
    }

    fn device(api: &Api) -> Result<Device, String> {
        // SAFETY: a NUL-terminated configuration string.
        let device = unsafe { (api.new_device)(c"threads=1".as_ptr()) };
        if device.is_null() {
            return Err("Embree 3: rtcNewDevice failed".into());
        }
        Ok(device)
    }

    /// A committed scene of one triangle geometry, and its commit's wall time.
    ///
    /// # Safety
    /// `device` is a live device of `api`.
    unsafe fn mesh_scene(
        api: &Api,
        device: Device,
        tris: &[[Vec3; 3]],
        flags: c_int,
    ) -> (Scene, Duration) {
        // SAFETY: the calls follow Embree's API: a scene, one triangle geometry whose buffers
        // Embree allocates (`rtcSetNewGeometryBuffer`, sized for `n` items with the strides
        // given) and this function fills within those sizes.
        unsafe {
            let scene = (api.new_scene)(device);
            (api.set_scene_flags)(scene, flags);
            let geom = (api.new_geometry)(device, GEOMETRY_TRIANGLE);
            let n = tris.len();
            let v =
                (api.set_new_buffer)(geom, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 12, 3 * n) as *mut f32;
            let idx = (api.set_new_buffer)(geom, BUFFER_INDEX, 0, FORMAT_UINT3, 12, n) as *mut u32;
            let v = std::slice::from_raw_parts_mut(v, 9 * n);
            let idx = std::slice::from_raw_parts_mut(idx, 3 * n);
            for (i, t) in tris.iter().enumerate() {
                for (j, p) in t.iter().enumerate() {
                    v[9 * i + 3 * j..9 * i + 3 * j + 3].copy_from_slice(&p.to_array());
                    idx[3 * i + j] = (3 * i + j) as u32;
                }
            }
            (api.commit_geometry)(geom);
            (api.attach_geometry)(scene, geom);
            (api.release_geometry)(geom);
            let start = Instant::now();
            (api.commit_scene)(scene);
            (scene, start.elapsed())
        }
    }

    /// `rtcIntersect1` on every ray; returns the number of hits.
    pub fn closest1(&self, rays: &[Ray]) -> u64 {
        let mut ctx = context(false);
        let mut hits = 0;
        for r in rays {
            let mut rh = RtcRayHit {
                ray: rtc_ray(r),
                hit: RtcHit {
                    ng: [0.0; 3],
                    u: 0.0,
                    v: 0.0,
                    prim_id: INVALID_ID,
                    geom_id: INVALID_ID,
                    inst_id: [INVALID_ID],
                },
            };
            // SAFETY: a committed scene, an initialised context and ray/hit of Embree's layout.
            unsafe { (self.api.intersect1)(self.scene, &mut ctx, &mut rh) };
            hits += u64::from(rh.hit.geom_id != INVALID_ID);
        }
        hits
    }

    /// `rtcOccluded1` on every ray; returns the number occluded.
    pub fn any1(&self, rays: &[Ray]) -> u64 {
        let mut ctx = context(false);
        let mut hits = 0;
        for r in rays {
            let mut ray = rtc_ray(r);
            // SAFETY: as in `closest1`.
            unsafe { (self.api.occluded1)(self.scene, &mut ctx, &mut ray) };
            hits += u64::from(ray.tfar == f32::NEG_INFINITY);
        }
        hits
    }

    /// `rtcIntersect8` on packets of 8 consecutive rays (a coherent context); returns the number
    /// of hits.
    pub fn closest8(&self, rays: &[Ray]) -> u64 {
        let mut ctx = context(true);
        let mut hits = 0;
        for c in rays.chunks(8) {
            let (ray, valid) = rtc_ray8(c);
            let mut rh = RtcRayHit8 {
                ray,
                hit: RtcHit8 {
                    ng: [[0.0; 8]; 3],
                    u: [0.0; 8],
                    v: [0.0; 8],
                    prim_id: [INVALID_ID; 8],
                    geom_id: [INVALID_ID; 8],
                    inst_id: [[INVALID_ID; 8]],
                },
            };
            // SAFETY: as in `closest1`; the packet and mask are 32-byte aligned.
            unsafe { (self.api.intersect8)(valid.0.as_ptr(), self.scene, &mut ctx, &mut rh) };
            hits += rh.hit.geom_id[..c.len()]
                .iter()
                .filter(|&&g| g != INVALID_ID)
                .count() as u64;
        }
        hits
    }

    /// `rtcOccluded8` on packets of 8 consecutive rays; returns the number occluded.
    pub fn any8(&self, rays: &[Ray]) -> u64 {
        let mut ctx = context(true);
        let mut hits = 0;
        for c in rays.chunks(8) {
            let (mut ray, valid) = rtc_ray8(c);
            // SAFETY: as in `closest8`.
            unsafe { (self.api.occluded8)(valid.0.as_ptr(), self.scene, &mut ctx, &mut ray) };
            hits += ray.tfar[..c.len()]
                .iter()
                .filter(|&&t| t == f32::NEG_INFINITY)
                .count() as u64;
        }
        hits
    }
}

/// The filter of [`EmbreeScene::all_hits1`]: records each valid lane's hit (its `t`, now the
/// ray's `tfar`, and primitive) in the [`CollectingContext`] and rejects it, so the walk goes on.
unsafe extern "C" fn collect_hit(args: *const FilterArgs) {
    // SAFETY: Embree passes its arguments; the context is the `CollectingContext` the query was
    // started with (its first field is the `Context`); rays and hits are SoA of `n` lanes
    // (`RTCRayN`: `tfar` is float 8; `RTCHitN`: `primID` is word 5).
    unsafe {
        let a = &*args;
        let n = a.n as usize;
        let ctx = &mut *(a.context as *mut CollectingContext);
        for i in 0..n {
            if *a.valid.add(i) != 0 {
                let t = *a.ray.add(8 * n + i);
                let prim = *(a.hit as *const u32).add(5 * n + i);
                ctx.hits.push((t, prim));
                *a.valid.add(i) = 0;
            }
        }
    }
}

/// What [`closest_point_query`] reads and keeps: the triangles, and the best so far.
struct PointUser<'a> {
    tris: &'a [[Vec3; 3]],
    prim: u32,
    dist: f32,
}

/// Embree's closest-point tutorial callback: the point of triangle `primID` nearest to the
/// query (Ericson's region test in f32, as the tutorial's `closestPointTriangle`), shrinking the
/// query radius when nearer.
unsafe extern "C" fn closest_point_query(args: *mut PointQueryArgs) -> bool {
    // SAFETY: Embree passes its arguments; `user` is the `PointUser` the query was started
    // with, and `primID` indexes the triangles the scene was built from.
    unsafe {
        let a = &mut *args;
        let user = &mut *(a.user as *mut PointUser<'_>);
        let q = &mut *a.query;
        let p = Vec3::from(q.p);
        let Some(t) = user.tris.get(a.prim_id as usize) else {
            return false;
        };
        let d = (closest_point_triangle(p, t[0], t[1], t[2]) - p).length();
        if d < q.radius {
            q.radius = d;
            user.prim = a.prim_id;
            user.dist = d;
            return true;
        }
        false
    }
}

/// Ericson's closest point on triangle `abc` to `p`, in f32 (Embree's tutorial's).
fn closest_point_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + d1 / (d1 - d3) * ab;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + d2 / (d2 - d6) * ac;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

impl EmbreeScene {
    /// Every hit of each ray in range (`rtcIntersect1` with a context filter that records every
    /// hit and rejects it, Embree's way to gather all hits), sorted by `t` with repeats of a
    /// primitive at one `t` dropped; returns the total number of hits. Needs a scene from
    /// [`EmbreeScene::build_collecting`].
    pub fn all_hits1(&self, rays: &[Ray]) -> u64 {
        let mut ctx = CollectingContext {
            ctx: context(false),
            hits: Vec::with_capacity(64),
        };
        ctx.ctx.filter = collect_hit as *const c_void;
        let mut total = 0;
        for r in rays {
            ctx.hits.clear();
            let mut rh = RtcRayHit {
                ray: rtc_ray(r),
                hit: RtcHit {
                    ng: [0.0; 3],
                    u: 0.0,
                    v: 0.0,
                    prim_id: INVALID_ID,
                    geom_id: INVALID_ID,
                    inst_id: [INVALID_ID],
                },
            };
            // SAFETY: as in `closest1`; the context's filter is `collect_hit`, which reads the
            // `CollectingContext` this context is the first field of.
            unsafe { (self.api.intersect1)(self.scene, &mut ctx.ctx, &mut rh) };
            ctx.hits
                .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            ctx.hits.dedup();
            total += ctx.hits.len() as u64;
        }
        total
    }

    /// The triangle nearest to each point (`rtcPointQuery` with the closest-point tutorial's
    /// callback over `tris`, the triangles this scene was built from): its index and distance.
    pub fn closest_points(&self, tris: &[[Vec3; 3]], points: &[Vec3], out: &mut Vec<(u32, f32)>) {
        out.clear();
        let mut ctx = Box::new(PointQueryContext([0; 1024]));
        for p in points {
            let mut q = RtcPointQuery {
                p: p.to_array(),
                time: 0.0,
                radius: f32::INFINITY,
            };
            let mut user = PointUser {
                tris,
                prim: INVALID_ID,
                dist: f32::INFINITY,
            };
            // SAFETY: a committed scene, an aligned query and context of Embree's layout (the
            // zeroed context is an empty instance stack), a callback of Embree's prototype and
            // the user data it expects, alive for the call.
            unsafe {
                (self.api.point_query)(
                    self.scene,
                    &mut q,
                    &mut *ctx,
                    closest_point_query,
                    &mut user as *mut PointUser<'_> as *mut c_void,
                )
            };
            out.push((user.prim, user.dist));
        }
    }
}

impl Traces for EmbreeScene {
    fn trace(&self, query: Query, traversal: Traversal, rays: &[Ray]) -> Option<u64> {
        match (query, traversal) {
            (Query::Closest, Traversal::Packet8) => Some(self.closest8(rays)),
            (Query::Closest, Traversal::Single) => Some(self.closest1(rays)),
            (Query::Any, Traversal::Packet8) => Some(self.any8(rays)),
            (Query::Any, Traversal::Single) => Some(self.any1(rays)),
            _ => None,
        }
    }
}
