//! One ray-primitive test at a time: the workloads, every speed entry (tiers and peers), the
//! candidate layouts and the trade report as data.

pub mod candidates;
pub mod peers;
pub mod report;
pub mod speed;
pub mod workload;
