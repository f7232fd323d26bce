//! Triangle layouts, named for what they store: [`VertexTriangle`] (the three vertices as given
//! and the unit normal: what the watertight kernel and the textbook read) and [`PackedTriangle`]
//! (`v0` and two edges: what Möller-Trumbore reads), and their lanes.

use super::{clip_triangle, clip_triangle_slabs, down, up, Aabb, Primitive, Words};
use crate::lanes::{Lanes, Scalar, V3};
use glam::Vec3;

/// A triangle in exactly what the Möller-Trumbore kernel reads: `v0`, `e1 = v1 − v0`,
/// `e2 = v2 − v0` and the unnormalised normal `ng = e1 × e2` (12 floats, 48 bytes, no index;
/// Embree's `TriangleM` layout). `bytemuck` casts slices of it to and from `&[f32]`.
///
/// The edges are rounded once to f32 when packed, so a packed triangle's `v1`/`v2` can differ
/// from the input by half an ulp of the edge; the kernels' contracts are stated for the packed
/// triangle. `ng` is the f32 cross product of the stored edges in the kernels' operation order,
/// so reading it gives the same bits as computing it per test (which the f32 kernels no longer
/// do: 9 of their ~43 FP operations); the f64 tier recomputes it from the widened edges.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PackedTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// `v1 − v0`.
    pub e1: [f32; 3],
    /// `v2 − v0`.
    pub e2: [f32; 3],
    /// `e1 × e2`, as [`crate::lanes::V3::cross`] computes it at `f32`.
    pub ng: [f32; 3],
}

impl PackedTriangle {
    /// The corners as the kernels read them, exactly (`v0 + e1` and `v0 + e2` in f64).
    fn points(&self) -> [[f64; 3]; 3] {
        let p = |e: [f32; 3]| core::array::from_fn(|k| self.v0[k] as f64 + e[k] as f64);
        [p([0.0; 3]), p(self.e1), p(self.e2)]
    }

    /// Packs three vertices.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        Self::from_edges(v0.to_array(), (v1 - v0).to_array(), (v2 - v0).to_array())
    }

    /// A packed triangle from `v0` and the edges as stored (the normal is computed from them).
    pub fn from_edges(v0: [f32; 3], e1: [f32; 3], e2: [f32; 3]) -> Self {
        let ng = V3::<f32>::new(e1[0], e1[1], e1[2]).cross(V3::new(e2[0], e2[1], e2[2]));
        Self {
            v0,
            e1,
            e2,
            ng: [ng.x, ng.y, ng.z],
        }
    }
}

/// A triangle as its three vertices and its unit normal (12 floats, 48 bytes,
/// `bytemuck`-castable): what the watertight kernel reads, because watertightness needs the
/// shared vertices themselves, not rounded edges; the normal places its hit on the plane.
///
/// `n` is derived: [`VertexTriangle::new`] forms `(v1 − v0) × (v2 − v0)` from the vertices in
/// f64 (the differences exact), normalises it and rounds each component once to f32, so it is
/// within about an ulp of the exact unit normal however thin the triangle (an f32 cross of
/// rounded edges of a needle is off by the needle's aspect ratio). Zero for a degenerate
/// triangle. A normal that does not match the vertices (a hand-built or stored value) changes
/// only where on the ray a hit is placed, never whether the watertight tier reports it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VertexTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// Second vertex.
    pub v1: [f32; 3],
    /// Third vertex.
    pub v2: [f32; 3],
    /// The unit normal `(v1 − v0) × (v2 − v0) / |…|`, formed in f64 and rounded to f32.
    pub n: [f32; 3],
}

impl VertexTriangle {
    /// The vertices in f64.
    fn points(&self) -> [[f64; 3]; 3] {
        [self.v0, self.v1, self.v2].map(|v| v.map(f64::from))
    }

    /// Stores three vertices and their normal.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        let (v0, v1, v2) = (v0.to_array(), v1.to_array(), v2.to_array());
        Self {
            v0,
            v1,
            v2,
            n: unit_normal(v0, v1, v2),
        }
    }

    /// The three vertices as vectors.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.v0, self.v1, self.v2].map(Vec3::from)
    }
}

/// `(v1 − v0) × (v2 − v0)` normalised, in f64 from the f32 vertices (each difference exact
/// unless the coordinates' exponents differ by more than 29, the products and sums within a few
/// units of 2⁻⁵³: no f32 vertices over- or underflow them), rounded once to f32; zero when the
/// cross product is zero or a vertex is not finite.
fn unit_normal(v0: [f32; 3], v1: [f32; 3], v2: [f32; 3]) -> [f32; 3] {
    let w = |v: [f32; 3]| V3::<f64>::new(v[0].into(), v[1].into(), v[2].into());
    let (p0, p1, p2) = (w(v0), w(v1), w(v2));
    let n = (p1 - p0).cross(p2 - p0);
    let len = libm::sqrt(n.dot(n));
    if len > 0.0 && len.is_finite() {
        [n.x, n.y, n.z].map(|x| (x / len) as f32)
    } else {
        [0.0; 3]
    }
}

/// Box of three points, or `None` when a coordinate is not finite (checked first: `min` and
/// `max` would drop a NaN).
fn points_bounds(p: [[f32; 3]; 3]) -> Option<Aabb> {
    if !p.iter().flatten().all(|x| x.is_finite()) {
        return None;
    }
    let b = Aabb::EMPTY.grow(p[0]).grow(p[1]).grow(p[2]);
    b.is_finite().then_some(b)
}

/// [`PackedTriangle`] as lanes: `v0`, `e1`, `e2`, `ng`.
#[derive(Clone, Copy, Debug)]
pub struct EdgeLanes<L> {
    /// First vertex.
    pub v0: V3<L>,
    /// `v1 − v0`.
    pub e1: V3<L>,
    /// `v2 − v0`.
    pub e2: V3<L>,
    /// `e1 × e2`: the stored f32 normal at f32 widths; at f64 widths recomputed from the widened
    /// edges (the f32-rounded one would cost the f64 tier its accuracy).
    pub ng: V3<L>,
}

/// The normal lanes: the stored one at f32 widths, `e1 × e2` recomputed at wider scalars.
#[inline(always)]
fn normal_lanes<L: Lanes>(stored: V3<L>, e1: V3<L>, e2: V3<L>) -> V3<L> {
    if <L::Scalar as Scalar>::UNIT_ROUNDOFF < f32::EPSILON as f64 / 2.0 {
        e1.cross(e2)
    } else {
        stored
    }
}

impl Primitive for PackedTriangle {
    type Lanes<L: Lanes> = EdgeLanes<L>;
    const TAG: u32 = u32::from_le_bytes(*b"PTri");
    #[inline(always)]
    fn from_words<L: Lanes, W: Words>(w: &W) -> EdgeLanes<L> {
        let (e1, e2) = (w.word3(3), w.word3(6));
        EdgeLanes {
            v0: w.word3(0),
            e1,
            e2,
            ng: normal_lanes(w.word3(9), e1, e2),
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        let (v0, e1, e2) = (self.v0, self.e1, self.e2);
        if !(v0.iter().chain(&e1).chain(&e2).all(|x| x.is_finite())) {
            return None;
        }
        // v0 + e1 and v0 + e2 are exact in the kernels' algebra; their rounded sums are within
        // half an ulp, so one ulp outward holds the exact points.
        // A sum that overflows (finite edges reaching past f32's range) is clamped: the box
        // then reaches f32::MAX, and the builder's slack makes its nodes infinite there.
        let a: [f32; 3] = core::array::from_fn(|k| (v0[k] + e1[k]).clamp(-f32::MAX, f32::MAX));
        let b: [f32; 3] = core::array::from_fn(|k| (v0[k] + e2[k]).clamp(-f32::MAX, f32::MAX));
        let mut bx = points_bounds([v0, a, b])?;
        for k in 0..3 {
            bx.lo[k] = down(bx.lo[k]);
            bx.hi[k] = up(bx.hi[k]);
        }
        Some(bx.clamped())
    }

    fn clip(&self, axis: usize, lo: f32, hi: f32) -> Option<Aabb> {
        clip_triangle(self.points(), axis, lo, hi)
    }
    fn clip_slabs(&self, axis: usize, planes: &[f32], out: &mut [Option<Aabb>]) {
        clip_triangle_slabs(self.points(), axis, planes, out);
    }
}

/// [`VertexTriangle`] as lanes: the three vertices and the normal.
#[derive(Clone, Copy, Debug)]
pub struct VertexLanes<L> {
    /// First vertex.
    pub v0: V3<L>,
    /// Second vertex.
    pub v1: V3<L>,
    /// Third vertex.
    pub v2: V3<L>,
    /// The stored unit normal (the f32 watertight tier places its hits with it; the f64 tier's
    /// blend of depths is plane-accurate without it).
    pub n: V3<L>,
}

impl Primitive for VertexTriangle {
    type Lanes<L: Lanes> = VertexLanes<L>;
    const TAG: u32 = u32::from_le_bytes(*b"VTri");
    #[inline(always)]
    fn from_words<L: Lanes, W: Words>(w: &W) -> VertexLanes<L> {
        VertexLanes {
            v0: w.word3(0),
            v1: w.word3(3),
            v2: w.word3(6),
            n: w.word3(9),
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        points_bounds([self.v0, self.v1, self.v2])
    }

    fn clip(&self, axis: usize, lo: f32, hi: f32) -> Option<Aabb> {
        clip_triangle(self.points(), axis, lo, hi)
    }
    fn clip_slabs(&self, axis: usize, planes: &[f32], out: &mut [Option<Aabb>]) {
        clip_triangle_slabs(self.points(), axis, planes, out);
    }
}

impl From<VertexTriangle> for PackedTriangle {
    fn from(t: VertexTriangle) -> Self {
        let [v0, v1, v2] = t.vertices();
        Self::new(v0, v1, v2)
    }
}
