//! The textbook ray-triangle test, line by line (its accuracy: the [module docs](super)).

use super::TextbookHit;
use crate::prim::{Ray, VertexTriangle};
use glam::Vec3;

/// How the inside-outside test compares the three edge cross products.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InsideTest {
    /// Project each cross product on `n` (`((a_i − p) × (a_j − p))·n`) and require the three
    /// to agree in sign.
    Full,
    /// The sheet's shortcut: compare only the component on the dominant axis of `n`
    /// (the largest `|n_k|`; ties go to the lower axis).
    DominantAxis,
}

/// Why the textbook test ended where it did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TriangleOutcome {
    /// `p` is inside (edges included).
    Hit(TextbookHit),
    /// `n` is zero or not finite: a zero-area triangle or a non-finite vertex.
    Degenerate,
    /// `d·n == 0` (or not finite): the ray is parallel to the plane, or its direction is zero.
    Parallel,
    /// `t` is not finite or lies outside `[t_min, t_max]`.
    OutOfRange,
    /// The edge tests disagree in sign (or one is NaN): `p` is outside.
    Outside,
}

/// Every intermediate value of the textbook ray-triangle test, as on the sheet.
///
/// Fields the test did not reach are NaN (`t`, `p`, the edge tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleSteps {
    /// `n = (a2 − a1) × (a3 − a1)`.
    pub n: Vec3,
    /// `d·n`.
    pub d_dot_n: f32,
    /// `(o − a1)·n`.
    pub o_dot_n: f32,
    /// `t = −((o − a1)·n) / (d·n)`.
    pub t: f32,
    /// `p = o + t·d`.
    pub p: Vec3,
    /// `a_i − p` for i = 1, 2, 3 (the sheet's `p a_i` vectors).
    pub to_vertices: [Vec3; 3],
    /// `(a_i − p) × (a_j − p)` for the edges (1,2), (2,3), (3,1).
    pub edge_cross: [Vec3; 3],
    /// The edge cross products projected on `n` (the [`InsideTest::Full`] values).
    pub edge_tests: [f32; 3],
    /// The dominant axis of `n` (0 = x, 1 = y, 2 = z).
    pub dominant_axis: usize,
    /// The edge cross products' components on the dominant axis
    /// (the [`InsideTest::DominantAxis`] values; the sheet's "x components").
    pub edge_tests_dominant: [f32; 3],
    /// The outcome under the test that was asked for.
    pub outcome: TriangleOutcome,
}

/// True when three values agree in sign, zeros counting with either side (a point on an edge is
/// inside). Any NaN makes it false.
fn agree_in_sign(e: [f32; 3]) -> bool {
    (e[0] >= 0.0 && e[1] >= 0.0 && e[2] >= 0.0) || (e[0] <= 0.0 && e[1] <= 0.0 && e[2] <= 0.0)
}

/// Index of the largest `|n_k|`, ties to the lower axis.
fn dominant_axis(n: Vec3) -> usize {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// Runs the textbook test and returns all its intermediate values.
pub fn triangle_steps(ray: &Ray, tri: &VertexTriangle, test: InsideTest) -> TriangleSteps {
    let (o, d) = (ray.origin, ray.dir);
    let [a1, a2, a3] = tri.vertices();
    let nan3 = Vec3::splat(f32::NAN);
    let mut s = TriangleSteps {
        n: Vec3::NAN,
        d_dot_n: f32::NAN,
        o_dot_n: f32::NAN,
        t: f32::NAN,
        p: nan3,
        to_vertices: [nan3; 3],
        edge_cross: [nan3; 3],
        edge_tests: [f32::NAN; 3],
        dominant_axis: 0,
        edge_tests_dominant: [f32::NAN; 3],
        outcome: TriangleOutcome::Degenerate,
    };

    // The plane through a1 with normal n: (x − a1)·n = 0.
    s.n = (a2 - a1).cross(a3 - a1);
    s.dominant_axis = dominant_axis(s.n);
    if s.n == Vec3::ZERO || !s.n.is_finite() {
        return s;
    }
    s.d_dot_n = d.dot(s.n);
    s.o_dot_n = (o - a1).dot(s.n);
    // Parallel (or zero direction): the sheet reports no intersection even when the ray lies
    // in the plane.
    if s.d_dot_n == 0.0 || !s.d_dot_n.is_finite() {
        s.outcome = TriangleOutcome::Parallel;
        return s;
    }
    // Substituting o + t·d into the plane equation: (o − a1)·n + t (d·n) = 0.
    s.t = -s.o_dot_n / s.d_dot_n;
    if !(s.t.is_finite() && s.t >= ray.t_min && s.t <= ray.t_max) {
        s.outcome = TriangleOutcome::OutOfRange;
        return s;
    }
    s.p = ray.at(s.t);

    // p is inside when it sees every edge turn the same way: the cross products
    // (a_i − p) × (a_j − p) all point along n (or all against it).
    s.to_vertices = [a1 - s.p, a2 - s.p, a3 - s.p];
    let [pa1, pa2, pa3] = s.to_vertices;
    s.edge_cross = [pa1.cross(pa2), pa2.cross(pa3), pa3.cross(pa1)];
    let k = s.dominant_axis;
    s.edge_tests = s.edge_cross.map(|c| c.dot(s.n));
    s.edge_tests_dominant = s.edge_cross.map(|c| c[k]);
    let inside = match test {
        InsideTest::Full => agree_in_sign(s.edge_tests),
        InsideTest::DominantAxis => agree_in_sign(s.edge_tests_dominant),
    };
    s.outcome = if inside && s.p.is_finite() {
        TriangleOutcome::Hit(TextbookHit { t: s.t, point: s.p })
    } else {
        TriangleOutcome::Outside
    };
    s
}

/// The textbook test's answer: the hit, or `None`.
pub fn intersect_triangle(
    ray: &Ray,
    tri: &VertexTriangle,
    test: InsideTest,
) -> Option<TextbookHit> {
    match triangle_steps(ray, tri, test).outcome {
        TriangleOutcome::Hit(h) => Some(h),
        _ => None,
    }
}
