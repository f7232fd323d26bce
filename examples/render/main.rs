//! octoray's demo: an embedded scene (a jittered icosphere on a ground quad, three spheres, a
//! sun) or your own Wavefront OBJ, primary and shadow rays traced in packets on all cores,
//! written to a PNG, with a summary of what it cost and which accuracy tier it used and why.
//!
//! Run: `cargo run --release --example render` (then open `render.png`).
//! Options: `--size WxH` (640x400), `--output PATH` (render.png), `--tier auto|standard|
//! watertight|fast|f64` (auto), `--lanes 4|8|16` (8), `--obj PATH` (replaces the icosphere).
//! Brute force over every primitive (no acceleration structure): keep OBJ meshes to a few
//! thousand triangles.

mod cli;
mod scene;

use cli::{load_scene, parse, USAGE};
use indicatif::{ProgressBar, ProgressStyle};
use scene::{render, resolve_tier, write_png};
use std::process::ExitCode;
use std::time::Instant;

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
    let scene = match load_scene(&o.obj) {
        Ok(s) => s,
        Err(msg) => {
            eprintln!("render: {msg}");
            return ExitCode::from(1);
        }
    };
    let (tier, why) = resolve_tier(&scene, o.tier);
    let bar = ProgressBar::new(u64::from(o.height));
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} rows {elapsed}").expect("template"),
    );
    let start = Instant::now();
    let img = match render(&scene, tier, o.lanes, o.width, o.height, &|n| bar.inc(n)) {
        Ok(img) => img,
        Err(msg) => {
            bar.abandon();
            eprintln!("render: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let secs = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    if let Err(msg) = write_png(&img, &o.output) {
        eprintln!("render: {msg}");
        return ExitCode::from(1);
    }
    let tests = img.rays as f64 * (scene.tris.len() + scene.spheres.len()) as f64;
    println!("octoray render: {}", o.output.display());
    println!("  resolution   {}x{}", o.width, o.height);
    println!(
        "  scene        {} triangles, {} spheres{}",
        scene.tris.len(),
        scene.spheres.len(),
        o.obj
            .as_ref()
            .map_or(String::new(), |p| format!(" (mesh from {})", p.display()))
    );
    println!(
        "  rays traced  {} (primary and shadow), brute force: {:.3e} ray-primitive tests",
        img.rays, tests
    );
    println!(
        "  throughput   {:.2} Mrays/s on {} threads",
        img.rays as f64 / secs / 1e6,
        rayon::current_num_threads()
    );
    println!(
        "  tier         {} with {} lanes ({})",
        tier.name(),
        o.lanes,
        why
    );
    println!("  build        {}", flags());
    println!("  wall time    {secs:.3} s");
    ExitCode::SUCCESS
}
