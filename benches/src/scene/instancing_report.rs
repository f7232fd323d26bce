//! The scene report's instancing section: a field of instances of one mesh, the two-level scene
//! against the same triangles flattened into one tree and against Embree 3's instancing
//! (`RTC_GEOMETRY_TYPE_INSTANCE`). Measured into an [`InstancingReport`], then written.

use super::embree::EmbreeScene;
use super::instancing::{
    field, flatten, instanced, scene_packets_closest, scene_singles_any, scene_singles_closest,
};
use super::row::{Query, Traversal};
use super::sets::{jittered_sphere, SceneSet};
use super::timing::{alternating, rate};
use super::trace::{OctorayTree, Traces};
use octoray::bvh::Bvh8;
use octoray::kernels::Watertight;
use octoray::prim::Ray;
use std::fmt::Write as _;
use std::time::Instant;

/// One row: Mrays/s and hits, two-level and flattened; Embree robust instanced and flattened
/// (`None` without Embree).
pub struct InstancingRow {
    /// Rays, query and traversal.
    pub label: [&'static str; 3],
    /// Two-level, flattened: Mrays/s and hits.
    pub octoray: [(f64, u64); 2],
    /// Embree 3 robust, instanced and flattened: Mrays/s and hits.
    pub embree: [Option<(f64, u64)>; 2],
}

/// The section, measured.
pub struct InstancingReport {
    /// Instances, triangles of the mesh, triangles flattened.
    pub sizes: [usize; 3],
    /// Primary and bounce rays.
    pub rays: [usize; 2],
    /// Builds: two-level, flattened (seconds).
    pub builds: [f64; 2],
    /// The rows.
    pub rows: Vec<InstancingRow>,
    /// Why Embree's columns are missing, if they are.
    pub skipped: Option<String>,
}

/// Measures the section: 16 × 16 instances of a jittered sphere, `runs` rounds per row.
pub fn measure(runs: usize) -> InstancingReport {
    let mesh = jittered_sphere(64).tris;
    let (places, camera) = field(16);
    let flat = SceneSet {
        name: "instanced field (flattened)",
        tris: flatten(&mesh, &places),
        meshes: vec![0],
        cameras: [camera; 2],
        light: glam::Vec3::new(0.0, 1e3, 0.0),
    };
    let t0 = Instant::now();
    let scene = instanced(&mesh, &places);
    let scene_build = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let tree = Bvh8::build(&flat.vertex_tris());
    let flat_build = t0.elapsed().as_secs_f64();
    let p8 = flat.primary_tiled(0, 1024, 768, 4, 2);
    let bounce = flat.diffuse_bounces(&p8, &tree);
    let embree = EmbreeScene::build_instanced(&mesh, &places, true).map(|e| e.0);
    let embree_flat = EmbreeScene::build(&flat.tris, true).map(|e| e.0);
    let (sr, flat_tree) = (
        scene.as_ref(),
        OctorayTree::<Watertight, _>::new(tree.as_ref()),
    );
    let rows: [([&str; 3], Query, Traversal, &[Ray]); 4] = [
        (
            ["primary", "closest", "packet-8"],
            Query::Closest,
            Traversal::Packet8,
            &p8,
        ),
        (
            ["primary", "closest", "single ray"],
            Query::Closest,
            Traversal::Single,
            &p8,
        ),
        (
            ["primary", "any", "single ray"],
            Query::Any,
            Traversal::Single,
            &p8,
        ),
        (
            ["diffuse bounce", "closest", "single ray"],
            Query::Closest,
            Traversal::Single,
            &bounce,
        ),
    ];
    let rows = rows
        .into_iter()
        .map(|(label, q, how, set)| {
            let two_level = &mut || match (q, how) {
                (Query::Closest, Traversal::Packet8) => scene_packets_closest(sr, set),
                (Query::Any, _) => scene_singles_any(sr, set),
                _ => scene_singles_closest(sr, set),
            };
            let flattened = &mut || flat_tree.trace(q, how, set).expect("a tree row");
            let r = alternating(runs, set.len(), &mut [two_level, flattened]);
            let em = |e: &Result<EmbreeScene, String>| {
                e.as_ref().ok().map(|e| {
                    rate(runs, set.len(), &mut || {
                        e.trace(q, how, set).expect("an Embree row")
                    })
                })
            };
            eprintln!("instancing {label:?}: {r:?}");
            InstancingRow {
                label,
                octoray: [r[0], r[1]],
                embree: [em(&embree), em(&embree_flat)],
            }
        })
        .collect();
    InstancingReport {
        sizes: [places.len(), mesh.len(), flat.tris.len()],
        rays: [p8.len(), bounce.len()],
        builds: [scene_build, flat_build],
        rows,
        skipped: embree.err(),
    }
}

impl InstancingReport {
    /// Writes the section.
    pub fn markdown(&self, md: &mut String) {
        let ([n, mesh, flat], [primary, bounce], [two, one]) = (self.sizes, self.rays, self.builds);
        writeln!(
            md,
            "\n### Instancing: {n} instances of a {mesh}-triangle mesh ({flat} triangles flattened)\n"
        )
        .unwrap();
        writeln!(
            md,
            "Random rotations and scales 0.6–1.4 on a grid; {primary} primary rays at 1024×768, {bounce} diffuse-bounce rays (from the flattened tree's hits). Builds: two-level {two:.3} s (the mesh once, then the top level over the instances), flattened {one:.3} s. Hit counts differ slightly: the flattened triangles are the instances' vertices rounded to f32 in world space, the two-level scene tests the exact mesh with each ray carried into object space.\n"
        )
        .unwrap();
        writeln!(
            md,
            "| rays | query | traversal | two-level | flattened | two-level / flattened | Embree 3 robust, instanced | two-level / Embree instanced | Embree 3 robust, flattened |"
        )
        .unwrap();
        writeln!(md, "|---|---|---|---|---|---|---|---|---|").unwrap();
        let cell = |e: Option<(f64, u64)>| {
            e.map_or("n/a".to_string(), |(r, h)| format!("{r:.2} ({h} hits)"))
        };
        for r in &self.rows {
            let [rays, q, how] = r.label;
            let [(a, ha), (b, hb)] = r.octoray;
            let vs = r.embree[0].map_or("n/a".to_string(), |(e, _)| format!("{:.2}×", a / e));
            writeln!(
                md,
                "| {rays} | {q} | {how} | {a:.2} ({ha} hits) | {b:.2} ({hb} hits) | {:.2}× | {} | {vs} | {} |",
                a / b,
                cell(r.embree[0]),
                cell(r.embree[1])
            )
            .unwrap();
        }
        if let Some(e) = &self.skipped {
            writeln!(md, "\nEmbree rows skipped: {e}.").unwrap();
        }
    }
}
