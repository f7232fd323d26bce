//! Zero-copy ingest: the precomputed primitive stores built straight from what mesh loaders (glTF,
//! OBJ) hand over: flat `&[f32]` or `&[[f32; 3]]` positions and `&[u32]` triangle indices, and
//! centre/radius slices for spheres. `bytemuck` does the casting; indices are validated, so a bad
//! mesh is an error value, never a panic. The `pack_*` functions write into caller-provided
//! slices (no allocator needed); with the `alloc` feature the `*_vec` forms return a `Vec`.

#[cfg(feature = "sphere")]
use crate::prim::PackedSphere;
#[cfg(feature = "triangle")]
use crate::prim::{PackedTriangle, VertexTriangle};
use core::fmt;
#[cfg(any(feature = "triangle", feature = "sphere"))]
use glam::Vec3;

/// Why a mesh or sphere set could not be ingested.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IngestError {
    /// The flat position slice's length is not a multiple of 3.
    PositionsNotTriples {
        /// Its length.
        len: usize,
    },
    /// The index slice's length is not a multiple of 3.
    IndicesNotTriangles {
        /// Its length.
        len: usize,
    },
    /// An index refers past the end of the positions.
    IndexOutOfRange {
        /// The triangle it belongs to.
        triangle: usize,
        /// The index.
        index: u32,
        /// The number of positions.
        positions: usize,
    },
    /// The output slice does not have one entry per primitive.
    OutputLength {
        /// Entries needed.
        needed: usize,
        /// Entries given.
        given: usize,
    },
    /// Centre and radius slices differ in length.
    SphereSlicesDiffer {
        /// Centres.
        centers: usize,
        /// Radii.
        radii: usize,
    },
}

impl core::error::Error for IngestError {}

impl fmt::Display for IngestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::PositionsNotTriples { len } => write!(
                f,
                "{len} position floats is not a whole number of xyz triples"
            ),
            Self::IndicesNotTriangles { len } => {
                write!(f, "{len} indices is not a whole number of triangles")
            }
            Self::IndexOutOfRange {
                triangle,
                index,
                positions,
            } => {
                write!(f, "triangle {triangle} uses vertex {index}, but there are only {positions} positions")
            }
            Self::OutputLength { needed, given } => {
                write!(f, "output holds {given} primitives, {needed} needed")
            }
            Self::SphereSlicesDiffer { centers, radii } => {
                write!(f, "{centers} centres but {radii} radii")
            }
        }
    }
}

/// Views flat `x, y, z, x, y, z, …` floats as positions, without copying.
pub fn positions_from_flat(flat: &[f32]) -> Result<&[[f32; 3]], IngestError> {
    bytemuck::try_cast_slice(flat).map_err(|_| IngestError::PositionsNotTriples { len: flat.len() })
}

/// Checks every index and calls `emit(i, v0, v1, v2)` for each triangle.
#[cfg(feature = "triangle")]
fn for_each_triangle(
    positions: &[[f32; 3]],
    indices: &[u32],
    out_len: usize,
    mut emit: impl FnMut(usize, Vec3, Vec3, Vec3),
) -> Result<(), IngestError> {
    if !indices.len().is_multiple_of(3) {
        return Err(IngestError::IndicesNotTriangles { len: indices.len() });
    }
    let n = indices.len() / 3;
    if out_len != n {
        return Err(IngestError::OutputLength {
            needed: n,
            given: out_len,
        });
    }
    let tris: &[[u32; 3]] = bytemuck::cast_slice(indices);
    for (i, t) in tris.iter().enumerate() {
        let mut v = [Vec3::ZERO; 3];
        for (k, &idx) in t.iter().enumerate() {
            let p = positions
                .get(idx as usize)
                .ok_or(IngestError::IndexOutOfRange {
                    triangle: i,
                    index: idx,
                    positions: positions.len(),
                })?;
            v[k] = Vec3::from(*p);
        }
        emit(i, v[0], v[1], v[2]);
    }
    Ok(())
}

/// Checks an indexed mesh without writing anything: the index count is a multiple of 3 and every
/// index is in range (the errors the `pack_*` functions would return).
#[cfg(feature = "triangle")]
pub fn check_mesh(positions: &[[f32; 3]], indices: &[u32]) -> Result<(), IngestError> {
    for_each_triangle(positions, indices, indices.len() / 3, |_, _, _, _| {})
}

/// Packs an indexed mesh for the Möller-Trumbore tiers (`v0, e1, e2, ng`), one entry per index
/// triple. On error the entries before the first bad triangle have been written: treat `out` as
/// unspecified.
#[cfg(feature = "triangle")]
pub fn pack_triangles(
    positions: &[[f32; 3]],
    indices: &[u32],
    out: &mut [PackedTriangle],
) -> Result<(), IngestError> {
    let len = out.len();
    for_each_triangle(positions, indices, len, |i, a, b, c| {
        out[i] = PackedTriangle::new(a, b, c)
    })
}

/// Stores an indexed mesh's vertices for the watertight tier.
#[cfg(feature = "triangle")]
pub fn pack_vertex_triangles(
    positions: &[[f32; 3]],
    indices: &[u32],
    out: &mut [VertexTriangle],
) -> Result<(), IngestError> {
    let len = out.len();
    for_each_triangle(positions, indices, len, |i, a, b, c| {
        out[i] = VertexTriangle::new(a, b, c)
    })
}

/// Packs spheres from centres and radii (bad radii become never-hit spheres, see
/// [`PackedSphere::new`]).
#[cfg(feature = "sphere")]
pub fn pack_spheres(
    centers: &[[f32; 3]],
    radii: &[f32],
    out: &mut [PackedSphere],
) -> Result<(), IngestError> {
    if centers.len() != radii.len() {
        return Err(IngestError::SphereSlicesDiffer {
            centers: centers.len(),
            radii: radii.len(),
        });
    }
    if out.len() != centers.len() {
        return Err(IngestError::OutputLength {
            needed: centers.len(),
            given: out.len(),
        });
    }
    for ((o, c), &r) in out.iter_mut().zip(centers).zip(radii) {
        *o = PackedSphere::new(Vec3::from(*c), r);
    }
    Ok(())
}

/// [`pack_triangles`] into a new `Vec`.
#[cfg(all(feature = "triangle", feature = "alloc"))]
pub fn pack_triangles_vec(
    positions: &[[f32; 3]],
    indices: &[u32],
) -> Result<alloc::vec::Vec<PackedTriangle>, IngestError> {
    // Validate before allocating: a bad mesh costs no memory.
    check_mesh(positions, indices)?;
    let mut out = alloc::vec![PackedTriangle::default(); indices.len() / 3];
    pack_triangles(positions, indices, &mut out)?;
    Ok(out)
}

/// [`pack_vertex_triangles`] into a new `Vec`.
#[cfg(all(feature = "triangle", feature = "alloc"))]
pub fn pack_vertex_triangles_vec(
    positions: &[[f32; 3]],
    indices: &[u32],
) -> Result<alloc::vec::Vec<VertexTriangle>, IngestError> {
    // Validate before allocating: a bad mesh costs no memory.
    check_mesh(positions, indices)?;
    let mut out = alloc::vec![VertexTriangle::default(); indices.len() / 3];
    pack_vertex_triangles(positions, indices, &mut out)?;
    Ok(out)
}

/// [`pack_spheres`] into a new `Vec`.
#[cfg(all(feature = "sphere", feature = "alloc"))]
pub fn pack_spheres_vec(
    centers: &[[f32; 3]],
    radii: &[f32],
) -> Result<alloc::vec::Vec<PackedSphere>, IngestError> {
    if centers.len() != radii.len() {
        return Err(IngestError::SphereSlicesDiffer {
            centers: centers.len(),
            radii: radii.len(),
        });
    }
    let mut out = alloc::vec![PackedSphere::default(); centers.len()];
    pack_spheres(centers, radii, &mut out)?;
    Ok(out)
}
