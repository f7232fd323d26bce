//! The point of a sphere nearest to a query point, in f64.
//!
//! # Guarantees
//! - The point `c + r·(p − c)/|p − c|` and the squared distance `(|p − c| − r)²` carry a few
//!   units of 2⁻⁵² relative; a point at the centre answers the sphere's point along `+x`. A
//!   sphere that is never hit (`radius_sq` not a finite normal `> 0`) is at infinite distance.
//! - `u = v = 0`.

use super::super::Nearest;
use crate::lanes::Lanes;

/// The point of the sphere at `c` with squared radius `r2` nearest to `p`.
pub(crate) fn nearest_on_sphere(c: [f64; 3], r2: f32, p: [f64; 3]) -> Nearest {
    if !(r2.is_normal() && r2 > 0.0) {
        return Nearest {
            point: c,
            u: 0.0,
            v: 0.0,
            dist2: f64::INFINITY,
        };
    }
    let r = Lanes::sqrt(f64::from(r2));
    let d: [f64; 3] = core::array::from_fn(|k| p[k] - c[k]);
    let len = Lanes::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    let dir = if len > 0.0 {
        d.map(|x| x / len)
    } else {
        [1.0, 0.0, 0.0]
    };
    let gap = len - r;
    Nearest {
        point: core::array::from_fn(|k| c[k] + r * dir[k]),
        u: 0.0,
        v: 0.0,
        dist2: gap * gap,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outside_inside_and_at_the_centre() {
        let c = [1.0, 0.0, 0.0];
        let n = nearest_on_sphere(c, 4.0, [1.0, 5.0, 0.0]);
        assert_eq!((n.point, n.dist2), ([1.0, 2.0, 0.0], 9.0));
        let n = nearest_on_sphere(c, 4.0, [1.0, 0.5, 0.0]);
        assert_eq!((n.point, n.dist2), ([1.0, 2.0, 0.0], 2.25));
        let n = nearest_on_sphere(c, 4.0, c);
        assert_eq!((n.point, n.dist2), ([3.0, 0.0, 0.0], 4.0));
        assert_eq!(nearest_on_sphere(c, f32::NAN, c).dist2, f64::INFINITY);
    }
}
