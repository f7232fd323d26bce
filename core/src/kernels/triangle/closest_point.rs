//! The point of a triangle nearest to a query point: Ericson's region test (Real-Time Collision
//! Detection, §5.1.5) in f64.
//!
//! # Guarantees
//! - Inputs are f32 (vertices and point), so every difference is exact in f64 and every
//!   product of two carries one rounding: the point is the exact nearest point to within a few
//!   units of 2⁻⁵² of the triangle's extent and the distance to the point (it rounds to f32
//!   within an ulp or so), and the squared distance is within a few units of 2⁻⁵² of the exact
//!   one, relative.
//! - A degenerate triangle (a segment or a point) answers its nearest point on the segments
//!   between its vertices; never NaN for finite inputs. A triangle with a non-finite vertex is
//!   infinitely far (it is never hit, and trees leave it out).
//!
//! # The regions
//! With `ab = b − a`, `ac = c − a` and `d₁…d₆` the projections of `p − a`, `p − b`, `p − c` on
//! `ab` and `ac`, `p` projects to a vertex when both projections from it point away from the
//! triangle, onto an edge when its two projections place it between the ends and the signed
//! area `v` opposite that edge (`vc = d₁d₄ − d₃d₂`, …) is not positive, and inside otherwise,
//! at barycentrics `(vb, vc)/(va + vb + vc)`.

use super::super::Nearest;

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a + s·x + t·y`.
fn at(a: P, x: P, s: f64, y: P, t: f64) -> P {
    core::array::from_fn(|k| a[k] + s * x[k] + t * y[k])
}

/// The answer at `point` with barycentrics `(u, v)` of the second and third vertex.
fn nearest(point: P, (u, v): (f64, f64), p: P) -> Nearest {
    let d = sub(point, p);
    Nearest {
        point,
        u,
        v,
        dist2: dot(d, d),
    }
}

/// The point of the triangle `[a, b, c]` nearest to `p` (see the module docs); infinitely far
/// when a vertex is not finite (such a triangle is never hit, nor in a tree).
pub(crate) fn nearest_on_triangle([a, b, c]: [P; 3], p: P) -> Nearest {
    if ![a, b, c].iter().flatten().all(|x| x.is_finite()) {
        return Nearest {
            point: a,
            u: 0.0,
            v: 0.0,
            dist2: f64::INFINITY,
        };
    }
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return nearest(a, (0.0, 0.0), p);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return nearest(b, (1.0, 0.0), p);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let s = d1 / (d1 - d3);
        return nearest(at(a, ab, s, ac, 0.0), (s, 0.0), p);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return nearest(c, (0.0, 1.0), p);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return nearest(at(a, ab, 0.0, ac, t), (0.0, t), p);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return nearest(at(b, sub(c, b), t, ab, 0.0), (1.0 - t, t), p);
    }
    let sum = va + vb + vc;
    if sum > 0.0 && sum.is_finite() {
        let (s, t) = (vb / sum, vc / sum);
        return nearest(at(a, ab, s, ac, t), (s, t), p);
    }
    // A degenerate triangle whose region tests fell through (or roundings that made the area
    // vanish): the nearest of its three edges.
    let edges = [
        (a, b, (0.0, 0.0), (1.0, 0.0)),
        (b, c, (1.0, 0.0), (0.0, 1.0)),
        (c, a, (0.0, 1.0), (0.0, 0.0)),
    ];
    let mut best: Option<Nearest> = None;
    for (x, y, bx, by) in edges {
        let n = nearest_on_segment(x, y, bx, by, p);
        if best.is_none_or(|b| n.dist2 < b.dist2) {
            best = Some(n);
        }
    }
    best.unwrap_or(nearest(a, (0.0, 0.0), p))
}

/// The point of segment `xy` nearest to `p`, with barycentrics blended from the ends' `bx`, `by`.
fn nearest_on_segment(x: P, y: P, bx: (f64, f64), by: (f64, f64), p: P) -> Nearest {
    let (xy, xp) = (sub(y, x), sub(p, x));
    let len2 = dot(xy, xy);
    let s = if len2 > 0.0 {
        (dot(xy, xp) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let lerp = |a: f64, b: f64| a + s * (b - a);
    nearest(
        at(x, xy, s, xy, 0.0),
        (lerp(bx.0, by.0), lerp(bx.1, by.1)),
        p,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [P; 3] = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];

    #[test]
    fn each_region_answers_its_feature() {
        let n = |p: P| {
            let r = nearest_on_triangle(TRI, p);
            (r.point, r.u, r.v, r.dist2)
        };
        // Inside, above the face.
        assert_eq!(n([0.5, 0.5, 3.0]), ([0.5, 0.5, 0.0], 0.25, 0.25, 9.0));
        // The three vertex regions.
        assert_eq!(n([-1.0, -1.0, 0.0]), ([0.0; 3], 0.0, 0.0, 2.0));
        assert_eq!(n([3.0, -1.0, 0.0]), ([2.0, 0.0, 0.0], 1.0, 0.0, 2.0));
        assert_eq!(n([-1.0, 3.0, 0.0]), ([0.0, 2.0, 0.0], 0.0, 1.0, 2.0));
        // The three edge regions.
        assert_eq!(n([1.0, -1.0, 0.0]), ([1.0, 0.0, 0.0], 0.5, 0.0, 1.0));
        assert_eq!(n([-1.0, 1.0, 0.0]), ([0.0, 1.0, 0.0], 0.0, 0.5, 1.0));
        assert_eq!(n([2.0, 2.0, 0.0]), ([1.0, 1.0, 0.0], 0.5, 0.5, 2.0));
    }

    #[test]
    fn degenerate_triangles_answer_their_segments() {
        // Collinear: the segment (0,0,0)–(2,0,0) with its middle vertex.
        let line = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let r = nearest_on_triangle(line, [1.5, 1.0, 0.0]);
        assert_eq!((r.point, r.dist2), ([1.5, 0.0, 0.0], 1.0));
        // A point.
        let r = nearest_on_triangle([[1.0; 3]; 3], [1.0, 1.0, 3.0]);
        assert_eq!((r.point, r.dist2), ([1.0; 3], 4.0));
        assert!(r.u.is_finite() && r.v.is_finite());
    }
}
