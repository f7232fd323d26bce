//! octoray's C ABI: build a scene from vertex, index and sphere buffers, place instances, trace
//! single rays, ray arrays and 8/16-ray SoA packets (closest hit and occlusion) at a tier chosen
//! per scene, read hits (`t`, `u`, `v`, primitive, geometry, instance), store a scene as bytes
//! and load it back (validated). Every function returns an [`OctorayStatus`]; on failure
//! [`octoray_last_error`] says why. No panic crosses the boundary: each call catches it and
//! answers [`OctorayStatus::Panic`].
//!
//! The answers are those of the Rust API on the same inputs, bit for bit (the same walks:
//! `octoray::scene::Trace` at 8 lanes, 16 for 16-ray packets).
//!
//! The header `include/octoray.h` is generated from this file by cbindgen (`tests/header.rs`
//! fails when it is stale).
use core::ffi::c_char;

use octoray::glam::{Affine3A, Mat3A, Vec3, Vec3A};
use octoray::hit::Hit;
use octoray::prim::{PackedSphere, PackedTriangle, Ray, VertexTriangle};
use octoray::scene::{Scene, SceneRef, Transform};
use octoray::tree::PointHit;
use octoray::{f32x16, f32x8};

mod status;
mod store;
mod trace;

use trace::{Closest, Occluded};

/// What a call answered.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OctorayStatus {
    /// Success.
    Ok = 0,
    /// A required pointer was null.
    NullPointer = 1,
    /// An argument is out of its range (an unknown tier, an index past a buffer, a geometry
    /// that does not exist, a transform that is not invertible, a buffer too small).
    InvalidArgument = 2,
    /// A tree could not be built (more primitives than a tree holds).
    BuildFailed = 3,
    /// The scene changed since its last `octoray_scene_commit`.
    NotCommitted = 4,
    /// Stored scene bytes are not a valid scene (nothing is read past a check that failed).
    InvalidScene = 5,
    /// The call was given a scene loaded from bytes, which cannot be changed.
    ReadOnly = 6,
    /// octoray panicked (a bug): the call had no effect on its outputs.
    Panic = 7,
}

/// The accuracy tier a scene's triangles are tested with (its layout follows).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OctorayTier {
    /// Möller-Trumbore on packed triangles: fastest, not watertight.
    Standard = 0,
    /// Woop-Benthin-Wald with exact fallbacks: no ray escapes a closed mesh.
    Watertight = 1,
    /// Exact hit/miss decisions for the f32 inputs, `t` within about an ulp.
    Exact = 2,
}

impl OctorayTier {
    fn from_raw(raw: u32) -> Option<Self> {
        [Self::Standard, Self::Watertight, Self::Exact]
            .into_iter()
            .find(|t| *t as u32 == raw)
    }
}

/// A ray: origin, direction (any length, not zero) and the accepted range of `t`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OctorayRay {
    /// Origin x, y, z.
    pub org: [f32; 3],
    /// Direction x, y, z.
    pub dir: [f32; 3],
    /// Smallest accepted `t`.
    pub t_min: f32,
    /// Largest accepted `t` (`INFINITY` for none).
    pub t_max: f32,
}

impl From<&OctorayRay> for Ray {
    fn from(r: &OctorayRay) -> Ray {
        Ray::with_range(Vec3::from(r.org), Vec3::from(r.dir), r.t_min, r.t_max)
    }
}

/// `prim`, `geom` and `inst` of a miss.
pub const OCTORAY_NO_HIT: u32 = u32::MAX;

/// A hit, or a miss (`prim == OCTORAY_NO_HIT`, `t` infinite, the rest 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctorayHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric weight of the triangle's second vertex (0 for spheres).
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex (0 for spheres).
    pub v: f32,
    /// The primitive's index in its geometry.
    pub prim: u32,
    /// The geometry.
    pub geom: u32,
    /// The instance the ray met it through.
    pub inst: u32,
}

impl From<OctorayHit> for Hit {
    fn from(h: OctorayHit) -> Self {
        Hit {
            t: h.t,
            u: h.u,
            v: h.v,
            prim: h.prim,
            geom: h.geom,
            inst: h.inst,
        }
    }
}

impl From<Option<Hit>> for OctorayHit {
    fn from(h: Option<Hit>) -> Self {
        match h {
            Some(h) => Self {
                t: h.t,
                u: h.u,
                v: h.v,
                prim: h.prim,
                geom: h.geom,
                inst: h.inst,
            },
            None => Self {
                t: f32::INFINITY,
                u: 0.0,
                v: 0.0,
                prim: OCTORAY_NO_HIT,
                geom: OCTORAY_NO_HIT,
                inst: OCTORAY_NO_HIT,
            },
        }
    }
}

/// `N` rays, structure of arrays. A lane with `t_min > t_max` is a miss (fill unused lanes
/// so).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctorayRays<const N: usize> {
    /// Origins, x, y, z per lane.
    pub org: [[f32; N]; 3],
    /// Directions, x, y, z per lane.
    pub dir: [[f32; N]; 3],
    /// Smallest accepted `t` per lane.
    pub t_min: [f32; N],
    /// Largest accepted `t` per lane.
    pub t_max: [f32; N],
}

/// `N` hits, structure of arrays (a miss as in [`OctorayHit`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctorayHits<const N: usize> {
    /// `t` per lane.
    pub t: [f32; N],
    /// `u` per lane.
    pub u: [f32; N],
    /// `v` per lane.
    pub v: [f32; N],
    /// Primitive per lane.
    pub prim: [u32; N],
    /// Geometry per lane.
    pub geom: [u32; N],
    /// Instance per lane.
    pub inst: [u32; N],
}

/// Eight rays, structure of arrays.
pub type OctorayRay8 = OctorayRays<8>;
/// Eight hits, structure of arrays.
pub type OctorayHit8 = OctorayHits<8>;
/// Sixteen rays, structure of arrays.
pub type OctorayRay16 = OctorayRays<16>;
/// Sixteen hits, structure of arrays.
pub type OctorayHit16 = OctorayHits<16>;

impl<const N: usize> Default for OctorayRays<N> {
    /// Every lane a miss: zero origin and direction, `t_min` 1 above `t_max` 0.
    fn default() -> Self {
        Self {
            org: [[0.0; N]; 3],
            dir: [[0.0; N]; 3],
            t_min: [1.0; N],
            t_max: [0.0; N],
        }
    }
}

impl<const N: usize> OctorayRays<N> {
    /// Lane `i`'s ray.
    fn ray(&self, i: usize) -> Ray {
        let o = Vec3::new(self.org[0][i], self.org[1][i], self.org[2][i]);
        let d = Vec3::new(self.dir[0][i], self.dir[1][i], self.dir[2][i]);
        Ray::with_range(o, d, self.t_min[i], self.t_max[i])
    }
}

impl<const N: usize> From<[OctorayHit; N]> for OctorayHits<N> {
    fn from(h: [OctorayHit; N]) -> Self {
        Self {
            t: h.map(|h| h.t),
            u: h.map(|h| h.u),
            v: h.map(|h| h.v),
            prim: h.map(|h| h.prim),
            geom: h.map(|h| h.geom),
            inst: h.map(|h| h.inst),
        }
    }
}

/// A scene: built by the caller (geometries, instances, commit) or loaded from stored bytes.
/// Opaque to C; create with [`octoray_scene_new`] or [`octoray_scene_load`], free with
/// [`octoray_scene_free`]. Not safe to change from two threads at once; tracing from many
/// threads at once is safe.
pub struct OctorayScene {
    tier: OctorayTier,
    body: Body,
}

enum Body {
    Packed(Scene<PackedTriangle, PackedSphere>),
    Vertex(Scene<VertexTriangle, PackedSphere>),
    Loaded(store::Loaded),
}

/// The scene as borrowed slices, for a trace.
enum View<'a> {
    Packed(SceneRef<'a, PackedTriangle, PackedSphere>),
    Vertex(SceneRef<'a, VertexTriangle, PackedSphere>),
}

/// Records `message` as this thread's last error and answers `status`.
fn fail(status: OctorayStatus, message: impl Into<String>) -> OctorayStatus {
    status::record(message.into());
    status
}

/// Runs `body`, turning a panic into [`OctorayStatus::Panic`] with its message.
fn guard(body: impl FnOnce() -> OctorayStatus) -> OctorayStatus {
    status::catch(body).unwrap_or(OctorayStatus::Panic)
}

/// The message of the last failed call on this thread (empty after none), valid until the next
/// failing call on this thread. Never null.
#[no_mangle]
pub extern "C" fn octoray_last_error() -> *const c_char {
    status::last()
}

/// Creates an empty scene whose triangles are tested with `tier` (an [`OctorayTier`] value).
///
/// # Safety
/// `out` is null or valid for writing one pointer. On success `*out` owns a scene the caller
/// frees with [`octoray_scene_free`].
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_new(
    tier: u32,
    out: *mut *mut OctorayScene,
) -> OctorayStatus {
    guard(|| {
        if out.is_null() {
            return fail(OctorayStatus::NullPointer, "octoray_scene_new: out is null");
        }
        let Some(tier) = OctorayTier::from_raw(tier) else {
            return fail(
                OctorayStatus::InvalidArgument,
                format!("octoray_scene_new: unknown tier {tier}"),
            );
        };
        let body = match tier {
            OctorayTier::Standard => Body::Packed(Scene::new()),
            _ => Body::Vertex(Scene::new()),
        };
        let scene = Box::into_raw(Box::new(OctorayScene { tier, body }));
        // SAFETY: `out` is non-null and, by the contract, valid for writing one pointer.
        unsafe { out.write(scene) };
        OctorayStatus::Ok
    })
}

/// Frees a scene (null is allowed and does nothing).
///
/// # Safety
/// `scene` is null or a pointer from [`octoray_scene_new`] / [`octoray_scene_load`] not freed
/// before, and no other call uses it during or after this one.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_free(scene: *mut OctorayScene) {
    if !scene.is_null() {
        // SAFETY: by the contract `scene` came from `Box::into_raw` and is freed only here.
        drop(unsafe { Box::from_raw(scene) });
    }
}

/// `&mut` to a caller's scene, or the status to answer.
///
/// # Safety
/// `scene` is null or a live scene no other call uses meanwhile.
unsafe fn scene_mut<'a>(
    scene: *mut OctorayScene,
    call: &str,
) -> Result<&'a mut OctorayScene, OctorayStatus> {
    // SAFETY: by the contract, a non-null `scene` is live and not aliased during the call.
    unsafe { scene.as_mut() }
        .ok_or_else(|| fail(OctorayStatus::NullPointer, format!("{call}: scene is null")))
}

/// `&` to a caller's scene, or the status to answer.
///
/// # Safety
/// `scene` is null or a live scene not changed meanwhile.
unsafe fn scene_ref<'a>(
    scene: *const OctorayScene,
    call: &str,
) -> Result<&'a OctorayScene, OctorayStatus> {
    // SAFETY: by the contract, a non-null `scene` is live and not changed during the call.
    unsafe { scene.as_ref() }
        .ok_or_else(|| fail(OctorayStatus::NullPointer, format!("{call}: scene is null")))
}

/// A caller's buffer of `n` items as a slice (empty when `n == 0`, whatever the pointer).
///
/// # Safety
/// `ptr` is null or valid for reading `n` items.
unsafe fn slice<'a, T>(
    ptr: *const T,
    n: usize,
    call: &str,
    what: &str,
) -> Result<&'a [T], OctorayStatus> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(fail(
            OctorayStatus::NullPointer,
            format!("{call}: {what} is null"),
        ));
    }
    // SAFETY: non-null and, by the contract, valid for reading `n` items.
    Ok(unsafe { core::slice::from_raw_parts(ptr, n) })
}

/// A caller's output buffer of `n` items as a slice.
///
/// # Safety
/// `ptr` is null or valid for writing `n` items, and not read or written elsewhere during the
/// call.
unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    n: usize,
    call: &str,
    what: &str,
) -> Result<&'a mut [T], OctorayStatus> {
    if n == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() {
        return Err(fail(
            OctorayStatus::NullPointer,
            format!("{call}: {what} is null"),
        ));
    }
    // SAFETY: non-null and, by the contract, valid and exclusive for `n` items.
    Ok(unsafe { core::slice::from_raw_parts_mut(ptr, n) })
}

/// An output pointer, or [`OctorayStatus::NullPointer`] naming it.
fn null_check<T>(p: *mut T, call: &str, what: &str) -> Result<*mut T, OctorayStatus> {
    if p.is_null() {
        Err(fail(
            OctorayStatus::NullPointer,
            format!("{call}: {what} is null"),
        ))
    } else {
        Ok(p)
    }
}

/// Writes `value` through an output pointer that the caller checked is non-null.
///
/// # Safety
/// `ptr` is valid for writing one `T`.
unsafe fn put<T>(ptr: *mut T, value: T) {
    // SAFETY: the caller's contract.
    unsafe { ptr.write(value) }
}

/// Turns an early-exit status into the answer.
fn run(body: impl FnOnce() -> Result<(), OctorayStatus>) -> OctorayStatus {
    guard(|| match body() {
        Ok(()) => OctorayStatus::Ok,
        Err(s) => s,
    })
}

/// Adds a triangle mesh: `vertex_count` vertices of three floats (x, y, z) and
/// `triangle_count` triangles of three vertex indices. Its geometry ID goes to `*geom`.
/// Triangles with a non-finite vertex are never hit.
///
/// # Safety
/// `scene` is a live scene no other call uses meanwhile; `vertices` is valid for reading
/// `3·vertex_count` floats, `indices` for `3·triangle_count` indices, `geom` for writing one
/// ID.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_add_mesh(
    scene: *mut OctorayScene,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    geom: *mut u32,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_add_mesh";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_mut(scene, CALL) }?;
        let words = vertex_count
            .checked_mul(3)
            .ok_or_else(|| fail(OctorayStatus::InvalidArgument, "too many vertices"))?;
        let n = triangle_count
            .checked_mul(3)
            .ok_or_else(|| fail(OctorayStatus::InvalidArgument, "too many triangles"))?;
        // SAFETY: the function's contract.
        let v = unsafe { slice(vertices, words, CALL, "vertices") }?;
        // SAFETY: the function's contract.
        let idx = unsafe { slice(indices, n, CALL, "indices") }?;
        if geom.is_null() {
            return Err(fail(
                OctorayStatus::NullPointer,
                format!("{CALL}: geom is null"),
            ));
        }
        if let Some(k) = idx.iter().position(|&i| i as usize >= vertex_count) {
            return Err(fail(
                OctorayStatus::InvalidArgument,
                format!(
                    "{CALL}: index {k} is {}, past the {vertex_count} vertices",
                    idx[k]
                ),
            ));
        }
        let p = |i: u32| Vec3::from_slice(&v[3 * i as usize..][..3]);
        let tri = |t: &[u32]| (p(t[0]), p(t[1]), p(t[2]));
        let built = match &mut s.body {
            Body::Packed(sc) => {
                let prims: Vec<_> = idx
                    .chunks(3)
                    .map(|t| {
                        let (a, b, c) = tri(t);
                        PackedTriangle::new(a, b, c)
                    })
                    .collect();
                sc.add_triangles(&prims)
            }
            Body::Vertex(sc) => {
                let prims: Vec<_> = idx
                    .chunks(3)
                    .map(|t| {
                        let (a, b, c) = tri(t);
                        VertexTriangle::new(a, b, c)
                    })
                    .collect();
                sc.add_triangles(&prims)
            }
            Body::Loaded(_) => return Err(read_only(CALL)),
        };
        let id = built.map_err(|e| fail(OctorayStatus::BuildFailed, format!("{CALL}: {e}")))?;
        // SAFETY: `geom` is non-null and, by the contract, valid for writing.
        unsafe { put(geom, id) };
        Ok(())
    })
}

fn read_only(call: &str) -> OctorayStatus {
    fail(
        OctorayStatus::ReadOnly,
        format!("{call}: a loaded scene cannot be changed"),
    )
}

/// Adds a set of spheres: `count` spheres of four floats (center x, y, z, radius). Its
/// geometry ID goes to `*geom`.
///
/// # Safety
/// `scene` is a live scene no other call uses meanwhile; `spheres` is valid for reading
/// `4·count` floats, `geom` for writing one ID.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_add_spheres(
    scene: *mut OctorayScene,
    spheres: *const f32,
    count: usize,
    geom: *mut u32,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_add_spheres";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_mut(scene, CALL) }?;
        let n = count
            .checked_mul(4)
            .ok_or_else(|| fail(OctorayStatus::InvalidArgument, "too many spheres"))?;
        // SAFETY: the function's contract.
        let f = unsafe { slice(spheres, n, CALL, "spheres") }?;
        if geom.is_null() {
            return Err(fail(
                OctorayStatus::NullPointer,
                format!("{CALL}: geom is null"),
            ));
        }
        let prims: Vec<PackedSphere> = f
            .chunks(4)
            .map(|c| PackedSphere::new(Vec3::new(c[0], c[1], c[2]), c[3]))
            .collect();
        let built = match &mut s.body {
            Body::Packed(sc) => sc.add_spheres(&prims),
            Body::Vertex(sc) => sc.add_spheres(&prims),
            Body::Loaded(_) => return Err(read_only(CALL)),
        };
        let id = built.map_err(|e| fail(OctorayStatus::BuildFailed, format!("{CALL}: {e}")))?;
        // SAFETY: `geom` is non-null and, by the contract, valid for writing.
        unsafe { put(geom, id) };
        Ok(())
    })
}

/// Places geometries of one kind (all meshes or all sphere sets; one bottom-level tree over all
/// of them, shared by every instance of the same set) with `object_to_world`, 12 floats: a 3×4 row-major matrix `[A | b]` mapping object
/// to world (null for the identity), and a mask ANDed with each query's. Its instance ID goes
/// to `*inst`. Rays are carried into object space by the inverse, formed in f64 and rounded
/// once (`octoray::scene::Transform::placing`).
///
/// # Safety
/// `scene` is a live scene no other call uses meanwhile; `geoms` is valid for reading
/// `geom_count` IDs; `object_to_world` is null or valid for reading 12 floats; `inst` is valid
/// for writing one ID.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_add_instance(
    scene: *mut OctorayScene,
    geoms: *const u32,
    geom_count: usize,
    object_to_world: *const f32,
    mask: u32,
    inst: *mut u32,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_add_instance";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_mut(scene, CALL) }?;
        // SAFETY: the function's contract.
        let ids = unsafe { slice(geoms, geom_count, CALL, "geoms") }?;
        if inst.is_null() {
            return Err(fail(
                OctorayStatus::NullPointer,
                format!("{CALL}: inst is null"),
            ));
        }
        let transform = if object_to_world.is_null() {
            Transform::IDENTITY
        } else {
            // SAFETY: non-null and, by the contract, valid for reading 12 floats.
            let m = unsafe { slice(object_to_world, 12, CALL, "object_to_world") }?;
            let col = |j: usize| Vec3A::new(m[j], m[4 + j], m[8 + j]);
            let place = Affine3A {
                matrix3: Mat3A::from_cols(col(0), col(1), col(2)),
                translation: col(3),
            };
            Transform::placing(place).ok_or_else(|| {
                fail(
                    OctorayStatus::InvalidArgument,
                    format!("{CALL}: the transform is not finite or not invertible"),
                )
            })?
        };
        let known = match &s.body {
            Body::Packed(sc) => sc.geometries(),
            Body::Vertex(sc) => sc.geometries(),
            Body::Loaded(_) => return Err(read_only(CALL)),
        };
        if ids.is_empty() {
            return Err(fail(
                OctorayStatus::InvalidArgument,
                format!("{CALL}: no geometries"),
            ));
        }
        if let Some(&g) = ids.iter().find(|&&g| g as usize >= known.len()) {
            return Err(fail(
                OctorayStatus::InvalidArgument,
                format!("{CALL}: no geometry {g}"),
            ));
        }
        // One tree per instance: its geometries are all meshes or all sphere sets.
        let kind = |g: u32| known[g as usize].kind;
        if ids.iter().any(|&g| kind(g) != kind(ids[0])) {
            return Err(fail(
                OctorayStatus::InvalidArgument,
                format!("{CALL}: an instance places meshes or sphere sets, not both"),
            ));
        }
        let id = match &mut s.body {
            Body::Packed(sc) => sc.add_instance(ids, transform, mask),
            Body::Vertex(sc) => sc.add_instance(ids, transform, mask),
            Body::Loaded(_) => unreachable!("checked above"),
        };
        // SAFETY: `inst` is non-null and, by the contract, valid for writing.
        unsafe { put(inst, id) };
        Ok(())
    })
}

/// Builds the top-level tree over the instances: call after adding or changing instances and
/// before tracing.
///
/// # Safety
/// `scene` is a live scene no other call uses meanwhile.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_commit(scene: *mut OctorayScene) -> OctorayStatus {
    const CALL: &str = "octoray_scene_commit";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_mut(scene, CALL) }?;
        let done = match &mut s.body {
            Body::Packed(sc) => sc.commit_on(&octoray::bvh::Sequential),
            Body::Vertex(sc) => sc.commit_on(&octoray::bvh::Sequential),
            Body::Loaded(_) => return Err(read_only(CALL)),
        };
        done.map_err(|e| fail(OctorayStatus::BuildFailed, format!("{CALL}: {e}")))
    })
}

impl OctorayScene {
    fn view(&self, call: &str) -> Result<View<'_>, OctorayStatus> {
        let not_committed = || {
            fail(
                OctorayStatus::NotCommitted,
                format!("{call}: the scene changed since its last commit"),
            )
        };
        Ok(match &self.body {
            Body::Packed(sc) if sc.is_committed() => View::Packed(sc.as_ref()),
            Body::Vertex(sc) if sc.is_committed() => View::Vertex(sc.as_ref()),
            Body::Packed(_) | Body::Vertex(_) => return Err(not_committed()),
            Body::Loaded(l) => l.view(),
        })
    }
}

/// The closest hit of one ray whose geometry and instance masks share a bit with `mask`.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading, `hit` for
/// writing.
#[no_mangle]
pub unsafe extern "C" fn octoray_closest1(
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    hit: *mut OctorayHit,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::one::<Closest>("octoray_closest1", scene, ray, mask, hit) }
}

/// Whether one ray hits anything in its range (occlusion): `*occluded` is 1 or 0.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading, `occluded` for
/// writing.
#[no_mangle]
pub unsafe extern "C" fn octoray_occluded1(
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    occluded: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::one::<Occluded>("octoray_occluded1", scene, ray, mask, occluded) }
}

/// The closest hit of each of `count` rays (`hits[i]` for `rays[i]`), in 8-ray packets where
/// neighbouring rays share a direction octant.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading `count` rays,
/// `hits` for writing `count` hits.
#[no_mangle]
pub unsafe extern "C" fn octoray_closest(
    scene: *const OctorayScene,
    rays: *const OctorayRay,
    count: usize,
    mask: u32,
    hits: *mut OctorayHit,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::many::<Closest>("octoray_closest", scene, rays, count, mask, hits) }
}

/// Occlusion of each of `count` rays (`occluded[i]` is 1 or 0), packets as
/// [`octoray_closest`].
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading `count` rays,
/// `occluded` for writing `count` bytes.
#[no_mangle]
pub unsafe extern "C" fn octoray_occluded(
    scene: *const OctorayScene,
    rays: *const OctorayRay,
    count: usize,
    mask: u32,
    occluded: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::many::<Occluded>("octoray_occluded", scene, rays, count, mask, occluded) }
}

/// Every hit of one ray in its range whose geometry and instance masks share a bit with `mask`,
/// nearest first (by `t`, then instance, geometry and primitive; each primitive of each
/// instance once), into `hits`: the first `capacity` hits after `*after` (null: from the
/// start). `*stored` gets how many were written and `*complete` 1 when they are all of them,
/// 0 when more follow: call again with `after` the last one written.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `after` is null
/// or valid for reading; `hits` is valid for writing `capacity` hits (may be null when
/// `capacity` is 0); `stored` and `complete` are valid for writing.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the C signature
pub unsafe extern "C" fn octoray_all_hits1(
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    after: *const OctorayHit,
    hits: *mut OctorayHit,
    capacity: usize,
    stored: *mut usize,
    complete: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe {
        trace::all_hits(
            "octoray_all_hits1",
            scene,
            ray,
            mask,
            after,
            hits,
            capacity,
            (stored, complete),
        )
    }
}

/// The primitive nearest to a point, and the point on it (a miss: `prim == OCTORAY_NO_HIT`,
/// `dist` infinite, the rest 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctorayPointHit {
    /// The nearest point (world space).
    pub point: [f32; 3],
    /// Its distance to the query point.
    pub dist: f32,
    /// Barycentric weight of the triangle's second vertex at the point (0 for spheres).
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex at the point (0 for spheres).
    pub v: f32,
    /// The primitive's index in its geometry.
    pub prim: u32,
    /// The geometry.
    pub geom: u32,
    /// The instance path it was found through.
    pub inst: u32,
}

impl From<Option<PointHit>> for OctorayPointHit {
    fn from(h: Option<PointHit>) -> Self {
        match h {
            Some(h) => Self {
                point: h.point.to_array(),
                dist: h.dist,
                u: h.u,
                v: h.v,
                prim: h.prim,
                geom: h.geom,
                inst: h.inst,
            },
            None => Self {
                point: [0.0; 3],
                dist: f32::INFINITY,
                u: 0.0,
                v: 0.0,
                prim: OCTORAY_NO_HIT,
                geom: OCTORAY_NO_HIT,
                inst: OCTORAY_NO_HIT,
            },
        }
    }
}

/// Where a primitive of a scene lies: the instance path it is reached through, its geometry and
/// its index in the geometry (ordered in that order).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct OctorayPlace {
    /// The instance path.
    pub inst: u32,
    /// The geometry.
    pub geom: u32,
    /// The primitive's index in its geometry.
    pub prim: u32,
}

impl From<octoray::scene::Place> for OctorayPlace {
    fn from(p: octoray::scene::Place) -> Self {
        Self {
            inst: p.inst,
            geom: p.geom,
            prim: p.prim,
        }
    }
}

impl From<OctorayPlace> for octoray::scene::Place {
    fn from(p: OctorayPlace) -> Self {
        Self {
            inst: p.inst,
            geom: p.geom,
            prim: p.prim,
        }
    }
}

/// The primitives that meet the closed world box `[lo, hi]` (three floats each) among the
/// instances and geometries whose masks share a bit with `mask`, in ascending order of place,
/// each once: the first `capacity` after `*after` (null: from the start) into `places`.
/// `*stored` gets how many were written and `*complete` 1 when they are all of them, 0 when
/// more follow: call again with `after` the last one written. Each candidate is tested in world
/// space (an instanced sphere as the ellipsoid its instance makes of it), exactly but for
/// primitives touching the box within a few units of 2⁻⁵⁰ of its coordinates; a box with a NaN
/// corner or `lo > hi` on an axis meets nothing.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `lo` and `hi` are valid for reading three
/// floats; `after` is null or valid for reading; `places` is valid for writing `capacity`
/// places (may be null when `capacity` is 0); `stored` and `complete` are valid for writing.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the C signature
pub unsafe extern "C" fn octoray_overlapping1(
    scene: *const OctorayScene,
    lo: *const f32,
    hi: *const f32,
    mask: u32,
    after: *const OctorayPlace,
    places: *mut OctorayPlace,
    capacity: usize,
    stored: *mut usize,
    complete: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe {
        trace::overlapping(
            "octoray_overlapping1",
            scene,
            (lo, hi),
            mask,
            after,
            (places, capacity),
            (stored, complete),
        )
    }
}

/// The primitive nearest to `point` (three floats, world space) at a distance of at most
/// `max_dist` (`INFINITY`: no limit) among the instances and geometries whose masks share a bit
/// with `mask`, into `*out`: the point on it, its distance and barycentrics, where it lies; a
/// miss when none is that near, for a non-finite point and for a NaN or negative `max_dist`.
/// Ties in distance go to the lower (instance, geometry, primitive). Each primitive is measured
/// in world space in f64 (an instanced sphere as the ellipsoid its instance makes of it).
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` is valid for writing one `OctorayPointHit`.
#[no_mangle]
pub unsafe extern "C" fn octoray_closest_point1(
    scene: *const OctorayScene,
    point: *const f32,
    max_dist: f32,
    mask: u32,
    out: *mut OctorayPointHit,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::closest_point("octoray_closest_point1", scene, point, max_dist, mask, out) }
}

/// How many triangles one ray crosses in `(t_min, t_max)` among the instances and geometries
/// whose masks share a bit with `mask`, into `*out`: exactly, each triangle of each instance
/// once, a ray through a shared edge or vertex of a closed mesh crossing one triangle there
/// (the crossing rule, in each instance's object space); spheres do not count. For a
/// scene of closed meshes, the parity says whether the ray's ends are on the same side.
/// `InvalidArgument` for a standard-tier scene (its layout has no crossing rule).
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `out` is valid
/// for writing one `uint32_t`.
#[no_mangle]
pub unsafe extern "C" fn octoray_crossings1(
    scene: *const OctorayScene,
    ray: *const OctorayRay,
    mask: u32,
    out: *mut u32,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::crossings("octoray_crossings1", scene, ray, mask, out) }
}

/// Whether `point` (three floats, world space) is inside the scene's closed meshes among the
/// instances and geometries whose masks share a bit with `mask`: `*out` is 1 inside an odd
/// number of them, else 0; exact for the point as each instance's map carries it (a point on a
/// surface as moved an infinitesimal step along +x, then +y, then +z; a non-finite point is
/// outside). Meaningful for scenes whose triangle geometries are closed. `InvalidArgument` for
/// a standard-tier scene.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` is valid for writing one byte.
#[no_mangle]
pub unsafe extern "C" fn octoray_contains1(
    scene: *const OctorayScene,
    point: *const f32,
    mask: u32,
    out: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::contains("octoray_contains1", scene, point, mask, out) }
}

/// The signed distance from `point` (three floats, world space) to the instances and
/// geometries whose masks share a bit with `mask`, into `*out`: the distance to the nearest
/// primitive (as `octoray_closest_point1` finds it), negative where `octoray_contains1` says
/// the point is inside; infinite when nothing is admitted, NaN for a non-finite point.
/// `InvalidArgument` for a standard-tier scene.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `out` is valid for writing one float.
#[no_mangle]
pub unsafe extern "C" fn octoray_signed_distance1(
    scene: *const OctorayScene,
    point: *const f32,
    mask: u32,
    out: *mut f32,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::signed_distance("octoray_signed_distance1", scene, point, mask, out) }
}

/// The `capacity` primitives nearest to `point` (three floats, world space) within `radius`
/// among the instances and geometries whose masks share a bit with `mask`, each as
/// `octoray_closest_point1` reports it, into `near` in order of distance (ties by instance,
/// geometry, primitive), each once. `*stored` gets how many were written; `*complete` is 1
/// when the buffer was not filled (they are all there are), 0 when it was (more may lie within
/// `radius`, none nearer than the last); with `capacity` 0, 1 when none lies within `radius`.
/// A non-finite point, a NaN or negative radius: none.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
/// `near` is valid for writing `capacity` answers (may be null when `capacity` is 0); `stored`
/// and `complete` are valid for writing.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the C signature
pub unsafe extern "C" fn octoray_nearest_within1(
    scene: *const OctorayScene,
    point: *const f32,
    radius: f32,
    mask: u32,
    near: *mut OctorayPointHit,
    capacity: usize,
    stored: *mut usize,
    complete: *mut u8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe {
        trace::nearest_within(
            "octoray_nearest_within1",
            scene,
            (point, radius, mask),
            (near, capacity),
            (stored, complete),
        )
    }
}

/// The closest hits of an 8-ray SoA packet (every lane traced; an empty range is a miss).
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
/// `hits` for writing one.
#[no_mangle]
pub unsafe extern "C" fn octoray_closest8(
    scene: *const OctorayScene,
    rays: *const OctorayRay8,
    mask: u32,
    hits: *mut OctorayHit8,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::packet::<Closest, f32x8, 8>("octoray_closest8", scene, rays, mask, hits) }
}

/// The closest hits of a 16-ray SoA packet (every lane traced; an empty range is a miss).
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
/// `hits` for writing one.
#[no_mangle]
pub unsafe extern "C" fn octoray_closest16(
    scene: *const OctorayScene,
    rays: *const OctorayRay16,
    mask: u32,
    hits: *mut OctorayHit16,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::packet::<Closest, f32x16, 16>("octoray_closest16", scene, rays, mask, hits) }
}

/// Occlusion of an 8-ray SoA packet: bit `i` of `*occluded` is lane `i`'s answer.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
/// `occluded` for writing one word.
#[no_mangle]
pub unsafe extern "C" fn octoray_occluded8(
    scene: *const OctorayScene,
    rays: *const OctorayRay8,
    mask: u32,
    occluded: *mut u32,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe { trace::packet::<Occluded, f32x8, 8>("octoray_occluded8", scene, rays, mask, occluded) }
}

/// Occlusion of a 16-ray SoA packet: bit `i` of `*occluded` is lane `i`'s answer.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
/// `occluded` for writing one word.
#[no_mangle]
pub unsafe extern "C" fn octoray_occluded16(
    scene: *const OctorayScene,
    rays: *const OctorayRay16,
    mask: u32,
    occluded: *mut u32,
) -> OctorayStatus {
    // SAFETY: the same contract.
    unsafe {
        trace::packet::<Occluded, f32x16, 16>("octoray_occluded16", scene, rays, mask, occluded)
    }
}

/// Stores a committed scene as bytes: with `bytes` null, `*len` receives the size needed;
/// otherwise the scene is written to `bytes` (`capacity` bytes available) and `*len` receives
/// its size. The bytes are octoray's stored scene (`SceneRef::to_words`, little-endian words),
/// which the Rust API reads too; load them with [`octoray_scene_load`] on any little-endian
/// machine.
///
/// # Safety
/// `scene` is a live scene not changed meanwhile; `bytes` is null or valid for writing
/// `capacity` bytes; `len` is valid for writing.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_store(
    scene: *const OctorayScene,
    bytes: *mut u8,
    capacity: usize,
    len: *mut usize,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_store";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_ref(scene, CALL) }?;
        let len = null_check(len, CALL, "len")?;
        let words = match s.view(CALL)? {
            View::Packed(sc) => sc.to_words(),
            View::Vertex(sc) => sc.to_words(),
        };
        let need = words.len() * 4;
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(len, need) };
        if bytes.is_null() {
            return Ok(());
        }
        if capacity < need {
            return Err(fail(
                OctorayStatus::InvalidArgument,
                format!("{CALL}: {capacity} bytes given, {need} needed"),
            ));
        }
        // SAFETY: non-null and, by the contract, valid for writing `capacity ≥ need` bytes.
        let out = unsafe { slice_mut(bytes, need, CALL, "bytes") }?;
        for (o, w) in out.chunks_exact_mut(4).zip(&words) {
            o.copy_from_slice(&w.to_le_bytes());
        }
        Ok(())
    })
}

/// Loads a stored scene (from [`octoray_scene_store`] or the Rust API's `SceneRef::to_words`)
/// to be traced with `tier` (the layout must be the tier's: the standard tier's scenes load as
/// standard, the watertight and exact tiers' as either), validating every byte in time linear
/// in `len`: bytes that are not a valid scene give [`OctorayStatus::InvalidScene`], never a
/// crash or a query that runs long. The work per ray is bounded too: a scene whose rays could
/// enter more instances than it stores 32-bit words (its instance copies multiplied down the
/// levels of nested groups) is refused as [`OctorayStatus::InvalidScene`], so one ray enters at
/// most about `len / 4` instances, each walking one tree once. Only instances reached from the
/// world are traced. The bytes are copied; the scene can be traced, not changed.
///
/// # Safety
/// `bytes` is valid for reading `len` bytes; `out` is valid for writing one pointer. On
/// success `*out` owns a scene the caller frees with [`octoray_scene_free`].
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_load(
    bytes: *const u8,
    len: usize,
    tier: u32,
    out: *mut *mut OctorayScene,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_load";
    run(|| {
        // SAFETY: the function's contract.
        let b = unsafe { slice(bytes, len, CALL, "bytes") }?;
        let out = null_check(out, CALL, "out")?;
        let tier = OctorayTier::from_raw(tier).ok_or_else(|| {
            fail(
                OctorayStatus::InvalidArgument,
                format!("{CALL}: unknown tier {tier}"),
            )
        })?;
        let loaded = store::Loaded::new(b, tier)
            .map_err(|e| fail(OctorayStatus::InvalidScene, format!("{CALL}: {e}")))?;
        let scene = Box::into_raw(Box::new(OctorayScene {
            tier,
            body: Body::Loaded(loaded),
        }));
        // SAFETY: non-null and, by the contract, valid for writing one pointer.
        unsafe { put(out, scene) };
        Ok(())
    })
}

/// The scene's tier (an [`OctorayTier`] value) in `*tier`.
///
/// # Safety
/// `scene` is a live scene; `tier` is valid for writing.
#[no_mangle]
pub unsafe extern "C" fn octoray_scene_tier(
    scene: *const OctorayScene,
    tier: *mut u32,
) -> OctorayStatus {
    const CALL: &str = "octoray_scene_tier";
    run(|| {
        // SAFETY: the function's contract.
        let s = unsafe { scene_ref(scene, CALL) }?;
        let out = null_check(tier, CALL, "tier")?;
        // SAFETY: non-null and, by the contract, valid for writing.
        unsafe { put(out, s.tier as u32) };
        Ok(())
    })
}
