//! The measuring harness behind octoray's reports and criterion benchmarks, in two layers:
//! - [`kernel`]: one ray-primitive test at a time — workloads with a chosen hit rate, every tier
//!   and the peers' tests written the way a Rust renderer would write them, candidate layouts,
//!   and the trade report (`benches/tradeoff.md`) as data.
//! - [`scene`]: whole scenes — the scene sets and their rays, each system's built scene behind
//!   one trait, the report's rows and targets as types, measurement apart from the markdown, the
//!   chart and the counts report.
//! - [`query`]: queries beyond the first hit (containment, closest point, every hit) against the
//!   peers that have them, and the query report (`benches/queries.md`).
#![deny(unsafe_code)] // allowed only in the Embree FFI shim (`embree`)
#![deny(missing_docs)]

pub mod kernel;
pub mod query;
pub mod scene;

/// The CPU's model name (Linux) and the thread count, for the reports' headers.
pub fn machine() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = info
        .lines()
        .find_map(|l| {
            l.strip_prefix("model name")
                .map(|r| r.trim_start_matches([' ', '\t', ':']))
        })
        .unwrap_or("unknown CPU");
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{model}, {cores} threads")
}

/// The SIMD level this build was compiled for, for the reports' headers.
pub fn build_flags() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "-C target-cpu=native (AVX-512, FMA)"
    } else if cfg!(target_feature = "avx2") {
        "AVX2"
    } else {
        "default x86-64 (SSE2)"
    }
}
