//! One scene of the scene report, measured: builds, every system's rows on the same rays, the
//! rows on all threads. [`super::markdown`] writes it.

use super::embree::EmbreeScene;
use super::peers::{BvhScene, ObvhsScene, TinyBvhScene};
use super::row::{RaySet, Row, System, Tier, Traversal};
use super::sets::{packets_closest, singles_closest, SceneSet};
use super::timing::best;
use super::trace::{OctorayTree, Traces};
use glam::Vec3;
use octoray::bvh::{BuildOptions, BuildStats, Bvh8, Bvh8Node, Bvh8Ref, Sequential};
use octoray::kernels::{MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
use rayon::prelude::*;
use wide::f32x8;

/// The ray sets of one scene at 1024×768, traced from its first camera unless named.
pub struct RaySets {
    /// Primary rays in 4×2 tiles (packets of 8, single rays).
    pub p8: Vec<Ray>,
    /// Primary rays in 4×4 tiles (packets of 16).
    pub p16: Vec<Ray>,
    /// The second camera's primary rays in 4×2 tiles.
    pub second: Vec<Ray>,
    /// Diffuse bounces from the hits of `p8`.
    pub bounce: Vec<Ray>,
    /// Shadow rays from the hits of `p8`.
    pub shadow: Vec<Ray>,
}

impl RaySets {
    /// The report's rays of `s`, bounces and shadow rays from the hits in `tree`.
    pub fn new(s: &SceneSet, tree: &Bvh8<VertexTriangle>) -> Self {
        let (w, h) = (1024u32, 768u32);
        let p8 = s.primary_tiled(0, w, h, 4, 2);
        Self {
            p16: s.primary_tiled(0, w, h, 4, 4),
            second: s.primary_tiled(1, w, h, 4, 2),
            bounce: s.diffuse_bounces(&p8, tree),
            shadow: s.shadow_rays(&p8, tree),
            p8,
        }
    }

    /// The rays of `set` in the order `traversal` takes them.
    pub fn get(&self, set: RaySet, traversal: Traversal) -> &[Ray] {
        match (set, traversal) {
            (RaySet::Primary, Traversal::Packet16) => &self.p16,
            (RaySet::Primary, _) => &self.p8,
            (RaySet::Camera2, _) => &self.second,
            (RaySet::Bounce, _) => &self.bounce,
            (RaySet::Shadow, _) => &self.shadow,
        }
    }
}

/// One row measured.
#[derive(Clone, Copy, Debug)]
pub struct Measured {
    /// The row.
    pub row: Row,
    /// Its speed, one thread.
    pub mrays: f64,
    /// Rays that hit (or were occluded).
    pub hits: u64,
}

/// A row on all threads (rayon), watertight.
#[derive(Clone, Copy, Debug)]
pub struct Threaded {
    /// The rays.
    pub rays: RaySet,
    /// How they are handed over.
    pub traversal: Traversal,
    /// Threads used.
    pub threads: usize,
    /// The speed on all of them.
    pub mrays: f64,
}

/// The watertight tree's build times: one thread, all threads, and validating it as untrusted
/// slices (what a renderer loading a stored tree pays), seconds.
#[derive(Clone, Copy, Debug)]
pub struct BuildTimes {
    /// One thread.
    pub one: f64,
    /// All threads (rayon).
    pub all: f64,
    /// `Bvh8Ref::new` on its slices.
    pub validate: f64,
}

/// One scene, measured.
pub struct Section {
    /// The scene's name.
    pub name: &'static str,
    /// Its triangles.
    pub triangles: usize,
    /// Rays per camera, bounces and shadow rays.
    pub rays: [usize; 3],
    /// The watertight tree's statistics.
    pub stats: BuildStats,
    /// Its SAH terms: node, leaf, leaf in blocks of 8 ([`sah_terms`]).
    pub sah: (f32, f32, f32),
    /// Its build times.
    pub times: BuildTimes,
    /// Every row measured, in order.
    pub rows: Vec<Measured>,
    /// The rows on all threads.
    pub threaded: Vec<Threaded>,
    /// The other builds (spatial splits, the peers): what was built, seconds.
    pub builds: Vec<(String, f64)>,
    /// Why a peer's rows are missing, one line each.
    pub skipped: Vec<String>,
}

impl Section {
    /// Mrays/s per row, for the targets and the chart.
    pub fn rates(&self) -> super::chart::Rates {
        self.rows.iter().map(|m| (m.row, m.mrays)).collect()
    }
}

/// What [`measure`] times: best of `runs`, only the rows whose labels contain `only`.
pub struct Timing<'a> {
    /// Runs per row.
    pub runs: usize,
    /// A filter on the row labels ("" keeps all).
    pub only: &'a str,
}

/// Times every row of `system` ([`System::rows`]) traced by `tracer` on `sets`.
fn time_rows(
    out: &mut Vec<Measured>,
    timing: &Timing<'_>,
    system: System,
    tracer: &dyn Traces,
    sets: &RaySets,
) {
    for &(set, query, traversal) in system.rows() {
        let row = Row::new(set, query, traversal, system);
        if !row.cells().join(" ").contains(timing.only) {
            continue;
        }
        let rays = sets.get(set, traversal);
        let (t, hits) = best(timing.runs, || {
            tracer
                .trace(query, traversal, rays)
                .unwrap_or_else(|| panic!("{} offers its rows: {row}", system.label()))
        });
        let mrays = rays.len() as f64 / t / 1e6;
        eprintln!("{row}: {mrays:.2} Mrays/s");
        out.push(Measured { row, mrays, hits });
    }
}

/// The peers' rows on `tris`, same rays, same run; their builds and a line per peer skipped.
fn peer_rows(
    rows: &mut Vec<Measured>,
    timing: &Timing<'_>,
    tris: &[[Vec3; 3]],
    sets: &RaySets,
) -> (Vec<(String, f64)>, Vec<String>) {
    let mut skipped = vec![];
    let (ob, ob_build) = ObvhsScene::build(tris);
    let (bv, bv_build) = BvhScene::build(tris);
    time_rows(rows, timing, System::Obvhs, &ob, sets);
    time_rows(rows, timing, System::Bvh, &bv, sets);
    let (n, l, b) = ob.sah_cost();
    let mut builds = vec![
        (
            format!(
                "obvhs 0.4 (CWBVH, medium_build; SAH cost {:.1} = {n:.1} node + {l:.1} leaf; in blocks of 8: {:.1})",
                n + l,
                n + b
            ),
            ob_build.as_secs_f64(),
        ),
        (System::Bvh.label().to_string(), bv_build.as_secs_f64()),
    ];
    for hq in [true, false] {
        let system = System::TinyBvh { hq };
        match TinyBvhScene::build(tris, hq) {
            Ok((tb, built)) => {
                builds.push((system.label().to_string(), built.as_secs_f64()));
                time_rows(rows, timing, system, &tb, sets);
            }
            Err(e) => {
                skipped.push(format!("tinybvh rows skipped: {e}."));
                break;
            }
        }
    }
    for robust in [true, false] {
        let system = System::Embree { robust };
        match EmbreeScene::build(tris, robust) {
            Ok((em, built)) => {
                builds.push((system.label().to_string(), built.as_secs_f64()));
                time_rows(rows, timing, system, &em, sets);
            }
            Err(e) => {
                skipped.push(format!("Embree rows skipped: {e}."));
                break;
            }
        }
    }
    (builds, skipped)
}

/// The watertight rows on all threads: primary packets and bounce single rays.
fn threaded_rows(runs: usize, tree: Bvh8Ref<'_, VertexTriangle>, sets: &RaySets) -> Vec<Threaded> {
    let threads = rayon::current_num_threads();
    let (p, _) = best(runs, || {
        sets.p8
            .par_chunks(1024)
            .map(|c| packets_closest::<f32x8, Watertight>(tree, c))
            .sum()
    });
    let (b, _) = best(runs, || {
        sets.bounce
            .par_chunks(1024)
            .map(|c| singles_closest::<f32x8, Watertight>(tree, c))
            .sum()
    });
    vec![
        Threaded {
            rays: RaySet::Primary,
            traversal: Traversal::Packet8,
            threads,
            mrays: sets.p8.len() as f64 / p / 1e6,
        },
        Threaded {
            rays: RaySet::Bounce,
            traversal: Traversal::Single,
            threads,
            mrays: sets.bounce.len() as f64 / b / 1e6,
        },
    ]
}

impl BuildTimes {
    /// The build times of the watertight tree over `verts`.
    fn measure(verts: &[VertexTriangle], runs: usize) -> Self {
        let (one, _) = best(runs, || Bvh8::build(verts).stats().nodes as u64);
        let (all, _) = best(runs, || {
            Bvh8::try_build_on(verts, &octoray::parallel::Rayon)
                .expect("build")
                .stats()
                .nodes as u64
        });
        let wt = Bvh8::build(verts);
        let (validate, _) = best(runs, || {
            u64::from(
                Bvh8Ref::<VertexTriangle>::new(wt.nodes(), wt.blocks(), wt.ids(), verts.len())
                    .is_ok(),
            )
        });
        Self { one, all, validate }
    }
}

/// Measures one scene: builds, octoray's tiers and trees, the peers, the threaded rows.
pub fn measure(s: &SceneSet, timing: &Timing<'_>) -> Section {
    let verts = s.vertex_tris();
    let packed: Vec<PackedTriangle> = s
        .tris
        .iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect();
    let times = BuildTimes::measure(&verts, timing.runs);
    let wt = Bvh8::build(&verts);
    let st = Bvh8::build(&packed);
    let sets = RaySets::new(s, &wt);
    let mut rows = vec![];
    let watertight = OctorayTree::<Watertight, _>::new(wt.as_ref());
    time_rows(
        &mut rows,
        timing,
        System::Octoray(Tier::Watertight),
        &watertight,
        &sets,
    );
    let standard = OctorayTree::<MollerTrumbore, _>::new(st.as_ref());
    time_rows(
        &mut rows,
        timing,
        System::Octoray(Tier::Standard),
        &standard,
        &sets,
    );
    let spatial =
        || Bvh8::try_build_options(&verts, BuildOptions::SPATIAL, &Sequential).expect("build");
    let (spatial_s, _) = best(timing.runs, || spatial().stats().nodes as u64);
    let ws = spatial();
    let spatial_tree = OctorayTree::<Watertight, _>::new(ws.as_ref());
    time_rows(
        &mut rows,
        timing,
        System::Octoray(Tier::Spatial),
        &spatial_tree,
        &sets,
    );
    let ws_stats = ws.stats();
    let mut builds = vec![(
        format!(
            "octoray, spatial splits (`BuildOptions::SPATIAL`; {} references for {} triangles, SAH cost {:.1})",
            ws_stats.references, ws_stats.prims, ws_stats.sah_cost
        ),
        spatial_s,
    )];
    let (peer_builds, skipped) = peer_rows(&mut rows, timing, &s.tris, &sets);
    builds.extend(peer_builds);
    Section {
        name: s.name,
        triangles: s.tris.len(),
        rays: [sets.p8.len(), sets.bounce.len(), sets.shadow.len()],
        stats: wt.stats(),
        sah: sah_terms(wt.nodes()),
        times,
        rows,
        threaded: threaded_rows(timing.runs, wt.as_ref(), &sets),
        builds,
        skipped,
    }
}

/// The two terms of `BuildStats::sah_cost` (1 + Σ inner children's areas; Σ leaf area × count),
/// recomputed from the nodes, relative to the root's box; and the leaf term in blocks of 8.
pub fn sah_terms(nodes: &[Bvh8Node]) -> (f32, f32, f32) {
    let half_area = |lo: [f32; 3], hi: [f32; 3]| {
        let e: [f32; 3] = std::array::from_fn(|a| (hi[a] - lo[a]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    };
    let slot = |n: &Bvh8Node, s: usize| {
        (
            std::array::from_fn(|a| n.lo[a][s]),
            std::array::from_fn(|a| n.hi[a][s]),
        )
    };
    let Some(root) = nodes.first() else {
        return (0.0, 0.0, 0.0);
    };
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for s in 0..root.len() {
        let (l, h): ([f32; 3], [f32; 3]) = slot(root, s);
        for a in 0..3 {
            lo[a] = lo[a].min(l[a]);
            hi[a] = hi[a].max(h[a]);
        }
    }
    let root_area = half_area(lo, hi).max(f32::MIN_POSITIVE);
    let (mut inner, mut leaves, mut blocks) = (1.0, 0.0, 0.0);
    for n in nodes {
        for s in 0..n.len() {
            let (l, h) = slot(n, s);
            let a = half_area(l, h) / root_area;
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
