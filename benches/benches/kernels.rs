//! Criterion benchmarks: time per ray-primitive test (`Throughput::Elements` = rays × primitives)
//! for every entry of `octoray_benches::kernel::speed::entries()` (our tiers at widths 1/4/8/16, the f64
//! tier, closest and any hit, and the peers) at hit rates of 0 %, ~50 % and 100 %, plus a scaling
//! group (64 to 65 536 primitives per query).
//!
//! Build flags matter (`wide` chooses SSE2/AVX/AVX-512 at compile time):
//! `cargo bench -p octoray-benches` vs `RUSTFLAGS="-C target-cpu=native" cargo bench -p octoray-benches`.
//! Quick mode: `cargo bench -p octoray-benches -- --quick`.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use octoray_benches::kernel::speed::{entries, entry, Prepared, Prim};
use octoray_benches::kernel::workload::{HitRate, Workload};
use std::hint::black_box;
use std::time::Duration;

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20)
}

fn by_hit_rate(c: &mut Criterion) {
    for rate in HitRate::ALL {
        let p = Prepared::new(Workload::new(rate, 1024, 64, 7));
        for prim in [Prim::Triangle, Prim::Sphere] {
            let group_name = format!(
                "{}_{}",
                if prim == Prim::Triangle {
                    "triangle"
                } else {
                    "sphere"
                },
                rate.name()
            );
            let mut g = c.benchmark_group(group_name);
            g.throughput(Throughput::Elements(p.w.tests()));
            for e in entries().into_iter().filter(|e| e.prim == prim) {
                g.bench_function(e.name, |b| b.iter(|| (e.run)(black_box(&p))));
            }
            g.finish();
        }
    }
}

fn scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("triangle_scaling_standard_x8");
    for prims in [64usize, 1024, 16_384, 65_536] {
        // About 2^22 tests per iteration whatever the primitive count.
        let rays = ((1usize << 22) / prims).max(8);
        let p = Prepared::new(Workload::new(HitRate::Half, rays, prims, 11));
        g.throughput(Throughput::Elements(p.w.tests()));
        let e = entry("standard x8").expect("entry");
        g.bench_with_input(BenchmarkId::from_parameter(prims), &p, |b, p| {
            b.iter(|| (e.run)(black_box(p)))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = config();
    targets = by_hit_rate, scaling
}
criterion_main!(benches);
