//! The accuracy report: every tier against the exact oracle (big-integer arithmetic), on random,
//! edge-aimed, grazing and translated cases; spheres near and far; crack rates on closed meshes;
//! and the extreme cases. Run: `cargo run --release --example accuracy`.

#[path = "../tests/common/mod.rs"]
mod common;

use common::accuracy::*;

fn row(name: &str, s: &Stats) {
    println!(
        "| {name} | {} | {} | {} | {} | {} | {} | {} / {} / {} | {:.1} |",
        s.cases,
        s.exact_hits,
        s.wrong,
        s.in_margin,
        s.bad_t,
        s.behind,
        s.percentile(0.5),
        s.percentile(0.99),
        s.max_ulps(),
        s.max_scaled()
    );
}

fn header(title: &str) {
    println!("\n### {title}\n");
    println!("| tier | cases | exact hits | wrong (outside margin) | disagree in margin | bad t | behind origin | t error ulp p50 / p99 / max | max t error / (ε·scale) |");
    println!("|---|---|---|---|---|---|---|---|---|");
}

fn main() {
    let n = 20_000;
    let sets: Vec<(String, Vec<TriCase>)> = vec![
        ("random".into(), random_cases(1, n)),
        ("aimed at edges and vertices".into(), edge_cases(2, n)),
        ("grazing 1e-3 rad".into(), grazing_cases(3, n, 1e-3)),
        ("grazing 1e-5 rad".into(), grazing_cases(4, n, 1e-5)),
        ("grazing 1e-7 rad".into(), grazing_cases(5, n, 1e-7)),
        ("translated 1e2".into(), translated_cases(6, n, 1e2, 1.0)),
        ("translated 1e4".into(), translated_cases(7, n, 1e4, 1.0)),
        ("translated 1e6".into(), translated_cases(8, n, 1e6, 1.0)),
    ];
    for (name, cases) in &sets {
        header(&format!("Triangles: {name}"));
        for tier in TriTier::ALL {
            row(tier.name(), &measure_triangles(tier, cases));
        }
    }
    let ssets: Vec<(String, Vec<SphereCase>)> = vec![
        ("near".into(), near_sphere_cases(9, n)),
        ("distance 1e2 r".into(), distant_sphere_cases(10, n, 1e2)),
        ("distance 1e4 r".into(), distant_sphere_cases(11, n, 1e4)),
        ("distance 1e6 r".into(), distant_sphere_cases(12, n, 1e6)),
    ];
    for (name, cases) in &ssets {
        header(&format!("Spheres: {name}"));
        for tier in SphereTier::ALL {
            row(tier.name(), &measure_spheres(tier, cases));
        }
    }
}
