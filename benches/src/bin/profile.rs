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

use octoray::bvh::{BuildOptions, Bvh8, Bvh8Ref, Sequential};
use octoray::kernels::{Kernel, MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, Ray};
use octoray_benches::embree::EmbreeScene;
use octoray_benches::scene_peers::{ObvhsScene, TinyBvhScene};
use octoray_benches::scenes::{
    city, jittered_sphere, open_field, packets_any, packets_closest, scanned, singles_any,
    singles_closest, sponza, terrain,
};
use wide::f32x8;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: profile <sponza|sphere|city|terrain|scanned|open> <primary|primary-any|camera2|bounce|shadow> <watertight|spatial|standard|tinybvh|embree-robust|embree-fast|obvhs> [single|packet8]";
    let (scene, rays, system, packets) = match args.as_slice() {
        [a, b, c] => (a, b, c, false),
        [a, b, c, d] if d == "single" || d == "packet8" => (a, b, c, d == "packet8"),
        _ => return Err(usage.into()),
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
        _ => return Err(usage.into()),
    };
    let verts = s.vertex_tris();
    let binned = Bvh8::build(&verts);
    let primary = s.primary_tiled(0, 256, 256, 4, 2);
    let any = matches!(rays.as_str(), "shadow" | "primary-any");
    let rays = match rays.as_str() {
        "primary" | "primary-any" => primary,
        "camera2" => s.primary_tiled(1, 256, 256, 4, 2),
        "bounce" => s.diffuse_bounces(&primary, &binned),
        "shadow" => s.shadow_rays(&primary, &binned),
        _ => return Err(usage.into()),
    };
    let hits = match system.as_str() {
        "watertight" | "spatial" => {
            let tree = if system == "spatial" {
                Bvh8::try_build_options(&verts, BuildOptions::SPATIAL, &Sequential)
                    .map_err(|e| format!("{e:?}"))?
            } else {
                binned
            };
            octoray_row::<Watertight>(tree.as_ref(), &rays, any, packets)
        }
        "standard" => {
            let packed: Vec<PackedTriangle> = s
                .tris
                .iter()
                .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
                .collect();
            octoray_row::<MollerTrumbore>(Bvh8::build(&packed).as_ref(), &rays, any, packets)
        }
        "tinybvh" => {
            let (tb, _) = TinyBvhScene::build(&s.tris, true)?;
            traced(&|| tb.closest(&rays))
        }
        "embree-robust" | "embree-fast" => {
            let (em, _) = EmbreeScene::build(&s.tris, system == "embree-robust")?;
            traced(&|| match (any, packets) {
                (true, true) => em.any8(&rays),
                (true, false) => em.any1(&rays),
                (false, true) => em.closest8(&rays),
                (false, false) => em.closest1(&rays),
            })
        }
        "obvhs" => {
            let (ob, _) = ObvhsScene::build(&s.tris);
            traced(&|| {
                if any {
                    ob.any(&rays)
                } else {
                    ob.closest(&rays)
                }
            })
        }
        _ => return Err(usage.into()),
    };
    println!("{} rays, {hits} hits", rays.len());
    Ok(())
}

/// An octoray row: single rays (or packets of 8) through `bvh` with kernel `K`, occlusion when
/// `any`.
fn octoray_row<K: Kernel<f32x8>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    any: bool,
    packets: bool,
) -> u64 {
    traced(&|| match (any, packets) {
        (true, true) => packets_any::<f32x8, K>(bvh, rays),
        (true, false) => singles_any::<f32x8, K>(bvh, rays),
        (false, true) => packets_closest::<f32x8, K>(bvh, rays),
        (false, false) => singles_closest::<f32x8, K>(bvh, rays),
    })
}

/// The traversal of every ray, and nothing else: what the counts are taken over.
#[inline(never)]
fn traced(f: &dyn Fn() -> u64) -> u64 {
    f()
}
