//! Affine maps in f64 ([`Affine64`]): how a point query carries its point into an instance's
//! object space and the instance's primitives back into world space.

use crate::lanes::Lanes;

/// An affine map `x ↦ m·x + t` in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine64 {
    /// The linear part, by rows.
    pub m: [[f64; 3]; 3],
    /// The translation.
    pub t: [f64; 3],
}

impl Affine64 {
    /// The identity.
    pub const IDENTITY: Self = Self {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    /// `m·v` (the map of a direction).
    #[inline]
    pub fn linear(&self, v: [f64; 3]) -> [f64; 3] {
        self.m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2])
    }

    /// `m·p + t` (the map of a point).
    #[inline]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let l = self.linear(p);
        core::array::from_fn(|k| l[k] + self.t[k])
    }

    /// `next` after `self`: `x ↦ next(self(x))`.
    pub fn then(&self, next: &Self) -> Self {
        let col = |j: usize| next.linear([self.m[0][j], self.m[1][j], self.m[2][j]]);
        let cols = [col(0), col(1), col(2)];
        Self {
            m: core::array::from_fn(|i| core::array::from_fn(|j| cols[j][i])),
            t: next.apply(self.t),
        }
    }

    /// The inverse map (its linear part by cofactors), `None` when `m` is singular or anything
    /// is not finite.
    pub fn inverse(&self) -> Option<Self> {
        let (m, _) = invert3(&self.m)?;
        let mt = Self { m, t: [0.0; 3] }.linear(self.t);
        Some(Self {
            m,
            t: mt.map(|x| -x),
        })
    }

    /// How far the map can stretch a distance, at least: `m`'s largest singular value (from
    /// the eigenvalues of `mᵀm` in f64), raised by 2⁻³⁰ to cover their rounding.
    pub fn stretch(&self) -> f64 {
        let m = &self.m;
        let mtm: [[f64; 3]; 3] = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..3).map(|k| m[k][i] * m[k][j]).sum())
        });
        let (vals, _) = symmetric_eigen(mtm);
        Lanes::sqrt(vals[2].max(0.0)) * (1.0 + 1.0 / 1_073_741_824.0)
    }
}

/// The eigenvalues of a symmetric 3×3 matrix, ascending, and its eigenvectors (the columns of
/// the second, in the same order), by cyclic Jacobi rotations.
pub(crate) fn symmetric_eigen(mut a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut v = Affine64::IDENTITY.m;
    for _ in 0..50 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        // Also stops on NaN.
        if off.partial_cmp(&(diag * 1e-34)) != Some(core::cmp::Ordering::Greater) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // The rotation that zeroes a[p][q] (Numerical Recipes §11.1).
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = 1.0f64.copysign(theta) / (theta.abs() + Lanes::sqrt(theta * theta + 1.0));
            let c = 1.0 / Lanes::sqrt(t * t + 1.0);
            let s = t * c;
            for row in a.iter_mut().chain(v.iter_mut()) {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = core::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = core::array::from_fn(|k| s * rp[k] + c * rq[k]);
        }
    }
    let mut order = [0, 1, 2];
    order.sort_unstable_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    (order.map(|i| a[i][i]), v.map(|row| order.map(|i| row[i])))
}

/// The inverse of a 3×3 matrix by cofactors in f64 and `‖a‖∞·‖a⁻¹‖∞`; `None` when the
/// determinant is zero or anything is not finite.
pub(crate) fn invert3(a: &[[f64; 3]; 3]) -> Option<([[f64; 3]; 3], f64)> {
    let cof = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
    };
    let det = a[0][0] * cof(0, 0) + a[0][1] * cof(0, 1) + a[0][2] * cof(0, 2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // inv[i][j] = cofactor(j, i) / det.
    let inv: [[f64; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|j| cof(j, i) / det));
    let norm = |m: &[[f64; 3]; 3]| {
        m.iter()
            .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let cond = norm(a) * norm(&inv);
    (cond.is_finite() && inv.iter().flatten().all(|x| x.is_finite())).then_some((inv, cond))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composes_and_inverts() {
        let a = Affine64 {
            m: [[2.0, 0.0, 1.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]],
            t: [1.0, -2.0, 0.5],
        };
        let inv = a.inverse().unwrap();
        let p = [0.25, -1.5, 3.0];
        let back = a.then(&inv).apply(p);
        assert!((0..3).all(|k| (back[k] - p[k]).abs() < 1e-15));
        assert_eq!(a.apply(p), [1.0 + 0.5 + 3.0, -6.5, 12.5]);
        assert_eq!(Affine64::IDENTITY.then(&a), a);
        assert!(Affine64 {
            m: [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            t: [0.0; 3]
        }
        .inverse()
        .is_none());
        assert!((Affine64::IDENTITY.stretch() - 1.0).abs() < 1e-8);
        let d = Affine64 {
            m: [[2.0, 0.0, 0.0], [0.0, -3.0, 0.0], [0.0, 0.0, 0.5]],
            t: [9.0; 3],
        };
        assert!(d.stretch() >= 3.0 && d.stretch() < 3.0 + 1e-8);
    }

    #[test]
    fn jacobi_diagonalises() {
        let a = [[4.0, 1.0, -2.0], [1.0, 2.0, 0.5], [-2.0, 0.5, 3.0]];
        let (vals, v) = symmetric_eigen(a);
        assert!(vals[0] <= vals[1] && vals[1] <= vals[2]);
        for i in 0..3 {
            for j in 0..3 {
                let back: f64 = (0..3).map(|k| v[i][k] * vals[k] * v[j][k]).sum();
                assert!((back - a[i][j]).abs() < 1e-12, "{i} {j}: {back}");
            }
        }
    }
}
