//! Shared by the criterion benchmarks, the cycle-count workloads and the trade report: the
//! workloads (rays and primitives with a chosen hit rate), the peers, each written the way a
//! Rust renderer would use it, and the candidate layouts measured beside the tiers.
#![deny(unsafe_code)] // allowed only in the Embree FFI shim (`embree`)
#![allow(missing_docs)]

pub mod candidates;
pub mod counts;
pub mod embree;
pub mod instancing;
pub mod peers;
pub mod report;
pub mod scene_chart;
pub mod scene_peers;
pub mod scenes;
pub mod speed;
pub mod targets;
pub mod workload;

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
