//! The crossing rule: which triangles a ray crosses when every tie is broken by one symbolic
//! perturbation of its origin, so that a ray through a shared edge or vertex of a closed mesh
//! crosses it exactly once, and a crossing count's parity is exactly right.
//!
//! # Guarantees (the [`crate::kernels::ExactCrossing`] tier)
//! - **The answer is exact for the perturbed ray** `o' + t·d`, `o' = o + ε·x̂ + ε²·ŷ + ε³·ẑ` in the
//!   limit `ε → 0⁺`: the ray crosses the triangle's interior (never an edge, a vertex or its
//!   plane at `t_min`/`t_max`: the perturbed ray meets none of them), the triangle is not
//!   parallel to `d` nor degenerate (`D ≠ 0`), and `t_min < t < t_max` for the perturbed `t`.
//! - **Each crossing of a closed surface is counted once.** Two triangles sharing an edge with
//!   opposite orientation see the same perturbed ray on opposite sides of it, so a ray through
//!   the edge (or through a vertex, or along a face) crosses exactly the triangles the perturbed
//!   ray crosses: the parity of the count along a ray from `p` to infinity is whether `p'` (`p`
//!   perturbed the same way) is inside, for every direction, and the sum of the crossings'
//!   signs (`+1` where `d·n > 0`, leaving an outward-facing surface) is its winding number.
//! - A point on the surface is classified as `p'` is: as if moved by an infinitesimal step
//!   along `+x`, then `+y`, then `+z`.
//! - Same bits everywhere: f64 with certified error bounds, then exact integer arithmetic
//!   ([`ExactSum`]) where f64 cannot decide; no FMA.
//!
//! # Limits
//! - Hits are those of the exact tier first (the closed rule, whose hits include every
//!   perturbed crossing); the rule is applied to those only, so it costs nothing on misses.
//! - `t` is the exact tier's (the exact `t` rounded once); a perturbed crossing at an exact
//!   `t = t_min` or `t_max` is reported at that `t`.
//!
//! # The perturbation
//! With `a, b, c` the vertices relative to the origin, moving the origin by `δ` changes the edge
//! functions to `wᵢ + δ·(d × eᵢ)` (`eᵢ = v_k − v_j`, the edge opposite `vᵢ`) and `N − b·D` (whose
//! sign is that of `t − b` times that of `D`) to `N − b·D − δ·n` (`n = (v₁ − v₀) × (v₂ − v₀)`);
//! `D` does not change. With `δ = ε·x̂ + ε²·ŷ + ε³·ẑ` the sign of a quantity that is exactly zero
//! is the sign of the first nonzero component of its `δ`-coefficient; that coefficient is never
//! zero when `D ≠ 0` (`d × eᵢ = 0` and `n = 0` both make `D = 0`).

use super::exact::{ExactPlane, PlaneF64};
use crate::hit::LanesHit;
use crate::lanes::exact::ExactSum;
use crate::lanes::{LaneMask, Lanes, Scalar, V3};
use crate::prim::{Ray, RayLanes, VertexLanes, VertexTriangle};
use core::cmp::Ordering;

type P = [f32; 3];

/// One crossing under the rule: its side (`true` where `d·n > 0`, the ray leaving through a
/// face whose normal `(v₁ − v₀) × (v₂ − v₀)` points along it).
type Leaves = bool;

/// Which way a ray crosses a triangle, by its normal `n = (v₁ − v₀) × (v₂ − v₀)`
/// (counter-clockwise seen from the front).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// `d·n < 0`: through the front, into a surface whose normals face out.
    Enters,
    /// `d·n > 0`: through the back, out of it.
    Leaves,
}

impl Side {
    /// The crossing's term in a winding number: `−1` entering, `+1` leaving.
    pub fn winding(self) -> i32 {
        match self {
            Side::Enters => -1,
            Side::Leaves => 1,
        }
    }
}

/// The crossing rule for one ray and one triangle (see the module docs): `Some(side)` where the
/// perturbed ray crosses it with `t_min < t < t_max`; `None` where it does not, and for
/// non-finite inputs.
pub fn crossing(ray: &Ray, tri: &VertexTriangle) -> Option<Side> {
    let (o, d) = (ray.origin.to_array(), ray.dir.to_array());
    let leaves = crosses(o, d, [tri.v0, tri.v1, tri.v2], ray.t_min, ray.t_max)?;
    Some(if leaves { Side::Leaves } else { Side::Enters })
}

/// Does the perturbed ray `o + t·d`, `t_min < t < t_max`, cross the triangle `v`? `Some(side)`
/// when it does (see the module docs), `None` when not (and for non-finite inputs or NaN bounds).
pub(crate) fn crosses(o: P, d: P, v: [P; 3], t_min: f32, t_max: f32) -> Option<Leaves> {
    if t_min.is_nan() || t_max.is_nan() {
        return None;
    }
    match crosses_f64(o, d, v, t_min, t_max) {
        Some(answer) => answer,
        None => crosses_exact(o, d, v, t_min, t_max),
    }
}

/// The hits of the exact tier `h` (its closed rule: a superset of the crossings) that the
/// perturbed rule keeps, lane by lane.
#[inline(never)]
pub(crate) fn keep_crossings<L: Lanes>(
    ray: &RayLanes<L>,
    tri: &VertexLanes<L>,
    mut h: LanesHit<L>,
) -> LanesHit<L> {
    let point = |p: &V3<L>, i: usize| [p.x, p.y, p.z].map(|c| c.lane(i).to_f32());
    let mut bits = h.mask.bitmask();
    let mut keep = 0;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let v = [point(&tri.v0, i), point(&tri.v1, i), point(&tri.v2, i)];
        let (o, d) = (point(&ray.origin, i), point(&ray.dir, i));
        let range = (ray.t_min.lane(i).to_f32(), ray.t_max.lane(i).to_f32());
        if crosses(o, d, v, range.0, range.1).is_some() {
            keep |= 1 << i;
        }
    }
    h.mask = h.mask & L::mask_from_bits(keep);
    h
}

/// [`crosses`] in f64 with the error bounds of the exact tier's f64 stage: `None` where a sign
/// is not certified (a tie the perturbation may have to break, or too close to call).
fn crosses_f64(o: P, d: P, v: [P; 3], t_min: f32, t_max: f32) -> Option<Option<Leaves>> {
    let plane = PlaneF64::new(o, d, v)?;
    let (den, err_d) = plane.den;
    if den.abs() <= err_d || plane.w.iter().any(|&(x, e)| x.abs() <= e) {
        return None;
    }
    if plane.w.iter().any(|&(x, _)| (x > 0.0) != (den > 0.0)) {
        return Some(None);
    }
    let in_range = plane.t_cmp(f64::from(t_min))? == Ordering::Greater
        && plane.t_cmp(f64::from(t_max))? == Ordering::Less;
    Some(in_range.then_some(den > 0.0))
}

/// [`crosses`] with exact arithmetic and the perturbation's tie breaks.
fn crosses_exact(o: P, d: P, v: [P; 3], t_min: f32, t_max: f32) -> Option<Leaves> {
    let plane = ExactPlane::new(o, d, v)?;
    let den = plane.den.sign();
    if den == Ordering::Equal {
        return None;
    }
    for (i, w) in plane.w.iter().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let s = match w.sign() {
            Ordering::Equal => first_nonzero(d_cross_edge(d, v[j], v[k])),
            s => s,
        };
        if s != den {
            return None;
        }
    }
    // The tie of `N − b·D` breaks on `−δ·n`.
    let n = normal(v);
    let above = |b: f32| -> Option<Ordering> {
        if b.is_infinite() {
            return Some(if b > 0.0 {
                Ordering::Less
            } else {
                Ordering::Greater
            });
        }
        let diff = plane.num.plus(&plane.den.times(b)?.negated());
        let s = match diff.sign() {
            Ordering::Equal => first_nonzero(n).reverse(),
            s => s,
        };
        Some(if den == Ordering::Less {
            s.reverse()
        } else {
            s
        })
    };
    let in_range = above(t_min)? == Ordering::Greater && above(t_max)? == Ordering::Less;
    in_range.then_some(den == Ordering::Greater)
}

/// The sign of the first nonzero of three exact values (`Equal` when all are zero).
fn first_nonzero(c: [ExactSum; 3]) -> Ordering {
    c.iter()
        .map(ExactSum::sign)
        .find(|&s| s != Ordering::Equal)
        .unwrap_or(Ordering::Equal)
}

/// `x·y − z·w + …`: the exact sum of the products `±pᵢ·qᵢ`.
fn products<const K: usize>(terms: [(f32, f32, bool); K]) -> ExactSum {
    let mut s = ExactSum::ZERO;
    for (p, q, neg) in terms {
        // Every factor is finite here (ExactPlane::new checked).
        s.add_product(&[if neg { -p } else { p }, q]);
    }
    s
}

/// `d × (v_k − v_j)`, exactly.
fn d_cross_edge(d: P, vj: P, vk: P) -> [ExactSum; 3] {
    // (d × e)ₓ = d_y·e_z − d_z·e_y with e = v_k − v_j expanded, and its rotations.
    core::array::from_fn(|x| {
        let (y, z) = ((x + 1) % 3, (x + 2) % 3);
        products([
            (d[y], vk[z], false),
            (d[y], vj[z], true),
            (d[z], vk[y], true),
            (d[z], vj[y], false),
        ])
    })
}

/// `n = (v₁ − v₀) × (v₂ − v₀)`, exactly.
fn normal(v: [P; 3]) -> [ExactSum; 3] {
    // nₓ = (v₁ − v₀)_y·(v₂ − v₀)_z − (v₁ − v₀)_z·(v₂ − v₀)_y, expanded (the v₀·v₀ terms cancel).
    let [v0, v1, v2] = v;
    core::array::from_fn(|x| {
        let (y, z) = ((x + 1) % 3, (x + 2) % 3);
        products([
            (v1[y], v2[z], false),
            (v1[y], v0[z], true),
            (v0[y], v2[z], true),
            (v1[z], v2[y], true),
            (v1[z], v0[y], false),
            (v0[z], v2[y], false),
        ])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [P; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn an_interior_crossing_and_its_side() {
        let down = [0.0, 0.0, -1.0];
        assert_eq!(
            crosses([0.25, 0.25, 1.0], down, TRI, 0.0, f32::INFINITY),
            Some(false)
        );
        assert_eq!(
            crosses([0.25, 0.25, -1.0], [0.0, 0.0, 1.0], TRI, 0.0, f32::INFINITY),
            Some(true)
        );
        assert_eq!(crosses([0.25, 0.25, 1.0], down, TRI, 0.0, 0.5), None);
        assert_eq!(crosses([0.25, 0.25, 1.0], down, TRI, f32::NAN, 2.0), None);
    }

    #[test]
    fn a_shared_edge_or_vertex_is_crossed_once() {
        let down = [0.0, 0.0, -1.0];
        // The unit square as a fan of four triangles around its centre (counter-clockwise).
        let c = [0.5, 0.5, 0.0];
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let fan: [[P; 3]; 4] = core::array::from_fn(|i| [c, corners[i], corners[(i + 1) % 4]]);
        let count = |x: f32, y: f32| {
            fan.iter()
                .filter(|&&v| crosses([x, y, 1.0], down, v, 0.0, f32::INFINITY).is_some())
                .count()
        };
        // Through the centre (a vertex of four), along the spokes (shared edges), inside.
        for (x, y) in [
            (0.5, 0.5),
            (0.25, 0.25),
            (0.75, 0.25),
            (0.25, 0.75),
            (0.5, 0.9),
        ] {
            assert_eq!(count(x, y), 1, "({x}, {y})");
        }
        // The perturbed origin moves to +x, then +y: the outer corner (0, 0) and the edge
        // y = 0 are inside; the corners (1, 0), (1, 1), (0, 1) and the edges x = 1, y = 1
        // outside.
        for (x, y, n) in [
            (0.0, 0.0, 1),
            (0.5, 0.0, 1),
            (1.0, 0.0, 0),
            (1.0, 1.0, 0),
            (0.0, 1.0, 0),
        ] {
            assert_eq!(count(x, y), n, "({x}, {y})");
        }
        assert_eq!(count(0.0, 0.5), 1);
        assert_eq!(count(1.0, 0.5), 0);
        assert_eq!(count(0.5, 1.0), 0);
    }

    #[test]
    fn a_point_on_the_plane_is_moved_off_it() {
        // Origin in the plane z = 0 of TRI, whose n = +z: δ·n = ε³ > 0 puts the origin above,
        // so a ray going down crosses it at t = 0⁺ and one going up never does.
        let o = [0.25, 0.25, 0.0];
        assert_eq!(crosses(o, [0.0, 0.0, -1.0], TRI, 0.0, 1.0), Some(false));
        assert_eq!(crosses(o, [0.0, 0.0, 1.0], TRI, 0.0, 1.0), None);
        assert_eq!(
            normal(TRI).map(|s| s.sign()),
            [Ordering::Equal, Ordering::Equal, Ordering::Greater]
        );
    }
}
