//! The scene-level report: BVH build and traversal on Sponza and generated scenes (a ≥ 1
//! M-triangle sphere, a city of boxes, beams and needles, a 1 M-triangle terrain at grazing
//! angles), one thread and all cores, packets of 8 and 16, single rays, closest and any hit,
//! primary and diffuse-bounce rays. Writes `benches/scenes.md` and prints it.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo run --release -p octoray-benches --bin scenes`
//! (`-- --quick` for one run per row instead of the best of five; `-- --only TEXT` for the rows
//! whose description contains TEXT, `-- --sponza` for Sponza alone, `-- --no-scene-model`
//! without the scene-model and instancing sections). tinybvh's rows need `--features tinybvh`
//! (a C++20 compiler builds it); without it they say "skipped".

use octoray::bvh::{BuildOptions, Bvh8, Bvh8Ref, Sequential};
use octoray::kernels::{MollerTrumbore, Watertight};
use octoray::lanes::LaneMask;
use octoray::prim::{PackedTriangle, RayLanes, VertexTriangle};
use octoray::tree::{closest_packet_with, closest_ray_with};
use octoray_benches::embree::EmbreeScene;
use octoray_benches::instancing::{
    alpha, field, flatten, instanced, restart_closest, scene_of, scene_packets_closest,
    scene_singles_any, scene_singles_closest, wave, Layout,
};
use octoray_benches::scene_chart::{self, Rates};
use octoray_benches::scene_peers::{BvhScene, ObvhsScene, TinyBvhScene};
use octoray_benches::scenes::{
    batch_closest, city, jittered_sphere, open_field, packets_any, packets_closest, scanned,
    singles_any, singles_closest, sponza, terrain, SceneSet,
};
use octoray_benches::targets::TARGETS;
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

fn report(s: &SceneSet, runs: usize, md: &mut String) -> Rates {
    let (w, h) = (1024u32, 768u32);
    let verts = s.vertex_tris();
    let packed: Vec<PackedTriangle> = s
        .tris
        .iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect();
    let (build_s, _) = best(runs, || Bvh8::build(&verts).stats().nodes as u64);
    let (build_par_s, _) = best(runs, || {
        Bvh8::try_build_on(&verts, &octoray::parallel::Rayon)
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
    let p8 = s.primary_tiled(0, w, h, 4, 2);
    let p16 = s.primary_tiled(0, w, h, 4, 4);
    let second = s.primary_tiled(1, w, h, 4, 2);
    let bounce = s.diffuse_bounces(&p8, &wt);
    let shadow = s.shadow_rays(&p8, &wt);
    let (wr, sr) = (wt.as_ref(), st.as_ref());
    writeln!(
        md,
        "\n### {} ({} triangles; {} primary rays at {w}×{h} from each of two cameras, {} diffuse-bounce rays and {} shadow rays from the first camera's hits)\n",
        s.name,
        s.tris.len(),
        p8.len(),
        bounce.len(),
        shadow.len()
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
    row(
        "primary (camera 2)",
        "closest",
        "packet-8 (4×2 tiles)",
        "watertight",
        second.len(),
        &mut || packets_closest::<f32x8, Watertight>(wr, &second),
    );
    row(
        "primary (camera 2)",
        "closest",
        "single ray",
        "watertight",
        second.len(),
        &mut || singles_closest::<f32x8, Watertight>(wr, &second),
    );
    row(
        "primary (camera 2)",
        "closest",
        "single ray",
        "standard",
        second.len(),
        &mut || singles_closest::<f32x8, MollerTrumbore>(sr, &second),
    );
    row(
        "shadow",
        "any",
        "packet-8",
        "watertight",
        shadow.len(),
        &mut || packets_any::<f32x8, Watertight>(wr, &shadow),
    );
    row(
        "shadow",
        "any",
        "single ray",
        "watertight",
        shadow.len(),
        &mut || singles_any::<f32x8, Watertight>(wr, &shadow),
    );
    // The watertight tier on the tree with spatial splits.
    let spatial =
        || Bvh8::try_build_options(&verts, BuildOptions::SPATIAL, &Sequential).expect("build");
    let (spatial_s, _) = best(runs, || spatial().stats().nodes as u64);
    let ws = spatial();
    let (wsr, ws_stats) = (ws.as_ref(), ws.stats());
    let tier = "watertight, spatial splits";
    row(
        "primary",
        "closest",
        "packet-8 (4×2 tiles)",
        tier,
        p8.len(),
        &mut || packets_closest::<f32x8, Watertight>(wsr, &p8),
    );
    row(
        "primary",
        "closest",
        "single ray (leaves ×8)",
        tier,
        p8.len(),
        &mut || singles_closest::<f32x8, Watertight>(wsr, &p8),
    );
    row("primary", "any", "single ray", tier, p8.len(), &mut || {
        singles_any::<f32x8, Watertight>(wsr, &p8)
    });
    row(
        "diffuse bounce",
        "closest",
        "single ray",
        tier,
        bounce.len(),
        &mut || singles_closest::<f32x8, Watertight>(wsr, &bounce),
    );
    row(
        "primary (camera 2)",
        "closest",
        "single ray",
        tier,
        second.len(),
        &mut || singles_closest::<f32x8, Watertight>(wsr, &second),
    );
    row(
        "shadow",
        "any",
        "single ray",
        tier,
        shadow.len(),
        &mut || singles_any::<f32x8, Watertight>(wsr, &shadow),
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
        "primary (camera 2)",
        "closest",
        "single ray",
        "obvhs 0.4 (CWBVH)",
        second.len(),
        &mut || ob.closest(&second),
    );
    row(
        "shadow",
        "any",
        "single ray",
        "obvhs 0.4 (CWBVH)",
        shadow.len(),
        &mut || ob.any(&shadow),
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
            format!(
                "octoray, spatial splits (`BuildOptions::SPATIAL`; {} references for {} triangles, SAH cost {:.1})",
                ws_stats.references, ws_stats.prims, ws_stats.sah_cost
            ),
            spatial_s,
        ),
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
    for hq in [true, false] {
        let name = if hq {
            "tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)"
        } else {
            "tinybvh 1.6.8 (BVH8_CPU, Build: binned)"
        };
        match TinyBvhScene::build(&s.tris, hq) {
            Ok((tb, built)) => {
                builds.push((name.to_string(), built.as_secs_f64()));
                row(
                    "primary",
                    "closest",
                    "single ray",
                    name,
                    p8.len(),
                    &mut || tb.closest(&p8),
                );
                row(
                    "diffuse bounce",
                    "closest",
                    "single ray",
                    name,
                    bounce.len(),
                    &mut || tb.closest(&bounce),
                );
                row(
                    "primary (camera 2)",
                    "closest",
                    "single ray",
                    name,
                    second.len(),
                    &mut || tb.closest(&second),
                );
                // The wrapper has no occlusion query: its closest hit within the segment.
                row(
                    "shadow",
                    "closest (no occlusion query)",
                    "single ray",
                    name,
                    shadow.len(),
                    &mut || tb.closest(&shadow),
                );
            }
            Err(e) => {
                writeln!(md_peers, "tinybvh rows skipped: {e}.").unwrap();
                break;
            }
        }
    }
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
                row(
                    "primary (camera 2)",
                    "closest",
                    "packet-8 (rtcIntersect8)",
                    &name,
                    second.len(),
                    &mut || em.closest8(&second),
                );
                row(
                    "primary (camera 2)",
                    "closest",
                    "single ray (rtcIntersect1)",
                    &name,
                    second.len(),
                    &mut || em.closest1(&second),
                );
                row(
                    "shadow",
                    "any",
                    "packet-8 (rtcOccluded8)",
                    &name,
                    shadow.len(),
                    &mut || em.any8(&shadow),
                );
                row(
                    "shadow",
                    "any",
                    "single ray (rtcOccluded1)",
                    &name,
                    shadow.len(),
                    &mut || em.any1(&shadow),
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
    for t in TARGETS {
        let (what, a, b) = (t.what, t.octoray, t.peer);
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
    rates
}

/// One row of a comparison table: `f` timed over `n` rays; returns Mrays/s and hits.
fn rate(runs: usize, n: usize, f: &mut dyn FnMut() -> u64) -> (f64, u64) {
    let (t, hits) = best(runs, f);
    (n as f64 / t / 1e6, hits)
}

/// The columns of one comparison row, timed in alternation (`runs` rounds, each running every
/// column once) so that a slow spell of a shared machine hits every column alike: best Mrays/s
/// and hits per column.
fn rates(runs: usize, n: usize, fs: &mut [&mut dyn FnMut() -> u64]) -> Vec<(f64, u64)> {
    let mut out = vec![(0.0f64, 0u64); fs.len()];
    for _ in 0..runs {
        for (f, o) in fs.iter_mut().zip(out.iter_mut()) {
            let s = Instant::now();
            let hits = black_box(f());
            let r = n as f64 / s.elapsed().as_secs_f64() / 1e6;
            *o = (o.0.max(r), hits);
        }
    }
    out
}

/// The renderer's scene model on a file of several meshes: one tree against a scene of one
/// geometry and a scene of one geometry per mesh; refit against rebuild and an animation
/// refitted frame by frame; alpha-tested leaves through a filter against the restart loop.
fn scene_model_report(s: &SceneSet, runs: usize, md: &mut String) {
    let (w, h) = (1024u32, 768u32);
    let verts = s.vertex_tris();
    let tree = Bvh8::build(&verts);
    let p8 = s.primary_tiled(0, w, h, 4, 2);
    let bounce = s.diffuse_bounces(&p8, &tree);
    let one = scene_of(s, Layout::OneGeometry);
    let many = scene_of(s, Layout::MeshesOneTree);
    let inst = scene_of(s, Layout::MeshesInstanced);
    let geoms = many.geometries().len();
    writeln!(
        md,
        "\n### {}: one tree against scenes of its meshes\n",
        s.name
    )
    .unwrap();
    writeln!(
        md,
        "The same triangles, watertight, the query mask all ones: `Bvh8` alone; a scene of one geometry; a scene of its {geoms} meshes as geometries in one tree (one instance of the set: what a renderer does with static meshes); the {geoms} meshes each in its own tree and instance (two levels, identity transforms). The columns of a row are timed in alternation, best of {runs} rounds; ratios against the one-tree column of the same rays.\n"
    )
    .unwrap();
    writeln!(
        md,
        "| rays | query | traversal | one tree | 1 geometry | 1 geometry / one tree | {geoms} geometries, one tree | {geoms} geometries / one tree | {geoms} instances | {geoms} instances / one tree |"
    )
    .unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|").unwrap();
    let (tr, r1, rn, ri) = (tree.as_ref(), one.as_ref(), many.as_ref(), inst.as_ref());
    type Row<'a> = (
        &'a str,
        &'a str,
        &'a str,
        &'a [octoray::prim::Ray],
        Box<dyn Fn(&[octoray::prim::Ray]) -> u64 + 'a>,
        Box<dyn Fn(&[octoray::prim::Ray]) -> u64 + 'a>,
        Box<dyn Fn(&[octoray::prim::Ray]) -> u64 + 'a>,
        Box<dyn Fn(&[octoray::prim::Ray]) -> u64 + 'a>,
    );
    let rows: Vec<Row<'_>> = vec![
        (
            "primary",
            "closest",
            "packet-8",
            &p8,
            Box::new(|r| packets_closest::<f32x8, Watertight>(tr, r)),
            Box::new(|r| scene_packets_closest(r1, r)),
            Box::new(|r| scene_packets_closest(rn, r)),
            Box::new(|r| scene_packets_closest(ri, r)),
        ),
        (
            "primary",
            "closest",
            "single ray",
            &p8,
            Box::new(|r| singles_closest::<f32x8, Watertight>(tr, r)),
            Box::new(|r| scene_singles_closest(r1, r)),
            Box::new(|r| scene_singles_closest(rn, r)),
            Box::new(|r| scene_singles_closest(ri, r)),
        ),
        (
            "primary",
            "any",
            "single ray",
            &p8,
            Box::new(|r| singles_any::<f32x8, Watertight>(tr, r)),
            Box::new(|r| scene_singles_any(r1, r)),
            Box::new(|r| scene_singles_any(rn, r)),
            Box::new(|r| scene_singles_any(ri, r)),
        ),
        (
            "diffuse bounce",
            "closest",
            "single ray",
            &bounce,
            Box::new(|r| singles_closest::<f32x8, Watertight>(tr, r)),
            Box::new(|r| scene_singles_closest(r1, r)),
            Box::new(|r| scene_singles_closest(rn, r)),
            Box::new(|r| scene_singles_closest(ri, r)),
        ),
    ];
    for (rays, q, how, set, a, b, c, d) in &rows {
        let r = rates(
            runs,
            set.len(),
            &mut [&mut || a(set), &mut || b(set), &mut || c(set), &mut || {
                d(set)
            }],
        );
        let [(ra, ha), (rb, hb), (rc, hc), (rd, hd)] = [r[0], r[1], r[2], r[3]];
        assert_eq!(
            [ha, ha, ha],
            [hb, hc, hd],
            "the same hits through every structure"
        );
        eprintln!(
            "{} {rays} {q} {how}: tree {ra:.2}, 1 geometry {rb:.2}, {geoms} in one tree {rc:.2}, {geoms} instances {rd:.2} Mrays/s",
            s.name
        );
        writeln!(
            md,
            "| {rays} | {q} | {how} | {ra:.2} | {rb:.2} | {:.2}× | {rc:.2} | {:.2}× | {rd:.2} | {:.2}× |",
            rb / ra,
            rc / ra,
            rd / ra
        )
        .unwrap();
    }

    // Refit against rebuild, and an animation: the wave's amplitude grows frame by frame; the
    // refitted tree keeps the first frame's topology.
    let (build_s, _) = best(runs, || Bvh8::build(&verts).stats().nodes as u64);
    let moved = wave(&s.tris, 1);
    let mut refit = tree.clone();
    let (refit_s, _) = best(runs, || {
        refit.refit(&moved).expect("same slice");
        1
    });
    let (refit_par_s, _) = best(runs, || {
        refit
            .refit_on(&moved, &octoray::parallel::Rayon)
            .expect("same slice");
        1
    });
    writeln!(
        md,
        "\nRefit after every vertex moved (`Bvh8::refit`): **{:.2} ms** ({} threads: {:.2} ms) against a rebuild's {:.1} ms: {:.0}× faster on one thread.\n",
        refit_s * 1e3,
        rayon::current_num_threads(),
        refit_par_s * 1e3,
        build_s * 1e3,
        build_s / refit_s
    )
    .unwrap();
    writeln!(
        md,
        "| animation frame (wave amplitude) | primary single ray, refitted | rebuilt | refitted / rebuilt | bounce single ray, refitted | rebuilt | refitted / rebuilt |"
    )
    .unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|").unwrap();
    for frame in [1u32, 4, 16, 64] {
        let moved = wave(&s.tris, frame);
        let mut refit = tree.clone();
        refit.refit(&moved).expect("same slice");
        let rebuilt = Bvh8::build(&moved);
        let r = rates(
            runs,
            p8.len(),
            &mut [
                &mut || singles_closest::<f32x8, Watertight>(refit.as_ref(), &p8),
                &mut || singles_closest::<f32x8, Watertight>(rebuilt.as_ref(), &p8),
            ],
        );
        let [(a, ha), (b, hb)] = [r[0], r[1]];
        assert_eq!(ha, hb, "refitted and rebuilt trees hit alike");
        let r = rates(
            runs,
            bounce.len(),
            &mut [
                &mut || singles_closest::<f32x8, Watertight>(refit.as_ref(), &bounce),
                &mut || singles_closest::<f32x8, Watertight>(rebuilt.as_ref(), &bounce),
            ],
        );
        let [(c, _), (d, _)] = [r[0], r[1]];
        writeln!(
            md,
            "| {frame} ({:.2}) | {a:.2} | {b:.2} | {:.2}× | {c:.2} | {d:.2} | {:.2}× |",
            0.02 * frame as f32,
            a / b,
            c / d
        )
        .unwrap();
    }

    // Alpha-tested leaves.
    let mut alpha_f = alpha;
    let (fa, hf) = rate(runs, p8.len(), &mut || {
        p8.iter()
            .filter(|r| closest_ray_with::<f32x8, Watertight, _>(tr, r, &mut alpha_f).is_some())
            .count() as u64
    });
    let (re, hr) = rate(runs, p8.len(), &mut || {
        p8.iter()
            .filter(|ray| restart_closest(tr, ray, alpha).is_some())
            .count() as u64
    });
    let (pf, _) = rate(runs, p8.len(), &mut || {
        p8.chunks(8)
            .map(|c| {
                u64::from(
                    closest_packet_with::<f32x8, Watertight, _>(
                        tr,
                        &RayLanes::load(c),
                        &mut alpha_f,
                    )
                    .mask
                    .bitmask()
                    .count_ones(),
                )
            })
            .sum()
    });
    let (none, _) = rate(runs, p8.len(), &mut || {
        singles_closest::<f32x8, Watertight>(tr, &p8)
    });
    writeln!(
        md,
        "\nAlpha-tested leaves (every other triangle cut out in a 6×6 checkerboard of its barycentrics), primary closest hit, one thread: hit filter **{fa:.2}** Mrays/s single ray ({hf} hits), {pf:.2} packet-8; the restart loop a renderer writes without one (trace again from just past each cut-out hit) {re:.2} ({hr} hits): the filter is {:.2}× the loop. Without alpha: {none:.2}.",
        fa / re
    )
    .unwrap();
}

/// A field of instances of one mesh: the two-level scene against the same triangles flattened
/// into one tree, and against Embree 3's instancing (`RTC_GEOMETRY_TYPE_INSTANCE`).
fn instancing_report(runs: usize, md: &mut String) {
    let side = 16u32;
    let mesh = jittered_sphere(64).tris;
    let (places, camera) = field(side);
    let flat = SceneSet {
        name: "instanced field (flattened)",
        tris: flatten(&mesh, &places),
        meshes: vec![0],
        cameras: [camera; 2],
        light: glam::Vec3::new(0.0, 1e3, 0.0),
    };
    let (w, h) = (1024u32, 768u32);
    let t0 = Instant::now();
    let scene = instanced(&mesh, &places);
    let scene_build = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let tree = Bvh8::build(&flat.vertex_tris());
    let flat_build = t0.elapsed().as_secs_f64();
    let p8 = flat.primary_tiled(0, w, h, 4, 2);
    let bounce = flat.diffuse_bounces(&p8, &tree);
    writeln!(
        md,
        "\n### Instancing: {} instances of a {}-triangle mesh ({} triangles flattened)\n",
        places.len(),
        mesh.len(),
        flat.tris.len()
    )
    .unwrap();
    writeln!(
        md,
        "Random rotations and scales 0.6–1.4 on a grid; {} primary rays at {w}×{h}, {} diffuse-bounce rays (from the flattened tree's hits). Builds: two-level {:.3} s (the mesh once, then the top level over the instances), flattened {:.3} s. Hit counts differ slightly: the flattened triangles are the instances' vertices rounded to f32 in world space, the two-level scene tests the exact mesh with each ray carried into object space.\n",
        p8.len(),
        bounce.len(),
        scene_build,
        flat_build
    )
    .unwrap();
    let sr = scene.as_ref();
    let tr = tree.as_ref();
    let embree = EmbreeScene::build_instanced(&mesh, &places, true);
    let embree_flat = EmbreeScene::build(&flat.tris, true);
    writeln!(
        md,
        "| rays | query | traversal | two-level | flattened | two-level / flattened | Embree 3 robust, instanced | two-level / Embree instanced | Embree 3 robust, flattened |"
    )
    .unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|---|---|").unwrap();
    let rows: [(&str, &str, &str, &[octoray::prim::Ray]); 4] = [
        ("primary", "closest", "packet-8", &p8),
        ("primary", "closest", "single ray", &p8),
        ("primary", "any", "single ray", &p8),
        ("diffuse bounce", "closest", "single ray", &bounce),
    ];
    for (k, (rays, q, how, set)) in rows.iter().enumerate() {
        let r = rates(
            runs,
            set.len(),
            &mut [
                &mut || match k {
                    0 => scene_packets_closest(sr, set),
                    2 => scene_singles_any(sr, set),
                    _ => scene_singles_closest(sr, set),
                },
                &mut || match k {
                    0 => packets_closest::<f32x8, Watertight>(tr, set),
                    2 => singles_any::<f32x8, Watertight>(tr, set),
                    _ => singles_closest::<f32x8, Watertight>(tr, set),
                },
            ],
        );
        let [(a, ha), (b, hb)] = [r[0], r[1]];
        let em = |e: &Result<(EmbreeScene, std::time::Duration), String>| match e {
            Ok((e, _)) => {
                let (r, hits) = rate(runs, set.len(), &mut || match k {
                    0 => e.closest8(set),
                    2 => e.any1(set),
                    _ => e.closest1(set),
                });
                (Some(r), format!("{r:.2} ({hits} hits)"))
            }
            Err(_) => (None, "n/a".into()),
        };
        let (ei, ei_s) = em(&embree);
        let (_, ef_s) = em(&embree_flat);
        eprintln!("instancing {rays} {q} {how}: two-level {a:.2}, flattened {b:.2}, Embree instanced {ei_s}");
        writeln!(
            md,
            "| {rays} | {q} | {how} | {a:.2} ({ha} hits) | {b:.2} ({hb} hits) | {:.2}× | {ei_s} | {} | {ef_s} |",
            a / b,
            ei.map_or("n/a".into(), |e| format!("{:.2}×", a / e))
        )
        .unwrap();
    }
    if let Err(e) = &embree {
        writeln!(md, "\nEmbree rows skipped: {e}.").unwrap();
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let runs = if quick { 1 } else { 5 };
    let mut md = String::new();
    writeln!(md, "# octoray scene-level report\n").unwrap();
    writeln!(
        md,
        "Generated by `RUSTFLAGS=\"-C target-cpu=native\" cargo run --release -p octoray-benches --bin scenes`. Build: {}. Best of {runs} runs per row; 8-wide BVH (binned SAH, 32 bins, leaves of at most one SoA block of 8; rows marked \"spatial splits\" on the tree of `BuildOptions::SPATIAL`); one thread unless the row says otherwise. Machine: {}.",
        octoray_benches::build_flags(),
        octoray_benches::machine()
    )
    .unwrap();
    writeln!(
        md,
        "\nWhat bounds each target missed below, per ray (instructions, mispredicted branches and D1 misses under callgrind, octoray's row beside the peer's), and the design step that would move it: `benches/counts.md` (`profile --report`)."
    )
    .unwrap();
    let scene_model = !std::env::args().any(|a| a == "--no-scene-model");
    let mut charted = vec![];
    match sponza() {
        Ok(s) => {
            charted.push((s.name.to_string(), report(&s, runs, &mut md)));
            if scene_model {
                scene_model_report(&s, runs, &mut md);
            }
        }
        Err(e) => writeln!(md, "\nSponza skipped: {e}").unwrap(),
    }
    if scene_model {
        instancing_report(runs, &mut md);
    }
    if !std::env::args().any(|a| a == "--sponza") {
        // Generated scenes of other kinds: no downloads, the same triangles on every machine.
        for make in [
            || jittered_sphere(1024),
            city,
            || terrain(708),
            || scanned(640),
            open_field,
        ] {
            let s = make();
            charted.push((s.name.to_string(), report(&s, runs, &mut md)));
        }
    }
    print!("{md}");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes.md");
    if let Err(e) = std::fs::write(path, &md) {
        eprintln!("cannot write {path}: {e}");
    }
    let svg = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes.svg");
    if let Err(e) = scene_chart::draw(
        &charted,
        &format!(
            "{}, {}",
            octoray_benches::machine(),
            octoray_benches::build_flags()
        ),
        svg,
    ) {
        eprintln!("cannot draw {svg}: {e}");
    }
}
