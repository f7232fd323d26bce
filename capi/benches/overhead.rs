//! What a call through the C ABI costs over the Rust API on the same scene and rays: single
//! rays, 8- and 16-ray packets and a ray array (closest hit, watertight tier). The C functions
//! are called from Rust here through the crate's `extern "C"` items (not inlined across the
//! crate boundary), so the difference is the wrapper's work: pointer checks, the panic guard,
//! the tier dispatch and the conversions of rays and hits.
use std::hint::black_box;
use std::ptr::null;

use criterion::{criterion_group, criterion_main, Criterion};
use octoray::glam::Vec3;
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{PackedSphere, Ray, RayLanes, VertexTriangle};
use octoray::scene::{Scene, Trace, Transform};
use octoray::{f32x16, f32x8};
use octoray_capi::*;

const GRID: u32 = 64;

/// A terrain of `2·GRID²` triangles as vertex and index buffers.
fn terrain() -> (Vec<f32>, Vec<u32>) {
    let mut v = Vec::new();
    for z in 0..=GRID {
        for x in 0..=GRID {
            v.extend([x as f32, ((x * 7 + z * 13) % 5) as f32 * 0.25, z as f32]);
        }
    }
    let mut idx = Vec::new();
    for z in 0..GRID {
        for x in 0..GRID {
            let a = z * (GRID + 1) + x;
            idx.extend([a, a + 1, a + GRID + 2, a, a + GRID + 2, a + GRID + 1]);
        }
    }
    (v, idx)
}

fn rays() -> Vec<Ray> {
    (0..4096)
        .map(|k| {
            let (x, y) = ((k % 64) as f32, (k / 64) as f32);
            Ray::new(Vec3::new(x, 10.0, y - 10.0), Vec3::new(0.01, -1.0, 0.5))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let (v, idx) = terrain();
    let tris: Vec<VertexTriangle> = idx
        .chunks(3)
        .map(|t| {
            let p = |i: u32| Vec3::from_slice(&v[3 * i as usize..][..3]);
            VertexTriangle::new(p(t[0]), p(t[1]), p(t[2]))
        })
        .collect();
    let mut rust = Scene::<VertexTriangle, PackedSphere>::new();
    let g = rust.add_triangles(&tris).expect("build");
    rust.add_instance(&[g], Transform::IDENTITY, 1);
    rust.commit().expect("commit");
    let rust = rust.as_ref();

    let (mut cs, mut cg, mut ci) = (std::ptr::null_mut(), 0, 0);
    // SAFETY: valid buffers of the stated lengths; the scene is freed at the end.
    unsafe {
        octoray_scene_new(OctorayTier::Watertight as u32, &mut cs);
        octoray_scene_add_mesh(
            cs,
            v.as_ptr(),
            v.len() / 3,
            idx.as_ptr(),
            idx.len() / 3,
            &mut cg,
        );
        octoray_scene_add_instance(cs, &cg, 1, null(), 1, &mut ci);
        octoray_scene_commit(cs);
    }
    let rays = rays();
    let crays: Vec<OctorayRay> = rays
        .iter()
        .map(|r| OctorayRay {
            org: r.origin.into(),
            dir: r.dir.into(),
            t_min: r.t_min,
            t_max: r.t_max,
        })
        .collect();
    let soa = |n: usize, k: usize| -> ([[f32; 16]; 3], [[f32; 16]; 3]) {
        let (mut o, mut d) = ([[0.0; 16]; 3], [[0.0; 16]; 3]);
        for i in 0..n {
            for a in 0..3 {
                (o[a][i], d[a][i]) = (crays[k + i].org[a], crays[k + i].dir[a]);
            }
        }
        (o, d)
    };
    let p8: Vec<OctorayRay8> = (0..rays.len() / 8)
        .map(|k| {
            let (o, d) = soa(8, 8 * k);
            let cut = |x: [[f32; 16]; 3]| x.map(|r| core::array::from_fn(|i| r[i]));
            OctorayRay8 {
                org: cut(o),
                dir: cut(d),
                t_min: [0.0; 8],
                t_max: [f32::INFINITY; 8],
            }
        })
        .collect();
    let p16: Vec<OctorayRay16> = (0..rays.len() / 16)
        .map(|k| {
            let (o, d) = soa(16, 16 * k);
            OctorayRay16 {
                org: o,
                dir: d,
                t_min: [0.0; 16],
                t_max: [f32::INFINITY; 16],
            }
        })
        .collect();

    let mut g = c.benchmark_group("capi_overhead");
    g.bench_function("single/rust", |b| {
        b.iter(|| {
            for r in &rays {
                black_box(rust.closest_ray::<f32x8, Watertight, StableSphere>(r, !0));
            }
        })
    });
    g.bench_function("single/c_abi", |b| {
        let mut h = OctorayHit::from(None);
        b.iter(|| {
            for r in &crays {
                // SAFETY: valid pointers; the scene is live.
                unsafe { octoray_closest1(cs, r, !0, &mut h) };
                black_box(h);
            }
        })
    });
    g.bench_function("packet8/rust", |b| {
        b.iter(|| {
            for c in rays.chunks(8) {
                black_box(
                    rust.closest_packet::<f32x8, Watertight, StableSphere>(&RayLanes::load(c), !0),
                );
            }
        })
    });
    g.bench_function("packet8/c_abi", |b| {
        let mut h = std::mem::MaybeUninit::<OctorayHit8>::uninit();
        b.iter(|| {
            for p in &p8 {
                // SAFETY: valid pointers; the scene is live.
                unsafe { octoray_closest8(cs, p, !0, h.as_mut_ptr()) };
                black_box(&h);
            }
        })
    });
    g.bench_function("packet16/rust", |b| {
        b.iter(|| {
            for c in rays.chunks(16) {
                black_box(
                    rust.closest_packet::<f32x16, Watertight, StableSphere>(&RayLanes::load(c), !0),
                );
            }
        })
    });
    g.bench_function("packet16/c_abi", |b| {
        let mut h = std::mem::MaybeUninit::<OctorayHit16>::uninit();
        b.iter(|| {
            for p in &p16 {
                // SAFETY: valid pointers; the scene is live.
                unsafe { octoray_closest16(cs, p, !0, h.as_mut_ptr()) };
                black_box(&h);
            }
        })
    });
    g.bench_function("array/rust", |b| {
        let mut out = vec![None; rays.len()];
        b.iter(|| rust.closest::<f32x8, Watertight, StableSphere>(&rays, !0, &mut out))
    });
    g.bench_function("array/c_abi", |b| {
        let mut out = vec![OctorayHit::from(None); rays.len()];
        // SAFETY: valid buffers of `rays.len()` items; the scene is live.
        b.iter(|| unsafe { octoray_closest(cs, crays.as_ptr(), crays.len(), !0, out.as_mut_ptr()) })
    });
    g.finish();
    // SAFETY: freed once, after its last use.
    unsafe { octoray_scene_free(cs) };
}

criterion_group!(benches, bench);
criterion_main!(benches);
