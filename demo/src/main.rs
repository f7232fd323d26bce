//! octoray's demo: an embedded scene (a jittered icosphere on a ground quad, three spheres, a
//! sun, and a field of 1 600 instances of the icosphere: 2.1 billion virtual triangles) or your
//! own Wavefront OBJ (each model its own geometry, coloured its own way), primary and shadow
//! rays traced in packets on all cores through one two-level scene, written to a PNG, with a
//! summary of what it cost and which accuracy tier it used and why.
//!
//! Run: `cargo run --release --bin render` (then open `render.png`).
//! Options: `--size WxH` (640x400), `--output PATH` (render.png), `--tier auto|standard|
//! watertight|f64|watertight-f64` (auto), `--lanes 4|8|16` (8), `--obj PATH` (replaces the icosphere),
//! `--export DIR` (the scene and primary rays for the C ABI's examples, `capi/examples/trace.c`).
//! Triangles and spheres are geometries of one scene (8-wide BVHs under a top-level tree over
//! the instances; built once, timed and reported), traced by one query per ray set.

use indicatif::{ProgressBar, ProgressStyle};
use octoray::kernels::{Exact, MollerTrumbore, Watertight};
use octoray::{f32x16, f32x4, f32x8};
use octoray_demo::cli::{self, parse, scene_for, Options, USAGE};
use octoray_demo::scene::{
    export, render_with, resolve_tier, write_png, F64Width, Image, Scene, Tracer, Width,
};
use std::process::ExitCode;
use std::time::Instant;
use wide::{f64x4, f64x8};

/// Renders with the instantiation of [`render_with`] that `tracer` names: the only place the
/// demo instantiates every tier at every width (the library's tests instantiate what they test).
fn render(scene: &Scene, tracer: Tracer, w: u32, h: u32, progress: &(dyn Fn(u64) + Sync)) -> Image {
    use {F64Width as D, Tracer as T, Width as S};
    match tracer {
        T::Standard(S::X4) => render_with::<f32x4, MollerTrumbore>(scene, w, h, progress),
        T::Standard(S::X8) => render_with::<f32x8, MollerTrumbore>(scene, w, h, progress),
        T::Standard(S::X16) => render_with::<f32x16, MollerTrumbore>(scene, w, h, progress),
        T::Watertight(S::X4) => render_with::<f32x4, Watertight>(scene, w, h, progress),
        T::Watertight(S::X8) => render_with::<f32x8, Watertight>(scene, w, h, progress),
        T::Watertight(S::X16) => render_with::<f32x16, Watertight>(scene, w, h, progress),
        T::Exact(S::X4) => render_with::<f32x4, Exact>(scene, w, h, progress),
        T::Exact(S::X8) => render_with::<f32x8, Exact>(scene, w, h, progress),
        T::Exact(S::X16) => render_with::<f32x16, Exact>(scene, w, h, progress),
        T::F64(D::X4) => render_with::<f64x4, MollerTrumbore>(scene, w, h, progress),
        T::F64(D::X8) => render_with::<f64x8, MollerTrumbore>(scene, w, h, progress),
        T::WatertightF64(D::X4) => render_with::<f64x4, Watertight>(scene, w, h, progress),
        T::WatertightF64(D::X8) => render_with::<f64x8, Watertight>(scene, w, h, progress),
    }
}

fn flags() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "AVX-512 (target-cpu=native)"
    } else if cfg!(target_feature = "avx2") {
        "AVX2"
    } else {
        "SSE2 (default build; RUSTFLAGS=\"-C target-cpu=native\" for AVX/AVX-512)"
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let o = match parse(&args) {
        Ok(o) => o,
        Err(msg) if msg.is_empty() => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("render: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&o) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, msg)) => {
            eprintln!("render: {msg}");
            ExitCode::from(code)
        }
    }
}

/// Renders as `o` says, writes the PNG and prints the summary; on failure the exit code and
/// the message.
fn run(o: &Options) -> Result<(), (u8, String)> {
    let fail = |msg| (1, msg);
    let scene = scene_for(o).map_err(fail)?;
    let (tier, lanes, why) = resolve_tier(&scene, o.tier, o.lanes).map_err(fail)?;
    let tracer = Tracer::new(tier, lanes).map_err(|msg| (2, format!("{msg}\n{USAGE}")))?;
    // The output is checked before tracing (see `cli::open_output`).
    let out_file = cli::open_output(o)?;
    if let Some(dir) = &o.export {
        export(&scene, tier, o.width, o.height, dir).map_err(fail)?;
    }
    let bar = ProgressBar::new(u64::from(o.height));
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} rows {elapsed}").expect("template"),
    );
    let start = Instant::now();
    let img = render(&scene, tracer, o.width, o.height, &|n| bar.inc(n));
    let secs = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    write_png(&img, out_file, &o.output).map_err(fail)?;
    let tier = format!("{} with {lanes} lanes ({why})", tier.name());
    summary(o, &scene, &img, &tier, secs);
    Ok(())
}

/// Prints what was rendered, what it cost and the tier it used (`tier`, with why).
fn summary(o: &Options, scene: &Scene, img: &Image, tier: &str, secs: f64) {
    println!("octoray render: {}", o.output.display());
    println!("  resolution   {}x{}", o.width, o.height);
    let degenerate = scene.degenerate_triangles();
    println!(
        "  scene        {} triangles{}, {} spheres{}",
        scene.tris.len(),
        if degenerate > 0 {
            format!(
                " ({degenerate} degenerate: zero area, never hit, left out of the tier estimate)"
            )
        } else {
            String::new()
        },
        scene.spheres.len(),
        o.obj
            .as_ref()
            .map_or(String::new(), |p| format!(" (mesh from {})", p.display()))
    );
    let (geoms, trees, insts) = img.counts;
    println!(
        "  scene model  {geoms} geometries in {trees} trees (8-wide BVHs), {insts} instances: {} virtual triangles; built in {:.3} s ({} threads)",
        scene.virtual_triangles(),
        img.build_secs,
        rayon::current_num_threads()
    );
    println!(
        "  rays traced  {} (primary, shadow{}) in {:.3} s: {:.2} Mrays/s on {} threads",
        img.rays,
        if scene.ao_samples > 0 {
            format!(" and {} ambient-occlusion per pixel", scene.ao_samples)
        } else {
            String::new()
        },
        img.trace_secs,
        img.rays as f64 / img.trace_secs / 1e6,
        rayon::current_num_threads()
    );
    println!("  tier         {tier}");
    println!("  digest       0x{:016x} (the primary hits)", img.digest);
    println!("  build        {}", flags());
    println!("  wall time    {secs:.3} s");
}
