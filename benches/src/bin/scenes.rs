//! The scene-level report: BVH build and traversal on Sponza and a generated ≥ 1 M-triangle
//! sphere, one thread and all cores, packets of 8 and 16, single rays, closest and any hit,
//! primary and diffuse-bounce rays. Writes `benches/scenes.md` and prints it.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo run --release -p octoray-benches --bin scenes`
//! (`-- --quick` for one run per row instead of the best of five; `-- --only TEXT` for the rows
//! whose description contains TEXT, and `-- --sponza` for Sponza alone).

use octoray::bvh::{Bvh8, Bvh8Ref};
use octoray::kernels::{MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, VertexTriangle};
use octoray_benches::embree::EmbreeScene;
use octoray_benches::scene_peers::{BvhScene, ObvhsScene};
use octoray_benches::scenes::{
    batch_closest, jittered_sphere, packets_any, packets_closest, singles_any, singles_closest,
    sponza, SceneSet,
};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Instant;
use wide::{f32x16, f32x8};

/// Best wall time of `runs` runs of `f`, seconds.
fn best(runs: usize, mut f: impl FnMut() -> u64) -> (f64, u64) {
    let mut t = f64::INFINITY;
    let mut r = 0;
    for _ in 0..runs {
        let s = Instant::now();
        r = black_box(f());
        t = t.min(s.elapsed().as_secs_f64());
    }
    (t, r)
}

/// The two terms of `BuildStats::sah_cost` (1 + Σ inner children's areas; Σ leaf area × count),
/// recomputed from the nodes, relative to the root's box; and the leaf term in blocks of 8.
fn sah_terms(nodes: &[octoray::bvh::Bvh8Node]) -> (f32, f32, f32) {
    let half_area = |n: &octoray::bvh::Bvh8Node, s: usize| {
        let e: [f32; 3] = std::array::from_fn(|a| (n.hi[a][s] - n.lo[a][s]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    };
    let Some(root) = nodes.first() else {
        return (0.0, 0.0, 0.0);
    };
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for s in 0..root.len() {
        for a in 0..3 {
            lo[a] = lo[a].min(root.lo[a][s]);
            hi[a] = hi[a].max(root.hi[a][s]);
        }
    }
    let e: [f32; 3] = std::array::from_fn(|a| (hi[a] - lo[a]).max(0.0));
    let root_area = (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]).max(f32::MIN_POSITIVE);
    let (mut inner, mut leaves, mut blocks) = (1.0, 0.0, 0.0);
    for n in nodes {
        for s in 0..n.len() {
            let a = half_area(n, s) / root_area;
            if n.count[s] == 0 {
                inner += a;
            } else {
                leaves += a * n.count[s] as f32;
                blocks += a * n.count[s].div_ceil(8) as f32;
            }
        }
    }
    (inner, leaves, blocks)
}

fn flags() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "-C target-cpu=native (AVX-512, FMA)"
    } else if cfg!(target_feature = "avx2") {
        "AVX2"
    } else {
        "default x86-64 (SSE2)"
    }
}

fn report(s: &SceneSet, runs: usize, md: &mut String) {
    let (w, h) = (1024u32, 768u32);
    let verts = s.vertex_tris();
    let packed: Vec<PackedTriangle> = s
        .tris
        .iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect();
    let (build_s, _) = best(runs, || Bvh8::build(&verts).stats().nodes as u64);
    let (build_par_s, _) = best(runs, || {
        Bvh8::try_build_with(&verts, &octoray::parallel::Rayon)
            .expect("build")
            .stats()
            .nodes as u64
    });
    let wt = Bvh8::build(&verts);
    let st = Bvh8::build(&packed);
    let stats = wt.stats();
    // The stored tree read back as untrusted slices: what a renderer loading it pays.
    let (validate_s, _) = best(runs, || {
        u64::from(
            Bvh8Ref::<VertexTriangle>::new(wt.nodes(), wt.blocks(), wt.ids(), verts.len()).is_ok(),
        )
    });
    let own_sah = sah_terms(wt.nodes());
    let p8 = s.primary_tiled(w, h, 4, 2);
    let p16 = s.primary_tiled(w, h, 4, 4);
    let bounce = s.diffuse_bounces(&p8, &wt);
    let (wr, sr) = (wt.as_ref(), st.as_ref());
    writeln!(
        md,
        "\n### {} ({} triangles; {} primary rays at {w}×{h}, {} diffuse-bounce rays)\n",
        s.name,
        s.tris.len(),
        p8.len(),
        bounce.len()
    )
    .unwrap();
    writeln!(
        md,
        "Build (1 thread): **{:.3} s** ({} threads, rayon: {:.3} s); {} nodes, {} leaves, depth {}, SAH cost {:.1}, {:.0} bytes per triangle (watertight layout, SoA blocks of 8, {:.0} % of block slots filled). Validating the stored tree as untrusted slices (`Bvh8Ref::new`): {:.2} ms.\n",
        build_s, rayon::current_num_threads(), build_par_s, stats.nodes, stats.leaves, stats.depth, stats.sah_cost, stats.bytes_per_prim, 100.0 * stats.block_fill, validate_s * 1e3
    )
    .unwrap();
    writeln!(
        md,
        "| rays | query | traversal | tier or peer | Mrays/s, 1 thread | hits |"
    )
    .unwrap();
    writeln!(md, "|---|---|---|---|---|---|").unwrap();
    let only = std::env::args()
        .skip_while(|a| a != "--only")
        .nth(1)
        .unwrap_or_default();
    let mut rates = std::collections::HashMap::new();
    let mut md_peers = String::new();
    let mut row =
        |rays: &str, q: &str, how: &str, tier: &str, n: usize, f: &mut dyn FnMut() -> u64| {
            if !format!("{rays} {q} {how} {tier}").contains(&only) {
                return;
            }
            let (t, hits) = best(runs, f);
            rates.insert(format!("{rays}|{q}|{how}|{tier}"), n as f64 / t / 1e6);
            writeln!(
                md,
                "| {rays} | {q} | {how} | {tier} | {:.2} | {hits} |",
                n as f64 / t / 1e6
            )
            .unwrap();
            eprintln!(
                "{} {rays} {q} {how} {tier}: {:.2} Mrays/s",
                s.name,
                n as f64 / t / 1e6
            );
        };
    row(
        "primary",
        "closest",
        "packet-8 (4×2 tiles)",
        "watertight",
        p8.len(),
        &mut || packets_closest::<f32x8, Watertight>(wr, &p8),
    );
    row(
        "primary",
        "closest",
        "packet-16 (4×4 tiles)",
        "watertight",
        p16.len(),
        &mut || packets_closest::<f32x16, Watertight>(wr, &p16),
    );
    row(
        "primary",
        "closest",
        "single ray (leaves ×8)",
        "watertight",
        p8.len(),
        &mut || singles_closest::<f32x8, Watertight>(wr, &p8),
    );
    row(
        "primary",
        "closest",
        "packet-8",
        "standard",
        p8.len(),
        &mut || packets_closest::<f32x8, MollerTrumbore>(sr, &p8),
    );
    row(
        "primary",
        "closest",
        "single ray",
        "standard",
        p8.len(),
        &mut || singles_closest::<f32x8, MollerTrumbore>(sr, &p8),
    );
    row(
        "primary",
        "any",
        "packet-8",
        "watertight",
        p8.len(),
        &mut || packets_any::<f32x8, Watertight>(wr, &p8),
    );
    row(
        "primary",
        "any",
        "single ray",
        "watertight",
        p8.len(),
        &mut || singles_any::<f32x8, Watertight>(wr, &p8),
    );
    row(
        "diffuse bounce",
        "closest",
        "single ray",
        "watertight",
        bounce.len(),
        &mut || singles_closest::<f32x8, Watertight>(wr, &bounce),
    );
    row(
        "diffuse bounce",
        "closest",
        "batch (picks per 8 rays)",
        "watertight",
        bounce.len(),
        &mut || batch_closest::<f32x8, Watertight>(wr, &bounce),
    );
    row(
        "diffuse bounce",
        "any",
        "single ray",
        "watertight",
        bounce.len(),
        &mut || singles_any::<f32x8, Watertight>(wr, &bounce),
    );
    // Peers, same rays, same run.
    let (ob, ob_build) = ObvhsScene::build(&s.tris);
    let (bv, bv_build) = BvhScene::build(&s.tris);
    row(
        "primary",
        "closest",
        "single ray",
        "obvhs 0.4 (CWBVH)",
        p8.len(),
        &mut || ob.closest(&p8),
    );
    row(
        "primary",
        "any",
        "single ray",
        "obvhs 0.4 (CWBVH)",
        p8.len(),
        &mut || ob.any(&p8),
    );
    row(
        "diffuse bounce",
        "closest",
        "single ray",
        "obvhs 0.4 (CWBVH)",
        bounce.len(),
        &mut || ob.closest(&bounce),
    );
    row(
        "primary",
        "closest",
        "single ray",
        "bvh 0.13",
        p8.len(),
        &mut || bv.closest(&p8),
    );
    let mut builds = vec![
        (
            {
                let (n, l, b) = ob.sah_cost();
                format!(
                    "obvhs 0.4 (CWBVH, medium_build; SAH cost {:.1} = {n:.1} node + {l:.1} leaf; in blocks of 8: {:.1})",
                    n + l,
                    n + b
                )
            },
            ob_build.as_secs_f64(),
        ),
        ("bvh 0.13".to_string(), bv_build.as_secs_f64()),
    ];
    for robust in [true, false] {
        let mode = if robust { "robust" } else { "fast" };
        match EmbreeScene::build(&s.tris, robust) {
            Ok((em, built)) => {
                builds.push((format!("Embree 3 {mode}"), built.as_secs_f64()));
                let name = format!("Embree 3 {mode}");
                row(
                    "primary",
                    "closest",
                    "packet-8 (rtcIntersect8)",
                    &name,
                    p8.len(),
                    &mut || em.closest8(&p8),
                );
                row(
                    "primary",
                    "closest",
                    "single ray (rtcIntersect1)",
                    &name,
                    p8.len(),
                    &mut || em.closest1(&p8),
                );
                row(
                    "primary",
                    "any",
                    "packet-8 (rtcOccluded8)",
                    &name,
                    p8.len(),
                    &mut || em.any8(&p8),
                );
                row(
                    "primary",
                    "any",
                    "single ray (rtcOccluded1)",
                    &name,
                    p8.len(),
                    &mut || em.any1(&p8),
                );
                row(
                    "diffuse bounce",
                    "closest",
                    "single ray (rtcIntersect1)",
                    &name,
                    bounce.len(),
                    &mut || em.closest1(&bounce),
                );
            }
            Err(e) => {
                writeln!(md_peers, "Embree rows skipped: {e}.").unwrap();
                break;
            }
        }
    }
    let threads = rayon::current_num_threads();
    let (t, _) = best(runs, || {
        p8.par_chunks(1024)
            .map(|c| packets_closest::<f32x8, Watertight>(wr, c))
            .sum()
    });
    writeln!(
        md,
        "| primary | closest | packet-8, {threads} threads (rayon) | watertight | {:.2} ({threads} threads) | |",
        p8.len() as f64 / t / 1e6
    )
    .unwrap();
    let (t, _) = best(runs, || {
        bounce
            .par_chunks(1024)
            .map(|c| singles_closest::<f32x8, Watertight>(wr, c))
            .sum()
    });
    writeln!(
        md,
        "| diffuse bounce | closest | single ray, {threads} threads (rayon) | watertight | {:.2} ({threads} threads) | |",
        bounce.len() as f64 / t / 1e6
    )
    .unwrap();
    md.push_str(&md_peers);
    let builds_line: Vec<String> = builds
        .iter()
        .map(|(n, t)| format!("{n} {t:.3} s"))
        .collect();
    writeln!(
        md,
        "\nPeers' builds (1 thread): {}; octoray {build_s:.3} s (SAH cost {:.1} = {:.1} node + {:.1} leaf; in blocks of 8: {:.1}). SAH costs: 1 per node visit and 1 per primitive test (\"in blocks of 8\": 1 per leaf block of up to 8, what one octoray leaf test costs), relative to the scene's box.",
        builds_line.join(", "),
        stats.sah_cost,
        own_sah.0,
        own_sah.1,
        own_sah.0 + own_sah.2
    )
    .unwrap();
    let ratio = |a: &str, b: &str| match (rates.get(a), rates.get(b)) {
        (Some(x), Some(y)) => format!("{:.2}×", x / y),
        _ => "n/a".into(),
    };
    writeln!(
        md,
        "\n| target (1 thread) | octoray row | peer row | ratio |"
    )
    .unwrap();
    writeln!(md, "|---|---|---|---|").unwrap();
    for (what, a, b) in [
        (
            "primary packet-8 ≥ 1.2× Embree robust rtcIntersect8",
            "primary|closest|packet-8 (4×2 tiles)|watertight",
            "primary|closest|packet-8 (rtcIntersect8)|Embree 3 robust",
        ),
        (
            "primary single ray ≥ 1.2× Embree robust rtcIntersect1",
            "primary|closest|single ray (leaves ×8)|watertight",
            "primary|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ),
        (
            "diffuse bounce ≥ 1.2× Embree robust rtcIntersect1",
            "diffuse bounce|closest|single ray|watertight",
            "diffuse bounce|closest|single ray (rtcIntersect1)|Embree 3 robust",
        ),
        (
            "primary single ray ≥ 2× obvhs",
            "primary|closest|single ray (leaves ×8)|watertight",
            "primary|closest|single ray|obvhs 0.4 (CWBVH)",
        ),
        (
            "primary any hit ≥ 2× obvhs",
            "primary|any|single ray|watertight",
            "primary|any|single ray|obvhs 0.4 (CWBVH)",
        ),
        (
            "diffuse bounce ≥ 2× obvhs",
            "diffuse bounce|closest|single ray|watertight",
            "diffuse bounce|closest|single ray|obvhs 0.4 (CWBVH)",
        ),
    ] {
        let show = |k: &str| k.replace('|', ", ");
        writeln!(
            md,
            "| {what} | {} | {} | {} |",
            show(a),
            show(b),
            ratio(a, b)
        )
        .unwrap();
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let runs = if quick { 1 } else { 5 };
    let mut md = String::new();
    writeln!(md, "# octoray scene-level report\n").unwrap();
    writeln!(
        md,
        "Generated by `RUSTFLAGS=\"-C target-cpu=native\" cargo run --release -p octoray-benches --bin scenes`. Build: {}. Best of {runs} runs per row; 8-wide BVH (binned SAH, 32 bins, leaves of at most one SoA block of 8); one thread unless the row says otherwise.",
        flags()
    )
    .unwrap();
    match sponza() {
        Ok(s) => report(&s, runs, &mut md),
        Err(e) => writeln!(md, "\nSponza skipped: {e}").unwrap(),
    }
    if !std::env::args().any(|a| a == "--sponza") {
        report(&jittered_sphere(1024), runs, &mut md);
    }
    print!("{md}");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes.md");
    if let Err(e) = std::fs::write(path, &md) {
        eprintln!("cannot write {path}: {e}");
    }
}
