//! Does a sphere meet an axis-aligned box: as it is (a ball), or placed by an affine map (an
//! ellipsoid), in f64 from the f32 inputs.
//!
//! # Guarantees
//! Exact but for a sphere and box that touch or miss by less than a few units of 2⁻⁵⁰ of their
//! coordinates (relative), where either answer may come.
//!
//! # The ellipsoid
//! The image of the ball `|x − c| ≤ r` under `M` meets the box `B` exactly when the ball meets
//! `M⁻¹(B)`, a parallelepiped `o + V·s`, `s ∈ [0, 1]³`: when `min |o + V·s − c|² ≤ r²`. That is
//! a least-squares problem on a box; its minimum lies on one of the 27 faces of the cube of `s`
//! (each `sᵢ` at 0, at 1 or free), at the unconstrained minimum on that face's affine hull. Each
//! face's minimum is solved from the normal equations, clamped into the cube (so every candidate
//! is a point of the parallelepiped) and measured; the least is the distance.

type P = [f64; 3];

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Does the ball of centre `c` and squared radius `r2` meet `[lo, hi]`? A box with a NaN corner
/// or `lo > hi` on an axis, and a ball that is never hit (not finite, `r2` not normal and
/// positive), meet nothing.
pub fn ball_meets_box(c: [f32; 3], r2: f32, lo: P, hi: P) -> bool {
    if !valid(c, r2, lo, hi) {
        return false;
    }
    let d2: f64 = (0..3)
        .map(|k| {
            let c = f64::from(c[k]);
            let d = (lo[k] - c).max(c - hi[k]).max(0.0);
            d * d
        })
        .sum();
    d2 <= f64::from(r2)
}

/// Does the ball of centre `c` and squared radius `r2`, in object space, placed in the world by
/// the affine map whose inverse is `to_object`, meet the world box `[lo, hi]`? As
/// [`ball_meets_box`] for bad input; a `to_object` that is not finite meets nothing.
pub fn mapped_ball_meets_box(
    c: [f32; 3],
    r2: f32,
    to_object: &crate::prim::Affine64,
    lo: P,
    hi: P,
) -> bool {
    if !valid(c, r2, lo, hi) {
        return false;
    }
    let o = to_object.apply(lo);
    let edge = |i: usize| {
        let mut e = [0.0; 3];
        e[i] = hi[i] - lo[i];
        to_object.linear(e)
    };
    let v = [edge(0), edge(1), edge(2)];
    let c = c.map(f64::from);
    if !(o.iter().chain(v.iter().flatten()).all(|x| x.is_finite())) {
        return false;
    }
    least_distance2(o, v, c) <= f64::from(r2)
}

/// A ball that can be hit and a box that is not empty.
fn valid(c: [f32; 3], r2: f32, lo: P, hi: P) -> bool {
    r2.is_normal() && r2 > 0.0 && c.iter().all(|x| x.is_finite()) && (0..3).all(|k| lo[k] <= hi[k])
}

/// `min |o + V·s − c|²` over `s ∈ [0, 1]³` (columns `v[i]`), by the 27 faces.
fn least_distance2(o: P, v: [P; 3], c: P) -> f64 {
    let point = |s: P| -> P {
        core::array::from_fn(|k| o[k] + s[0] * v[0][k] + s[1] * v[1][k] + s[2] * v[2][k])
    };
    let mut best = f64::INFINITY;
    // Face `f`: digit `i` (base 3) of `f` is sᵢ's state: 0, 1 or free (2).
    for f in 0..27u32 {
        let state = [f % 3, f / 3 % 3, f / 9];
        let mut s: P = state.map(|x| if x == 1 { 1.0 } else { 0.0 });
        let mut free = [0usize; 3];
        let mut n = 0;
        for (i, &st) in state.iter().enumerate() {
            if st == 2 {
                free[n] = i;
                n += 1;
            }
        }
        if n > 0 {
            // The normal equations on the free variables (the fixed ones at their values):
            // `Σ_b (v_a·v_b)·s_b = v_a·(c − base)`, padded to 3×3 with the identity.
            let base = point(s);
            let r: P = core::array::from_fn(|k| c[k] - base[k]);
            let m: [[f64; 3]; 3] = core::array::from_fn(|a| {
                core::array::from_fn(|b| match (a < n, b < n) {
                    (true, true) => dot(v[free[a]], v[free[b]]),
                    _ => f64::from(u8::from(a == b)),
                })
            });
            let rhs: P = core::array::from_fn(|a| if a < n { dot(v[free[a]], r) } else { 0.0 });
            let Some(sol) = solve3(m, rhs) else {
                continue;
            };
            for a in 0..n {
                s[free[a]] = sol[a].clamp(0.0, 1.0);
            }
        }
        let p = point(s);
        let d: P = core::array::from_fn(|k| p[k] - c[k]);
        best = best.min(dot(d, d));
    }
    best
}

/// `m·x = b` by Cramer's rule, `None` when `m` is singular or the answer not finite.
fn solve3(m: [[f64; 3]; 3], b: P) -> Option<P> {
    let det3 = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det3(m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let x: P = core::array::from_fn(|j| {
        let mut mj = m;
        for (row, bi) in mj.iter_mut().zip(b) {
            row[j] = bi;
        }
        det3(mj) / d
    });
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prim::Affine64;

    #[test]
    fn a_stretched_ball_meets_what_its_ellipsoid_meets() {
        // The unit ball stretched 3× along x (object → world): world → object divides x by 3.
        let to_object = Affine64 {
            m: [[1.0 / 3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            t: [0.0; 3],
        };
        let meets = |lo: P, hi: P| mapped_ball_meets_box([0.0; 3], 1.0, &to_object, lo, hi);
        assert!(meets([2.5, -0.1, -0.1], [2.6, 0.1, 0.1]));
        assert!(!meets([3.1, -0.1, -0.1], [3.2, 0.1, 0.1]));
        assert!(!meets([0.0, 1.1, 0.0], [0.1, 1.2, 0.1]));
        // Near the ellipse x²/9 + y² = 1 at 45° in (x, y): (2.1, 0.71) is inside, (2.2, 0.75)
        // outside.
        assert!(meets([2.1, 0.71, 0.0], [2.1, 0.71, 0.0]));
        assert!(!meets([2.2, 0.75, 0.0], [2.3, 0.8, 0.0]));
        // A box holding the whole ellipsoid, and one cutting through its middle.
        assert!(meets([-5.0; 3], [5.0; 3]));
        assert!(meets([-0.1, -5.0, -5.0], [0.1, 5.0, 5.0]));
        // The identity agrees with the ball test.
        for (lo, hi) in [
            ([0.5, 0.5, 0.5], [1.0, 1.0, 1.0]),
            ([0.6, 0.6, 0.6], [1.0, 1.0, 1.0]),
        ] {
            assert_eq!(
                mapped_ball_meets_box([0.0; 3], 1.0, &Affine64::IDENTITY, lo, hi),
                ball_meets_box([0.0; 3], 1.0, lo, hi)
            );
        }
    }
}
