//! Criterion benchmarks of scene-scale traversal (the scene report's rows as criterion groups):
//! BVH build, the validation of its slices as untrusted data (`Bvh8Ref::new`, and of crafted
//! hostile trees), and closest and any hit through it for 8-ray packets and single rays, on Sponza
//! (found through `cargo metadata`; skipped with a message when it cannot be found) and a
//! generated 1 M-triangle sphere. `Throughput::Elements` = rays, so criterion prints rays/s.
//! The full-frame figures and the peers are in `benches/scenes.md` (`--bin scenes`).
//!
//! `RUSTFLAGS="-C target-cpu=native" cargo bench -p octoray-benches --bench scenes`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use octoray::bvh::{Bvh8, Bvh8Ref, MAX_DEPTH};
use octoray::glam::Vec3;
use octoray::kernels::Watertight;
use octoray::prim::{Ray, VertexTriangle};
use octoray::tree::closest_ray_with;
use octoray_benches::scene::instancing::{alpha, restart_closest};
use octoray_benches::scene::sets::{
    jittered_sphere, packets_closest, singles_any, singles_closest, sponza, SceneSet,
};
use octoray_testkit::trees::{bushy_chain, shared_chain};
use std::hint::black_box;
use std::time::Duration;
use wide::f32x8;

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .sample_size(10)
}

/// One scene: its build, and 16 384 primary rays (a 256×64 band through the frame's middle, in
/// 4×2 tiles) and their diffuse bounces through the tree.
fn scene(c: &mut Criterion, s: &SceneSet) {
    let verts = s.vertex_tris();
    let mut g = c.benchmark_group(format!("bvh_build_{}", s.name.replace(' ', "_")));
    g.throughput(Throughput::Elements(verts.len() as u64));
    g.bench_function("binned_sah", |b| b.iter(|| Bvh8::build(black_box(&verts))));
    g.finish();

    // Refit after every vertex moved (a sway of 1 % of the scene's extent, as an animation step
    // might), against the rebuild above.
    let mut bvh = Bvh8::build(&verts);
    let lo = verts
        .iter()
        .flat_map(|t| t.vertices())
        .fold(f32::INFINITY, |m, v| m.min(v.min_element()));
    let hi = verts
        .iter()
        .flat_map(|t| t.vertices())
        .fold(f32::NEG_INFINITY, |m, v| m.max(v.max_element()));
    let sway = 0.01 * (hi - lo);
    let moved: Vec<VertexTriangle> = verts
        .iter()
        .map(|t| {
            let [a, b, c] = t
                .vertices()
                .map(|v| v + sway * Vec3::new(v.y.sin(), v.z.cos(), v.x.sin()));
            VertexTriangle::new(a, b, c)
        })
        .collect();
    let mut g = c.benchmark_group(format!("bvh_refit_{}", s.name.replace(' ', "_")));
    g.throughput(Throughput::Elements(verts.len() as u64));
    let mut flip = false;
    g.bench_function("refit", |b| {
        b.iter(|| {
            flip = !flip;
            bvh.refit(black_box(if flip { &moved } else { &verts }))
                .is_ok()
        })
    });
    g.bench_function("refit_rayon", |b| {
        b.iter(|| {
            flip = !flip;
            let prims = if flip { &moved } else { &verts };
            bvh.refit_on(black_box(prims), &octoray::parallel::Rayon)
                .is_ok()
        })
    });
    g.finish();
    bvh.refit(&verts).expect("same slice");
    let mut g = c.benchmark_group(format!("bvh_validate_{}", s.name.replace(' ', "_")));
    g.throughput(Throughput::Bytes(
        (std::mem::size_of_val(bvh.nodes()) + std::mem::size_of_val(bvh.ids())) as u64,
    ));
    g.bench_function("bvh8ref_new", |b| {
        b.iter(|| {
            Bvh8Ref::<VertexTriangle>::new(bvh.nodes(), bvh.blocks(), bvh.ids(), verts.len())
                .is_ok()
        })
    });
    g.finish();
    let r = bvh.as_ref();
    let all = s.primary_tiled(0, 1024, 768, 4, 2);
    let primary: Vec<Ray> = all[all.len() / 2..all.len() / 2 + 16_384].to_vec();
    let bounce = s.diffuse_bounces(&primary, &bvh);
    let mut g = c.benchmark_group(format!("bvh_traverse_{}", s.name.replace(' ', "_")));
    g.throughput(Throughput::Elements(primary.len() as u64));
    g.bench_function("primary_closest_packet8", |b| {
        b.iter(|| packets_closest::<f32x8, Watertight>(r, &primary))
    });
    g.bench_function("primary_closest_single", |b| {
        b.iter(|| singles_closest::<f32x8, Watertight>(r, &primary))
    });
    g.bench_function("primary_any_single", |b| {
        b.iter(|| singles_any::<f32x8, Watertight>(r, &primary))
    });
    g.throughput(Throughput::Elements(bounce.len() as u64));
    g.bench_function("bounce_closest_single", |b| {
        b.iter(|| singles_closest::<f32x8, Watertight>(r, &bounce))
    });
    g.finish();

    // Alpha-tested leaves: every other primitive cut out in a checkerboard of its barycentrics.
    // The filter against the restart loop a renderer writes without one (trace, and on a
    // cut-out hit trace again from just past it).
    let mut g = c.benchmark_group(format!("alpha_{}", s.name.replace(' ', "_")));
    g.throughput(Throughput::Elements(primary.len() as u64));
    g.bench_function("filter_closest_single", |b| {
        b.iter(|| {
            primary
                .iter()
                .filter(|ray| {
                    closest_ray_with::<f32x8, Watertight, _>(r, ray, &mut alpha).is_some()
                })
                .count()
        })
    });
    g.bench_function("restart_closest_single", |b| {
        b.iter(|| {
            primary
                .iter()
                .filter(|ray| restart_closest(r, ray, alpha).is_some())
                .count()
        })
    });
    g.finish();
}

/// Validation of crafted trees: the exponential shared chain (64 nodes, 16 KiB, rejected) and the
/// bushy chain at the depth limit (505 nodes, accepted).
fn crafted(c: &mut Criterion) {
    let mut g = c.benchmark_group("bvh_validate_crafted");
    for (name, t) in [
        ("shared_chain_64", shared_chain(64)),
        ("bushy_chain_64", bushy_chain(MAX_DEPTH)),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                Bvh8Ref::<VertexTriangle>::new(black_box(&t.nodes), &t.blocks, &t.ids, t.prims)
                    .is_ok()
            })
        });
    }
    g.finish();
}

fn scenes(c: &mut Criterion) {
    crafted(c);
    match sponza() {
        Ok(s) => scene(c, &s),
        Err(e) => eprintln!("Sponza skipped: {e}"),
    }
    scene(c, &jittered_sphere(1024));
}

criterion_group! {
    name = benches;
    config = config();
    targets = scenes
}
criterion_main!(benches);
