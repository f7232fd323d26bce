//! The signed solid angle a triangle subtends at a point (Van Oosterom and Strackee 1983), and
//! the far field of a cluster of triangles with its error bound: what the generalized winding
//! number (Jacobson, Kavan and Sorkine-Hornung 2013) sums, exactly near the point and by a
//! truncated expansion far from it (Barill et al. 2018).
//!
//! # Guarantees
//! - [`solid_angle`] is computed in f64 from the f32 inputs with `libm` (the same bits on every
//!   machine): every difference is exact, each product carries one rounding, so away from the
//!   triangle's plane the angle is within a few units of 2⁻⁵² of the exact one, relative.
//! - [`Cluster::far_field`] differs from the sum of its triangles' solid angles by at most
//!   [`Cluster::error_bound`] (before rounding), wherever the point lies outside the cluster's
//!   ball.
//!
//! # The far field
//! Seen from `p`, a triangle's solid angle is `∫ n·F(x − p) dA` with `F(y) = y/|y|³`. Around a
//! centre `c` with `y = c − p` and `h = x − c`, `F(y + h) = F(y) + J(y)·h + R`, where
//! `J(y) = (I − 3ŷŷᵀ)/|y|³`. Summed over a cluster with area vector `N = Σ Aᵢnᵢ` and first
//! moment `M = Σ Aᵢ nᵢ ⊗ (gᵢ − c)` (`gᵢ` the centroids), the first two terms are
//! `N·F(y) + M : J(y)`. `n·R` is a third derivative of `1/|y|` (`F = −∇(1/|y|)`) in the
//! directions `n, h, h`; those of `1/|y|` along one unit direction are `k!·Pₖ/|y|ᵏ⁺¹` with
//! `|Pₖ| ≤ 1` (the Legendre expansion), and a symmetric form's norm is its norm on the diagonal
//! (Banach), so `|n·R| ≤ ½·6·|h|²/|ξ|⁴ ≤ 3r²/(d − r)⁴` for a cluster within distance `r` of
//! `c` and `d = |y| > r`: the error is at most `3·A·r²/(d − r)⁴` for total area `A`.

use crate::lanes::{Lanes, Scalar, V3};

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: P) -> f64 {
    libm::sqrt(dot(a, a))
}

/// The solid angle triangle `v` subtends at `p`, in `(−2π, 2π)`: positive where `p` sees its
/// back (the side `(v₁ − v₀) × (v₂ − v₀)` points away from), so the angles of a closed,
/// outward-oriented mesh sum to 4π inside and 0 outside. A point in the triangle's plane (on it
/// or beside it) and a triangle with a non-finite coordinate give 0. [`AngleLanes`] at `f64`.
pub fn solid_angle(v: [P; 3], p: P) -> f64 {
    let mut sum = AngleLanes::<f64>::new();
    let [v0, v1, v2] = v.map(|x| V3::new(x[0], x[1], x[2]));
    sum.add_triangles(v0, v1, v2, V3::new(p[0], p[1], p[2]), true);
    sum.total()
}

/// Per-lane sums of triangles' solid angles without an arctangent per triangle: each lane
/// multiplies its triangles' half-angles as complex numbers (`arg(z₁z₂) = arg z₁ + arg z₂` up
/// to whole turns, which it counts); [`AngleLanes::total`] takes one `atan2` per lane.
///
/// The half-angle of triangle `a, b, c` (relative to `p`) is `arg(x + iy)` with
/// `y = a·(b × c)` and `x = |a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|` (Van Oosterom and
/// Strackee 1983). The running product is divided by its larger part after each factor, so it
/// stays in `[1, √2]`; each factor's roundings move the angle by a few units of 2⁻⁵³, as a sum
/// of `atan2`s would. A turn is counted from the signs of the computed product, so a rounding
/// across the negative real axis and its count agree: the total is continuous there. Only
/// IEEE-exact lane operations and `libm`: the same bits on every machine.
#[derive(Clone, Copy, Debug)]
pub struct AngleLanes<L: Lanes> {
    re: L,
    im: L,
    turns: L,
}

impl<L: Lanes> Default for AngleLanes<L> {
    fn default() -> Self {
        Self::new()
    }
}

/// Lanes whose `arg(re + i·im)` lies in `(0, π]`.
#[cfg_attr(not(debug_assertions), inline(always))]
fn upper<L: Lanes>(re: L, im: L) -> L::Mask {
    let zero = L::zero();
    im.gt(zero) | (!im.ne(zero) & re.lt(zero))
}

impl<L: Lanes> AngleLanes<L> {
    /// Zero in every lane.
    pub fn new() -> Self {
        Self {
            re: L::splat(1.0),
            im: L::zero(),
            turns: L::zero(),
        }
    }

    /// Adds, in the lanes of `keep`, the solid angle triangle `(v0, v1, v2)` subtends at `p`.
    #[cfg_attr(not(debug_assertions), inline(always))]
    pub fn add_triangles(&mut self, v0: V3<L>, v1: V3<L>, v2: V3<L>, p: V3<L>, keep: L::Mask) {
        let (a, b, c) = (v0 - p, v1 - p, v2 - p);
        let y = a.dot(b.cross(c));
        let (la, lb, lc) = (a.dot(a).sqrt(), b.dot(b).sqrt(), c.dot(c).sqrt());
        let x = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        let zero = L::zero();
        // In the plane (y = 0), non-finite or not kept: the factor 1, angle 0.
        let ok = keep & y.ne(zero) & y.is_finite() & x.is_finite();
        self.multiply(L::select(ok, x, L::splat(1.0)), L::select(ok, y, zero));
    }

    /// Multiplies each lane's product by `x + iy` (not zero), counting whole turns.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn multiply(&mut self, x: L, y: L) {
        let zero = L::zero();
        let (re, im) = (self.re * x - self.im * y, self.re * y + self.im * x);
        // Two angles in (0, π] sum past π, two in (−π, 0) to −π or below: a whole turn.
        let up = upper(self.re, self.im) & upper(x, y) & !upper(re, im);
        let down = self.im.lt(zero) & y.lt(zero) & im.ge(zero);
        self.turns =
            self.turns + L::select(up, L::splat(1.0), zero) - L::select(down, L::splat(1.0), zero);
        let m = re.abs().max_or_rhs(im.abs());
        (self.re, self.im) = (re / m, im / m);
    }

    /// The sum of every lane's solid angles.
    pub fn total(&self) -> f64 {
        let mut one = AngleLanes::<f64>::new();
        for i in 0..L::LANES {
            one.multiply(self.re.lane(i).to_f64(), self.im.lane(i).to_f64());
            one.turns += self.turns.lane(i).to_f64();
        }
        let turn = 2.0 * core::f64::consts::PI;
        2.0 * (libm::atan2(one.im, one.re) + turn * one.turns)
    }
}

/// What the far field of a set of triangles needs: their total area, area vector and first
/// moment about a centre, and a radius around the centre that holds them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cluster {
    /// The centre the moments are taken about.
    pub centre: P,
    /// Every point of the triangles lies within this distance of `centre`.
    pub radius: f64,
    /// Total area `Σ Aᵢ`.
    pub area: f64,
    /// Area vector `N = Σ Aᵢnᵢ` (half the sum of the edge cross products).
    pub normal: P,
    /// First moment `M[j][k] = Σ Aᵢ nᵢⱼ (gᵢ − c)ₖ`.
    pub moment: [P; 3],
}

impl Cluster {
    /// One triangle about `centre` (a non-finite one is empty).
    pub fn triangle(v: [P; 3], centre: P) -> Self {
        let n = cross(sub(v[1], v[0]), sub(v[2], v[0])).map(|x| 0.5 * x);
        let g: P = core::array::from_fn(|k| (v[0][k] + v[1][k] + v[2][k]) / 3.0);
        let radius = v.iter().map(|&x| norm(sub(x, centre))).fold(0.0, f64::max);
        let t = Self {
            centre,
            radius,
            area: norm(n),
            normal: n,
            moment: outer(n, sub(g, centre)),
        };
        if t.area.is_finite() && radius.is_finite() {
            t
        } else {
            Self::empty(centre)
        }
    }

    /// Nothing, about `centre`.
    pub fn empty(centre: P) -> Self {
        Self {
            centre,
            ..Self::default()
        }
    }

    /// Adds `other` (its moment carried to this centre), growing the radius to hold it.
    pub fn add(&mut self, other: &Self) {
        if other.area == 0.0 && other.radius == 0.0 {
            return;
        }
        let shift = sub(other.centre, self.centre);
        let carried = outer(other.normal, shift);
        let (n, m) = (self.normal, self.moment);
        self.normal = core::array::from_fn(|j| n[j] + other.normal[j]);
        self.moment = core::array::from_fn(|j| {
            core::array::from_fn(|k| m[j][k] + (other.moment[j][k] + carried[j][k]))
        });
        self.area += other.area;
        self.radius = self.radius.max(norm(shift) + other.radius);
    }

    /// The sum of the cluster's solid angles at `p` to first order in the offsets from the
    /// centre (`N·F(y) + M : J(y)` above). Meaningful where `p` is outside the ball.
    pub fn far_field(&self, p: P) -> f64 {
        let y = sub(self.centre, p);
        let d2 = dot(y, y);
        let d = libm::sqrt(d2);
        let inv3 = 1.0 / (d2 * d);
        let mut s = dot(self.normal, y) * inv3;
        for j in 0..3 {
            for k in 0..3 {
                let delta = if j == k { 1.0 } else { 0.0 };
                s += self.moment[j][k] * (delta - 3.0 * y[j] * y[k] / d2) * inv3;
            }
        }
        s
    }

    /// The distance from `p` to the centre, and whether `p` is outside the ball.
    pub fn distance(&self, p: P) -> (f64, bool) {
        let d = norm(sub(self.centre, p));
        (d, d > self.radius)
    }

    /// A bound on `|far_field(p) − Σ solid angles|` for a point at distance `d > radius` from
    /// the centre: `3·area·r²/(d − r)⁴`.
    pub fn error_bound(&self, d: f64) -> f64 {
        let g = d - self.radius;
        3.0 * self.area * self.radius * self.radius / (g * g * g * g)
    }
}

fn outer(a: P, b: P) -> [P; 3] {
    core::array::from_fn(|j| core::array::from_fn(|k| a[j] * b[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    const X: P = [1.0, 0.0, 0.0];
    const Y: P = [0.0, 1.0, 0.0];
    const Z: P = [0.0, 0.0, 1.0];

    #[test]
    fn an_octant_is_an_eighth_of_the_sphere_signed_by_the_side_seen() {
        // (X, Y, Z) has normal (1, 1, 1)/√3 facing away from the origin: the origin sees its back.
        assert!((solid_angle([X, Y, Z], [0.0; 3]) - PI / 2.0).abs() < 1e-15);
        assert!((solid_angle([X, Z, Y], [0.0; 3]) + PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn in_the_plane_and_non_finite_give_zero() {
        assert_eq!(solid_angle([X, Y, Z], [0.5, 0.25, 0.25]), 0.0);
        assert_eq!(solid_angle([X, Y, Z], [2.0, -1.0, 0.0]), 0.0);
        assert_eq!(solid_angle([[f64::NAN, 0.0, 0.0], Y, Z], [0.0; 3]), 0.0);
    }

    #[test]
    fn the_far_field_is_within_its_bound() {
        // A small fan of triangles around (0, 0, 0) seen from points ever nearer.
        let v: [P; 5] = [
            [0.0, 0.0, 0.1],
            [0.3, 0.0, 0.0],
            [0.0, 0.25, 0.05],
            [-0.2, 0.1, 0.0],
            [0.1, -0.3, 0.02],
        ];
        let tris = [[v[0], v[1], v[2]], [v[0], v[2], v[3]], [v[0], v[4], v[1]]];
        let mut c = Cluster::empty([0.0; 3]);
        for t in tris {
            c.add(&Cluster::triangle(t, [0.05, -0.02, 0.01]));
        }
        for k in 1..40 {
            let s = f64::from(k) * 0.1;
            let p = [0.7 * s, -0.4 * s, 0.9 * s];
            let (d, outside) = c.distance(p);
            if !outside {
                continue;
            }
            let exact: f64 = tris.iter().map(|&t| solid_angle(t, p)).sum();
            let err = (c.far_field(p) - exact).abs();
            assert!(err <= c.error_bound(d) * (1.0 + 1e-9) + 1e-15, "{s}: {err}");
        }
    }
}
