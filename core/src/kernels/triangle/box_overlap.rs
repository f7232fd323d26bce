//! Does a triangle meet an axis-aligned box? The separating-axis test (Akenine-Möller 2001) in
//! f64: the box's three face normals, the triangle's normal and the nine cross products of their
//! edges; the two closed sets meet when no axis separates their projections.
//!
//! # Guarantees
//! f32 inputs make every difference exact in f64 and each projection carries a few roundings:
//! the answer is exact unless the triangle and the box touch (or miss) by less than about 2⁻⁵⁰
//! of their coordinates. A degenerate triangle is tested as the segment or point it is (its
//! normal axis is zero and separates nothing). A non-finite vertex or box corner: no overlap.

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Does the triangle `v` meet the box `[lo, hi]` (both closed)?
pub(crate) fn triangle_meets_box(v: [P; 3], lo: P, hi: P) -> bool {
    let finite = |p: &P| p.iter().all(|x| x.is_finite());
    if !(v.iter().all(finite) && finite(&lo) && finite(&hi)) || (0..3).any(|k| lo[k] > hi[k]) {
        return false;
    }
    // The box's centre and half extents; the triangle relative to the centre.
    let c: P = core::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let h: P = core::array::from_fn(|k| 0.5 * (hi[k] - lo[k]));
    let t = v.map(|p| sub(p, c));
    // An axis separates when the triangle's projection lies beyond the box's radius on it.
    let separates = |axis: P| {
        let r = h[0] * axis[0].abs() + h[1] * axis[1].abs() + h[2] * axis[2].abs();
        let p = t.map(|q| dot(q, axis));
        let (min, max) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        min > r || max < -r
    };
    let e = [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
    let units = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if units.iter().any(|&u| separates(u)) || separates(cross(e[0], e[1])) {
        return false;
    }
    !units
        .iter()
        .any(|&u| e.iter().any(|&edge| separates(cross(u, edge))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_touching_crossing_and_apart() {
        let tri = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let unit = |o: P| (o, [o[0] + 1.0, o[1] + 1.0, o[2] + 1.0]);
        let meets = |o: P| {
            let (lo, hi) = unit(o);
            triangle_meets_box(tri, lo, hi)
        };
        assert!(meets([-0.5, -0.5, -0.5])); // a vertex inside
        assert!(meets([0.2, 0.2, -0.5])); // the face through the box
        assert!(meets([1.0, 1.0, 0.0])); // touching the hypotenuse at (1, 1, 0)
        assert!(!meets([1.01, 1.01, -0.5])); // past the hypotenuse
        assert!(!meets([0.2, 0.2, 0.01])); // above the face
        assert!(meets([0.2, 0.2, 0.0])); // touching the face
                                         // A box that holds no vertex and no edge point but is crossed by the face: the big
                                         // triangle through a small box.
        let big = [[-10.0, -10.0, 0.5], [10.0, -10.0, 0.5], [0.0, 10.0, 0.5]];
        assert!(triangle_meets_box(big, [0.0; 3], [1.0; 3]));
        // Degenerate: a segment along x through the box, a point beside it.
        assert!(triangle_meets_box(
            [[-5.0, 0.5, 0.5], [5.0, 0.5, 0.5], [0.0, 0.5, 0.5]],
            [0.0; 3],
            [1.0; 3]
        ));
        assert!(!triangle_meets_box([[2.0; 3]; 3], [0.0; 3], [1.0; 3]));
        assert!(!triangle_meets_box([[f64::NAN; 3]; 3], [0.0; 3], [1.0; 3]));
    }
}
