//! Shared by the criterion benchmarks, the cycle-count workloads and the trade report: the
//! workloads (rays and primitives with a chosen hit rate) and the peers, each written the way a
//! Rust renderer would use it.
#![forbid(unsafe_code)]
#![allow(missing_docs)]

pub mod peers;
pub mod report;
pub mod scenes;
pub mod speed;
pub mod workload;
