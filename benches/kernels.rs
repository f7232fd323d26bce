//! Criterion benchmarks: ray-primitive tests per second for the scalar twin and the packet
//! kernels at 4, 8 and 16 lanes, triangles and spheres, closest hit and occlusion.
//!
//! Throughput is reported per ray-primitive test (`Elements` = rays × primitives). Build flags
//! matter (`wide` chooses SSE2/AVX/AVX-512 at compile time): compare
//! `cargo bench --bench kernels` with `RUSTFLAGS="-C target-cpu=native" cargo bench --bench kernels`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use octoray::core::{query, RayLanes};
use octoray::glam::Vec3;
use octoray::packet::{f32x16, f32x4, f32x8, Lanes};
use octoray::{PackedSphere, PackedTriangle, Ray};
use std::hint::black_box;

const RAYS: usize = 4096;
const PRIMS: usize = 64;

struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
    fn v(&mut self, s: f32) -> Vec3 {
        Vec3::new(self.f() * s, self.f() * s, self.f() * s)
    }
}

/// A scene in a unit box and rays from a camera-like point towards it: roughly half the rays
/// hit something, each ray-primitive test hits a few percent of the time.
pub fn scene() -> (Vec<Ray>, Vec<PackedTriangle>, Vec<PackedSphere>) {
    let mut r = Lcg(7);
    let tris = (0..PRIMS)
        .map(|_| {
            let c = r.v(1.0);
            PackedTriangle::new(c + r.v(0.3), c + r.v(0.3), c + r.v(0.3))
        })
        .collect();
    let spheres = (0..PRIMS)
        .map(|_| PackedSphere::new(r.v(1.0), 0.05 + 0.05 * r.f().abs()))
        .collect();
    let rays = (0..RAYS)
        .map(|_| {
            let o = Vec3::new(0.0, 0.0, -4.0) + r.v(0.1);
            Ray::new(o, r.v(1.0) - o)
        })
        .collect();
    (rays, tris, spheres)
}

fn closest_tris<L: Lanes>(rays: &[Ray], tris: &[PackedTriangle]) -> u32 {
    let mut hits = 0;
    for chunk in rays.chunks(L::LANES) {
        let h = query::closest_triangle(&RayLanes::<L>::load(chunk), tris);
        hits += octoray::core::LaneMask::bitmask(h.mask).count_ones();
    }
    hits
}

fn any_tris<L: Lanes>(rays: &[Ray], tris: &[PackedTriangle]) -> u32 {
    let mut hits = 0;
    for chunk in rays.chunks(L::LANES) {
        let m = query::any_triangle(&RayLanes::<L>::load(chunk), tris);
        hits += octoray::core::LaneMask::bitmask(m).count_ones();
    }
    hits
}

fn closest_spheres<L: Lanes>(rays: &[Ray], spheres: &[PackedSphere]) -> u32 {
    let mut hits = 0;
    for chunk in rays.chunks(L::LANES) {
        let h = query::closest_sphere(&RayLanes::<L>::load(chunk), spheres);
        hits += octoray::core::LaneMask::bitmask(h.mask).count_ones();
    }
    hits
}

fn bench(c: &mut Criterion) {
    let (rays, tris, spheres) = scene();
    let tests = (RAYS * PRIMS) as u64;

    let mut g = c.benchmark_group("triangle_closest");
    g.throughput(Throughput::Elements(tests));
    g.bench_function(BenchmarkId::new("scalar_twin", 1), |b| {
        b.iter(|| closest_tris::<f32>(black_box(&rays), black_box(&tris)))
    });
    g.bench_function(BenchmarkId::new("packet", 4), |b| {
        b.iter(|| closest_tris::<f32x4>(black_box(&rays), black_box(&tris)))
    });
    g.bench_function(BenchmarkId::new("packet", 8), |b| {
        b.iter(|| closest_tris::<f32x8>(black_box(&rays), black_box(&tris)))
    });
    g.bench_function(BenchmarkId::new("packet", 16), |b| {
        b.iter(|| closest_tris::<f32x16>(black_box(&rays), black_box(&tris)))
    });
    g.finish();

    let mut g = c.benchmark_group("triangle_any");
    g.throughput(Throughput::Elements(tests));
    g.bench_function(BenchmarkId::new("scalar_twin", 1), |b| {
        b.iter(|| any_tris::<f32>(black_box(&rays), black_box(&tris)))
    });
    g.bench_function(BenchmarkId::new("packet", 8), |b| {
        b.iter(|| any_tris::<f32x8>(black_box(&rays), black_box(&tris)))
    });
    g.finish();

    let mut g = c.benchmark_group("sphere_closest");
    g.throughput(Throughput::Elements(tests));
    g.bench_function(BenchmarkId::new("scalar_twin", 1), |b| {
        b.iter(|| closest_spheres::<f32>(black_box(&rays), black_box(&spheres)))
    });
    g.bench_function(BenchmarkId::new("packet", 4), |b| {
        b.iter(|| closest_spheres::<f32x4>(black_box(&rays), black_box(&spheres)))
    });
    g.bench_function(BenchmarkId::new("packet", 8), |b| {
        b.iter(|| closest_spheres::<f32x8>(black_box(&rays), black_box(&spheres)))
    });
    g.bench_function(BenchmarkId::new("packet", 16), |b| {
        b.iter(|| closest_spheres::<f32x16>(black_box(&rays), black_box(&spheres)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
