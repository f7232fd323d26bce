//! The point of a sphere nearest to a query point, in f64.
//!
//! # Guarantees
//! - The point `c + r·(p − c)/|p − c|` and the squared distance `(|p − c| − r)²` carry a few
//!   units of 2⁻⁵² relative; a point at the centre answers the sphere's point along `+x`. A
//!   sphere that is never hit (`radius_sq` not a finite normal `> 0`) is at infinite distance.
//! - `u = v = 0`.
//! - Placed by an affine map (an instance: `NearestPoint::nearest_point_mapped`) a sphere is an
//!   ellipsoid; its nearest point solves the trust-region equation below in f64 and lies within
//!   a few units of 2⁻⁴⁰ of the exact one, relative to the ellipsoid's extent; a map that keeps
//!   it a sphere (rotation, uniform scale) answers as the sphere at its image.
//!
//! # The ellipsoid
//! Its points are `C + L·u` with `|u| = 1` (`C` the centre's image, `L` the map's linear part
//! times the radius). With `q = p − C`, the nearest minimises `|L·u − q|²` on the unit sphere: in
//! the eigenbasis `V` of `LᵀL = V·diag(s)·Vᵀ` (`s₀` the smallest), with `b = Vᵀ·Lᵀ·q` and
//! `y = Vᵀ·u`, the minimiser has `yᵢ = bᵢ/(sᵢ − λ)` for the `λ ≤ s₀` at which `Σ yᵢ² = 1`
//! (found by bisection on `[s₀ − |b|, s₀]`, where the sum rises from at most 1 to infinity);
//! when `b₀ = 0` and the sum stays below 1 up to `s₀` (a point on the shortest axis, deep
//! inside), `λ = s₀` and `y₀` takes what is left of the unit length.

use super::super::Nearest;
use crate::lanes::Lanes;
use crate::prim::{symmetric_eigen, Affine64};

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
    on_sphere(c, Lanes::sqrt(f64::from(r2)), p)
}

/// The point of the sphere at `c` with radius `r > 0` nearest to `p`.
fn on_sphere(c: [f64; 3], r: f64, p: [f64; 3]) -> Nearest {
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

/// The point of the sphere at `c` with squared radius `r2`, placed by `map` (object → world),
/// nearest to the world point `p` (see the module docs).
pub(crate) fn nearest_on_mapped_sphere(
    c: [f64; 3],
    r2: f32,
    map: &Affine64,
    p: [f64; 3],
) -> Nearest {
    let centre = map.apply(c);
    let far = Nearest {
        point: centre,
        u: 0.0,
        v: 0.0,
        dist2: f64::INFINITY,
    };
    if !(r2.is_normal() && r2 > 0.0 && centre.iter().all(|x| x.is_finite())) {
        return far;
    }
    let r = Lanes::sqrt(f64::from(r2));
    let l = map.m.map(|row| row.map(|x| x * r));
    // LᵀL, and its eigenbasis.
    let s: [[f64; 3]; 3] =
        core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| l[k][i] * l[k][j]).sum()));
    let (vals, vecs) = symmetric_eigen(s);
    let (lo, hi) = (vals[0], vals[2]);
    if !(lo > 0.0 && hi.is_finite()) {
        return far;
    }
    if hi - lo <= hi * 1e-13 {
        // A sphere still: its image's radius is √s.
        return on_sphere(centre, Lanes::sqrt((lo + hi) / 2.0), p);
    }
    let q: [f64; 3] = core::array::from_fn(|k| p[k] - centre[k]);
    let ltq: [f64; 3] = core::array::from_fn(|i| (0..3).map(|k| l[k][i] * q[k]).sum());
    let b: [f64; 3] = core::array::from_fn(|i| (0..3).map(|k| vecs[k][i] * ltq[k]).sum());
    let y = unit_minimiser(vals, b);
    let u: [f64; 3] = core::array::from_fn(|k| (0..3).map(|i| vecs[k][i] * y[i]).sum());
    let point: [f64; 3] =
        core::array::from_fn(|k| centre[k] + (0..3).map(|j| l[k][j] * u[j]).sum::<f64>());
    let d: [f64; 3] = core::array::from_fn(|k| point[k] - p[k]);
    Nearest {
        point,
        u: 0.0,
        v: 0.0,
        dist2: d[0] * d[0] + d[1] * d[1] + d[2] * d[2],
    }
}

/// The unit `y` minimising `Σ sᵢyᵢ² − 2bᵢyᵢ` (`s` ascending, positive): the module docs' `λ`
/// by bisection, then `y`.
fn unit_minimiser(s: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let sum = |lambda: f64| -> f64 {
        (0..3)
            .map(|i| {
                let y = b[i] / (s[i] - lambda);
                y * y
            })
            .sum()
    };
    let norm_b = Lanes::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    let (mut lo, mut hi) = (s[0] - norm_b - s[0] * 1e-12, s[0]);
    for _ in 0..200 {
        let mid = lo + (hi - lo) / 2.0;
        if mid <= lo || mid >= hi {
            break;
        }
        if sum(mid) > 1.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // The larger axes from λ; the shortest takes what is left of the unit length (exactly its
    // share at the root, and all of the rest in the case b₀ = 0 with λ = s₀).
    let lambda = lo;
    let mut y = [0.0; 3];
    for i in 1..3 {
        y[i] = b[i] / (s[i] - lambda);
    }
    let rest = 1.0 - y[1] * y[1] - y[2] * y[2];
    y[0] = Lanes::sqrt(rest.max(0.0)).copysign(if b[0] == 0.0 { 1.0 } else { b[0] });
    let n = Lanes::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    y.map(|x| x / n)
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

    /// A small deterministic generator (xorshift) in [-1, 1).
    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// The distance from `p` to the ellipsoid `{map(c + r·u)}` sampled on a fine grid of
    /// directions `u`: an upper bound on the exact distance that approaches it.
    fn sampled(c: [f64; 3], r: f64, map: &Affine64, p: [f64; 3]) -> f64 {
        let mut best = f64::INFINITY;
        let n = 400;
        for i in 0..=n {
            let th = core::f64::consts::PI * i as f64 / n as f64;
            for j in 0..2 * n {
                let ph = core::f64::consts::PI * j as f64 / n as f64;
                let u = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
                let x = map.apply(core::array::from_fn(|k| c[k] + r * u[k]));
                let d: f64 = (0..3).map(|k| (x[k] - p[k]).powi(2)).sum();
                best = best.min(d.sqrt());
            }
        }
        best
    }

    #[test]
    fn an_ellipsoid_s_nearest_point_is_on_it_and_no_sample_is_nearer() {
        let mut seed = 0x9E37_79B9_7F4A_7C15;
        for case in 0..40 {
            let m: [[f64; 3]; 3] =
                core::array::from_fn(|_| core::array::from_fn(|_| rng(&mut seed) * 2.0));
            let map = Affine64 {
                m,
                t: core::array::from_fn(|_| rng(&mut seed)),
            };
            let Some(inv) = map.inverse() else { continue };
            let (c, r) = ([0.5, -0.25, 1.0], 1.5);
            // Points outside, inside and (every tenth case) at the centre.
            let scale = if case % 2 == 0 { 6.0 } else { 0.5 };
            let p: [f64; 3] = if case % 10 == 0 {
                map.apply(c)
            } else {
                core::array::from_fn(|_| rng(&mut seed) * scale)
            };
            let n = nearest_on_mapped_sphere(c, (r * r) as f32, &map, p);
            // On the ellipsoid: its preimage is at distance r from c.
            let o = inv.apply(n.point);
            let len = (0..3).map(|k| (o[k] - c[k]).powi(2)).sum::<f64>().sqrt();
            assert!(
                (len - r).abs() < 1e-9,
                "case {case}: off the surface by {}",
                len - r
            );
            // As near as any sample (the grid's spacing bounds how much nearer the exact one is).
            let d = n.dist2.sqrt();
            let s = sampled(c, r, &map, p);
            let extent = map.stretch() * r;
            assert!(d <= s + 1e-9 * extent, "case {case}: {d} > sampled {s}");
            assert!(
                s - d < 0.02 * extent,
                "case {case}: {d} far below sampled {s}"
            );
        }
    }

    #[test]
    fn a_similarity_keeps_the_sphere() {
        let map = Affine64 {
            m: [[0.0, -2.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]],
            t: [1.0, 1.0, 1.0],
        };
        let n = nearest_on_mapped_sphere([0.0; 3], 1.0, &map, [1.0, 1.0, 6.0]);
        assert_eq!((n.point, n.dist2), ([1.0, 1.0, 3.0], 9.0));
        assert_eq!(
            nearest_on_mapped_sphere([0.0; 3], -1.0, &map, [0.0; 3]).dist2,
            f64::INFINITY
        );
    }
}
