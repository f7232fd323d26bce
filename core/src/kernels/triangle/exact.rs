//! The exact tier's decisions, and the exact predicates behind them (also what the watertight
//! tier falls back to when its filter cannot decide whether `t ≥ t_min`).
//!
//! # Guarantees (exact tier, [`crate::kernels::Exact`])
//! - **Hit/miss is the exact answer** for the given f32 inputs, for every finite input: the line
//!   passes inside the triangle, edges and vertices included (every `wᵢ ≥ 0` or every `wᵢ ≤ 0`,
//!   below), is not parallel to its plane (`D ≠ 0`; a degenerate triangle has `D = 0`), and the
//!   exact `t = N/D` lies in `[t_min, t_max]` (closed; an exact `t` beyond ±`f32::MAX` is a miss,
//!   as for every tier). With culling, front faces are those with `D < 0`. Watertight by
//!   construction: a shared edge's `w` is the exact negation for its two triangles.
//! - **`t` is the plane distance `((v0 − o)·n)/(d·n)` evaluated in f64 from the f32 inputs and
//!   rounded once** (on lanes decided past the filter, the exact `t` rounded): the vertex and
//!   origin differences are exact in f64, `n = (v1 − v0) × (v2 − v0)` and both dot products
//!   carry a few units of 2⁻⁵³, so `|t − t_exact| ≤ ε·|t_exact| + 16·2⁻⁵³·max(|t|,
//!   reach)/(|cos θ|·sin α)`: within one ulp of the exact `t` unless `|cos θ|·sin α·|t|/max(|t|,
//!   reach)` falls below ~3e-8 (a ray within ~1e-8 rad of the plane, a needle thinner than
//!   that, a hit 1e7 times nearer than the vertices); where `d·n` evaluates to zero the
//!   watertight tier's `t` stands, with its bound. Always inside `[t_min, t_max]`.
//! - **Barycentrics:** on filter lanes the watertight tier's (signs certified, so in `[0, 1]`);
//!   past the filter, the exact ones to f64 precision, rounded.
//! - **Same bits** across `f32` and `f32x4/x8/x16` and across builds (proptested, digest): the
//!   fallback is scalar f64 and integer arithmetic with no FMA.
//!
//! # Limits
//! - Closest-hit queries give the exact tier the caller's `t_max`
//!   ([`crate::kernels::Kernel::EXACT_T_MAX`]) and order its hits by the rounded `t`: two hits
//!   whose exact `t` differ by less than their rounding may come back in either order, and the
//!   tie rule picks the lower index.
//! - Since `t ≤ t_max` is decided on the exact `t` and the reported `t` is rounded, a hit
//!   reported at `t` can be a miss for a `t_max` at or just above `t` (the exact `t` lies within
//!   the `t` bound above of the reported one: an ulp, save the cases named there). A ray that
//!   must reach a reported hit point takes `t_max` beyond `t` by that bound, or the watertight
//!   tier, which keeps such hits.
//! - **Cost** grows with the share of tests the filter cannot decide: the filter's certificates
//!   on every test, the f64 plane distance on every lane that hits, and exact arithmetic on rays
//!   exactly through vertices and along edges' lines.
//!
//! # How
//! The watertight body is the filter. Its edge functions carry a certified bound (`22u·Rx·Ry`,
//! derived in [`crate::kernels::triangle::watertight`]); a lane is decided there when all three
//! clear it with one sign (inside) or two clear it with opposite signs (miss), and its range when
//! the division-free certificates decide both bounds. Every other lane, and every lane whose
//! products leave `[2⁻¹⁰⁰, 2¹⁰⁰]`, goes to `resolve`: f64 with certified bounds, then, for the
//! exact ties f64 cannot decide (a ray exactly through a vertex or along an edge's line),
//! [`ExactSum`].
//!
//! # Measured
//! - Against the big-integer oracle with the margin at zero (`tests/suite/exact.rs`: random,
//!   aimed at vertices and edges, grazing 1e-3…1e-9 rad, aspect 1e2…1e5, translated and scaled
//!   1e-20…1e30, `t_min`/`t_max` at and one f32 step around the hit; `tests/suite/fuzz.rs` on
//!   every hostile case); in the trade report's margin column 0 (report: `exact, 8 lanes`, in
//!   margin) where the watertight tier has 1898 (report: `watertight, 8 lanes`, in margin); zero
//!   escapes in every crack suite.
//! - `t`: 0 whole ulps at p50, p99 and max on every case family of the accuracy report (random,
//!   grazing to 1e-7 rad, translated to 1e6), where the watertight tier's has p99 up to 51 230
//!   ulps on grazing rays; hit points within 0.5 f32 steps of the exact plane at p99 on thin
//!   triangles and short rays at long trim, where the watertight tier's lie up to 41 steps off.
//! - Tests decided past the filter: random rays 0.05 %, rays aimed at f32 points of vertices and
//!   edges 100 %, grazing 1e-3 rad 2.6 %, 1e-5 rad 63 %, thin triangles of aspect 1e3 79 % (the
//!   report's table by ray family).
//! - Cost: 8.873 (report: `exact, 8 lanes`, ns/test) against the watertight tier's
//!   2.992 (report: `watertight, 8 lanes`, ns/test) on the trade workload, where half the tests
//!   hit; through the Sponza tree, where few tests hit, +11 % instructions per single ray, +16 %
//!   per packet ray and +10 % per diffuse bounce (cachegrind, x86-64-v3). Per ray family (one ray
//!   and one triangle per call): 1.0× the watertight tier on random and translated rays, 1.2× at
//!   1e-3 rad, ~10× at 1e-5 rad and on rays aimed exactly at vertices and edges, ~20× on thin
//!   triangles.

//! # The predicates
//! With `a, b, c` the vertices relative to the origin, the line `o + t·d` meets the plane at
//! `t = N/D`, `N = det[a, b, c]`, `D = d·((b − a) × (c − a))`, and passes edge `jk` on the side
//! given by the signed volume `wᵢ = det[d, v_j − o, v_k − o]` (`D = w₀ + w₁ + w₂`; the
//! barycentrics are `wᵢ/D`). Each is a polynomial of degree three in the inputs; expanding every
//! difference gives at most 24 products of three f32 values (terms that take the origin from two
//! rows cancel and are skipped), which [`ExactSum`] adds without rounding. `t ≥ b` is the sign of
//! `N − b·D` times that of `D` (products of four).

use crate::lanes::exact::ExactSum;
use core::cmp::Ordering;

type P = [f32; 3];

/// Adds `s·det[r₀ − q₀, r₁ − q₁, r₂ − q₂]` (rows as differences of f32 vectors, every `qᵢ` the
/// same vector or zero) term by term.
fn add_det(acc: &mut ExactSum, rows: [(P, P); 3], negate: bool) -> bool {
    // det = Σ over permutations σ of sgn(σ)·Π rowᵢ[σᵢ]; each entry x − y splits in two. Picking
    // the subtracted vector from two rows gives determinants with two equal rows, which cancel
    // over the permutations: those terms are skipped (a third fewer products).
    debug_assert!(rows
        .iter()
        .all(|r| r.1 == [0.0; 3] || r.1 == rows[1].1 || r.1 == rows[0].1));
    const PERMS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], false),
        ([1, 2, 0], false),
        ([2, 0, 1], false),
        ([0, 2, 1], true),
        ([2, 1, 0], true),
        ([1, 0, 2], true),
    ];
    let mut ok = true;
    for (sigma, odd) in PERMS {
        for pick in [0u32, 1, 2, 4] {
            let mut f = [0.0f32; 3];
            let mut neg = odd ^ negate;
            for (i, fi) in f.iter_mut().enumerate() {
                let (x, y) = rows[i];
                if (pick >> i) & 1 == 0 {
                    *fi = x[sigma[i]];
                } else {
                    *fi = y[sigma[i]];
                    neg = !neg;
                }
            }
            if f.contains(&0.0) {
                continue;
            }
            if neg {
                f[0] = -f[0];
            }
            ok &= acc.add_product(&f);
        }
    }
    ok
}

/// The exact plane quantities of one ray and one triangle (see the module docs).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ExactPlane {
    /// `wᵢ = det[d, v_j − o, v_k − o]` for the edges opposite `v0`, `v1`, `v2`.
    pub w: [ExactSum; 3],
    /// `N = det[v0 − o, v1 − o, v2 − o]`.
    pub num: ExactSum,
    /// `D = w₀ + w₁ + w₂`.
    pub den: ExactSum,
}

impl ExactPlane {
    /// The exact quantities, or `None` when an input is NaN or infinite.
    pub fn new(o: P, d: P, v: [P; 3]) -> Option<Self> {
        let finite = |p: &P| p.iter().all(|x| x.is_finite());
        if !(finite(&o) && finite(&d) && v.iter().all(finite)) {
            return None;
        }
        let zero = [0.0; 3];
        let mut w = [ExactSum::ZERO; 3];
        let mut ok = true;
        for (i, wi) in w.iter_mut().enumerate() {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            ok &= add_det(wi, [(d, zero), (v[j], o), (v[k], o)], false);
        }
        let mut num = ExactSum::ZERO;
        ok &= add_det(&mut num, [(v[0], o), (v[1], o), (v[2], o)], false);
        let den = w[0].plus(&w[1]).plus(&w[2]);
        ok.then_some(Self { w, num, den })
    }

    /// The line passes inside the triangle, edges and vertices included, and is not parallel to
    /// its plane (nor is the triangle degenerate): every `wᵢ ≥ 0` or every `wᵢ ≤ 0`, `D ≠ 0`.
    pub fn inside(&self) -> bool {
        let s = self.w.map(|w| w.sign());
        let nonneg = s.iter().all(|&x| x != Ordering::Less);
        let nonpos = s.iter().all(|&x| x != Ordering::Greater);
        (nonneg || nonpos) && self.den.sign() != Ordering::Equal
    }

    /// The line is parallel to the plane, or the triangle degenerate (`D = 0`): no `t`.
    pub fn parallel(&self) -> bool {
        self.den.sign() == Ordering::Equal
    }

    /// The normal `(v1 − v0) × (v2 − v0)` points against the ray (`D < 0`): a front face.
    pub fn front(&self) -> bool {
        self.den.sign() == Ordering::Less
    }

    /// The exact `t` compared with `bound` (`D ≠ 0`): `t.cmp(bound)`, `None` for a NaN bound.
    pub fn t_cmp(&self, bound: f32) -> Option<Ordering> {
        if bound.is_nan() {
            return None;
        }
        if bound.is_infinite() {
            return Some(if bound > 0.0 {
                Ordering::Less
            } else {
                Ordering::Greater
            });
        }
        // t − bound = (N − bound·D)/D.
        let diff = self.num.plus(&self.den.times(bound)?.negated());
        let s = diff.sign();
        Some(if self.den.sign() == Ordering::Less {
            s.reverse()
        } else {
            s
        })
    }

    /// The exact `t` compared with an `f64` bound: exact when the bound is an f32 value (as a
    /// caller's `t_min`/`t_max` always is); a bound strictly between two f32 values (an f64
    /// lane's `t_max` tightened to an earlier hit) is compared exactly with both neighbours and,
    /// only when `t` lies between them too, through the f64 value of `t` (relative error below
    /// 2⁻⁵¹).
    pub fn t_cmp_f64(&self, bound: f64) -> Option<Ordering> {
        let b = bound as f32;
        if b as f64 == bound || bound.is_nan() {
            return self.t_cmp(b);
        }
        let (lo, hi) = if (b as f64) < bound {
            (b, next_up(b))
        } else {
            (next_down(b), b)
        };
        match (self.t_cmp(lo)?, self.t_cmp(hi)?) {
            (Ordering::Less | Ordering::Equal, _) => Some(Ordering::Less),
            (_, Ordering::Greater | Ordering::Equal) => Some(Ordering::Greater),
            _ => self.t().partial_cmp(&bound),
        }
    }

    /// `t = N/D` to f64 (relative error below 2⁻⁵¹; NaN when `D = 0`).
    pub fn t(&self) -> f64 {
        self.num.ratio(&self.den)
    }

    /// The barycentrics of `v1` and `v2`, `w₁/D` and `w₂/D`, to f64 (relative error below
    /// 2⁻⁵¹).
    pub fn barycentrics(&self) -> (f64, f64) {
        (self.w[1].ratio(&self.den), self.w[2].ratio(&self.den))
    }
}

/// What [`resolve`] answers for a hit: `t` and the barycentrics of `v1`, `v2`, to f64 (relative
/// error below 2⁻³² for `t`, so it rounds to f32 within one ulp of the exact value).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Resolved {
    /// Ray parameter.
    pub t: f64,
    /// Barycentric weight of `v1`.
    pub b1: f64,
    /// Barycentric weight of `v2`.
    pub b2: f64,
}

/// One lane's question for [`resolve`]: the ray, the triangle, the range, and what is still to
/// be decided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LaneQuery {
    /// Ray origin.
    pub o: P,
    /// Ray direction.
    pub d: P,
    /// Triangle vertices.
    pub v: [P; 3],
    /// Range start.
    pub t_min: f64,
    /// Range end.
    pub t_max: f64,
    /// Decide the edges (else they were decided already).
    pub edges: bool,
    /// With `edges`: back faces (`D > 0`) are misses.
    pub cull: bool,
    /// Decide `t ≤ t_max` (else it was decided already).
    pub check_max: bool,
    /// Return `t` to within 2⁻³² of itself (else only the decisions are needed, and
    /// [`Resolved`]'s values are f64 estimates).
    pub needs_t: bool,
}

/// Decides one ray against one triangle exactly: with `edges`, that the line passes inside (and,
/// with `cull`, meets a front face); always that it is not parallel to the plane and that
/// `t ≥ t_min`; with `check_max`, that `t ≤ t_max`. `None` is a miss (also for a NaN bound or a
/// non-finite input). First in f64 with certified error bounds (a few dozen flops; decides all but
/// exact ties), then, where f64 cannot decide, with [`ExactPlane`].
pub(crate) fn resolve(q: &LaneQuery) -> Option<Resolved> {
    if q.t_min.is_nan() || q.t_max.is_nan() {
        return None;
    }
    if let Some(answer) = resolve_f64(q) {
        return answer;
    }
    let plane = ExactPlane::new(q.o, q.d, q.v)?;
    if plane.parallel() || q.edges && !(plane.inside() && (!q.cull || plane.front())) {
        return None;
    }
    let (lo, hi) = finite_range(q);
    let ge_min = matches!(
        plane.t_cmp_f64(lo),
        Some(Ordering::Greater | Ordering::Equal)
    );
    let le_max = matches!(plane.t_cmp_f64(hi), Some(Ordering::Less | Ordering::Equal));
    if !(ge_min && le_max) {
        return None;
    }
    let (b1, b2) = plane.barycentrics();
    Some(Resolved {
        t: plane.t(),
        b1,
        b2,
    })
}

/// The range [`resolve`] decides `t` against: `[t_min, t_max]` (`t_max` only with `check_max`)
/// within `±f32::MAX`, since an exact `t` beyond f32's range is a miss even where it would round
/// to `±f32::MAX`.
fn finite_range(q: &LaneQuery) -> (f64, f64) {
    let max = f64::from(f32::MAX);
    let hi = if q.check_max { q.t_max.min(max) } else { max };
    (q.t_min.max(-max), hi)
}

/// `det[r0, r1, r2] = r0·(r1 × r2)` in f64 and its permanent `|r0|·(|r1| × |r2|)` (the sum of
/// the absolute values of its six terms).
fn det_f64(r0: [f64; 3], r1: [f64; 3], r2: [f64; 3]) -> (f64, f64) {
    let c = cross3(r1, r2);
    let p = [
        (r1[1] * r2[2]).abs() + (r1[2] * r2[1]).abs(),
        (r1[2] * r2[0]).abs() + (r1[0] * r2[2]).abs(),
        (r1[0] * r2[1]).abs() + (r1[1] * r2[0]).abs(),
    ];
    (
        dot3(r0, c),
        r0[0].abs() * p[0] + r0[1].abs() * p[1] + r0[2].abs() * p[2],
    )
}

/// `a − b` in f64, component by component.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(super) fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a × b` in f64.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(super) fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a · b` in f64, summed left to right.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(super) fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The plane quantities of [`ExactPlane`] in f64, each with a certified bound on its error. f32
/// inputs keep every product of three far inside f64's range (1e-135 … 1e115), so the only
/// errors are roundings: each difference `v − o` once, each determinant term at most seven more
/// times, so `|ŵ − w| ≤ γ₈·perm` (16u·perm is used, u = 2⁻⁵³, which also covers the rounding of
/// the permanent); `D̂ = Σŵᵢ` adds `3u·Σ|ŵᵢ|`; `N̂ − b·D̂` adds `3u·(|N̂| + |b·D̂|)`.
pub(super) struct PlaneF64 {
    /// `wᵢ` and its error bound.
    pub w: [(f64, f64); 3],
    /// `N` and its error bound.
    pub num: (f64, f64),
    /// `D` and its error bound.
    pub den: (f64, f64),
}

impl PlaneF64 {
    /// The quantities, or `None` when one is not finite (a non-finite input).
    pub fn new(o: P, d: P, v: [P; 3]) -> Option<Self> {
        let u = f64::EPSILON / 2.0;
        let wide = |p: P| p.map(f64::from);
        let rel = |p: P| sub3(wide(p), wide(o));
        let (a, dd) = ([rel(v[0]), rel(v[1]), rel(v[2])], wide(d));
        let mut w = [(0.0, 0.0); 3];
        for (i, wi) in w.iter_mut().enumerate() {
            let (val, perm) = det_f64(dd, a[(i + 1) % 3], a[(i + 2) % 3]);
            *wi = (val, 16.0 * u * perm);
        }
        let (num, perm_n) = det_f64(a[0], a[1], a[2]);
        let err_n = 16.0 * u * perm_n;
        let den = w[0].0 + w[1].0 + w[2].0;
        let err_d =
            w[0].1 + w[1].1 + w[2].1 + 3.0 * u * (w[0].0.abs() + w[1].0.abs() + w[2].0.abs());
        let finite = num.is_finite() && den.is_finite() && err_n.is_finite() && err_d.is_finite();
        finite.then_some(Self {
            w,
            num: (num, err_n),
            den: (den, err_d),
        })
    }

    /// `t` compared with `b` (`sign(N − b·D)·sign(D)`), where certified; `D` must be certified
    /// nonzero.
    pub fn t_cmp(&self, b: f64) -> Option<Ordering> {
        if b.is_infinite() {
            return Some(if b > 0.0 {
                Ordering::Less
            } else {
                Ordering::Greater
            });
        }
        let u = f64::EPSILON / 2.0;
        let ((num, err_n), (den, err_d)) = (self.num, self.den);
        let bd = b * den;
        let x = num - bd;
        let err = err_n + b.abs() * err_d + 3.0 * u * (num.abs() + bd.abs());
        if x.abs().partial_cmp(&err) != Some(Ordering::Greater) {
            return None;
        }
        Some(if (x > 0.0) == (den > 0.0) {
            Ordering::Greater
        } else {
            Ordering::Less
        })
    }
}

/// [`resolve`]'s f64 stage ([`PlaneF64`]): `Some(answer)` where every decision is certified,
/// `None` where one is not.
fn resolve_f64(q: &LaneQuery) -> Option<Option<Resolved>> {
    let LaneQuery {
        o,
        d,
        v,
        edges,
        cull,
        ..
    } = *q;
    let plane = PlaneF64::new(o, d, v)?;
    let (w, (num, err_n), (den, err_d)) = (plane.w, plane.num, plane.den);
    if den.abs() <= err_d {
        return None;
    }
    if edges {
        let pos = w.iter().any(|&(x, e)| x > e);
        let neg = w.iter().any(|&(x, e)| x < -e);
        if pos && neg {
            return Some(None);
        }
        if w.iter().any(|&(x, e)| x.abs() <= e) {
            return None;
        }
        if cull && den > 0.0 {
            return Some(None);
        }
    }
    let cmp = |b: f64| plane.t_cmp(b);
    let (lo, hi) = finite_range(q);
    if cmp(lo)? == Ordering::Less || cmp(hi)? == Ordering::Greater {
        return Some(None);
    }
    // t to 2⁻³² relative, else the exact stage (t near 0, or N and D barely certified).
    let t_rel = 1.01 * (err_n / num.abs() + err_d / den.abs()) + f64::EPSILON;
    if q.needs_t
        && !matches!(
            t_rel.partial_cmp(&(1.0 / 4_294_967_296.0)),
            Some(Ordering::Less | Ordering::Equal)
        )
    {
        return None;
    }
    Some(Some(Resolved {
        t: num / den,
        b1: w[1].0 / den,
        b2: w[2].0 / den,
    }))
}

fn next_up(x: f32) -> f32 {
    match x {
        _ if x.is_nan() || x == f32::INFINITY => x,
        _ if x == 0.0 => f32::from_bits(1),
        _ if x > 0.0 => f32::from_bits(x.to_bits() + 1),
        _ => f32::from_bits(x.to_bits() - 1),
    }
}

fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_textbook_hit_and_its_exact_quantities() {
        // Ray down −z from (0.25, 0.25, 1) onto the unit right triangle in z = 0.
        let p = ExactPlane::new(
            [0.25, 0.25, 1.0],
            [0.0, 0.0, -1.0],
            [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        )
        .unwrap();
        assert!(p.inside());
        assert!(p.front());
        assert_eq!(p.t(), 1.0);
        assert_eq!(p.barycentrics(), (0.25, 0.25));
        assert_eq!(p.t_cmp(1.0), Some(Ordering::Equal));
        assert_eq!(p.t_cmp(1.0 - f32::EPSILON / 2.0), Some(Ordering::Greater));
        assert_eq!(p.t_cmp(f32::INFINITY), Some(Ordering::Less));
        assert_eq!(p.t_cmp(f32::NAN), None);
        assert_eq!(p.t_cmp_f64(1.0 + 1e-12), Some(Ordering::Less));
        assert_eq!(p.t_cmp_f64(1.0 - 1e-12), Some(Ordering::Greater));
        // Through the edge v1-v2 exactly: w0 = 0, still inside.
        let p = ExactPlane::new(
            [0.5, 0.5, 1.0],
            [0.0, 0.0, -1.0],
            [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        )
        .unwrap();
        assert_eq!(p.w[0].sign(), Ordering::Equal);
        assert!(p.inside());
        // Parallel to the plane: D = 0, never inside.
        let p = ExactPlane::new(
            [0.25, 0.25, 0.0],
            [1.0, 0.0, 0.0],
            [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        )
        .unwrap();
        assert!(!p.inside());
        assert!(ExactPlane::new([f32::NAN; 3], [1.0; 3], [[0.0; 3]; 3]).is_none());
    }
}
