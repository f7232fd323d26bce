//! Scenes from outside: the work a ray can make is bounded by what validation accepts (the entry
//! bound within a budget), only instances reached from the world are traced, and the scene
//! calls' panics are the documented ones, reported at the caller's line.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]

use super::scene::Stored;
use crate::dyn_filter;
use octoray::bvh::BvhError;
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::hit::Candidate;
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{PackedSphere, Ray, RayLanes, VertexTriangle};
use octoray::scene::{Scene, SceneError, SceneRef, Trace, Transform, MAX_INSTANCE_LEVELS};
use octoray_testkit::stored::{
    word, words, FIRST_MEMBER, FIRST_UNBOUNDED, KIND, LEVELS, MASK, PATHS, PRIMS, UNBOUNDED,
};
use std::cell::RefCell;

type S = Scene<VertexTriangle, PackedSphere>;
type R<'a> = SceneRef<'a, VertexTriangle, PackedSphere>;

/// One triangle across the z axis at z = 0.
fn triangle() -> [VertexTriangle; 1] {
    [VertexTriangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    )]
}

/// A ray down the z axis through the triangle.
fn down() -> Ray {
    Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z)
}

/// How many candidate hits one ray makes (the filter refuses them all, so every instance the
/// walk enters and whose triangle the ray crosses is seen): the walk's instance entries that
/// reached a primitive.
fn candidates(s: &R<'_>, ray: &Ray) -> u64 {
    let mut n = 0u64;
    let hit = s.closest_ray_with::<f32x8, Watertight, StableSphere, _>(
        ray,
        !0,
        &mut dyn_filter(&mut |_: &Candidate| {
            n += 1;
            false
        }),
    );
    assert_eq!(hit, None);
    n
}

/// A chain of `MAX_INSTANCE_LEVELS` instance levels, each placing `n` copies of the level below
/// (with `transform`), down to one triangle: the world holds `n` instances of group 2, which
/// holds `n` of group 1, which holds `n` of group 0, which holds `n` of the triangle.
fn chain(n: u32, transform: Transform) -> S {
    let mut s = S::new();
    let g = s.add_triangles(&triangle()).unwrap();
    let mut below = s.add_group();
    for _ in 0..n {
        s.add_to_group(below, &[g], transform, !0);
    }
    for _ in 2..MAX_INSTANCE_LEVELS {
        let above = s.add_group();
        for _ in 0..n {
            s.place_group(Some(above), below, transform, !0);
        }
        below = above;
    }
    for _ in 0..n {
        s.place_group(None, below, transform, !0);
    }
    s.commit().unwrap();
    s
}

/// The entry bound counts every instance entry down the levels, and the walk makes no more: a
/// ray through `n` stacked copies per level enters `n + n² + n³ + n⁴` instances and meets the
/// triangle `n⁴` times. A budget of exactly that is accepted, one less is refused.
#[test]
fn the_entry_bound_counts_every_entry_and_validation_enforces_it() {
    for n in [1u32, 2, 3, 5] {
        let scene = chain(n, Transform::IDENTITY);
        let r = scene.as_ref();
        let n = u64::from(n);
        let e = n + n * n + n * n * n + n * n * n * n;
        assert_eq!(r.entries_within(u64::MAX), Some(e));
        assert_eq!(r.entries_within(e), Some(e));
        assert_eq!(r.entries_within(e - 1), None);
        assert_eq!(candidates(&r, &down()), n.pow(4));
        let parts = scene.parts();
        let back = R::new_bounded(parts, e).unwrap();
        assert_eq!(candidates(&back, &down()), n.pow(4));
        assert_eq!(
            R::new_bounded(parts, e - 1).err(),
            Some(SceneError::TooMuchWork { budget: e - 1 })
        );
        let words = r.to_words();
        assert!(R::from_words_bounded(&words, e).is_ok());
        assert_eq!(
            R::from_words_bounded(&words, e - 1).err(),
            Some(SceneError::TooMuchWork { budget: e - 1 })
        );
    }
}

/// The default budget is the scene's length in words: a flat scene always fits it (its bound is
/// its world's slots and unbounded entries), a small stored scene that multiplies copies level
/// by level does not, and is refused before any ray is traced.
#[test]
fn the_default_budget_refuses_small_scenes_with_exponential_work() {
    // 64 copies per level: 16 843 009 entries per ray from 97 KB.
    let deep = chain(64, Transform::IDENTITY);
    let words = deep.as_ref().to_words();
    assert!(words.len() < 25_000, "{} words", words.len());
    let budget = deep.parts().words();
    assert_eq!(
        R::from_words(&words).err(),
        Some(SceneError::TooMuchWork { budget })
    );
    assert!(SceneError::TooMuchWork { budget }
        .to_string()
        .contains("more than"));
    // The same copies, nearly singular (outside every level's tree, on its unbounded list).
    let squash = Transform {
        rows: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1e-4, 0.0],
        ],
    };
    let flat_enough = chain(64, squash);
    assert!(flat_enough.parts().unbounded.len() >= 4 * 64);
    assert!(matches!(
        R::from_words(&flat_enough.as_ref().to_words()),
        Err(SceneError::TooMuchWork { .. })
    ));
    // Flat: 2 000 instances of one triangle, all on the ray, accepted by default.
    let mut flat = S::new();
    let g = flat.add_triangles(&triangle()).unwrap();
    for _ in 0..2000 {
        flat.add_instance(&[g], Transform::IDENTITY, !0);
    }
    flat.commit().unwrap();
    let words = flat.as_ref().to_words();
    let back = R::from_words(&words).unwrap();
    assert_eq!(back.entries_within(u64::MAX), Some(2000));
    assert_eq!(candidates(&back, &down()), 2000);
}

/// The hostile shape: every level's unbounded list names its one instance many times (the
/// builder never does). Its entry bound counts each copy; the walk's work stays within it; the
/// default budget refuses the large case.
#[test]
fn duplicate_unbounded_entries_are_counted_and_refused_past_the_budget() {
    for (copies, accepted) in [(2u32, true), (63, false)] {
        let scene = chain(1, Transform::IDENTITY);
        let mut st = Stored::of(&scene.parts());
        // The trees: the triangle's, then groups 0, 1, 2; instances: the world's (index 0),
        // then each group's one. Each level's list: `copies` entries of its instance.
        let group_first: Vec<u32> = st.trees[1..]
            .iter()
            .map(|t| words(t)[FIRST_MEMBER])
            .collect();
        st.unbounded.clear();
        st.unbounded.extend(std::iter::repeat_n(0, copies as usize));
        for (k, &first) in group_first.iter().enumerate() {
            let t = &mut st.trees[1 + k];
            *word(t, FIRST_UNBOUNDED) = st.unbounded.len() as u32;
            *word(t, UNBOUNDED) = copies;
            st.unbounded
                .extend(std::iter::repeat_n(first, copies as usize));
        }
        let c = u64::from(copies) + 1; // each level: its tree slot and the copies
        let e = c + c * c + c * c * c + c * c * c * c;
        let r = R::new_bounded(st.parts(), u64::MAX).unwrap();
        assert_eq!(r.entries_within(u64::MAX), Some(e));
        // The world's one instance is entered once (no top level to walk), every level below
        // `c` times per visit.
        let met = candidates(&r, &down());
        assert_eq!(met, c * c * c);
        assert!(met <= e);
        let budget = st.parts().words();
        match R::new(st.parts()) {
            Ok(_) => assert!(accepted && e <= budget),
            Err(err) => {
                assert!(!accepted && e > budget);
                assert_eq!(err, SceneError::TooMuchWork { budget });
            }
        }
    }
}

/// A group that no instance places contributes nothing: no hit through it, whatever the query
/// (single, filtered, packet, occlusion), built or stored, and beside a placed instance only the
/// placed one is hit, with its path.
#[test]
fn a_group_placed_nowhere_is_not_traced() {
    for world_instance in [false, true] {
        let mut s = S::new();
        let g = s.add_triangles(&triangle()).unwrap();
        let group = s.add_group();
        s.add_to_group(group, &[g], Transform::IDENTITY, !0);
        let far = Transform::placing(octoray::glam::Affine3A::from_translation(Vec3::new(
            0.0, 0.0, -2.0,
        )))
        .unwrap();
        if world_instance {
            s.add_instance(&[g], far, !0);
        }
        s.commit().unwrap();
        let words = s.as_ref().to_words();
        let stored = R::from_words(&words).unwrap();
        for r in [s.as_ref(), stored] {
            let want = world_instance.then_some(7.0f32);
            assert_eq!(r.paths(), u64::from(world_instance));
            let ray = down();
            let hit = r.closest_ray::<f32x8, Watertight, StableSphere>(&ray, !0);
            assert_eq!(hit.map(|h| (h.t, h.inst)), want.map(|t| (t, 0)));
            let filtered = r.closest_ray_with::<f32x8, Watertight, StableSphere, _>(
                &ray,
                !0,
                &mut dyn_filter(&mut |_: &Candidate| true),
            );
            assert_eq!(filtered, hit);
            assert_eq!(
                r.occluded_ray::<f32x8, Watertight, StableSphere>(&ray, !0),
                world_instance
            );
            let packet =
                r.closest_packet::<f32x8, Watertight, StableSphere>(&RayLanes::load(&[ray; 8]), !0);
            for k in 0..8 {
                assert_eq!(packet.lane(k), hit);
            }
            if let Some(h) = hit {
                assert!(u64::from(h.inst) < r.paths());
                assert!(r.instance_path(h.inst).is_some());
            }
        }
    }
}

/// Too many instance levels: `commit` and `commit_on` answer the same error, which says so
/// (not a tree depth), and the scene stays uncommitted.
#[test]
fn too_many_levels_is_one_error_from_both_commits() {
    let mut deep = S::new();
    let g = deep.add_triangles(&triangle()).unwrap();
    let mut below = deep.add_group();
    deep.add_to_group(below, &[g], Transform::IDENTITY, !0);
    for _ in 0..MAX_INSTANCE_LEVELS {
        let above = deep.add_group();
        deep.place_group(Some(above), below, Transform::IDENTITY, !0);
        below = above;
    }
    deep.place_group(None, below, Transform::IDENTITY, !0);
    let mut other = deep.clone();
    assert_eq!(deep.commit(), Err(BvhError::TooManyLevels));
    assert_eq!(
        other.commit_on(&octoray::bvh::Sequential),
        Err(BvhError::TooManyLevels)
    );
    assert!(!deep.is_committed());
    assert!(BvhError::TooManyLevels.to_string().contains("instances"));
}

thread_local! {
    /// Where the last panic on this thread was reported, while [`panic_location`] listens.
    static LOCATION: RefCell<Option<Option<String>>> = const { RefCell::new(None) };
}

/// The file a panic of `f` is reported at (`None` when it does not panic).
fn panic_location(f: impl FnOnce()) -> Option<String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let listening = LOCATION.with(|l| {
                let mut l = l.borrow_mut();
                let on = l.is_some();
                if on {
                    *l = Some(info.location().map(|at| at.file().to_string()));
                }
                on
            });
            if !listening {
                previous(info);
            }
        }));
    });
    LOCATION.with(|l| *l.borrow_mut() = Some(None));
    let panicked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_err();
    let at = LOCATION.with(|l| l.borrow_mut().take()).flatten();
    panicked.then(|| at.expect("the hook saw the panic"))
}

/// Every documented panic of the scene calls is reported at the caller's line (this file), not
/// inside the library.
#[test]
fn scene_panics_are_reported_at_the_callers_line() {
    let sphere = [PackedSphere::new(Vec3::ZERO, 1.0)];
    let fresh = || {
        let mut s = S::new();
        s.add_triangles(&triangle()).unwrap();
        s.add_spheres(&sphere).unwrap();
        s
    };
    let here = file!();
    type Call = Box<dyn Fn(&mut S)>;
    let calls: Vec<(&str, Call)> = vec![
        (
            "refit_triangles on spheres",
            Box::new(|s: &mut S| {
                let _ = s.refit_triangles(1, &triangle());
            }),
        ),
        (
            "refit_spheres out of range",
            Box::new(move |s: &mut S| {
                let _ = s.refit_spheres(7, &sphere);
            }),
        ),
        (
            "add_instance out of range",
            Box::new(|s: &mut S| {
                let _ = s.add_instance(&[5], Transform::IDENTITY, !0);
            }),
        ),
        (
            "add_instance of no geometry",
            Box::new(|s: &mut S| {
                let _ = s.add_instance(&[], Transform::IDENTITY, !0);
            }),
        ),
        (
            "add_instance of two kinds",
            Box::new(|s: &mut S| {
                let _ = s.add_instance(&[0, 1], Transform::IDENTITY, !0);
            }),
        ),
        (
            "set_geometry_mask out of range",
            Box::new(|s: &mut S| s.set_geometry_mask(9, 1)),
        ),
        (
            "add_to_group of no group",
            Box::new(|s: &mut S| {
                let _ = s.add_to_group(3, &[0], Transform::IDENTITY, !0);
            }),
        ),
        (
            "place_group of no group",
            Box::new(|s: &mut S| {
                let _ = s.place_group(None, 3, Transform::IDENTITY, !0);
            }),
        ),
        (
            "set_transform out of range",
            Box::new(|s: &mut S| s.set_transform(4, Transform::IDENTITY)),
        ),
        (
            "set_group_transform out of range",
            Box::new(|s: &mut S| {
                let g = s.add_group();
                s.set_group_transform(g, 0, Transform::IDENTITY);
            }),
        ),
        (
            "set_instance_mask out of range",
            Box::new(|s: &mut S| s.set_instance_mask(4, 1)),
        ),
        (
            "place_group into an older group",
            Box::new(|s: &mut S| {
                let a = s.add_group();
                let b = s.add_group();
                s.place_group(Some(a), b, Transform::IDENTITY, !0);
            }),
        ),
        (
            "as_ref uncommitted",
            Box::new(|s: &mut S| {
                s.add_instance(&[0], Transform::IDENTITY, !0);
                let _ = s.as_ref();
            }),
        ),
        (
            "parts uncommitted",
            Box::new(|s: &mut S| {
                s.add_instance(&[0], Transform::IDENTITY, !0);
                let _ = s.parts();
            }),
        ),
    ];
    for (what, call) in calls {
        let mut s = fresh();
        let at = panic_location(|| call(&mut s));
        assert_eq!(at.as_deref(), Some(here), "{what}");
    }
}

/// A scene's slices taken while it is stale (after a refit or a move, before `commit`) are
/// refused: `parts` panics as `as_ref` does, so a stale top level cannot be stored.
#[test]
fn stale_parts_cannot_be_taken() {
    let mut s = S::new();
    let g = s.add_triangles(&triangle()).unwrap();
    s.add_instance(&[g], Transform::IDENTITY, !0);
    s.commit().unwrap();
    assert!(R::new(s.parts()).is_ok());
    let moved = [VertexTriangle::new(
        Vec3::new(-1.0, -1.0, 3.0),
        Vec3::new(1.0, -1.0, 3.0),
        Vec3::new(0.0, 1.0, 3.0),
    )];
    s.refit_triangles(g, &moved).unwrap();
    assert!(panic_location(|| {
        let _ = s.parts();
    })
    .is_some());
    s.commit().unwrap();
    let r = R::new(s.parts()).unwrap();
    let hit = r.closest_ray::<f32x8, Watertight, StableSphere>(&down(), !0);
    assert_eq!(hit.map(|h| h.t), Some(2.0));
    s.set_transform(0, Transform::IDENTITY);
    assert!(panic_location(|| {
        let _ = s.parts();
    })
    .is_some());
}

/// What the scene docs state of threads: an owned scene and its borrowed view move between and
/// are shared by threads, and a committed scene traced from several threads at once answers as
/// from one.
#[test]
fn scenes_are_send_and_sync_and_trace_alike_from_threads() {
    fn send_sync<X: Send + Sync>() {}
    send_sync::<S>();
    send_sync::<R<'static>>();
    let scene = chain(2, Transform::IDENTITY);
    let r = scene.as_ref();
    let one = r.closest_ray::<f32x8, Watertight, StableSphere>(&down(), !0);
    assert!(one.is_some());
    std::thread::scope(|t| {
        let runs: Vec<_> = (0..4)
            .map(|_| t.spawn(|| r.closest_ray::<f32x8, Watertight, StableSphere>(&down(), !0)))
            .collect();
        for run in runs {
            assert_eq!(run.join().unwrap(), one);
        }
    });
}

#[test]
fn the_stored_tree_words_are_the_records_fields() {
    // testkit::stored names a tree record's words for the hostile-data tests: its names must be
    // where the library keeps the fields it reports.
    let scene = chain(3, Transform::IDENTITY);
    let trees = scene.as_ref().parts().trees;
    assert_eq!(trees.len(), 4);
    for t in trees {
        let w = words(t);
        assert_eq!(
            [w[KIND], w[PRIMS], w[MASK], w[PATHS]],
            [t.kind(), t.prims(), t.mask(), t.paths()]
        );
    }
    assert_eq!(words(&trees[0])[KIND], octoray::scene::TRIANGLES);
    assert!(trees[1..]
        .iter()
        .all(|t| t.kind() == octoray::scene::INSTANCES && words(t)[LEVELS] >= 1));
}
