//! The C ABI's contracts, called from Rust: every failure is a status with a message (null
//! pointers, an unknown tier, bad indices, a singular transform, an uncommitted scene, a
//! changed loaded scene, a short buffer), stored scenes load back with the same answers at
//! every tier, and hostile bytes (every truncation, every flipped byte of a small scene, random
//! words) never crash a load or a query on what loaded.
use std::ffi::CStr;
use std::ptr::{null, null_mut};

use octoray_capi::*;

fn last_error() -> String {
    // SAFETY: `octoray_last_error` returns a valid NUL-terminated string owned by this thread.
    unsafe { CStr::from_ptr(octoray_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// A tetrahedron and a sphere, one instance each (the tetrahedron's moved by +x 5), committed.
fn small(tier: u32) -> *mut OctorayScene {
    let v: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let idx: [u32; 12] = [0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3];
    let ball: [f32; 4] = [0.0, 0.0, 5.0, 1.0];
    let m: [f32; 12] = [1.0, 0.0, 0.0, 5.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let (mut scene, mut g, mut b, mut i) = (null_mut(), 0, 0, 0);
    // SAFETY: every pointer is valid for what the call reads or writes.
    unsafe {
        assert_eq!(octoray_scene_new(tier, &mut scene), OctorayStatus::Ok);
        assert_eq!(
            octoray_scene_add_mesh(scene, v.as_ptr(), 4, idx.as_ptr(), 4, &mut g),
            OctorayStatus::Ok
        );
        assert_eq!(
            octoray_scene_add_spheres(scene, ball.as_ptr(), 1, &mut b),
            OctorayStatus::Ok
        );
        assert_eq!(
            octoray_scene_add_instance(scene, &g, 1, m.as_ptr(), 1, &mut i),
            OctorayStatus::Ok
        );
        assert_eq!(
            octoray_scene_add_instance(scene, &b, 1, null(), 2, &mut i),
            OctorayStatus::Ok
        );
        assert_eq!(octoray_scene_commit(scene), OctorayStatus::Ok);
    }
    scene
}

fn rays() -> Vec<OctorayRay> {
    (0..64)
        .map(|k| {
            let (x, y) = ((k % 8) as f32 / 4.0 - 0.5, (k / 8) as f32 / 4.0 - 0.5);
            OctorayRay {
                org: [x + 5.0 * (k % 2) as f32, y, -3.0],
                dir: [0.01, 0.02, 1.0],
                t_min: 0.0,
                t_max: f32::INFINITY,
            }
        })
        .collect()
}

fn trace(scene: *const OctorayScene, rays: &[OctorayRay]) -> (OctorayStatus, Vec<OctorayHit>) {
    let mut hits = vec![OctorayHit::from(None); rays.len()];
    // SAFETY: `rays` and `hits` hold `rays.len()` items; `scene` is live.
    let s = unsafe { octoray_closest(scene, rays.as_ptr(), rays.len(), !0, hits.as_mut_ptr()) };
    (s, hits)
}

fn store(scene: *const OctorayScene) -> Vec<u8> {
    let mut len = 0;
    // SAFETY: a null buffer asks for the length; `len` is valid.
    let s = unsafe { octoray_scene_store(scene, null_mut(), 0, &mut len) };
    assert_eq!(s, OctorayStatus::Ok);
    let mut bytes = vec![0u8; len];
    // SAFETY: `bytes` holds `len` bytes.
    let s = unsafe { octoray_scene_store(scene, bytes.as_mut_ptr(), len, &mut len) };
    assert_eq!(s, OctorayStatus::Ok);
    bytes
}

/// Loads `bytes`; on success traces the rays (which must not fail) and frees the scene.
fn load_and_trace(bytes: &[u8]) -> OctorayStatus {
    let mut scene = null_mut();
    // SAFETY: `bytes` is valid for its length; `scene` for writing.
    let s = unsafe { octoray_scene_load(bytes.as_ptr(), bytes.len(), 1, &mut scene) };
    if s == OctorayStatus::Ok {
        let (t, hits) = trace(scene, &rays());
        assert_eq!(t, OctorayStatus::Ok);
        assert!(hits.iter().all(|h| h.prim == u32::MAX || h.t.is_finite()));
        // SAFETY: loaded above, freed once.
        unsafe { octoray_scene_free(scene) };
    } else {
        assert!(!last_error().is_empty());
    }
    s
}

#[test]
fn stored_scenes_load_back_with_the_same_answers_at_every_tier() {
    for tier in 0..3 {
        let scene = small(tier);
        let (s, hits) = trace(scene, &rays());
        assert_eq!(s, OctorayStatus::Ok);
        let (tri, ball) = (
            hits.iter().filter(|h| h.geom == 0).count(),
            hits.iter().filter(|h| h.geom == 1).count(),
        );
        assert!(
            tri > 0 && ball > 0,
            "tier {tier}: {tri} triangle and {ball} sphere hits"
        );
        let bytes = store(scene);
        let mut loaded = null_mut();
        // SAFETY: valid buffers.
        unsafe {
            assert_eq!(
                octoray_scene_load(bytes.as_ptr(), bytes.len(), tier, &mut loaded),
                OctorayStatus::Ok
            );
            let mut t = 9;
            assert_eq!(octoray_scene_tier(loaded, &mut t), OctorayStatus::Ok);
            assert_eq!(t, tier);
            // The layout is the tier's: standard scenes load only as standard, watertight and
            // exact scenes as either; an unknown tier is refused.
            for other in 0..4 {
                let mut o = null_mut();
                let s = octoray_scene_load(bytes.as_ptr(), bytes.len(), other, &mut o);
                let ok = other < 3 && (other == 0) == (tier == 0);
                assert_eq!(
                    s == OctorayStatus::Ok,
                    ok,
                    "stored at {tier}, loaded at {other}"
                );
                octoray_scene_free(o);
            }
        }
        assert_eq!(trace(loaded, &rays()), (OctorayStatus::Ok, hits));
        // A loaded scene is read-only.
        let mut g = 0;
        let ball = [0.0f32; 4];
        // SAFETY: valid buffers; both scenes freed once.
        unsafe {
            assert_eq!(
                octoray_scene_add_spheres(loaded, ball.as_ptr(), 1, &mut g),
                OctorayStatus::ReadOnly
            );
            octoray_scene_free(loaded);
            octoray_scene_free(scene);
        }
    }
}

#[test]
fn single_rays_and_packets_equal_the_array_call() {
    let scene = small(1);
    let rays = rays();
    let (_, hits) = trace(scene, &rays);
    for (k, r) in rays.iter().enumerate() {
        let mut one = OctorayHit::from(None);
        let mut occ = 7u8;
        // SAFETY: valid pointers.
        unsafe {
            assert_eq!(octoray_closest1(scene, r, !0, &mut one), OctorayStatus::Ok);
            assert_eq!(octoray_occluded1(scene, r, !0, &mut occ), OctorayStatus::Ok);
        }
        assert_eq!(one, hits[k]);
        assert_eq!(occ, u8::from(hits[k].prim != u32::MAX));
    }
    for (p, chunk) in rays.chunks(16).enumerate() {
        let mut r16 = OctorayRay16 {
            org: [[0.0; 16]; 3],
            dir: [[0.0; 16]; 3],
            t_min: [0.0; 16],
            t_max: [0.0; 16],
        };
        for (i, r) in chunk.iter().enumerate() {
            for a in 0..3 {
                (r16.org[a][i], r16.dir[a][i]) = (r.org[a], r.dir[a]);
            }
            (r16.t_min[i], r16.t_max[i]) = (r.t_min, r.t_max);
        }
        let mut h16 = std::mem::MaybeUninit::<OctorayHit16>::uninit();
        let mut occ = 0u32;
        // SAFETY: valid pointers; the call writes the whole packet on success.
        let h16 = unsafe {
            assert_eq!(
                octoray_closest16(scene, &r16, !0, h16.as_mut_ptr()),
                OctorayStatus::Ok
            );
            assert_eq!(
                octoray_occluded16(scene, &r16, !0, &mut occ),
                OctorayStatus::Ok
            );
            h16.assume_init()
        };
        for i in 0..16 {
            let h = &hits[16 * p + i];
            assert_eq!(
                (h16.t[i].to_bits(), h16.prim[i], h16.geom[i], h16.inst[i]),
                (h.t.to_bits(), h.prim, h.geom, h.inst)
            );
            assert_eq!(occ >> i & 1 == 1, h.prim != u32::MAX);
        }
    }
    // SAFETY: freed once.
    unsafe { octoray_scene_free(scene) };
}

#[test]
fn every_failure_is_a_status_with_a_message() {
    let mut scene = null_mut();
    let v = [0.0f32; 9];
    let (mut g, mut len) = (0, 0);
    // SAFETY: each call gets valid pointers except the one it is about.
    unsafe {
        assert_eq!(
            octoray_scene_new(3, &mut scene),
            OctorayStatus::InvalidArgument
        );
        assert!(last_error().contains("tier"));
        assert_eq!(octoray_scene_new(1, null_mut()), OctorayStatus::NullPointer);
        assert_eq!(octoray_scene_commit(null_mut()), OctorayStatus::NullPointer);
        assert_eq!(octoray_scene_new(1, &mut scene), OctorayStatus::Ok);
        let bad = [0u32, 1, 3];
        assert_eq!(
            octoray_scene_add_mesh(scene, v.as_ptr(), 3, bad.as_ptr(), 1, &mut g),
            OctorayStatus::InvalidArgument
        );
        assert!(
            last_error().contains("past the 3 vertices"),
            "{}",
            last_error()
        );
        assert_eq!(
            octoray_scene_add_mesh(scene, null(), 3, bad.as_ptr(), 1, &mut g),
            OctorayStatus::NullPointer
        );
        assert_eq!(
            octoray_scene_add_instance(scene, &7, 1, null(), 1, &mut g),
            OctorayStatus::InvalidArgument
        );
        let ok = [0u32, 1, 2];
        assert_eq!(
            octoray_scene_add_mesh(scene, v.as_ptr(), 3, ok.as_ptr(), 1, &mut g),
            OctorayStatus::Ok
        );
        let (ball, mut b) = ([0.0f32, 0.0, 0.0, 1.0], 0);
        assert_eq!(
            octoray_scene_add_spheres(scene, ball.as_ptr(), 1, &mut b),
            OctorayStatus::Ok
        );
        let mixed = [g, b];
        assert_eq!(
            octoray_scene_add_instance(scene, mixed.as_ptr(), 2, null(), 1, &mut b),
            OctorayStatus::InvalidArgument
        );
        assert!(last_error().contains("not both"), "{}", last_error());
        let singular = [0.0f32; 12];
        assert_eq!(
            octoray_scene_add_instance(scene, &g, 1, singular.as_ptr(), 1, &mut g),
            OctorayStatus::InvalidArgument
        );
        assert_eq!(
            octoray_scene_add_instance(scene, &g, 1, null(), 1, &mut g),
            OctorayStatus::Ok
        );
        let r = rays();
        let mut h = OctorayHit::from(None);
        assert_eq!(
            octoray_closest1(scene, &r[0], !0, &mut h),
            OctorayStatus::NotCommitted
        );
        assert_eq!(
            octoray_scene_store(scene, null_mut(), 0, &mut len),
            OctorayStatus::NotCommitted
        );
        assert_eq!(octoray_scene_commit(scene), OctorayStatus::Ok);
        assert_eq!(
            octoray_closest1(scene, &r[0], !0, &mut h),
            OctorayStatus::Ok
        );
        assert_eq!(
            octoray_closest1(scene, &r[0], !0, null_mut()),
            OctorayStatus::NullPointer
        );
        // All hits: a missing output is an error; a zero capacity says whether any hit exists.
        let (mut stored, mut complete) = (7usize, 7u8);
        let mut page = [OctorayHit::from(None); 4];
        assert_eq!(
            octoray_all_hits1(
                scene,
                &r[0],
                !0,
                null(),
                page.as_mut_ptr(),
                4,
                null_mut(),
                &mut complete
            ),
            OctorayStatus::NullPointer
        );
        assert!(last_error().contains("stored"), "{}", last_error());
        assert_eq!(
            octoray_all_hits1(
                scene,
                &r[0],
                !0,
                null(),
                null_mut(),
                4,
                &mut stored,
                &mut complete
            ),
            OctorayStatus::NullPointer
        );
        for ray in &r {
            octoray_closest1(scene, ray, !0, &mut h);
            let hit = h.prim != OCTORAY_NO_HIT;
            assert_eq!(
                octoray_all_hits1(
                    scene,
                    ray,
                    !0,
                    null(),
                    null_mut(),
                    0,
                    &mut stored,
                    &mut complete
                ),
                OctorayStatus::Ok
            );
            assert_eq!((stored, complete), (0, u8::from(!hit)));
            assert_eq!(
                octoray_all_hits1(
                    scene,
                    ray,
                    !0,
                    null(),
                    page.as_mut_ptr(),
                    4,
                    &mut stored,
                    &mut complete
                ),
                OctorayStatus::Ok
            );
            assert_eq!(stored > 0, hit);
            if hit {
                assert_eq!(page[0].t.to_bits(), h.t.to_bits());
            }
        }
        // Closest point: a hit point lies on the surface; a non-finite point and a negative
        // radius find nothing; a missing output is an error.
        let mut near = OctorayPointHit::from(None);
        for ray in &r {
            octoray_closest1(scene, ray, !0, &mut h);
            if h.prim == OCTORAY_NO_HIT {
                continue;
            }
            let p: [f32; 3] = core::array::from_fn(|k| ray.org[k] + h.t * ray.dir[k]);
            assert_eq!(
                octoray_closest_point1(scene, p.as_ptr(), f32::INFINITY, !0, &mut near),
                OctorayStatus::Ok
            );
            let size = p.iter().fold(1.0f32, |m, x| m.max(x.abs()));
            assert!(
                near.prim != OCTORAY_NO_HIT && near.dist <= 1e-5 * size,
                "{near:?}"
            );
            assert_eq!(
                octoray_closest_point1(scene, p.as_ptr(), -1.0, !0, &mut near),
                OctorayStatus::Ok
            );
            assert_eq!(near, OctorayPointHit::from(None));
        }
        let nan = [f32::NAN, 0.0, 0.0];
        assert_eq!(
            octoray_closest_point1(scene, nan.as_ptr(), f32::INFINITY, !0, &mut near),
            OctorayStatus::Ok
        );
        assert_eq!(near.prim, OCTORAY_NO_HIT);
        assert_eq!(
            octoray_closest_point1(scene, nan.as_ptr(), 1.0, !0, null_mut()),
            OctorayStatus::NullPointer
        );
        assert_eq!(
            octoray_scene_store(scene, null_mut(), 0, &mut len),
            OctorayStatus::Ok
        );
        let mut short = vec![0u8; len - 1];
        assert_eq!(
            octoray_scene_store(scene, short.as_mut_ptr(), short.len(), &mut len),
            OctorayStatus::InvalidArgument
        );
        octoray_scene_free(scene);
        octoray_scene_free(null_mut());
    }
}

#[test]
fn hostile_bytes_never_crash_a_load_or_a_query() {
    let scene = small(1);
    let bytes = store(scene);
    // SAFETY: freed once.
    unsafe { octoray_scene_free(scene) };
    assert_eq!(load_and_trace(&bytes), OctorayStatus::Ok);
    for n in 0..bytes.len() {
        assert_eq!(
            load_and_trace(&bytes[..n]),
            OctorayStatus::InvalidScene,
            "{n} bytes"
        );
    }
    let mut refused = 0;
    for i in 0..bytes.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut b = bytes.clone();
            b[i] ^= flip;
            let s = load_and_trace(&b);
            assert!(matches!(s, OctorayStatus::Ok | OctorayStatus::InvalidScene));
            refused += usize::from(s == OctorayStatus::InvalidScene);
        }
    }
    // Most flips land in box or vertex bits (a valid scene, other answers); those in counts,
    // indices and links are refused.
    assert!(refused > 0);
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..2000 {
        let mut b = bytes.clone();
        for _ in 0..4 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let at = (x % b.len() as u64) as usize & !3;
            b[at..at + 4].copy_from_slice(&((x >> 32) as u32).to_le_bytes());
        }
        assert!(matches!(
            load_and_trace(&b),
            OctorayStatus::Ok | OctorayStatus::InvalidScene
        ));
    }
}

/// Stored scenes made with the Rust API's groups: a group placed nowhere is not traced through
/// the C ABI either, and a small scene whose rays could enter millions of instances is refused
/// at load, with a message that says why.
#[test]
fn unplaced_groups_miss_and_scenes_past_the_work_budget_are_refused() {
    use octoray::glam::Vec3;
    use octoray::prim::{PackedSphere, VertexTriangle};
    use octoray::scene::{Scene, Transform, MAX_INSTANCE_LEVELS};
    let tri = [VertexTriangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    )];
    let bytes = |s: &Scene<VertexTriangle, PackedSphere>| -> Vec<u8> {
        bytemuck::cast_slice(&s.as_ref().to_words()).to_vec()
    };
    let ray = OctorayRay {
        org: [0.0, 0.0, 5.0],
        dir: [0.0, 0.0, -1.0],
        t_min: 0.0,
        t_max: f32::INFINITY,
    };
    // A group holding the only instance, placed nowhere.
    let mut s = Scene::<VertexTriangle, PackedSphere>::new();
    let g = s.add_triangles(&tri).unwrap();
    let group = s.add_group();
    s.add_to_group(group, &[g], Transform::IDENTITY, !0);
    s.commit().unwrap();
    let unplaced = bytes(&s);
    let mut scene = null_mut();
    // SAFETY: `unplaced` is valid for its length; `scene` for writing.
    let st = unsafe { octoray_scene_load(unplaced.as_ptr(), unplaced.len(), 1, &mut scene) };
    assert_eq!(st, OctorayStatus::Ok);
    let (st, hits) = trace(scene, &[ray]);
    assert_eq!(st, OctorayStatus::Ok);
    assert_eq!(
        hits[0].prim,
        u32::MAX,
        "a hit through a group placed nowhere"
    );
    // SAFETY: loaded above, freed once.
    unsafe { octoray_scene_free(scene) };
    // 64 copies per level, four levels: 16.8 M instance entries per ray.
    let mut deep = Scene::<VertexTriangle, PackedSphere>::new();
    let g = deep.add_triangles(&tri).unwrap();
    let mut below = deep.add_group();
    for _ in 0..64 {
        deep.add_to_group(below, &[g], Transform::IDENTITY, !0);
    }
    for _ in 2..MAX_INSTANCE_LEVELS {
        let above = deep.add_group();
        for _ in 0..64 {
            deep.place_group(Some(above), below, Transform::IDENTITY, !0);
        }
        below = above;
    }
    for _ in 0..64 {
        deep.place_group(None, below, Transform::IDENTITY, !0);
    }
    deep.commit().unwrap();
    let deep = bytes(&deep);
    assert_eq!(load_and_trace(&deep), OctorayStatus::InvalidScene);
    assert!(last_error().contains("more than"), "{}", last_error());
}

#[test]
fn crossings_and_containment_through_instances() {
    // The tetrahedron placed at +x 5 (mask 1); the unit ball at z = 5 (mask 2) does not count.
    let inside = [[5.1f32, 0.1, 0.1], [5.2, 0.3, 0.2]];
    let outside = [
        [0.1f32, 0.1, 0.1],
        [5.9, 0.9, 0.9],
        [0.1, 0.2, 5.0],
        [f32::NAN, 0.0, 0.0],
    ];
    for tier in [1, 2] {
        let scene = small(tier);
        let mut got = 9u8;
        for (points, want) in [(&inside[..], 1), (&outside[..], 0)] {
            for p in points {
                // SAFETY: `p` holds three floats; `got` is valid.
                let s = unsafe { octoray_contains1(scene, p.as_ptr(), !0, &mut got) };
                assert_eq!((s, got), (OctorayStatus::Ok, want), "{p:?}, tier {tier}");
            }
        }
        // Signed distances: negative inside the tetrahedron, the ball's surface counting for
        // the distance (not the sign).
        let mut d = 0.0f32;
        let centre = [5.1f32, 0.1, 0.1];
        // SAFETY: `centre` holds three floats; `d` is valid.
        let s = unsafe { octoray_signed_distance1(scene, centre.as_ptr(), !0, &mut d) };
        assert!(
            s == OctorayStatus::Ok && (d + 0.1).abs() < 1e-6,
            "{d}, tier {tier}"
        );
        let above = [0.0f32, 0.0, 7.5];
        // SAFETY: as above.
        let s = unsafe { octoray_signed_distance1(scene, above.as_ptr(), !0, &mut d) };
        assert_eq!((s, d), (OctorayStatus::Ok, 1.5));
        let nan = [f32::NAN, 0.0, 0.0];
        // SAFETY: as above.
        let s = unsafe { octoray_signed_distance1(scene, nan.as_ptr(), !0, &mut d) };
        assert!(s == OctorayStatus::Ok && d.is_nan());
        // A mask that leaves the tetrahedron out: nothing contains its inside.
        // SAFETY: as above.
        let s = unsafe { octoray_contains1(scene, inside[0].as_ptr(), 2, &mut got) };
        assert_eq!((s, got), (OctorayStatus::Ok, 0));
        // Through the tetrahedron (in through its base, out through a slanted face): 2; from
        // inside it: 1; through the ball: 0.
        let ray = |org: [f32; 3], t_max: f32| OctorayRay {
            org,
            dir: [0.0, 0.0, 1.0],
            t_min: 0.0,
            t_max,
        };
        for (r, want) in [
            (ray([5.2, 0.2, -1.0], 2.0), 2),
            (ray([5.2, 0.2, 0.1], 2.0), 1),
            (ray([0.0, 0.1, 2.0], f32::INFINITY), 0),
        ] {
            let mut n = 9u32;
            // SAFETY: `r` and `n` are valid.
            let s = unsafe { octoray_crossings1(scene, &r, !0, &mut n) };
            assert_eq!((s, n), (OctorayStatus::Ok, want), "{r:?}");
        }
        // SAFETY: a null output is reported, not written.
        let s = unsafe { octoray_crossings1(scene, &ray([0.0; 3], 1.0), !0, null_mut()) };
        assert_eq!(s, OctorayStatus::NullPointer);
        // SAFETY: `scene` is live.
        unsafe { octoray_scene_free(scene) };
    }
    // The standard tier's layout has no crossing rule: an error with a message.
    let scene = small(0);
    let mut got = 0u8;
    // SAFETY: as above.
    let s = unsafe { octoray_contains1(scene, inside[0].as_ptr(), !0, &mut got) };
    assert_eq!(s, OctorayStatus::InvalidArgument);
    assert!(last_error().contains("crossing rule"), "{}", last_error());
    // SAFETY: `scene` is live.
    unsafe { octoray_scene_free(scene) };
}

#[test]
fn boxes_find_the_primitives_they_meet_paged() {
    // The tetrahedron at +x 5 (instance 0, geometry 0), the ball at z = 5 (instance 1, geometry 1).
    let scene = small(1);
    let query = |lo: [f32; 3], hi: [f32; 3], mask: u32, cap: usize| {
        let (mut all, mut after) = (vec![], None::<OctorayPlace>);
        loop {
            let mut page = vec![OctorayPlace::default(); cap];
            let (mut stored, mut complete) = (0, 0);
            let a = after.as_ref().map_or(null(), |a| a as *const _);
            // SAFETY: every pointer is valid for what the call reads or writes.
            let s = unsafe {
                octoray_overlapping1(
                    scene,
                    lo.as_ptr(),
                    hi.as_ptr(),
                    mask,
                    a,
                    page.as_mut_ptr(),
                    cap,
                    &mut stored,
                    &mut complete,
                )
            };
            assert_eq!(s, OctorayStatus::Ok);
            all.extend_from_slice(&page[..stored]);
            if complete == 1 {
                return all;
            }
            after = Some(page[stored - 1]);
        }
    };
    let p = |inst, geom, prim| OctorayPlace { inst, geom, prim };
    let tet: Vec<_> = (0..4).map(|k| p(0, 0, k)).collect();
    for cap in [1, 2, 64] {
        assert_eq!(query([4.5, -1.0, -1.0], [6.5, 2.0, 2.0], !0, cap), tet);
        let mut both = tet.clone();
        both.push(p(1, 1, 0));
        assert_eq!(query([-1.0; 3], [7.0, 7.0, 7.0], !0, cap), both);
        assert_eq!(query([-1.0; 3], [7.0, 7.0, 7.0], 2, cap), vec![p(1, 1, 0)]);
    }
    // The face x + y + z = 1 of the tetrahedron (its triangle 3) alone, and nothing beyond it.
    let near = query([5.15, 0.35, 0.35], [5.25, 0.45, 0.45], !0, 4);
    assert_eq!(near, vec![p(0, 0, 3)]);
    assert_eq!(query([5.5, 0.5, 0.5], [5.6, 0.6, 0.6], !0, 4), vec![]);
    // A NaN corner or an inverted box meets nothing; a missing output is an error.
    assert_eq!(query([f32::NAN, 0.0, 0.0], [7.0; 3], !0, 4), vec![]);
    assert_eq!(query([7.0; 3], [-1.0; 3], !0, 4), vec![]);
    let (lo, hi) = ([0.0f32; 3], [1.0f32; 3]);
    let mut complete = 0;
    // SAFETY: a null `stored` is reported, not written.
    let s = unsafe {
        octoray_overlapping1(
            scene,
            lo.as_ptr(),
            hi.as_ptr(),
            !0,
            null(),
            null_mut(),
            0,
            null_mut(),
            &mut complete,
        )
    };
    assert_eq!(s, OctorayStatus::NullPointer);
    // SAFETY: `scene` is live.
    unsafe { octoray_scene_free(scene) };
}

#[test]
fn the_k_nearest_come_in_order_of_distance() {
    let scene = small(2);
    let p = [5.2f32, 0.2, 0.3];
    let near = |radius: f32, cap: usize| {
        let mut out = vec![OctorayPointHit::from(None); cap];
        let (mut stored, mut complete) = (0, 9);
        // SAFETY: every pointer is valid for what the call reads or writes.
        let s = unsafe {
            octoray_nearest_within1(
                scene,
                p.as_ptr(),
                radius,
                !0,
                out.as_mut_ptr(),
                cap,
                &mut stored,
                &mut complete,
            )
        };
        assert_eq!(s, OctorayStatus::Ok);
        out.truncate(stored);
        (out, complete)
    };
    // Four faces of the tetrahedron and the ball: all five in a buffer of 8, nearest first.
    let (all, complete) = near(f32::INFINITY, 8);
    assert_eq!((all.len(), complete), (5, 1));
    assert!(all.windows(2).all(|w| w[0].dist <= w[1].dist), "{all:?}");
    // The nearest is the slanted face (0.3/√3 away), then x = 5 and y = 0 (0.2), then z = 0.
    let mut closest = OctorayPointHit::from(None);
    // SAFETY: as above.
    unsafe { octoray_closest_point1(scene, p.as_ptr(), f32::INFINITY, !0, &mut closest) };
    assert_eq!(all[0], closest);
    let (two, complete) = near(f32::INFINITY, 2);
    assert_eq!((two.as_slice(), complete), (&all[..2], 0));
    // Within 0.25: the slanted face and the two 0.2 away.
    let (within, complete) = near(0.25, 8);
    assert_eq!((within.len(), complete), (3, 1));
    assert!(
        (within[0].dist - 0.3 / 3f32.sqrt()).abs() < 1e-6,
        "{within:?}"
    );
    assert_eq!(near(-1.0, 8), (vec![], 1));
    // SAFETY: `scene` is live.
    unsafe { octoray_scene_free(scene) };
}
