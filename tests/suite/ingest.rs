//! Zero-copy ingest: indexed meshes and sphere slices to the packed stores, with bad input as
//! error values.
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]

use octoray::glam::Vec3;
use octoray::ingest::{self, IngestError};
use octoray::prim::{PackedSphere, PackedTriangle, VertexTriangle};

/// A quad as two triangles, positions flat as a glTF accessor gives them.
const FLAT: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
const INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];

#[test]
fn indexed_mesh_round_trips_to_the_same_triangles() {
    let positions = ingest::positions_from_flat(&FLAT).unwrap();
    assert_eq!(positions.len(), 4);
    // Zero-copy: the view aliases the input.
    assert!(std::ptr::eq(
        positions.as_ptr().cast::<f32>(),
        FLAT.as_ptr()
    ));
    let packed = ingest::pack_triangles_vec(positions, &INDICES).unwrap();
    let verts = ingest::pack_vertex_triangles_vec(positions, &INDICES).unwrap();
    let p = |i: u32| Vec3::from(positions[i as usize]);
    for (k, t) in INDICES.chunks(3).enumerate() {
        assert_eq!(packed[k], PackedTriangle::new(p(t[0]), p(t[1]), p(t[2])));
        assert_eq!(verts[k], VertexTriangle::new(p(t[0]), p(t[1]), p(t[2])));
        // And back: v0 + e1, v0 + e2 are the mesh's vertices (exact here).
        let v0 = Vec3::from(packed[k].v0);
        assert_eq!(
            (v0 + Vec3::from(packed[k].e1), v0 + Vec3::from(packed[k].e2)),
            (p(t[1]), p(t[2]))
        );
    }
    // The stores are Pod: they cast to flat floats and back.
    let floats: &[f32] = bytemuck::cast_slice(&packed);
    assert_eq!(floats.len(), 24);
    assert_eq!(
        bytemuck::cast_slice::<f32, PackedTriangle>(floats),
        &packed[..]
    );
}

#[test]
fn bad_meshes_are_errors_not_panics() {
    assert_eq!(
        ingest::positions_from_flat(&FLAT[..11]),
        Err(IngestError::PositionsNotTriples { len: 11 })
    );
    let positions = ingest::positions_from_flat(&FLAT).unwrap();
    assert_eq!(
        ingest::pack_triangles_vec(positions, &INDICES[..5]),
        Err(IngestError::IndicesNotTriangles { len: 5 })
    );
    assert_eq!(
        ingest::pack_triangles_vec(positions, &[0, 1, 2, 0, 2, 4]),
        Err(IngestError::IndexOutOfRange {
            triangle: 1,
            index: 4,
            positions: 4
        })
    );
    assert_eq!(
        ingest::pack_vertex_triangles_vec(positions, &[u32::MAX, 0, 1]),
        Err(IngestError::IndexOutOfRange {
            triangle: 0,
            index: u32::MAX,
            positions: 4
        })
    );
    let mut too_small = [PackedTriangle::default(); 1];
    assert_eq!(
        ingest::pack_triangles(positions, &INDICES, &mut too_small),
        Err(IngestError::OutputLength {
            needed: 2,
            given: 1
        })
    );
    // The messages name the problem.
    let msg = IngestError::IndexOutOfRange {
        triangle: 1,
        index: 4,
        positions: 4,
    }
    .to_string();
    assert_eq!(
        msg,
        "triangle 1 uses vertex 4, but there are only 4 positions"
    );
}

#[test]
fn spheres_from_centre_and_radius_slices() {
    let centers = [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]];
    let s = ingest::pack_spheres_vec(&centers, &[2.0, -1.0]).unwrap();
    assert_eq!(s[0], PackedSphere::new(Vec3::ZERO, 2.0));
    assert!(
        s[1].radius_sq.is_nan(),
        "a negative radius is stored as never-hit"
    );
    assert_eq!(
        ingest::pack_spheres_vec(&centers, &[1.0]),
        Err(IngestError::SphereSlicesDiffer {
            centers: 2,
            radii: 1
        })
    );
}
