//! The scene report's scene-model section, on a file of several meshes: one tree against scenes
//! of its meshes (one geometry, a geometry per mesh, an instance per mesh), refit against
//! rebuild and an animation refitted frame by frame, alpha-tested leaves through a filter
//! against the restart loop. Measured into a [`ModelReport`], then written.

use super::embree::EmbreeScene;
use super::instancing::{
    alpha, restart_closest, scene_of, scene_packets_closest, scene_singles_any,
    scene_singles_closest, wave, Layout,
};
use super::row::{Query, Traversal};
use super::sets::{packets_closest, singles_any, singles_closest, SceneSet};
use super::timing::{alternating, best, rate};
use super::trace::Traces;
use octoray::bvh::Bvh8;
use octoray::kernels::Watertight;
use octoray::lanes::LaneMask;
use octoray::prim::{Ray, RayLanes, VertexTriangle};
use octoray::tree::{closest_packet_with, closest_ray_with};
use std::fmt::Write as _;
use wide::f32x8;

/// One row of the layouts table: Mrays/s through one tree, a scene of one geometry, a scene of
/// its meshes in one tree, and its meshes as instances; Embree 3 robust on one tree and on its
/// meshes as instances.
pub struct LayoutRow {
    /// Rays, query and traversal.
    pub label: [&'static str; 3],
    /// Mrays/s per layout, in that order.
    pub mrays: [f64; 4],
    /// Embree's Mrays/s: one tree, the meshes as instances (timed in alternation).
    pub embree: Option<[f64; 2]>,
}

/// An animation frame: Mrays/s on the refitted and on a rebuilt tree, primary and bounce.
pub struct Frame {
    /// The frame (the wave's amplitude is 0.02 × it).
    pub frame: u32,
    /// Primary single rays: refitted, rebuilt.
    pub primary: [f64; 2],
    /// Bounce single rays: refitted, rebuilt.
    pub bounce: [f64; 2],
}

/// The section, measured.
pub struct ModelReport {
    /// The scene's name.
    pub name: &'static str,
    /// Its meshes.
    pub geoms: usize,
    /// Rounds per row.
    pub runs: usize,
    /// The layouts table.
    pub layouts: Vec<LayoutRow>,
    /// Why Embree's columns are missing, if they are.
    pub embree_skipped: Option<String>,
    /// Refit one thread, all threads, and a rebuild: seconds.
    pub refit: [f64; 3],
    /// The animation.
    pub frames: Vec<Frame>,
    /// Alpha-tested leaves: filter single ray, its hits, filter packet-8, restart loop, its hits,
    /// no alpha (Mrays/s and hit counts).
    pub alpha: ([f64; 4], [u64; 2]),
}

/// A closure tracing a slice of rays, returning its hit count.
type Trace<'a> = Box<dyn Fn(&[Ray]) -> u64 + 'a>;

/// One row of the layouts table to measure: its label, its query for Embree, its rays and the
/// four layouts' traces.
type LayoutCase<'a> = (
    [&'static str; 3],
    (Query, Traversal),
    &'a [Ray],
    [Trace<'a>; 4],
);

/// Embree 3 robust on `s`'s triangles in one scene, and on its meshes each in a scene of its own
/// placed by an identity instance.
fn embree_layouts(s: &SceneSet) -> Result<[EmbreeScene; 2], String> {
    let mut bounds = s.meshes.clone();
    bounds.push(s.tris.len());
    let meshes: Vec<&[[glam::Vec3; 3]]> = bounds
        .windows(2)
        .filter(|w| w[0] != w[1])
        .map(|w| &s.tris[w[0]..w[1]])
        .collect();
    Ok([
        EmbreeScene::build(&s.tris, true)?.0,
        EmbreeScene::build_meshes_instanced(&meshes, true)?.0,
    ])
}

/// The layouts table: each row's four columns timed in alternation (they must hit alike), then
/// Embree's two in alternation.
fn layout_rows(
    s: &SceneSet,
    runs: usize,
    tree: &Bvh8<VertexTriangle>,
    p8: &[Ray],
    bounce: &[Ray],
    embree: &Result<[EmbreeScene; 2], String>,
) -> Vec<LayoutRow> {
    let (one, many, inst) = (
        scene_of(s, Layout::OneGeometry),
        scene_of(s, Layout::MeshesOneTree),
        scene_of(s, Layout::MeshesInstanced),
    );
    let (tr, r1, rn, ri) = (tree.as_ref(), one.as_ref(), many.as_ref(), inst.as_ref());
    let closest = |packets: bool| -> [Trace<'_>; 4] {
        if packets {
            [
                Box::new(move |r| packets_closest::<f32x8, Watertight>(tr, r)),
                Box::new(move |r| scene_packets_closest(r1, r)),
                Box::new(move |r| scene_packets_closest(rn, r)),
                Box::new(move |r| scene_packets_closest(ri, r)),
            ]
        } else {
            [
                Box::new(move |r| singles_closest::<f32x8, Watertight>(tr, r)),
                Box::new(move |r| scene_singles_closest(r1, r)),
                Box::new(move |r| scene_singles_closest(rn, r)),
                Box::new(move |r| scene_singles_closest(ri, r)),
            ]
        }
    };
    let any: [Trace<'_>; 4] = [
        Box::new(move |r| singles_any::<f32x8, Watertight>(tr, r)),
        Box::new(move |r| scene_singles_any(r1, r)),
        Box::new(move |r| scene_singles_any(rn, r)),
        Box::new(move |r| scene_singles_any(ri, r)),
    ];
    let rows: [LayoutCase<'_>; 4] = [
        (
            ["primary", "closest", "packet-8"],
            (Query::Closest, Traversal::Packet8),
            p8,
            closest(true),
        ),
        (
            ["primary", "closest", "single ray"],
            (Query::Closest, Traversal::Single),
            p8,
            closest(false),
        ),
        (
            ["primary", "any", "single ray"],
            (Query::Any, Traversal::Single),
            p8,
            any,
        ),
        (
            ["diffuse bounce", "closest", "single ray"],
            (Query::Closest, Traversal::Single),
            bounce,
            closest(false),
        ),
    ];
    rows.into_iter()
        .map(|(label, (q, how), set, [a, b, c, d])| {
            let r = alternating(
                runs,
                set.len(),
                &mut [&mut || a(set), &mut || b(set), &mut || c(set), &mut || {
                    d(set)
                }],
            );
            let hits = r.iter().map(|x| x.1).collect::<Vec<_>>();
            assert!(
                hits.iter().all(|&h| h == hits[0]),
                "the same hits through every structure"
            );
            let embree = embree.as_ref().ok().map(|[one, inst]| {
                let e = alternating(
                    runs,
                    set.len(),
                    &mut [
                        &mut || one.trace(q, how, set).expect("an Embree row"),
                        &mut || inst.trace(q, how, set).expect("an Embree row"),
                    ],
                );
                [e[0].0, e[1].0]
            });
            eprintln!("{} {label:?}: {r:?} Embree {embree:?}", s.name);
            LayoutRow {
                label,
                mrays: [r[0].0, r[1].0, r[2].0, r[3].0],
                embree,
            }
        })
        .collect()
}

/// Refit after every vertex moved, one thread and all, and a rebuild: seconds.
fn refit_times(
    s: &SceneSet,
    runs: usize,
    verts: &[VertexTriangle],
    tree: &Bvh8<VertexTriangle>,
) -> [f64; 3] {
    let (build, _) = best(runs, || Bvh8::build(verts).stats().nodes as u64);
    let moved = wave(&s.tris, 1);
    let mut refit = tree.clone();
    let (one, _) = best(runs, || {
        refit.refit(&moved).expect("same slice");
        1
    });
    let (all, _) = best(runs, || {
        refit
            .refit_on(&moved, &octoray::parallel::Rayon)
            .expect("same slice");
        1
    });
    [one, all, build]
}

/// The animation: the wave's amplitude grows frame by frame; the refitted tree keeps the first
/// frame's topology.
fn frames(
    s: &SceneSet,
    runs: usize,
    tree: &Bvh8<VertexTriangle>,
    p8: &[Ray],
    bounce: &[Ray],
) -> Vec<Frame> {
    let pair = |refit: &Bvh8<VertexTriangle>, rebuilt: &Bvh8<VertexTriangle>, rays: &[Ray]| {
        let r = alternating(
            runs,
            rays.len(),
            &mut [
                &mut || singles_closest::<f32x8, Watertight>(refit.as_ref(), rays),
                &mut || singles_closest::<f32x8, Watertight>(rebuilt.as_ref(), rays),
            ],
        );
        assert_eq!(r[0].1, r[1].1, "refitted and rebuilt trees hit alike");
        [r[0].0, r[1].0]
    };
    [1u32, 4, 16, 64]
        .into_iter()
        .map(|frame| {
            let moved = wave(&s.tris, frame);
            let mut refit = tree.clone();
            refit.refit(&moved).expect("same slice");
            let rebuilt = Bvh8::build(&moved);
            Frame {
                frame,
                primary: pair(&refit, &rebuilt, p8),
                bounce: pair(&refit, &rebuilt, bounce),
            }
        })
        .collect()
}

/// Alpha-tested leaves: the hit filter (single ray and packet-8), the restart loop, and no
/// alpha, primary closest hit.
fn alpha_rates(runs: usize, tree: &Bvh8<VertexTriangle>, p8: &[Ray]) -> ([f64; 4], [u64; 2]) {
    let tr = tree.as_ref();
    let mut filter = alpha;
    let (single, hf) = rate(runs, p8.len(), &mut || {
        p8.iter()
            .filter(|r| closest_ray_with::<f32x8, Watertight, _>(tr, r, &mut filter).is_some())
            .count() as u64
    });
    let (packet, _) = rate(runs, p8.len(), &mut || {
        p8.chunks(8)
            .map(|c| {
                let h = closest_packet_with::<f32x8, Watertight, _>(
                    tr,
                    &RayLanes::load(c),
                    &mut filter,
                );
                u64::from(h.mask.bitmask().count_ones())
            })
            .sum()
    });
    let (restart, hr) = rate(runs, p8.len(), &mut || {
        p8.iter()
            .filter(|ray| restart_closest(tr, ray, alpha).is_some())
            .count() as u64
    });
    let (none, _) = rate(runs, p8.len(), &mut || {
        singles_closest::<f32x8, Watertight>(tr, p8)
    });
    ([single, packet, restart, none], [hf, hr])
}

/// Measures the section on `s`.
pub fn measure(s: &SceneSet, runs: usize) -> ModelReport {
    let verts = s.vertex_tris();
    let tree = Bvh8::build(&verts);
    let p8 = s.primary_tiled(0, 1024, 768, 4, 2);
    let bounce = s.diffuse_bounces(&p8, &tree);
    let embree = embree_layouts(s);
    ModelReport {
        name: s.name,
        geoms: scene_of(s, Layout::MeshesOneTree).geometries().len(),
        runs,
        layouts: layout_rows(s, runs, &tree, &p8, &bounce, &embree),
        embree_skipped: embree.err(),
        refit: refit_times(s, runs, &verts, &tree),
        frames: frames(s, runs, &tree, &p8, &bounce),
        alpha: alpha_rates(runs, &tree, &p8),
    }
}

impl ModelReport {
    /// Writes the section.
    pub fn markdown(&self, md: &mut String) {
        self.layouts_table(md);
        self.refit_table(md);
        let ([fa, pf, re, none], [hf, hr]) = self.alpha;
        writeln!(
            md,
            "\nAlpha-tested leaves (every other triangle cut out in a 6×6 checkerboard of its barycentrics), primary closest hit, one thread: hit filter **{fa:.2}** Mrays/s single ray ({hf} hits), {pf:.2} packet-8; the restart loop a renderer writes without one (trace again from just past each cut-out hit) {re:.2} ({hr} hits): the filter is {:.2}× the loop. Without alpha: {none:.2}.",
            fa / re
        )
        .unwrap();
    }

    fn layouts_table(&self, md: &mut String) {
        let (name, geoms, runs) = (self.name, self.geoms, self.runs);
        writeln!(md, "\n### {name}: one tree against scenes of its meshes\n").unwrap();
        writeln!(
            md,
            "The same triangles, watertight, the query mask all ones: `Bvh8` alone; a scene of one geometry; a scene of its {geoms} meshes as geometries in one tree (one instance of the set: what a renderer does with static meshes); the {geoms} meshes each in its own tree and instance (two levels, identity transforms). The columns of a row are timed in alternation, best of {runs} rounds; ratios against the one-tree column of the same rays. Embree 3 robust on the same triangles in one scene and on the same meshes each in its own scene placed by an identity instance, those two timed in alternation after octoray's.{}\n",
            self.embree_skipped
                .as_ref()
                .map_or(String::new(), |e| format!(" Embree skipped: {e}."))
        )
        .unwrap();
        writeln!(
            md,
            "| rays | query | traversal | one tree | 1 geometry | 1 geometry / one tree | {geoms} geometries, one tree | {geoms} geometries / one tree | {geoms} instances | {geoms} instances / one tree | Embree 3 robust, one tree | Embree, {geoms} instances | Embree {geoms} instances / one tree | {geoms} instances / Embree {geoms} instances |"
        )
        .unwrap();
        writeln!(
            md,
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        )
        .unwrap();
        for r in &self.layouts {
            let [rays, q, how] = r.label;
            let [ra, rb, rc, rd] = r.mrays;
            let embree = r.embree.map_or("— | — | — | —".to_string(), |[eo, ei]| {
                format!("{eo:.2} | {ei:.2} | {:.2}× | {:.2}×", ei / eo, rd / ei)
            });
            writeln!(
                md,
                "| {rays} | {q} | {how} | {ra:.2} | {rb:.2} | {:.2}× | {rc:.2} | {:.2}× | {rd:.2} | {:.2}× | {embree} |",
                rb / ra,
                rc / ra,
                rd / ra
            )
            .unwrap();
        }
    }

    fn refit_table(&self, md: &mut String) {
        let [one, all, build] = self.refit;
        writeln!(
            md,
            "\nRefit after every vertex moved (`Bvh8::refit`): **{:.2} ms** ({} threads: {:.2} ms) against a rebuild's {:.1} ms: {:.0}× faster on one thread.\n",
            one * 1e3,
            rayon::current_num_threads(),
            all * 1e3,
            build * 1e3,
            build / one
        )
        .unwrap();
        writeln!(
            md,
            "| animation frame (wave amplitude) | primary single ray, refitted | rebuilt | refitted / rebuilt | bounce single ray, refitted | rebuilt | refitted / rebuilt |"
        )
        .unwrap();
        writeln!(md, "|---|---|---|---|---|---|---|").unwrap();
        for f in &self.frames {
            let ([a, b], [c, d]) = (f.primary, f.bounce);
            writeln!(
                md,
                "| {} ({:.2}) | {a:.2} | {b:.2} | {:.2}× | {c:.2} | {d:.2} | {:.2}× |",
                f.frame,
                0.02 * f.frame as f32,
                a / b,
                c / d
            )
            .unwrap();
        }
    }
}
