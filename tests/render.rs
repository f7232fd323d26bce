//! The demo renderer on its embedded scene at a small size: known pixels are hit, missed or
//! shadowed as the geometry dictates, for every tier; OBJ input and the command line fail with
//! messages, not panics.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]

#[path = "../examples/render/cli.rs"]
mod cli;
#[path = "../examples/render/scene.rs"]
mod scene;

use glam::Vec3;
use scene::{render, resolve_tier, PixelKind, Scene, TierArg};

const W: u32 = 120;
const H: u32 = 75;

fn kind_at(img: &scene::Image, p: (u32, u32)) -> PixelKind {
    img.kinds[(p.1 * img.width + p.0) as usize]
}

fn luminance(img: &scene::Image, p: (u32, u32)) -> u32 {
    let i = ((p.1 * img.width + p.0) * 3) as usize;
    img.rgb[i..i + 3].iter().map(|&c| u32::from(c)).sum()
}

#[test]
fn known_pixels_are_hit_missed_and_shadowed_as_the_geometry_dictates() {
    let s = Scene::default_scene();
    let mesh_centre = s.project(Vec3::new(0.0, 1.0, 0.0), W, H).unwrap();
    let sphere0 = s.project(s.spheres[0].0, W, H).unwrap();
    // Where sphere 0's centre casts its shadow on the ground: along −light down to y = 0.
    let (c, _) = s.spheres[0];
    let shadow = s.project(c - s.light * (c.y / s.light.y), W, H).unwrap();
    let lit_ground = s.project(Vec3::new(-2.5, 0.0, 2.5), W, H).unwrap();
    for (tier, lanes) in [
        (TierArg::Standard, 8),
        (TierArg::Watertight, 16),
        (TierArg::Fast, 4),
        (TierArg::F64, 4),
    ] {
        let img = render(&s, tier, lanes, W, H, &|_| {}).unwrap();
        let what = format!("{tier:?} x{lanes}");
        assert_eq!(
            kind_at(&img, (0, 0)),
            PixelKind::Sky,
            "{what}: top-left is sky"
        );
        assert!(
            matches!(kind_at(&img, mesh_centre), PixelKind::Mesh { .. }),
            "{what}: mesh centre {:?}",
            kind_at(&img, mesh_centre)
        );
        // The jittered mesh shadows itself in its pockets, but most of what the camera sees of it
        // faces the sun.
        let mesh: Vec<bool> = img
            .kinds
            .iter()
            .filter_map(|k| {
                if let PixelKind::Mesh { shadowed } = k {
                    Some(*shadowed)
                } else {
                    None
                }
            })
            .collect();
        assert!(
            mesh.len() > 100 && mesh.iter().filter(|s| !**s).count() * 2 > mesh.len(),
            "{what}: mesh mostly lit"
        );
        // A smooth sphere has no pockets: its centre faces the sun (n·l > 0), so any shadow there
        // would be self-intersection ("acne").
        assert_eq!(
            kind_at(&img, sphere0),
            PixelKind::Sphere {
                index: 0,
                shadowed: false
            },
            "{what}: sphere 0 centre"
        );
        assert_eq!(
            kind_at(&img, shadow),
            PixelKind::Ground { shadowed: true },
            "{what}: sphere 0's shadow"
        );
        assert_eq!(
            kind_at(&img, lit_ground),
            PixelKind::Ground { shadowed: false },
            "{what}: open ground"
        );
        assert!(
            luminance(&img, shadow) + 100 < luminance(&img, lit_ground),
            "{what}: the shadow is darker"
        );
        // Every primary ray plus one shadow ray per hit.
        let hits = img.kinds.iter().filter(|k| **k != PixelKind::Sky).count() as u64;
        assert_eq!(img.rays, u64::from(W * H) + hits, "{what}");
    }
}

#[test]
fn the_auto_tier_is_explained() {
    let s = Scene::default_scene();
    let (tier, why) = resolve_tier(&s, TierArg::Auto);
    assert_eq!(tier, TierArg::Watertight, "{why}");
    assert!(why.contains("closed meshes"), "{why}");
}

#[test]
fn obj_meshes_load_and_bad_ones_are_errors() {
    let dir = std::env::temp_dir().join(format!("octoray-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tetra = dir.join("tetra.obj");
    std::fs::write(
        &tetra,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let s = cli::load_scene(&Some(tetra)).unwrap();
    assert_eq!(s.mesh_tris, 4);
    let img = render(&s, TierArg::Standard, 8, 40, 25, &|_| {}).unwrap();
    assert!(
        img.kinds
            .iter()
            .any(|k| matches!(k, PixelKind::Mesh { .. })),
        "the tetrahedron is visible"
    );

    let bad_index = dir.join("bad.obj");
    std::fs::write(&bad_index, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let err = cli::load_scene(&Some(bad_index))
        .err()
        .expect("an out-of-range face is an error");
    assert!(err.contains("bad.obj"), "{err}");
    let garbage = dir.join("garbage.obj");
    std::fs::write(&garbage, "v 0 0 zero\nf a b c\n").unwrap();
    assert!(cli::load_scene(&Some(garbage)).is_err());
    assert!(cli::load_scene(&Some(dir.join("missing.obj")))
        .err()
        .unwrap()
        .contains("missing.obj"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_options_get_clear_messages() {
    let args = |s: &str| s.split_whitespace().map(String::from).collect::<Vec<_>>();
    let ok = cli::parse(&args("--size 320x200 --tier f64 --lanes 4 --output x.png")).unwrap();
    assert_eq!(
        (ok.width, ok.height, ok.tier, ok.lanes),
        (320, 200, TierArg::F64, 4)
    );
    for (bad, says) in [
        ("--size 320", "WxH"),
        ("--size 0x10", "outside"),
        ("--tier quantum", "unknown tier"),
        ("--lanes 7", "not 4, 8 or 16"),
        ("--lanes", "needs a value"),
        ("--frobnicate", "unknown option"),
    ] {
        let err = cli::parse(&args(bad)).err().unwrap();
        assert!(err.contains(says), "{bad}: {err}");
    }
    // f64 has no 16-lane form: a message, not a panic.
    let s = Scene::default_scene();
    assert!(render(&s, TierArg::F64, 16, 8, 8, &|_| {})
        .err()
        .unwrap()
        .contains("4 or 8 lanes"));
}
