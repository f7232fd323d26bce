//! The exact oracle: every finite f32 is m·2^e with an integer m, so after moving all inputs of a
//! case onto one power-of-two grid, the plane normal, d·n, t and the barycentrics are ratios of
//! big integers, computed without any rounding. t errors are measured exactly too, by counting
//! the f32 values between a kernel's t and the exact t (no rounding in the comparison).

use crate::ordered;
use glam::Vec3;
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};
use octoray::prim::Ray;
use std::cmp::Ordering;

/// An f32 as (mantissa, exponent) with x = m·2^e exactly (None for NaN/Inf).
fn decompose(x: f32) -> Option<(i64, i32)> {
    if !x.is_finite() {
        return None;
    }
    if x == 0.0 {
        return Some((0, 0));
    }
    let bits = x.to_bits();
    let sign = if bits >> 31 == 1 { -1 } else { 1 };
    let exp = ((bits >> 23) & 0xff) as i32;
    let frac = (bits & 0x7f_ffff) as i64;
    let (m, e) = if exp == 0 {
        (frac, -149)
    } else {
        (frac | 0x80_0000, exp - 150)
    };
    Some((sign * m, e))
}

/// Inputs on a common grid: x = X·2^E with integer X.
struct Grid {
    e: i32,
}

impl Grid {
    /// The finest grid on which every value is an integer (`scale2` values, such as r², must be
    /// integers at 2^(2E)).
    fn new(values: &[f32], scale2: &[f32]) -> Option<Self> {
        let mut e = i32::MAX;
        for &x in values {
            let (m, ex) = decompose(x)?;
            if m != 0 {
                e = e.min(ex);
            }
        }
        for &x in scale2 {
            let (m, ex) = decompose(x)?;
            if m != 0 {
                e = e.min(ex.div_euclid(2));
            }
        }
        Some(Self {
            e: if e == i32::MAX { 0 } else { e },
        })
    }
    fn int(&self, x: f32, power: i32) -> BigInt {
        let (m, ex) = decompose(x).expect("finite");
        BigInt::from(m) << ((ex - power * self.e) as usize)
    }
    /// An integer of this grid raised to `power` (a product of `power` values) as a real, to
    /// f64 precision.
    fn real(&self, x: &BigInt, power: i32) -> f64 {
        let shift = (x.bits() as i64 - 60).max(0);
        let top = (x >> shift as usize).to_f64().unwrap_or(f64::NAN);
        libm::scalbn(
            top,
            (shift + i64::from(power * self.e)).clamp(-4000, 4000) as i32,
        )
    }
    fn v(&self, v: Vec3) -> [BigInt; 3] {
        [self.int(v.x, 1), self.int(v.y, 1), self.int(v.z, 1)]
    }
}

fn sub(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}
fn dot(a: &[BigInt; 3], b: &[BigInt; 3]) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}
fn cross(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

/// Compares the f32 `x` with the exact ratio num/den (den ≠ 0).
fn cmp_f32_ratio(x: f32, num: &BigInt, den: &BigInt) -> Ordering {
    let (m, e) = decompose(x).expect("finite");
    // x ? num/den  ⇔  m·2^e·den ? num (flip when den < 0).
    let (mut lhs, mut rhs) = (BigInt::from(m) * den, num.clone());
    if e >= 0 {
        lhs <<= e as usize;
    } else {
        rhs <<= (-e) as usize;
    }
    let o = lhs.cmp(&rhs);
    if den.is_negative() {
        o.reverse()
    } else {
        o
    }
}

fn ratio_f64(num: &BigInt, den: &BigInt) -> f64 {
    // Each to ~60 leading bits with its own power of two, so ratios of very different sizes keep
    // their precision (a shared shift would round the smaller one away).
    let top = |x: &BigInt| {
        let shift = x.bits() as i64 - 60;
        if shift > 0 {
            ((x >> shift as usize).to_f64().unwrap_or(f64::NAN), shift)
        } else {
            (x.to_f64().unwrap_or(f64::NAN), 0)
        }
    };
    let ((n, en), (d, ed)) = (top(num), top(den));
    if d == 0.0 {
        return f64::NAN;
    }
    libm::scalbn(n / d, (en - ed).clamp(-4000, 4000) as i32)
}

/// The inverse of [`ordered`] (−0 comes back as +0).
fn from_ordered(k: i64) -> f32 {
    if k < 0 {
        f32::from_bits(((-k) as u32) | 0x8000_0000)
    } else {
        f32::from_bits(k as u32)
    }
}

/// Whole f32 steps between `x` and an exact value described by `side(y)` = the order of `y`
/// relative to that value: 0 when no f32 lies strictly between them (x is the exact value or one
/// of its two neighbours). Exponential then binary search, exact comparisons only.
pub fn ulps_between(x: f32, side: impl Fn(f32) -> Ordering) -> u64 {
    let k0 = ordered(x);
    let dir: i64 = match side(x) {
        Ordering::Equal => return 0,
        Ordering::Less => 1,
        Ordering::Greater => -1,
    };
    let wrong_side = |k: i64| {
        let y = from_ordered(k);
        !y.is_finite()
            || side(y)
                == if dir > 0 {
                    Ordering::Less
                } else {
                    Ordering::Greater
                }
    };
    // Find the number of steps n ≥ 1 such that k0 + dir·n is at or past the exact value.
    let mut hi = 1i64;
    while wrong_side(k0 + dir * hi) {
        hi *= 2;
        if hi > (1 << 32) {
            return u64::MAX;
        }
    }
    let mut lo = hi / 2; // lo: still before the value (or 0)
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if wrong_side(k0 + dir * mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // hi steps reach or pass the value; the floats strictly between x and the value: hi − 1.
    (hi - 1) as u64
}

/// The exact answer for one ray and one triangle.
#[derive(Clone, Debug)]
pub struct TriangleTruth {
    /// The ray is parallel to the plane (or in it), the triangle degenerate, or an input not
    /// finite: a miss for every tier by contract.
    pub degenerate: bool,
    /// Exact hit: inside (edges included) and t ∈ [t_min, t_max].
    pub hit: bool,
    /// Barycentrics (b0, b1, b2) of the line's plane point, to f64 precision.
    pub bary: [f64; 3],
    /// t to f64 precision.
    pub t: f64,
    /// The signed volumes `wᵢ = d·((v_j − o) × (v_k − o))` themselves (not over their sum), to
    /// f64 precision: what the watertight tiers' 2D edge functions are, times `d[kz]`.
    pub volumes: [f64; 3],
    num: BigInt,
    den: BigInt,
}

impl TriangleTruth {
    /// Smallest |bᵢ|: the barycentric distance of the exact hit point from the nearest edge line.
    pub fn edge_distance(&self) -> f64 {
        self.bary.iter().fold(f64::INFINITY, |m, b| m.min(b.abs()))
    }
    /// Whole f32 steps between `t` and the exact t.
    pub fn t_ulps(&self, t: f32) -> u64 {
        ulps_between(t, |y| cmp_f32_ratio(y, &self.num, &self.den))
    }
    /// What a kernel must report: an exact hit whose t is a finite f32 value (hits beyond
    /// ±f32::MAX are misses by every tier's contract).
    pub fn hit_finite(&self) -> bool {
        self.hit
            && !self.degenerate
            && self.t_cmp(f32::MAX) != Ordering::Greater
            && self.t_cmp(-f32::MAX) != Ordering::Less
    }
    /// The exact t compared with an f32 (for range checks).
    pub fn t_cmp(&self, x: f32) -> Ordering {
        cmp_f32_ratio(x, &self.num, &self.den).reverse()
    }
}

/// The exact ray-triangle answer for the triangle with vertices `v` (edges inclusive, closed t
/// range): what the watertight tier reads.
pub fn triangle(ray: &Ray, v: [Vec3; 3]) -> TriangleTruth {
    triangle_impl(ray, v, false)
}

/// The exact answer for the triangle a [`octoray::prim::PackedTriangle`] describes: `v0`, `v0 + e1`,
/// `v0 + e2` with the f32-rounded edges `e1 = v1 − v0`, `e2 = v2 − v0` (sums exact): what the
/// Möller-Trumbore tiers read.
pub fn triangle_packed(ray: &Ray, v: [Vec3; 3]) -> TriangleTruth {
    triangle_impl(ray, [v[0], v[1] - v[0], v[2] - v[0]], true)
}

fn triangle_impl(ray: &Ray, v: [Vec3; 3], packed: bool) -> TriangleTruth {
    let bad = TriangleTruth {
        degenerate: true,
        hit: false,
        bary: [f64::NAN; 3],
        t: f64::NAN,
        volumes: [f64::NAN; 3],
        num: BigInt::zero(),
        den: BigInt::from(1),
    };
    let vals: Vec<f32> = [ray.origin, ray.dir, v[0], v[1], v[2]]
        .iter()
        .flat_map(|x| x.to_array())
        .collect();
    let Some(g) = Grid::new(&vals, &[]) else {
        return bad;
    };
    if ray.t_min.is_nan() || ray.t_max.is_nan() {
        return bad;
    }
    let (o, d) = (g.v(ray.origin), g.v(ray.dir));
    let (a, b, c) = if packed {
        let a = g.v(v[0]);
        let (e1, e2) = (g.v(v[1]), g.v(v[2]));
        let b = [&a[0] + &e1[0], &a[1] + &e1[1], &a[2] + &e1[2]];
        let c = [&a[0] + &e2[0], &a[1] + &e2[1], &a[2] + &e2[2]];
        (a, b, c)
    } else {
        (g.v(v[0]), g.v(v[1]), g.v(v[2]))
    };
    let n = cross(&sub(&b, &a), &sub(&c, &a));
    let den = dot(&d, &n);
    if den.is_zero() {
        return bad;
    }
    // t = ((v0 − o)·n)/(d·n); the grid scale cancels.
    let num = dot(&sub(&a, &o), &n);
    // Barycentric i ∝ d·((v_j − o) × (v_k − o)): the signed volume the line sweeps past edge jk.
    let (ao, bo, co) = (sub(&a, &o), sub(&b, &o), sub(&c, &o));
    let w = [
        dot(&d, &cross(&bo, &co)),
        dot(&d, &cross(&co, &ao)),
        dot(&d, &cross(&ao, &bo)),
    ];
    let sum = &w[0] + &w[1] + &w[2];
    let inside = w.iter().all(|x| !x.is_negative()) || w.iter().all(|x| !x.is_positive());
    let t_ok = |bound: f32, want: Ordering| {
        bound.is_infinite() || {
            let o = cmp_f32_ratio(bound, &num, &den);
            o == want || o == Ordering::Equal
        }
    };
    let in_range = t_ok(ray.t_min, Ordering::Less)
        && t_ok(ray.t_max, Ordering::Greater)
        && !(ray.t_min == f32::INFINITY || ray.t_max == f32::NEG_INFINITY);
    TriangleTruth {
        degenerate: false,
        hit: inside && in_range,
        bary: [
            ratio_f64(&w[0], &sum),
            ratio_f64(&w[1], &sum),
            ratio_f64(&w[2], &sum),
        ],
        t: ratio_f64(&num, &den),
        volumes: w.each_ref().map(|x| g.real(x, 3)),
        num,
        den,
    }
}

/// The exact answer for one ray and one sphere given as centre and r² (the packed form).
#[derive(Clone, Debug)]
pub struct SphereTruth {
    /// Invalid input (non-finite, zero direction, r² not > 0): a miss by contract.
    pub degenerate: bool,
    /// The line meets the sphere (discriminant ≥ 0), exact.
    pub line_hits: bool,
    /// Δ/4 relative to a·r²: the discriminant's distance from a tangent, for margins.
    pub rel_disc: f64,
    a: BigInt,
    h: BigInt,
    c: BigInt,
    /// Roots to f64 precision (NaN when none).
    pub roots: [f64; 2],
}

impl SphereTruth {
    /// q(t) = a t² + 2h t + c at an f32 t, exactly, as a sign.
    fn q_sign(&self, t: f32) -> Ordering {
        let (m, e) = decompose(t).expect("finite");
        // t = m·2^e: scale by 2^(−2e) when e < 0: a m² + 2h m 2^−e + c 2^−2e.
        let m = BigInt::from(m);
        let val = if e >= 0 {
            let tt = m << e as usize;
            &self.a * &tt * &tt + BigInt::from(2) * &self.h * &tt + &self.c
        } else {
            let s = (-e) as usize;
            &self.a * &m * &m + ((BigInt::from(2) * &self.h * &m) << s) + (&self.c << (2 * s))
        };
        val.cmp(&BigInt::zero())
    }

    /// The origin is inside (c < 0, exact): the far root is the hit.
    pub fn inside(&self) -> bool {
        self.c.is_negative()
    }

    /// Whole f32 steps between `t` and the exact root a kernel should report (the far root when
    /// the origin is inside, else the near root). Meaningful away from tangency (a double root
    /// has no sign change to bracket).
    pub fn t_ulps(&self, t: f32) -> u64 {
        let near = !self.inside();
        ulps_between(t, |y| {
            let s = self.q_sign(y);
            if s == Ordering::Equal {
                return Ordering::Equal;
            }
            // q > 0 before the near root and after the far root; < 0 between.
            match (near, s) {
                (true, Ordering::Greater) => Ordering::Less,
                (true, _) => Ordering::Greater,
                (false, Ordering::Less) => Ordering::Less,
                (false, _) => Ordering::Greater,
            }
        })
    }
}

/// The exact ray-sphere answer for centre `c` and squared radius `r2` (as packed).
pub fn sphere(ray: &Ray, center: Vec3, r2: f32) -> SphereTruth {
    let bad = SphereTruth {
        degenerate: true,
        line_hits: false,
        rel_disc: f64::NAN,
        a: BigInt::zero(),
        h: BigInt::zero(),
        c: BigInt::zero(),
        roots: [f64::NAN; 2],
    };
    if r2.is_nan() || r2 <= 0.0 || r2.is_infinite() {
        return bad;
    }
    let vals: Vec<f32> = [ray.origin, ray.dir, center]
        .iter()
        .flat_map(|x| x.to_array())
        .collect();
    let Some(g) = Grid::new(&vals, &[r2]) else {
        return bad;
    };
    let (o, d, c) = (g.v(ray.origin), g.v(ray.dir), g.v(center));
    let f = sub(&o, &c);
    let a = dot(&d, &d);
    if a.is_zero() {
        return bad;
    }
    let h = dot(&f, &d);
    let cc = dot(&f, &f) - g.int(r2, 2);
    let disc = &h * &h - &a * &cc;
    let rel_disc = ratio_f64(&disc, &(&a * g.int(r2, 2)));
    // Roots to f64 precision (only used to tell the near root from the far one): with
    // h' = h/a, Δ' = Δ/a², c' = c/a the roots are −h' ∓ √Δ', formed stably.
    let roots = if disc.is_negative() {
        [f64::NAN; 2]
    } else {
        let (hr, dr, cr) = (
            ratio_f64(&h, &a),
            ratio_f64(&disc, &(&a * &a)),
            ratio_f64(&cc, &a),
        );
        let q = -(hr + if hr < 0.0 { -dr.sqrt() } else { dr.sqrt() });
        let (r0, r1) = (cr / q, q);
        [r0.min(r1), r0.max(r1)]
    };
    SphereTruth {
        degenerate: false,
        line_hits: !disc.is_negative(),
        rel_disc,
        a,
        h,
        c: cc,
        roots,
    }
}

/// The exact answer of a box test: does the segment `origin + t·dir`, `t ∈ [t_min, t_max]`, meet
/// the closed box `[lo, hi]`? `None` for non-finite inputs (an infinite `t_max` is no bound).
///
/// Per axis the ray is inside the slab for `t` between `(lo − o)/d` and `(hi − o)/d` (all of
/// `t` when `d = 0` and `lo ≤ o ≤ hi`, none when `o` is outside); the segment meets the box when
/// the largest lower end is at most the smallest upper end. The ends are ratios of integers on
/// one grid, compared by cross-multiplication.
pub fn box_meets(ray: &Ray, lo: Vec3, hi: Vec3) -> Option<bool> {
    let vals: Vec<f32> = [ray.origin, ray.dir, lo, hi]
        .iter()
        .flat_map(|v| v.to_array())
        .collect();
    if !ray.t_min.is_finite() || ray.t_max.is_nan() {
        return None;
    }
    let g = Grid::new(&vals, &[])?;
    let (o, d, lo, hi) = (g.v(ray.origin), g.v(ray.dir), g.v(lo), g.v(hi));
    // Interval ends as (num, den) with den > 0.
    let mut lower: Vec<(BigInt, BigInt)> = Vec::new();
    let mut upper: Vec<(BigInt, BigInt)> = Vec::new();
    for k in 0..3 {
        if d[k].is_zero() {
            if o[k] < lo[k] || o[k] > hi[k] {
                return Some(false);
            }
            continue;
        }
        let (mut a, mut b, mut den) = (&lo[k] - &o[k], &hi[k] - &o[k], d[k].clone());
        if den.is_negative() {
            (a, b, den) = (-b, -a, -den);
        }
        lower.push((a, den.clone()));
        upper.push((b, den));
    }
    let le = |x: &(BigInt, BigInt), y: &(BigInt, BigInt)| &x.0 * &y.1 <= &y.0 * &x.1;
    // t_min against every upper end, t_max against every lower end, then the ends pairwise.
    for u in &upper {
        if cmp_f32_ratio(ray.t_min, &u.0, &u.1) == Ordering::Greater {
            return Some(false);
        }
    }
    if ray.t_max.is_finite() {
        if ray.t_max < ray.t_min {
            return Some(false);
        }
        for l in &lower {
            if cmp_f32_ratio(ray.t_max, &l.0, &l.1) == Ordering::Less {
                return Some(false);
            }
        }
    } else if ray.t_max < 0.0 {
        return Some(false);
    }
    Some(lower.iter().all(|l| upper.iter().all(|u| le(l, u))))
}
