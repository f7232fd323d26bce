//! The `*_vec` ingest forms allocated their output before validating the
//! input (300 000 001 indices: 11 s and 3.5 GB before `IndicesNotTriangles`). With a memory cap
//! just above what the input itself takes, a bad mesh must be rejected without allocating.
#![cfg(all(feature = "triangle", feature = "alloc"))]

use cap::Cap;
use octoray::ingest::{self, IngestError};
use std::alloc::System;

#[global_allocator]
static ALLOC: Cap<System> = Cap::new(System, usize::MAX);

#[test]
fn bad_meshes_are_rejected_before_any_output_is_allocated() {
    // 30 000 001 indices (120 MB): the output would be 10 M triangles × 48 bytes = 480 MB.
    let positions = vec![[0.0f32; 3]; 4];
    let mut indices = vec![0u32; 30_000_001];
    // Allow 64 MB beyond what is allocated now: far less than the output.
    ALLOC.set_limit(ALLOC.allocated() + (64 << 20)).unwrap();
    assert_eq!(
        ingest::pack_triangles_vec(&positions, &indices).unwrap_err(),
        IngestError::IndicesNotTriangles { len: 30_000_001 }
    );
    indices.pop();
    indices[29_999_999] = 9; // the very last index is out of range
    assert!(matches!(
        ingest::pack_vertex_triangles_vec(&positions, &indices).unwrap_err(),
        IngestError::IndexOutOfRange { index: 9, .. }
    ));
    ALLOC.set_limit(usize::MAX).unwrap();
    // A valid mesh of the same size is still packed (the cap was the only obstacle).
    indices[29_999_999] = 3;
    assert_eq!(
        ingest::pack_triangles_vec(&positions, &indices)
            .unwrap()
            .len(),
        10_000_000
    );
}
