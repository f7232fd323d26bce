/* octoray's C API. Generated from octoray-capi/src/lib.rs by cbindgen (tests/header.rs); do not edit. */

#ifndef OCTORAY_H
#define OCTORAY_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

// `prim`, `geom` and `inst` of a miss.
#define OCTORAY_NO_HIT UINT32_MAX

// What a call answered.
typedef enum OctorayStatus {
  // Success.
  OCTORAY_STATUS_OK = 0,
  // A required pointer was null.
  OCTORAY_STATUS_NULL_POINTER = 1,
  // An argument is out of its range (an unknown tier, an index past a buffer, a geometry
  // that does not exist, a transform that is not invertible, a buffer too small).
  OCTORAY_STATUS_INVALID_ARGUMENT = 2,
  // A tree could not be built (more primitives than a tree holds).
  OCTORAY_STATUS_BUILD_FAILED = 3,
  // The scene changed since its last `octoray_scene_commit`.
  OCTORAY_STATUS_NOT_COMMITTED = 4,
  // Stored scene bytes are not a valid scene (nothing is read past a check that failed).
  OCTORAY_STATUS_INVALID_SCENE = 5,
  // The call was given a scene loaded from bytes, which cannot be changed.
  OCTORAY_STATUS_READ_ONLY = 6,
  // octoray panicked (a bug): the call had no effect on its outputs.
  OCTORAY_STATUS_PANIC = 7,
} OctorayStatus;

// The accuracy tier a scene's triangles are tested with (its layout follows).
typedef enum OctorayTier {
  // Möller-Trumbore on packed triangles: fastest, not watertight.
  OCTORAY_TIER_STANDARD = 0,
  // Woop-Benthin-Wald with exact fallbacks: no ray escapes a closed mesh.
  OCTORAY_TIER_WATERTIGHT = 1,
  // Exact hit/miss decisions for the f32 inputs, `t` within about an ulp.
  OCTORAY_TIER_EXACT = 2,
} OctorayTier;

// A scene: built by the caller (geometries, instances, commit) or loaded from stored bytes.
// Opaque to C; create with [`octoray_scene_new`] or [`octoray_scene_load`], free with
// [`octoray_scene_free`]. Not safe to change from two threads at once; tracing from many
// threads at once is safe.
typedef struct OctorayScene OctorayScene;

// A ray: origin, direction (any length, not zero) and the accepted range of `t`.
typedef struct OctorayRay {
  // Origin x, y, z.
  float org[3];
  // Direction x, y, z.
  float dir[3];
  // Smallest accepted `t`.
  float t_min;
  // Largest accepted `t` (`INFINITY` for none).
  float t_max;
} OctorayRay;

// A hit, or a miss (`prim == OCTORAY_NO_HIT`, `t` infinite, the rest 0).
typedef struct OctorayHit {
  // Ray parameter of the hit.
  float t;
  // Barycentric weight of the triangle's second vertex (0 for spheres).
  float u;
  // Barycentric weight of the triangle's third vertex (0 for spheres).
  float v;
  // The primitive's index in its geometry.
  uint32_t prim;
  // The geometry.
  uint32_t geom;
  // The instance the ray met it through.
  uint32_t inst;
} OctorayHit;

// Where a primitive of a scene lies: the instance path it is reached through, its geometry and
// its index in the geometry (ordered in that order).
typedef struct OctorayPlace {
  // The instance path.
  uint32_t inst;
  // The geometry.
  uint32_t geom;
  // The primitive's index in its geometry.
  uint32_t prim;
} OctorayPlace;

// The primitive nearest to a point, and the point on it (a miss: `prim == OCTORAY_NO_HIT`,
// `dist` infinite, the rest 0).
typedef struct OctorayPointHit {
  // The nearest point (world space).
  float point[3];
  // Its distance to the query point.
  float dist;
  // Barycentric weight of the triangle's second vertex at the point (0 for spheres).
  float u;
  // Barycentric weight of the triangle's third vertex at the point (0 for spheres).
  float v;
  // The primitive's index in its geometry.
  uint32_t prim;
  // The geometry.
  uint32_t geom;
  // The instance path it was found through.
  uint32_t inst;
} OctorayPointHit;

// `N` rays, structure of arrays. A lane with `t_min > t_max` is a miss (fill unused lanes
// so).
typedef struct OctorayRays_8 {
  // Origins, x, y, z per lane.
  float org[3][8];
  // Directions, x, y, z per lane.
  float dir[3][8];
  // Smallest accepted `t` per lane.
  float t_min[8];
  // Largest accepted `t` per lane.
  float t_max[8];
} OctorayRays_8;

// Eight rays, structure of arrays.
typedef struct OctorayRays_8 OctorayRay8;

// `N` hits, structure of arrays (a miss as in [`OctorayHit`]).
typedef struct OctorayHits_8 {
  // `t` per lane.
  float t[8];
  // `u` per lane.
  float u[8];
  // `v` per lane.
  float v[8];
  // Primitive per lane.
  uint32_t prim[8];
  // Geometry per lane.
  uint32_t geom[8];
  // Instance per lane.
  uint32_t inst[8];
} OctorayHits_8;

// Eight hits, structure of arrays.
typedef struct OctorayHits_8 OctorayHit8;

// `N` rays, structure of arrays. A lane with `t_min > t_max` is a miss (fill unused lanes
// so).
typedef struct OctorayRays_16 {
  // Origins, x, y, z per lane.
  float org[3][16];
  // Directions, x, y, z per lane.
  float dir[3][16];
  // Smallest accepted `t` per lane.
  float t_min[16];
  // Largest accepted `t` per lane.
  float t_max[16];
} OctorayRays_16;

// Sixteen rays, structure of arrays.
typedef struct OctorayRays_16 OctorayRay16;

// `N` hits, structure of arrays (a miss as in [`OctorayHit`]).
typedef struct OctorayHits_16 {
  // `t` per lane.
  float t[16];
  // `u` per lane.
  float u[16];
  // `v` per lane.
  float v[16];
  // Primitive per lane.
  uint32_t prim[16];
  // Geometry per lane.
  uint32_t geom[16];
  // Instance per lane.
  uint32_t inst[16];
} OctorayHits_16;

// Sixteen hits, structure of arrays.
typedef struct OctorayHits_16 OctorayHit16;

#ifdef __cplusplus
extern "C" {
#endif // __cplusplus

// The message of the last failed call on this thread (empty after none), valid until the next
// failing call on this thread. Never null.
const char *octoray_last_error(void);

// Creates an empty scene whose triangles are tested with `tier` (an [`OctorayTier`] value).
//
// # Safety
// `out` is null or valid for writing one pointer. On success `*out` owns a scene the caller
// frees with [`octoray_scene_free`].
enum OctorayStatus octoray_scene_new(uint32_t tier, struct OctorayScene **out);

// Frees a scene (null is allowed and does nothing).
//
// # Safety
// `scene` is null or a pointer from [`octoray_scene_new`] / [`octoray_scene_load`] not freed
// before, and no other call uses it during or after this one.
void octoray_scene_free(struct OctorayScene *scene);

// Adds a triangle mesh: `vertex_count` vertices of three floats (x, y, z) and
// `triangle_count` triangles of three vertex indices. Its geometry ID goes to `*geom`.
// Triangles with a non-finite vertex are never hit.
//
// # Safety
// `scene` is a live scene no other call uses meanwhile; `vertices` is valid for reading
// `3·vertex_count` floats, `indices` for `3·triangle_count` indices, `geom` for writing one
// ID.
enum OctorayStatus octoray_scene_add_mesh(struct OctorayScene *scene,
                                          const float *vertices,
                                          size_t vertex_count,
                                          const uint32_t *indices,
                                          size_t triangle_count,
                                          uint32_t *geom);

// Adds a set of spheres: `count` spheres of four floats (center x, y, z, radius). Its
// geometry ID goes to `*geom`.
//
// # Safety
// `scene` is a live scene no other call uses meanwhile; `spheres` is valid for reading
// `4·count` floats, `geom` for writing one ID.
enum OctorayStatus octoray_scene_add_spheres(struct OctorayScene *scene,
                                             const float *spheres,
                                             size_t count,
                                             uint32_t *geom);

// Places geometries of one kind (all meshes or all sphere sets; one bottom-level tree over all
// of them, shared by every instance of the same set) with `object_to_world`, 12 floats: a 3×4 row-major matrix `[A | b]` mapping object
// to world (null for the identity), and a mask ANDed with each query's. Its instance ID goes
// to `*inst`. Rays are carried into object space by the inverse, formed in f64 and rounded
// once (`octoray::scene::Transform::placing`).
//
// # Safety
// `scene` is a live scene no other call uses meanwhile; `geoms` is valid for reading
// `geom_count` IDs; `object_to_world` is null or valid for reading 12 floats; `inst` is valid
// for writing one ID.
enum OctorayStatus octoray_scene_add_instance(struct OctorayScene *scene,
                                              const uint32_t *geoms,
                                              size_t geom_count,
                                              const float *object_to_world,
                                              uint32_t mask,
                                              uint32_t *inst);

// Builds the top-level tree over the instances: call after adding or changing instances and
// before tracing.
//
// # Safety
// `scene` is a live scene no other call uses meanwhile.
enum OctorayStatus octoray_scene_commit(struct OctorayScene *scene);

// The closest hit of one ray whose geometry and instance masks share a bit with `mask`.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `ray` is valid for reading, `hit` for
// writing.
enum OctorayStatus octoray_closest1(const struct OctorayScene *scene,
                                    const struct OctorayRay *ray,
                                    uint32_t mask,
                                    struct OctorayHit *hit);

// Whether one ray hits anything in its range (occlusion): `*occluded` is 1 or 0.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `ray` is valid for reading, `occluded` for
// writing.
enum OctorayStatus octoray_occluded1(const struct OctorayScene *scene,
                                     const struct OctorayRay *ray,
                                     uint32_t mask,
                                     uint8_t *occluded);

// The closest hit of each of `count` rays (`hits[i]` for `rays[i]`), in 8-ray packets where
// neighbouring rays share a direction octant.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading `count` rays,
// `hits` for writing `count` hits.
enum OctorayStatus octoray_closest(const struct OctorayScene *scene,
                                   const struct OctorayRay *rays,
                                   size_t count,
                                   uint32_t mask,
                                   struct OctorayHit *hits);

// Occlusion of each of `count` rays (`occluded[i]` is 1 or 0), packets as
// [`octoray_closest`].
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading `count` rays,
// `occluded` for writing `count` bytes.
enum OctorayStatus octoray_occluded(const struct OctorayScene *scene,
                                    const struct OctorayRay *rays,
                                    size_t count,
                                    uint32_t mask,
                                    uint8_t *occluded);

// Every hit of one ray in its range whose geometry and instance masks share a bit with `mask`,
// nearest first (by `t`, then instance, geometry and primitive; each primitive of each
// instance once), into `hits`: the first `capacity` hits after `*after` (null: from the
// start). `*stored` gets how many were written and `*complete` 1 when they are all of them,
// 0 when more follow: call again with `after` the last one written.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `after` is null
// or valid for reading; `hits` is valid for writing `capacity` hits (may be null when
// `capacity` is 0); `stored` and `complete` are valid for writing.
enum OctorayStatus octoray_all_hits1(const struct OctorayScene *scene,
                                     const struct OctorayRay *ray,
                                     uint32_t mask,
                                     const struct OctorayHit *after,
                                     struct OctorayHit *hits,
                                     size_t capacity,
                                     size_t *stored,
                                     uint8_t *complete);

// The primitives that meet the closed world box `[lo, hi]` (three floats each) among the
// instances and geometries whose masks share a bit with `mask`, in ascending order of place,
// each once: the first `capacity` after `*after` (null: from the start) into `places`.
// `*stored` gets how many were written and `*complete` 1 when they are all of them, 0 when
// more follow: call again with `after` the last one written. Each candidate is tested in world
// space (an instanced sphere as the ellipsoid its instance makes of it), exactly but for
// primitives touching the box within a few units of 2⁻⁵⁰ of its coordinates; a box with a NaN
// corner or `lo > hi` on an axis meets nothing.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `lo` and `hi` are valid for reading three
// floats; `after` is null or valid for reading; `places` is valid for writing `capacity`
// places (may be null when `capacity` is 0); `stored` and `complete` are valid for writing.
enum OctorayStatus octoray_overlapping1(const struct OctorayScene *scene,
                                        const float *lo,
                                        const float *hi,
                                        uint32_t mask,
                                        const struct OctorayPlace *after,
                                        struct OctorayPlace *places,
                                        size_t capacity,
                                        size_t *stored,
                                        uint8_t *complete);

// The primitive nearest to `point` (three floats, world space) at a distance of at most
// `max_dist` (`INFINITY`: no limit) among the instances and geometries whose masks share a bit
// with `mask`, into `*out`: the point on it, its distance and barycentrics, where it lies; a
// miss when none is that near, for a non-finite point and for a NaN or negative `max_dist`.
// Ties in distance go to the lower (instance, geometry, primitive). Each primitive is measured
// in world space in f64 (an instanced sphere as the ellipsoid its instance makes of it).
//
// # Safety
// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
// `out` is valid for writing one `OctorayPointHit`.
enum OctorayStatus octoray_closest_point1(const struct OctorayScene *scene,
                                          const float *point,
                                          float max_dist,
                                          uint32_t mask,
                                          struct OctorayPointHit *out);

// How many triangles one ray crosses in `(t_min, t_max)` among the instances and geometries
// whose masks share a bit with `mask`, into `*out`: exactly, each triangle of each instance
// once, a ray through a shared edge or vertex of a closed mesh crossing one triangle there
// (the crossing rule, in each instance's object space); spheres do not count. For a
// scene of closed meshes, the parity says whether the ray's ends are on the same side.
// `InvalidArgument` for a standard-tier scene (its layout has no crossing rule).
//
// # Safety
// `scene` is a live scene not changed meanwhile; `ray` is valid for reading; `out` is valid
// for writing one `uint32_t`.
enum OctorayStatus octoray_crossings1(const struct OctorayScene *scene,
                                      const struct OctorayRay *ray,
                                      uint32_t mask,
                                      uint32_t *out);

// Whether `point` (three floats, world space) is inside the scene's closed meshes among the
// instances and geometries whose masks share a bit with `mask`: `*out` is 1 inside an odd
// number of them, else 0; exact for the point as each instance's map carries it (a point on a
// surface as moved an infinitesimal step along +x, then +y, then +z; a non-finite point is
// outside). Meaningful for scenes whose triangle geometries are closed. `InvalidArgument` for
// a standard-tier scene.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
// `out` is valid for writing one byte.
enum OctorayStatus octoray_contains1(const struct OctorayScene *scene,
                                     const float *point,
                                     uint32_t mask,
                                     uint8_t *out);

// The signed distance from `point` (three floats, world space) to the instances and
// geometries whose masks share a bit with `mask`, into `*out`: the distance to the nearest
// primitive (as `octoray_closest_point1` finds it), negative where `octoray_contains1` says
// the point is inside; infinite when nothing is admitted, NaN for a non-finite point.
// `InvalidArgument` for a standard-tier scene.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
// `out` is valid for writing one float.
enum OctorayStatus octoray_signed_distance1(const struct OctorayScene *scene,
                                            const float *point,
                                            uint32_t mask,
                                            float *out);

// The `capacity` primitives nearest to `point` (three floats, world space) within `radius`
// among the instances and geometries whose masks share a bit with `mask`, each as
// `octoray_closest_point1` reports it, into `near` in order of distance (ties by instance,
// geometry, primitive), each once. `*stored` gets how many were written; `*complete` is 1
// when the buffer was not filled (they are all there are), 0 when it was (more may lie within
// `radius`, none nearer than the last); with `capacity` 0, 1 when none lies within `radius`.
// A non-finite point, a NaN or negative radius: none.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `point` is valid for reading three floats;
// `near` is valid for writing `capacity` answers (may be null when `capacity` is 0); `stored`
// and `complete` are valid for writing.
enum OctorayStatus octoray_nearest_within1(const struct OctorayScene *scene,
                                           const float *point,
                                           float radius,
                                           uint32_t mask,
                                           struct OctorayPointHit *near,
                                           size_t capacity,
                                           size_t *stored,
                                           uint8_t *complete);

// The closest hits of an 8-ray SoA packet (every lane traced; an empty range is a miss).
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
// `hits` for writing one.
enum OctorayStatus octoray_closest8(const struct OctorayScene *scene,
                                    const OctorayRay8 *rays,
                                    uint32_t mask,
                                    OctorayHit8 *hits);

// The closest hits of a 16-ray SoA packet (every lane traced; an empty range is a miss).
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
// `hits` for writing one.
enum OctorayStatus octoray_closest16(const struct OctorayScene *scene,
                                     const OctorayRay16 *rays,
                                     uint32_t mask,
                                     OctorayHit16 *hits);

// Occlusion of an 8-ray SoA packet: bit `i` of `*occluded` is lane `i`'s answer.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
// `occluded` for writing one word.
enum OctorayStatus octoray_occluded8(const struct OctorayScene *scene,
                                     const OctorayRay8 *rays,
                                     uint32_t mask,
                                     uint32_t *occluded);

// Occlusion of a 16-ray SoA packet: bit `i` of `*occluded` is lane `i`'s answer.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `rays` is valid for reading one packet,
// `occluded` for writing one word.
enum OctorayStatus octoray_occluded16(const struct OctorayScene *scene,
                                      const OctorayRay16 *rays,
                                      uint32_t mask,
                                      uint32_t *occluded);

// Stores a committed scene as bytes: with `bytes` null, `*len` receives the size needed;
// otherwise the scene is written to `bytes` (`capacity` bytes available) and `*len` receives
// its size. The bytes are octoray's stored scene (`SceneRef::to_words`, little-endian words),
// which the Rust API reads too; load them with [`octoray_scene_load`] on any little-endian
// machine.
//
// # Safety
// `scene` is a live scene not changed meanwhile; `bytes` is null or valid for writing
// `capacity` bytes; `len` is valid for writing.
enum OctorayStatus octoray_scene_store(const struct OctorayScene *scene,
                                       uint8_t *bytes,
                                       size_t capacity,
                                       size_t *len);

// Loads a stored scene (from [`octoray_scene_store`] or the Rust API's `SceneRef::to_words`)
// to be traced with `tier` (the layout must be the tier's: the standard tier's scenes load as
// standard, the watertight and exact tiers' as either), validating every byte in time linear
// in `len`: bytes that are not a valid scene give [`OctorayStatus::InvalidScene`], never a
// crash or a query that runs long. The work per ray is bounded too: a scene whose rays could
// enter more instances than it stores 32-bit words (its instance copies multiplied down the
// levels of nested groups) is refused as [`OctorayStatus::InvalidScene`], so one ray enters at
// most about `len / 4` instances, each walking one tree once. Only instances reached from the
// world are traced. The bytes are copied; the scene can be traced, not changed.
//
// # Safety
// `bytes` is valid for reading `len` bytes; `out` is valid for writing one pointer. On
// success `*out` owns a scene the caller frees with [`octoray_scene_free`].
enum OctorayStatus octoray_scene_load(const uint8_t *bytes,
                                      size_t len,
                                      uint32_t tier,
                                      struct OctorayScene **out);

// The scene's tier (an [`OctorayTier`] value) in `*tier`.
//
// # Safety
// `scene` is a live scene; `tier` is valid for writing.
enum OctorayStatus octoray_scene_tier(const struct OctorayScene *scene, uint32_t *tier);

#ifdef __cplusplus
}  // extern "C"
#endif  // __cplusplus

#endif  /* OCTORAY_H */
