//! One row of the scene report, run once, for instruction and branch counts per ray under
//! `valgrind --tool=cachegrind --branch-sim=yes` (or `perf stat`):
//!
//! ```text
//! cargo build --release -p octoray-benches --bin profile
//! valgrind --tool=callgrind --branch-sim=yes --toggle-collect='*profile::traced*' \
//!     target/release/profile <scene> <rays> <system> [single|packet8]
//! ```
//!
//! `scene`: sponza, sphere, city, terrain, scanned, open. `rays`: primary, primary-any (the
//! same rays, occlusion), camera2, bounce, shadow (256×256 pixels from the scene's camera;
//! bounces and shadow rays from the first camera's hits). `system`: watertight, spatial (the
//! watertight tier on the spatial-split tree), standard, tinybvh (BVH8_CPU from BuildHQ; the
//! `tinybvh` feature), embree-robust, embree-fast, obvhs. Closest hit, except primary-any and
//! shadow rays: occlusion (tinybvh: closest hit, it has no occlusion query). `packet8`: the
//! rays in packets of 8 in their stored order (4×2 tiles for primary rays), for octoray's tiers
//! and Embree (`rtcIntersect8`/`rtcOccluded8`); single rays by default. Only [`traced`] runs
//! the rays: counting inside it alone (callgrind's
//! `--toggle-collect`) leaves out the scene, the trees and the rays' generation; divide by the
//! ray count printed.

//! `--report` counts every row the scene report's targets compare, in each scene, and writes
//! `benches/counts.md` (`counts::markdown`): it runs this binary under callgrind once per scene
//! and system, in the mode `profile <scene> all <system>` that traces each of the system's rows
//! in turn (`counts::rows`), with a profile dumped after each (`--dump-after`). Callgrind starts
//! with its instrumentation off (`--instr-atstart=no`), so that scene generation and tree builds
//! run at valgrind's uninstrumented speed (tinybvh's `BuildHQ` of a million triangles would take
//! tens of CPU-minutes instrumented); `--warm` has the run switch it on once the system's
//! structures are built and trace its first row once uncollected, so that every row starts with
//! warm simulated caches whatever the build left in them. It needs
//! `valgrind` (skipped with a message otherwise), and `--features tinybvh` for tinybvh's rows;
//! `--jobs N` runs N profiles at once (default: the machine's threads), `--only SCENE` one scene
//! (printed, not written), `--reuse` takes the profiles earlier runs left in `counts/` beside
//! the binary instead of running any (a row without one is reported as not counted).

use octoray::bvh::{BuildOptions, Bvh8, Bvh8Ref, Sequential};
use octoray::kernels::{Kernel, MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, Ray};
use octoray_benches::scene::counts::{self, Counted, Counts};
use octoray_benches::scene::embree::EmbreeScene;
use octoray_benches::scene::peers::{ObvhsScene, TinyBvhScene};
use octoray_benches::scene::sets::{
    city, jittered_sphere, open_field, packets_any, packets_closest, scanned, singles_any,
    singles_closest, sponza, terrain,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use wide::f32x8;

const USAGE: &str = "usage: profile <sponza|sphere|city|terrain|scanned|open> <primary|primary-any|camera2|bounce|shadow|all> <watertight|spatial|standard|tinybvh|embree-robust|embree-fast|obvhs> [single|packet8] [--warm]\n       profile --report [--jobs N] [--only SCENE] [--reuse]";

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().is_some_and(|a| a == "--report") {
        return report(&args[1..]);
    }
    let warm = args.iter().any(|a| a == "--warm");
    let args: Vec<String> = args.into_iter().filter(|a| a != "--warm").collect();
    let (scene, rays, system, packets) = match args.as_slice() {
        [a, b, c] => (a, b, c, false),
        [a, b, c, d] if d == "single" || d == "packet8" => (a, b, c, d == "packet8"),
        _ => return Err(USAGE.into()),
    };
    let runs: Vec<(&str, bool)> = if rays == "all" {
        counts::rows(system)
    } else {
        vec![(rays.as_str(), packets)]
    };
    if packets && matches!(system.as_str(), "tinybvh" | "obvhs") {
        return Err(format!("{system} has no packet traversal"));
    }
    let s = match scene.as_str() {
        "sponza" => sponza()?,
        "sphere" => jittered_sphere(1024),
        "city" => city(),
        "terrain" => terrain(708),
        "scanned" => scanned(640),
        "open" => open_field(),
        _ => return Err(USAGE.into()),
    };
    let verts = s.vertex_tris();
    let binned = Bvh8::build(&verts);
    let primary = s.primary_tiled(0, 256, 256, 4, 2);
    let ray_set = |name: &str| -> Result<Vec<Ray>, String> {
        Ok(match name {
            "primary" | "primary-any" => primary.clone(),
            "camera2" => s.primary_tiled(1, 256, 256, 4, 2),
            "bounce" => s.diffuse_bounces(&primary, &binned),
            "shadow" => s.shadow_rays(&primary, &binned),
            _ => return Err(USAGE.into()),
        })
    };
    // The system's structures, built once for every row it runs.
    let octoray_tree = match system.as_str() {
        "spatial" => Some(
            Bvh8::try_build_options(&verts, BuildOptions::SPATIAL, &Sequential)
                .map_err(|e| format!("{e:?}"))?,
        ),
        _ => None,
    };
    let packed: Vec<PackedTriangle> = if system == "standard" {
        s.tris
            .iter()
            .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
            .collect()
    } else {
        Vec::new()
    };
    let standard_tree = (system == "standard").then(|| Bvh8::build(&packed));
    let tiny = if system == "tinybvh" {
        Some(TinyBvhScene::build(&s.tris, true)?.0)
    } else {
        None
    };
    let embree = if system.starts_with("embree-") {
        Some(EmbreeScene::build(&s.tris, system == "embree-robust")?.0)
    } else {
        None
    };
    let obvhs = (system == "obvhs").then(|| ObvhsScene::build(&s.tris).0);
    if warm {
        instrumentation_on()?;
    }
    for (i, (name, packets)) in runs.into_iter().enumerate() {
        let ray_vec = ray_set(name)?;
        let rays = ray_vec.as_slice();
        let any = matches!(name, "shadow" | "primary-any");
        let trace: Box<dyn Fn() -> u64 + '_> = match system.as_str() {
            "watertight" | "spatial" => {
                let tree = octoray_tree.as_ref().unwrap_or(&binned).as_ref();
                octoray_row::<Watertight>(tree, rays, any, packets)
            }
            "standard" => octoray_row::<MollerTrumbore>(
                standard_tree.as_ref().ok_or(USAGE)?.as_ref(),
                rays,
                any,
                packets,
            ),
            "tinybvh" => {
                let tb = tiny.as_ref().ok_or(USAGE)?;
                Box::new(move || tb.closest(rays))
            }
            "embree-robust" | "embree-fast" => {
                let em = embree.as_ref().ok_or(USAGE)?;
                Box::new(move || match (any, packets) {
                    (true, true) => em.any8(rays),
                    (true, false) => em.any1(rays),
                    (false, true) => em.closest8(rays),
                    (false, false) => em.closest1(rays),
                })
            }
            "obvhs" => {
                let ob = obvhs.as_ref().ok_or(USAGE)?;
                Box::new(move || if any { ob.any(rays) } else { ob.closest(rays) })
            }
            _ => return Err(USAGE.into()),
        };
        if warm && i == 0 {
            // Outside `traced`: simulated, not collected.
            std::hint::black_box(trace());
        }
        let hits = traced(&*trace);
        let how = if packets { "packet8" } else { "single" };
        println!("row {name} {how}: {} rays, {hits} hits", rays.len());
    }
    Ok(())
}

/// An octoray row: single rays (or packets of 8) through `bvh` with kernel `K`, occlusion when
/// `any`.
fn octoray_row<'a, K: Kernel<f32x8>>(
    bvh: Bvh8Ref<'a, K::Prim>,
    rays: &'a [Ray],
    any: bool,
    packets: bool,
) -> Box<dyn Fn() -> u64 + 'a> {
    Box::new(move || match (any, packets) {
        (true, true) => packets_any::<f32x8, K>(bvh, rays),
        (true, false) => singles_any::<f32x8, K>(bvh, rays),
        (false, true) => packets_closest::<f32x8, K>(bvh, rays),
        (false, false) => singles_closest::<f32x8, K>(bvh, rays),
    })
}

/// Callgrind's instrumentation switched on for this process (`callgrind_control -i on`), for a
/// run started with `--instr-atstart=no`: polling for the command's end rather than blocking in
/// `wait`, as valgrind serves the command only while the program runs.
fn instrumentation_on() -> Result<(), String> {
    let pid = std::process::id().to_string();
    let mut control = Command::new("callgrind_control")
        .args(["-i", "on", &pid])
        .stdout(std::process::Stdio::null())
        .spawn()
        .map_err(|e| format!("callgrind_control: {e}"))?;
    loop {
        match control.try_wait().map_err(|e| e.to_string())? {
            Some(s) if s.success() => return Ok(()),
            Some(s) => return Err(format!("callgrind_control -i on: {s}")),
            None => std::hint::spin_loop(),
        }
    }
}

/// The traversal of every ray, and nothing else: what the counts are taken over.
#[inline(never)]
fn traced(f: &dyn Fn() -> u64) -> u64 {
    f()
}

/// `--report`: every scene's rows under callgrind, `benches/counts.md` written and printed.
fn report(args: &[String]) -> Result<(), String> {
    let mut jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut only = None;
    let mut reuse = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--jobs" => jobs = it.next().and_then(|n| n.parse().ok()).ok_or(USAGE)?,
            "--only" => only = Some(it.next().ok_or(USAGE)?.clone()),
            "--reuse" => reuse = true,
            _ => return Err(USAGE.into()),
        }
    }
    let valgrind = Command::new("valgrind").arg("--version").output();
    let version = match valgrind {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).trim().to_string(),
        _ => {
            println!("skipped: the counts report needs valgrind (apt-get install valgrind)");
            return Ok(());
        }
    };
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let dir = exe.parent().ok_or("no directory")?.join("counts");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut todo: Vec<(&'static str, &'static str)> = Vec::new();
    let skipped = Mutex::new(Vec::new());
    for (scene, _) in counts::SCENES {
        if only.as_deref().is_none_or(|o| o == scene) {
            todo.extend(counts::SYSTEMS.iter().map(|(system, _)| (scene, *system)));
        }
    }
    // Largest first, so that the last job to finish is a short one.
    todo.sort_by_key(|(scene, system)| {
        (
            std::cmp::Reverse(matches!(*scene, "sphere" | "terrain")),
            std::cmp::Reverse(*system == "spatial"),
        )
    });
    let queue = Mutex::new(todo.into_iter());
    let counted = Mutex::new(Vec::new());
    std::thread::scope(|sc| {
        for _ in 0..jobs.max(1) {
            sc.spawn(|| loop {
                let Some((scene, system)) = queue.lock().expect("queue").next() else {
                    break;
                };
                match count(&exe, &dir, scene, system, reuse) {
                    Ok(rows) => counted.lock().expect("counted").extend(rows),
                    Err(e) => {
                        eprintln!("{scene} {system}: {e}");
                        skipped
                            .lock()
                            .expect("skipped")
                            .push(format!("{scene} {system}: {e}"));
                    }
                }
            });
        }
    });
    let mut counted = counted.into_inner().expect("counted");
    let order = |c: &Counted| {
        (
            counts::SCENES.iter().position(|s| s.0 == c.scene),
            counts::SYSTEMS.iter().position(|s| s.0 == c.system),
            c.packets,
            counts::rows(c.system).iter().position(|r| r.0 == c.rays),
        )
    };
    counted.sort_by_key(order);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenes_md = std::fs::read_to_string(root.join("scenes.md")).map_err(|e| e.to_string())?;
    let mut header = format!(
        "# octoray per-ray counts\n\nGenerated by `cargo build --release -p octoray-benches --features tinybvh --bin profile && target/release/profile --report`. Build: {}. Machine: {}. {version} (callgrind, `--branch-sim=yes --cache-sim=yes`: its simulated branch predictor and caches, not the machine's), counting only the traversal (`--toggle-collect='*profile::traced*'`, one profile per row with `--dump-after`): no scene generation, tree build or ray generation. Instrumentation starts once a system's structures are built (`--instr-atstart=no`, then `callgrind_control -i on`) and its first row is traced once uncollected before it is counted, so the simulated caches are warm on every row. Per ray, 256×256 primary rays from each camera (4×2 tiles) and the first camera's diffuse bounces and shadow rays, the scene report's scenes, trees and peers (binned trees; \"watertight, spatial splits\" the tree of `BuildOptions::SPATIAL`; tinybvh from its `BuildHQ`, closest hit on every ray set, it has no occlusion query). Valgrind runs no AVX-512 code: on an AVX-512 machine the binary and tinybvh's C++ are built for an AVX2 CPU (`RUSTFLAGS=\"-C target-cpu=x86-64-v3\"` or an AVX2 model such as `znver3`, and the same `-march=` in place of tinybvh's `-march=native`).\n",
        octoray_benches::build_flags(),
        octoray_benches::machine()
    );
    for s in skipped.into_inner().expect("skipped") {
        header.push_str(&format!("\nNot counted: {s}.\n"));
    }
    let md = counts::markdown(&header, &counted, &scenes_md);
    if only.is_none() {
        std::fs::write(root.join("counts.md"), &md).map_err(|e| e.to_string())?;
    }
    print!("{md}");
    Ok(())
}

/// One scene and system under callgrind (`profile <scene> all <system>`): its rows' counts
/// (with `reuse`, from the files an earlier run left in `dir`, none run again).
fn count(
    exe: &Path,
    dir: &Path,
    scene: &'static str,
    system: &'static str,
    reuse: bool,
) -> Result<Vec<Counted>, String> {
    let out: PathBuf = dir.join(format!("{scene}-{system}.cg"));
    let printed = dir.join(format!("{scene}-{system}.out"));
    if reuse {
        let stdout = std::fs::read_to_string(&printed)
            .map_err(|_| "no profile from an earlier run (`--reuse` runs none)")?;
        return read_rows(dir, scene, system, &stdout);
    }
    for old in std::fs::read_dir(dir).map_err(|e| e.to_string())?.flatten() {
        if old
            .file_name()
            .to_string_lossy()
            .starts_with(&format!("{scene}-{system}."))
        {
            let _ = std::fs::remove_file(old.path());
        }
    }
    let run = Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--branch-sim=yes",
            "--cache-sim=yes",
            "--instr-atstart=no",
            "--toggle-collect=*profile::traced*",
            "--dump-after=profile::traced",
        ])
        .arg(format!("--callgrind-out-file={}", out.display()))
        .arg(exe)
        .args([scene, "all", system, "--warm"])
        .output()
        .map_err(|e| e.to_string())?;
    if !run.status.success() {
        let err = String::from_utf8_lossy(&run.stderr);
        let last = err
            .lines()
            .rev()
            .find(|l| !l.starts_with("=="))
            .unwrap_or("failed");
        return Err(last.trim().to_string());
    }
    let stdout = String::from_utf8_lossy(&run.stdout);
    std::fs::write(&printed, stdout.as_bytes()).map_err(|e| e.to_string())?;
    read_rows(dir, scene, system, &stdout)
}

/// The rows of one `profile <scene> all <system>` run: its printed lines and its dumps in `dir`.
fn read_rows(
    dir: &Path,
    scene: &'static str,
    system: &'static str,
    stdout: &str,
) -> Result<Vec<Counted>, String> {
    let rows = counts::rows(system);
    let mut got = Vec::new();
    for (i, line) in stdout.lines().filter(|l| l.starts_with("row ")).enumerate() {
        let (rays, packets) = *rows.get(i).ok_or("more rows than expected")?;
        let n: u64 = line
            .split(": ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| format!("unreadable row line: {line}"))?;
        let dump = dir.join(format!("{scene}-{system}.cg.{}", i + 1));
        let text =
            std::fs::read_to_string(&dump).map_err(|e| format!("{}: {e}", dump.display()))?;
        let counts =
            Counts::parse(&text).ok_or_else(|| format!("{}: no totals", dump.display()))?;
        got.push(Counted {
            scene,
            rays,
            system,
            packets,
            n,
            counts,
        });
    }
    if got.len() != rows.len() {
        return Err(format!("{} of {} rows ran", got.len(), rows.len()));
    }
    Ok(got)
}
