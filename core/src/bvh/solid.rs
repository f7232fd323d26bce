//! A closed triangle mesh and its tree: what exact containment and winding numbers need.

use super::{Bvh8Ref, PAD};
use crate::prim::{BlockLane, Primitive, VertexTriangle, BLOCK};
use alloc::vec::Vec;

/// A tree of triangles together with the triangles it was built from, checked to be a closed
/// surface: every edge is used as often in one direction as in the other (two triangles sharing
/// an edge with opposite orientation, the manifold case, or any balanced number of them).
///
/// On a solid, a crossing count along any ray from a point under the crossing rule
/// ([`crate::kernels::ExactCrossing`]) is even exactly when the point is outside, and the sum of
/// the crossings' sides is its winding number (`octoray-packet`'s `tree::contains` and
/// `tree::winding_number`). Edges are compared by their vertices' values (`−0` equals `+0`),
/// exactly: vertices that should be shared must be bitwise equal, as an indexed mesh's are.
#[derive(Clone, Copy, Debug)]
pub struct Solid<'a> {
    bvh: Bvh8Ref<'a, VertexTriangle>,
    tris: &'a [VertexTriangle],
}

/// Why [`Solid::new`] refused a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolidError {
    /// The tree was not built from these triangles: its primitive count differs, or block slot
    /// `slot` holds a triangle other than the one its index names.
    NotItsTree {
        /// The first slot that differs (the number of triangles when the counts differ).
        slot: usize,
    },
    /// The edge from `a` to `b` is used more often in one direction than in the other: the
    /// surface has a hole, a flipped triangle or a dangling face there.
    OpenEdge {
        /// One end.
        a: [f32; 3],
        /// The other end.
        b: [f32; 3],
    },
    /// A vertex coordinate is NaN or infinite.
    NonFinite {
        /// The triangle.
        tri: usize,
    },
}

impl core::fmt::Display for SolidError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotItsTree { slot } => {
                write!(
                    f,
                    "the tree was not built from these triangles (slot {slot})"
                )
            }
            Self::OpenEdge { a, b } => write!(
                f,
                "the mesh is not closed: edge {a:?}–{b:?} is used more often in one direction"
            ),
            Self::NonFinite { tri } => write!(f, "triangle {tri} has a non-finite vertex"),
        }
    }
}

impl core::error::Error for SolidError {}

/// A vertex as a sortable key: its coordinates' bits, with `−0` made `+0`.
type Key = [u32; 3];

fn key(p: [f32; 3]) -> Key {
    p.map(|x| (x + 0.0).to_bits())
}

impl<'a> Solid<'a> {
    /// Checks that `bvh` was built from `tris` (every slot holds the triangle its index names)
    /// and that `tris` is closed, in `O(n log n)` time and `O(n)` memory.
    pub fn new(
        bvh: Bvh8Ref<'a, VertexTriangle>,
        tris: &'a [VertexTriangle],
    ) -> Result<Self, SolidError> {
        if bvh.prims() != tris.len() {
            return Err(SolidError::NotItsTree { slot: tris.len() });
        }
        for (slot, &id) in bvh.ids().iter().enumerate() {
            if id == PAD {
                continue;
            }
            let block = bvh.block_of(slot);
            let stored = VertexTriangle::from_words::<f32, _>(&BlockLane::new::<VertexTriangle>(
                block,
                slot % BLOCK,
            ));
            let t = &tris[id as usize];
            let same = |p: &crate::lanes::V3<f32>, q: [f32; 3]| [p.x, p.y, p.z] == q;
            if !(same(&stored.v0, t.v0) && same(&stored.v1, t.v1) && same(&stored.v2, t.v2)) {
                return Err(SolidError::NotItsTree { slot });
            }
        }
        // Every edge as (lower end, upper end, +1 or −1 for its direction); the directions of
        // each edge must sum to zero.
        let mut edges: Vec<(Key, Key, i8)> = Vec::with_capacity(3 * tris.len());
        for (i, t) in tris.iter().enumerate() {
            let v = [t.v0, t.v1, t.v2];
            if v.iter().flatten().any(|x| !x.is_finite()) {
                return Err(SolidError::NonFinite { tri: i });
            }
            for j in 0..3 {
                let (a, b) = (key(v[j]), key(v[(j + 1) % 3]));
                match a.cmp(&b) {
                    core::cmp::Ordering::Less => edges.push((a, b, 1)),
                    core::cmp::Ordering::Greater => edges.push((b, a, -1)),
                    core::cmp::Ordering::Equal => {}
                }
            }
        }
        edges.sort_unstable();
        for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            if run.iter().map(|e| i64::from(e.2)).sum::<i64>() != 0 {
                let point = |k: Key| k.map(f32::from_bits);
                return Err(SolidError::OpenEdge {
                    a: point(run[0].0),
                    b: point(run[0].1),
                });
            }
        }
        Ok(Self { bvh, tris })
    }

    /// The tree.
    pub fn bvh(&self) -> Bvh8Ref<'a, VertexTriangle> {
        self.bvh
    }

    /// The triangles, in the order the tree's indices name them.
    pub fn tris(&self) -> &'a [VertexTriangle] {
        self.tris
    }
}
