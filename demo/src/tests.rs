//! The demo renderer on its embedded scene at a small size: known pixels are hit, missed or
//! shadowed as the geometry dictates, at the standard, watertight and f64 tiers; OBJ input and
//! the command line fail with messages, not panics. One lane width per tier: that every width
//! gives the same hits is the library's own tests' to prove (`tests/suite`).

use crate::cli;
use crate::scene::{
    self, render_with, resolve_tier, F64Width, PixelKind, Scene, TierArg, Tracer, Width,
};
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::kernels::{MollerTrumbore, Watertight};
use wide::f64x4;

const W: u32 = 120;
const H: u32 = 75;

/// The embedded default scene, built once for every test that only reads it (it holds a
/// 1.3 M-triangle mesh).
fn default_scene() -> &'static Scene {
    static SCENE: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    SCENE.get_or_init(Scene::default_scene)
}

/// The default scene at `W`×`H`, standard tier, 8 lanes: rendered once for the tests that read
/// the same picture.
fn standard_x8() -> &'static scene::Image {
    static IMAGE: std::sync::OnceLock<scene::Image> = std::sync::OnceLock::new();
    IMAGE.get_or_init(|| render_with::<f32x8, MollerTrumbore>(default_scene(), W, H, &|_| {}))
}

/// The default scene at `W`×`H`, watertight tier, 8 lanes: rendered once for the tests that
/// read the same picture.
fn watertight_x8() -> &'static scene::Image {
    static IMAGE: std::sync::OnceLock<scene::Image> = std::sync::OnceLock::new();
    IMAGE.get_or_init(|| render_with::<f32x8, Watertight>(default_scene(), W, H, &|_| {}))
}

fn kind_at(img: &scene::Image, p: (u32, u32)) -> PixelKind {
    img.kinds[(p.1 * img.width + p.0) as usize]
}

fn luminance(img: &scene::Image, p: (u32, u32)) -> u32 {
    let i = ((p.1 * img.width + p.0) * 3) as usize;
    img.rgb[i..i + 3].iter().map(|&c| u32::from(c)).sum()
}

#[test]
fn known_pixels_are_hit_missed_and_shadowed_as_the_geometry_dictates() {
    let s = default_scene();
    let mesh_centre = s.project(Vec3::new(0.0, 1.0, 0.0), W, H).unwrap();
    let sphere0 = s.project(s.spheres[0].0, W, H).unwrap();
    // Where sphere 0's centre casts its shadow on the ground: along −light down to y = 0.
    let (c, _) = s.spheres[0];
    let shadow = s.project(c - s.light * (c.y / s.light.y), W, H).unwrap();
    let lit_ground = s.project(Vec3::new(-2.5, 0.0, 2.5), W, H).unwrap();
    let f64_x4 = render_with::<f64x4, MollerTrumbore>(s, W, H, &|_| {});
    for (what, img) in [
        ("standard x8", standard_x8()),
        ("watertight x8", watertight_x8()),
        ("f64 x4", &f64_x4),
    ] {
        assert_eq!(
            kind_at(img, (0, 0)),
            PixelKind::Sky,
            "{what}: top-left is sky"
        );
        assert!(
            matches!(kind_at(img, mesh_centre), PixelKind::Mesh { .. }),
            "{what}: mesh centre {:?}",
            kind_at(img, mesh_centre)
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
            kind_at(img, sphere0),
            PixelKind::Sphere {
                index: 0,
                shadowed: false
            },
            "{what}: sphere 0 centre"
        );
        assert_eq!(
            kind_at(img, shadow),
            PixelKind::Ground { shadowed: true },
            "{what}: sphere 0's shadow"
        );
        assert_eq!(
            kind_at(img, lit_ground),
            PixelKind::Ground { shadowed: false },
            "{what}: open ground"
        );
        assert!(
            luminance(img, shadow) + 100 < luminance(img, lit_ground),
            "{what}: the shadow is darker"
        );
        // Every primary ray plus one shadow ray per hit.
        let hits = img.kinds.iter().filter(|k| **k != PixelKind::Sky).count() as u64;
        assert_eq!(img.rays, u64::from(W * H) + hits, "{what}");
    }
}

#[test]
fn the_auto_tier_is_explained() {
    let s = default_scene();
    let (tier, _, why) = resolve_tier(s, TierArg::Auto, 8).unwrap();
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
    let img = render_with::<f32x8, MollerTrumbore>(&s, 40, 25, &|_| {});
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
    // f64 has no 16-lane form, a resolved tier has a width, `auto` is resolved first: messages,
    // not panics; every other pair names its instantiation.
    for (tier, lanes, says) in [
        (TierArg::F64, 16, "4 or 8 lanes"),
        (TierArg::WatertightF64, 2, "4 or 8 lanes"),
        (TierArg::Exact, 7, "4, 8 or 16"),
        (TierArg::Auto, 8, "resolve the auto tier"),
    ] {
        let err = Tracer::new(tier, lanes).unwrap_err();
        assert!(err.contains(says), "{tier:?} x{lanes}: {err}");
    }
    assert_eq!(
        Tracer::new(TierArg::WatertightF64, 8),
        Ok(Tracer::WatertightF64(F64Width::X8))
    );
    assert_eq!(Tracer::new(TierArg::Exact, 4), Ok(Tracer::Exact(Width::X4)));
}

/// Writes `text` to a fresh OBJ file in a per-test folder.
fn obj(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("octoray-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TETRA_FACES: &str = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

#[test]
fn meshes_that_cannot_be_placed_are_errors_and_extreme_ones_are_placed() {
    // These rendered as an empty picture with exit 0.
    for (name, verts) in [
        ("inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nv 0 0 1\n"),
        ("nan-last.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\n"),
    ] {
        let err = cli::load_scene(&Some(obj(name, &format!("{verts}{TETRA_FACES}"))))
            .err()
            .unwrap_or_else(|| panic!("{name} must be an error"));
        assert!(err.contains("not finite"), "{name}: {err}");
    }
    // Huge (2e19, 3e38) and tiny (1e-40) coordinates are placed into the unit ball and seen.
    for (name, s) in [
        ("huge.obj", "2e19"),
        ("max.obj", "3e38"),
        ("tiny.obj", "1e-40"),
    ] {
        let text = format!("v 0 0 0\nv {s} 0 0\nv 0 {s} 0\nv 0 0 {s}\n{TETRA_FACES}");
        let sc = cli::load_scene(&Some(obj(name, &text))).unwrap();
        let r = sc.tris[..sc.mesh_tris]
            .iter()
            .flat_map(|t| t.iter())
            .map(|p| (*p - octoray::glam::Vec3::Y).length())
            .fold(0.0f32, f32::max);
        assert!((0.5..=1.01).contains(&r), "{name}: placed at radius {r}");
        let img = render_with::<f32x8, Watertight>(&sc, 40, 25, &|_| {});
        assert!(
            img.kinds
                .iter()
                .any(|k| matches!(k, PixelKind::Mesh { .. })),
            "{name}: the mesh is visible"
        );
    }
}

#[test]
fn degenerate_faces_are_counted_and_left_out_of_the_tier_estimate() {
    // One `f 1 1 2` made the smallest feature 0, so auto picked f64 and
    // `--tier auto --lanes 16` failed.
    let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{TETRA_FACES}f 1 1 2\n");
    let sc = cli::load_scene(&Some(obj("degenerate.obj", &text))).unwrap();
    assert_eq!(sc.degenerate_triangles(), 1);
    let (tier, lanes, why) = resolve_tier(&sc, TierArg::Auto, 16).unwrap();
    assert_eq!((tier, lanes), (TierArg::Watertight, 16), "{why}");
    assert_eq!(Tracer::new(tier, lanes), Ok(Tracer::Watertight(Width::X16)));
    // Rendered at 8 lanes: the width the tier resolves to does not change the pixels.
    let img = render_with::<f32x8, Watertight>(&sc, 16, 10, &|_| {});
    assert_eq!(img.kinds.len(), 160);
}

#[test]
fn the_output_is_checked_before_tracing_and_never_overwrites_the_input() {
    // The output is opened before tracing and never the input.
    let args = |s: String| s.split_whitespace().map(String::from).collect::<Vec<_>>();
    let mesh = obj(
        "keep.obj",
        &format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{TETRA_FACES}"),
    );
    let before = std::fs::read(&mesh).unwrap();
    let o = cli::parse(&args(format!("--obj {0} --output {0}", mesh.display()))).unwrap();
    let (code, msg) = cli::open_output(&o).unwrap_err();
    assert_eq!(code, 2);
    assert!(msg.contains("input mesh"), "{msg}");
    assert_eq!(
        std::fs::read(&mesh).unwrap(),
        before,
        "the mesh is untouched"
    );
    let o = cli::parse(&args("--output /nonexistent-dir/x.png".into())).unwrap();
    let (code, msg) = cli::open_output(&o).unwrap_err();
    assert_eq!(code, 1);
    assert!(msg.contains("cannot create"), "{msg}");
}

#[test]
fn camera_options_parse_and_keep_the_mesh_in_place() {
    let args = |s: String| s.split_whitespace().map(String::from).collect::<Vec<_>>();
    let mesh = obj(
        "place.obj",
        &format!("v 5 5 5\nv 6 5 5\nv 5 6 5\nv 5 5 6\n{TETRA_FACES}"),
    );
    let o = cli::parse(&args(format!(
        "--obj {} --camera 5.2,5.2,9 --look-at 5.2,5.2,5 --fov 30",
        mesh.display()
    )))
    .unwrap();
    let sc = cli::scene_for(&o).unwrap();
    assert_eq!(
        sc.tris[0][0],
        octoray::glam::Vec3::splat(5.0),
        "kept at its own coordinates"
    );
    let img = render_with::<f32x8, Watertight>(&sc, 20, 20, &|_| {});
    assert!(matches!(img.kinds[10 * 20 + 10], PixelKind::Mesh { .. }));
    for (bad, says) in [
        ("--camera 1,2", "X,Y,Z"),
        ("--camera 1,2,nan", "finite"),
        ("--fov 0", "outside"),
        ("--camera 1,1,1 --look-at 1,1,1", "same point"),
    ] {
        let err = cli::parse(&args(bad.into())).err().unwrap();
        assert!(err.contains(says), "{bad}: {err}");
    }
}

#[test]
fn an_obj_of_only_points_and_lines_has_no_faces() {
    // It rendered without a mesh and exited 0, calling its lines "degenerate triangles".
    let p = obj(
        "lines.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\np 1\nf 1 2\n",
    );
    let err = cli::load_scene(&Some(p))
        .err()
        .expect("no faces is an error");
    assert!(err.contains("has no faces"), "{err}");
    // Lines beside faces are left out, not counted as degenerate triangles.
    let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{TETRA_FACES}l 1 2\np 3\n");
    let sc = cli::load_scene(&Some(obj("mixed.obj", &text))).unwrap();
    assert_eq!((sc.mesh_tris, sc.degenerate_triangles()), (4, 0));
}

/// A `w`×`h` image of sky pixels in a colour gradient: what `write_png` writes does not depend
/// on how the pixels were traced.
fn gradient(w: u32, h: u32) -> scene::Image {
    let rgb = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    scene::Image {
        width: w,
        height: h,
        rgb,
        kinds: vec![PixelKind::Sky; (w * h) as usize],
        rays: u64::from(w * h),
        build_secs: 0.0,
        trace_secs: 0.0,
        counts: (0, 0, 0),
        digest: 0,
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_png_that_cannot_be_written_is_an_error_at_every_size() {
    // With --output /dev/full, 16x16 and 64x64 images reported success: the buffered writer's
    // last write error was dropped. 640x400 failed (its writes overflowed the buffer).
    for (w, h) in [(16, 16), (64, 64), (200, 100)] {
        let img = gradient(w, h);
        let path = std::path::Path::new("/dev/full");
        let file = std::fs::OpenOptions::new().write(true).open(path).unwrap();
        let err = scene::write_png(&img, file, path).err();
        assert!(
            err.as_deref().is_some_and(|e| e.contains("cannot write")),
            "{w}x{h}: {err:?}"
        );
    }
    // A writable file still gets a whole PNG.
    let img = gradient(16, 16);
    let path = std::env::temp_dir().join(format!("octoray-png-{}.png", std::process::id()));
    scene::write_png(&img, std::fs::File::create(&path).unwrap(), &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(&bytes[1..4], b"PNG");
    assert_eq!(&bytes[bytes.len() - 8..bytes.len() - 4], b"IEND");
}

#[test]
fn ambient_occlusion_darkens_the_ground_next_to_the_spheres_and_nothing_else_changes() {
    // (in front of the field)
    let mut s = Scene::default_scene();
    let flat = render_with::<f32x8, MollerTrumbore>(&s, W, H, &|_| {});
    s.ao_samples = 32;
    let ao = render_with::<f32x8, MollerTrumbore>(&s, W, H, &|_| {});
    // The same pixels are hit and shadowed; only the ambient term changed, and more rays ran.
    assert!(flat.kinds.iter().zip(&ao.kinds).all(|(a, b)| a == b));
    assert!(
        ao.rays > flat.rays + 20 * (W * H) as u64 / 4,
        "{} vs {}",
        ao.rays,
        flat.rays
    );
    // The ground in front of the field of instances (their contacts darken the ground behind).
    let front = s.project(Vec3::new(0.0, 0.0, -1.2), W, H).unwrap().1;
    let lit_ground: Vec<(u32, u32)> = (front..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            matches!(
                flat.kinds[(y * W + x) as usize],
                PixelKind::Ground { shadowed: false }
            )
        })
        .collect();
    assert!(lit_ground.len() > 1000, "{}", lit_ground.len());
    // Without ambient occlusion every lit ground pixel has the same colour (a flat plane).
    let l0 = luminance(&flat, lit_ground[0]);
    assert!(lit_ground.iter().all(|&p| luminance(&flat, p) == l0));
    // With it, the darkest lit ground pixel lies next to a sphere's contact point.
    let (&darkest, &brightest) = (
        lit_ground
            .iter()
            .min_by_key(|&&p| luminance(&ao, p))
            .unwrap(),
        lit_ground
            .iter()
            .max_by_key(|&&p| luminance(&ao, p))
            .unwrap(),
    );
    assert!(luminance(&ao, darkest) * 10 < luminance(&ao, brightest) * 9);
    let near_contact = s.spheres.iter().any(|&(c, r)| {
        s.project(Vec3::new(c.x, 0.0, c.z), W, H)
            .is_some_and(|(x, y)| {
                let d = (x as f32 - darkest.0 as f32).hypot(y as f32 - darkest.1 as f32);
                d <= 0.25 * W as f32 * r
            })
    });
    assert!(near_contact, "darkest lit ground pixel {darkest:?}");
}

/// The default scene's field: 1 600 instances of the mesh behind it, seen and lit, each a hit
/// of its own instance; the same picture, but for silhouette pixels, at the watertight and the
/// standard tier.
#[test]
fn the_field_of_instances_is_seen_lit_and_the_same_at_two_tiers() {
    let s = default_scene();
    assert_eq!(s.field.len(), 1600);
    assert!(s.virtual_triangles() > 2_000_000_000);
    let (a, b) = (watertight_x8(), standard_x8());
    assert_eq!(a.counts, (3, 3, 1603));
    let field: Vec<bool> = a
        .kinds
        .iter()
        .filter_map(|k| match k {
            PixelKind::Field { shadowed } => Some(*shadowed),
            _ => None,
        })
        .collect();
    assert!(field.len() > 200, "{} field pixels", field.len());
    assert!(field.iter().filter(|s| !**s).count() * 2 > field.len());
    // The tiers may differ on a pixel at a silhouette, not on the picture.
    let same = a.kinds.iter().zip(&b.kinds).filter(|(x, y)| x == y).count();
    assert!(
        same * 100 >= a.kinds.len() * 99,
        "{same} of {}",
        a.kinds.len()
    );
}

/// An OBJ of two models gives two geometries, coloured apart.
#[test]
fn each_obj_model_is_its_own_geometry() {
    let path = obj(
        "two_models.obj",
        "o a\nv -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv -1 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n",
    );
    let s = cli::load_scene(&Some(path.clone())).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(s.mesh_groups, vec![0, 1]);
    assert_ne!(s.tri_color[0], s.tri_color[1]);
    let img = render_with::<f32x8, Watertight>(&s, 16, 16, &|_| {});
    // Two models, the ground, the spheres.
    assert_eq!(img.counts.0, 4);
}

/// What `--export` writes is the scene the demo traces: read back as a stored scene and traced
/// with the exported rays, it gives the digest the render prints, at the standard and the
/// watertight tier (the C ABI's examples are checked against this digest).
#[test]
fn the_exported_scene_traces_to_the_rendered_digest() {
    let s = default_scene();
    let dir = std::env::temp_dir().join(format!("octoray-export-test-{}", std::process::id()));
    scene::export(s, TierArg::Standard, W, H, &dir).unwrap();
    let stored = scene::stored_digest::<f32x8, MollerTrumbore>(&dir).unwrap();
    assert_eq!(stored, standard_x8().digest, "standard");
    scene::export(s, TierArg::Watertight, W, H, &dir).unwrap();
    let stored = scene::stored_digest::<f32x8, Watertight>(&dir).unwrap();
    assert_eq!(stored, watertight_x8().digest, "watertight");
    // A scene stored for the other layout is refused, not misread.
    let err = scene::stored_digest::<f32x8, MollerTrumbore>(&dir).unwrap_err();
    assert!(err.starts_with("scene.bin"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
