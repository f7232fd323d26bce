//! Shared by the criterion benchmarks, the cycle-count workloads and the trade report: the
//! workloads (rays and primitives with a chosen hit rate), the peers, each written the way a
//! Rust renderer would use it, and the candidate layouts measured beside the tiers.
#![deny(unsafe_code)] // allowed only in the Embree FFI shim (`embree`)
#![allow(missing_docs)]

pub mod candidates;
pub mod embree;
pub mod instancing;
pub mod peers;
pub mod report;
pub mod scene_chart;
pub mod scene_peers;
pub mod scenes;
pub mod speed;
pub mod workload;
