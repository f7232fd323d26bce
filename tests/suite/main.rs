//! The integration tests, one contract per module (tests/README.md lists them), in one binary:
//! the generic walks and kernels they share are compiled once, not once per file.
//! `tests/ingest_alloc.rs` stays a binary of its own: its global allocator has a limit.
//!
//! Built with `--cfg octoray_isa_slice` (`.ci/cross.sh`, for the emulated ISAs), only the modules
//! of the cross-ISA slice are compiled.

#[cfg(not(octoray_isa_slice))]
mod accuracy;
#[cfg(not(octoray_isa_slice))]
mod architecture;
#[cfg(not(octoray_isa_slice))]
mod bad_input;
mod bvh;
mod determinism;
mod embedded;
mod exact;
#[cfg(not(octoray_isa_slice))]
mod extremes;
#[cfg(not(octoray_isa_slice))]
mod fuzz;
mod golden;
#[cfg(not(octoray_isa_slice))]
mod hostile;
#[cfg(not(octoray_isa_slice))]
mod ingest;
#[cfg(not(octoray_isa_slice))]
mod packet_api;
mod packet_bits;
#[cfg(not(octoray_isa_slice))]
mod packet_vs_textbook;
#[cfg(not(octoray_isa_slice))]
mod point;
mod queries;
#[cfg(not(octoray_isa_slice))]
mod recommend;
#[cfg(not(octoray_isa_slice))]
mod scene;
#[cfg(not(octoray_isa_slice))]
mod scene_points;
#[cfg(not(octoray_isa_slice))]
mod solid;
#[cfg(not(octoray_isa_slice))]
mod untrusted_scenes;
#[cfg(not(octoray_isa_slice))]
mod watertight;
#[cfg(not(octoray_isa_slice))]
mod winding;

use octoray::hit::Candidate;

/// The suite's one filter type. Each closure is a type of its own, and a walk called with it is
/// compiled again: the tests pass their filters through this, so the walks are compiled once per
/// width and kernel.
type DynFilter<'a> = &'a mut dyn FnMut(&Candidate) -> bool;

/// `f` as the suite's one filter type.
fn dyn_filter(f: &mut impl FnMut(&Candidate) -> bool) -> DynFilter<'_> {
    f
}
