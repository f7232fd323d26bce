//! Determinism across builds: the standard, watertight and exact triangle tiers and the stable sphere
//! give the same bits on every build. A digest of their results over a fixed case set is stored
//! here; `.ci/run` runs this test on the portable x86-64 build (SSE2), with `-C target-cpu=native`
//! (AVX2/AVX-512), on aarch64 (NEON, under QEMU) and on wasm32-wasip1 (simd128, under Node's
//! WASI): every one must reproduce the stored value. The cases come from platform-independent
//! generators (libm's sin, cos and pow, not the platform's).
//!
//! If a deliberate change to a kernel changes its results, update `STORED` with the value this
//! test prints, and say why in the commit.
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray_testkit as testkit;

use octoray::f32x8;
use octoray::hit::Digest;
use octoray::kernels::{Exact, Kernel, MollerTrumbore, StableSphere, Watertight};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, VertexTriangle};
use octoray::query::closest;
use testkit::accuracy::{
    distant_sphere_cases, edge_cases, grazing_cases, near_sphere_cases, random_cases,
};

const STORED: u64 = 0x6fdd_5018_5f73_e999;

/// Each ray against a group of 8 primitives, closest hit, at width 1 and 8.
fn digest_kernel<K, P>(f: &mut Digest, rays: &[Ray], prims: &[P])
where
    K: Kernel<f32, Prim = P> + Kernel<f32x8, Prim = P>,
    P: Copy,
{
    for (chunk, group) in rays.chunks(8).zip(prims.chunks(8)) {
        let p = closest::<f32x8, K>(&RayLanes::load(chunk), group);
        for (i, r) in chunk.iter().enumerate() {
            f.hit(closest::<f32, K>(&RayLanes::single(r), group).lane(0));
            f.hit(p.lane(i));
        }
    }
}

fn digest() -> u64 {
    let mut f = Digest::new();
    let mut cases = random_cases(7001, 4000);
    cases.extend(edge_cases(7002, 4000));
    cases.extend(grazing_cases(7003, 2000, 1e-4));
    let rays: Vec<Ray> = cases.iter().map(|c| c.ray).collect();
    let packed: Vec<PackedTriangle> = cases
        .iter()
        .map(|c| PackedTriangle::new(c.v[0], c.v[1], c.v[2]))
        .collect();
    let verts: Vec<VertexTriangle> = cases
        .iter()
        .map(|c| VertexTriangle::new(c.v[0], c.v[1], c.v[2]))
        .collect();
    digest_kernel::<MollerTrumbore, _>(&mut f, &rays, &packed);
    digest_kernel::<Watertight, _>(&mut f, &rays, &verts);
    digest_kernel::<Exact, _>(&mut f, &rays, &verts);
    let mut sc = near_sphere_cases(7004, 4000);
    sc.extend(distant_sphere_cases(7005, 4000, 1e3));
    let srays: Vec<Ray> = sc.iter().map(|c| c.ray).collect();
    let spheres: Vec<PackedSphere> = sc
        .iter()
        .map(|c| PackedSphere::new(c.center, c.radius))
        .collect();
    digest_kernel::<StableSphere, _>(&mut f, &srays, &spheres);
    f.value()
}

#[test]
fn results_match_the_stored_digest_on_this_build() {
    let d = digest();
    println!("determinism digest: {d:#018x}");
    assert_eq!(
        d, STORED,
        "results differ from the stored digest ({d:#018x} vs {STORED:#018x})"
    );
}
