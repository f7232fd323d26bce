//! The conservative ray-box (slab) test: one generic body, for one ray against the eight
//! children of a node (`f32x8`, the boxes in lanes) and for a packet against one box (the rays
//! in lanes).
//!
//! # Contract
//! The test never rejects a box that the ray meets within `[t_min, t_max]` — with the box grown
//! by the build slack and the ray's origin slack ([`SLACK`]) — for any finite ray, including
//! directions with zero or −0 components, subnormal components, and origins inside or on the box.
//!
//! Derivation (pbrt-v4 `Bounds3::IntersectP`; Ize 2013, "Robust BVH Ray Traversal"; Embree's
//! robust mode widens the reciprocals as here): the slab of axis `k` is crossed at
//! `t = (b − o)·(1/d)`. The ray carries `1/d` correctly rounded (no `recip` estimate), then
//! multiplied by `1 − w` for entry planes and `1 + w` for exit planes (`w = 2⁻²⁰`, rounded
//! once more); the subtraction and the product are rounded once each. Four roundings of at most
//! `2⁻²⁴` relative (`2⁻²²` where `1/d` is subnormal, `|d| > 2¹²⁶`: it keeps 21 bits) stay
//! below `w`, so a computed entry distance is `ρ·t` with `ρ ∈ (1 − 2w, 1)` and an exit distance
//! `ρ'·t` with `ρ' ∈ (1, 1 + 2w)`: at or below the exact entry, at or above the exact exit
//! wherever `t ≥ 0`, with no widening left on the test's latency chain. Where `t < 0` they
//! move the other way by at most `2w·|t|`, which matters only for distances in
//! `[t_min, 0)`: the entry distance is lowered by the ray's `pad`, `8w·max(0, −t_min)` plus
//! 2⁻¹²⁵ for results in the subnormal range (absolute error up to 2⁻¹⁵⁰ per rounding), before
//! the comparison, which so never rejects a box the exact test accepts. `o/d` is never
//! precomputed (that form cancels and has no such bound), and nothing is fused.
//!
//! Per axis, the ray enters through one face and leaves through the other, picked by the sign of
//! `1/d` (so no `min`/`max` per axis). Infinite reciprocals (zero or −0 components) give `±inf`
//! slab distances with the right sign; where `b − o` is also 0 the product is NaN, meaning the
//! ray runs inside that face's plane: that face then does not bound the ray (tested for +0 and −0
//! on both faces). A subnormal component whose reciprocal overflows is treated the same way: that
//! axis does not bound the ray. The test is then only looser, never wrong.

use octoray_core::bvh::SLACK;
use octoray_core::lanes::{LaneMask, Lanes, Scalar, MAX_LANES, V3};
use octoray_core::prim::RayLanes;
use wide::f32x8;

/// The reciprocals' relative widening, `w = 2⁻²⁰`: more than the four roundings of a slab
/// distance (module doc).
const WIDEN_INV: f32 = 1.0 / 1_048_576.0;

/// A ray (per lane) prepared for box tests: the correctly rounded reciprocal direction widened
/// for entry and exit planes, and the origin moved by its slack toward each axis' entry and exit
/// planes.
///
/// Per axis, the entry plane is the box's lower face when the direction's sign bit is clear and
/// its upper face otherwise (`−0` counts as negative: `1/−0 = −inf`), the exit plane the other
/// one. Testing entry and exit planes directly needs no `min`/`max` per axis.
#[derive(Clone, Copy, Debug)]
pub struct BoxRay<L: Lanes> {
    /// `o + δ` on axes entered through the lower face, `o − δ` on the others: the origin the
    /// entry plane is measured from (the box grown by `δ`).
    pub o_entry: V3<L>,
    /// The same for the exit plane (`o − δ` where the exit plane is the upper face).
    pub o_exit: V3<L>,
    /// `1/d` moved toward zero by `2⁻²⁰` of itself: the entry planes' reciprocal (±inf for
    /// ±0; NaN where `d` is subnormal and `1/d` overflows).
    pub inv_near: V3<L>,
    /// `1/d` moved away from zero by `2⁻²⁰` of itself: the exit planes' reciprocal.
    pub inv_far: V3<L>,
    /// What the entry distance is lowered by before the comparison: `8·2⁻²⁰·max(0, −t_min)`
    /// plus 2⁻¹²⁵ (module doc).
    pub pad: L,
    /// Axes entered through the upper face (`1/d < 0`), per lane.
    pub neg: [L::Mask; 3],
    /// `t_min` per lane.
    pub t_min: L,
    /// Lanes with a finite origin and direction and a non-zero direction: the only ones any
    /// kernel can report a hit for.
    pub valid: L::Mask,
    /// The relative origin slack the boxes were grown by ([`SLACK`], or a scene's top level's).
    pub slack: f32,
}

impl<L: Lanes> BoxRay<L> {
    /// Prepares every lane of `ray`, with the origin slack [`SLACK`].
    #[inline(always)]
    pub fn new(ray: &RayLanes<L>) -> Self {
        Self::with_slack(ray, SLACK)
    }

    /// Prepares every lane of `ray`, the origin moved by `slack` (relative, ≥ [`SLACK`]) of its
    /// largest coordinate magnitude.
    #[inline(always)]
    pub fn with_slack(ray: &RayLanes<L>, slack: f32) -> Self {
        let (o, d) = (ray.origin, ray.dir);
        let zero = L::zero();
        let m = max3(o.x.abs(), o.y.abs(), o.z.abs());
        let delta = m * L::splat(slack);
        let one = L::splat(1.0);
        let nan = L::splat(f32::NAN);
        let inv1 = |x: L| {
            let r = one / x;
            L::select(x.ne(zero) & !r.is_finite(), nan, r)
        };
        let finite = o.x.is_finite()
            & o.y.is_finite()
            & o.z.is_finite()
            & d.x.is_finite()
            & d.y.is_finite()
            & d.z.is_finite();
        let nonzero = d.x.ne(zero) | d.y.ne(zero) | d.z.ne(zero);
        let inv = V3::new(inv1(d.x), inv1(d.y), inv1(d.z));
        let scaled = |f: f32| {
            let f = L::splat(f);
            V3::new(inv.x * f, inv.y * f, inv.z * f)
        };
        let (inv_near, inv_far) = (scaled(1.0 - WIDEN_INV), scaled(1.0 + WIDEN_INV));
        // `max_or_rhs` keeps 0 where t_min is NaN (such lanes report no hit) or +inf.
        let behind = (-ray.t_min).max_or_rhs(zero);
        let pad = behind * L::splat(8.0 * WIDEN_INV) + L::splat(2.0 * f32::MIN_POSITIVE);
        let neg = [inv.x.lt(zero), inv.y.lt(zero), inv.z.lt(zero)];
        let (plus, minus) = (
            V3::new(o.x + delta, o.y + delta, o.z + delta),
            V3::new(o.x - delta, o.y - delta, o.z - delta),
        );
        let pick = |n: L::Mask, a: L, b: L| (L::select(n, b, a), L::select(n, a, b));
        let (ex, fx) = pick(neg[0], plus.x, minus.x);
        let (ey, fy) = pick(neg[1], plus.y, minus.y);
        let (ez, fz) = pick(neg[2], plus.z, minus.z);
        Self {
            o_entry: V3::new(ex, ey, ez),
            o_exit: V3::new(fx, fy, fz),
            inv_near,
            inv_far,
            pad,
            neg,
            t_min: ray.t_min,
            valid: ray.active & finite & nonzero,
            slack,
        }
    }
}

#[inline(always)]
fn max3<L: Lanes>(a: L, b: L, c: L) -> L {
    let m = L::select(a.ge(b), a, b);
    L::select(m.ge(c), m, c)
}

/// Per lane: does the ray meet the box `[lo, hi]` within `[t_min, t_max]`? Returns the mask
/// (`valid` lanes only) and the conservative entry distance (meaningful where the mask is set:
/// at or below the exact one, so a walk may drop the box once its best hit is nearer).
/// Picks each lane's entry and exit faces by its direction's signs, then [`slab_planes`].
#[inline(always)]
pub fn slab<L: Lanes>(lo: V3<L>, hi: V3<L>, r: &BoxRay<L>, t_max: L) -> (L::Mask, L) {
    let entry = V3::new(
        L::select(r.neg[0], hi.x, lo.x),
        L::select(r.neg[1], hi.y, lo.y),
        L::select(r.neg[2], hi.z, lo.z),
    );
    let exit = V3::new(
        L::select(r.neg[0], lo.x, hi.x),
        L::select(r.neg[1], lo.y, hi.y),
        L::select(r.neg[2], lo.z, hi.z),
    );
    let (m, near) = slab_planes(entry, exit, r, t_max);
    (r.valid & m, near)
}

/// The slab test on the entry and exit faces already picked per axis (what [`slab`] does per
/// lane; a single ray picks them once per node from its direction's signs): the one body of
/// every box test.
///
/// The mask is not restricted to `r.valid`: a lane that is not valid (NaN or zero direction)
/// may come out set. [`slab`] masks it; single-ray traversal checks `valid` once per ray and so
/// keeps the `and` off every node test's latency chain.
#[inline(always)]
pub fn slab_planes<L: Lanes>(entry: V3<L>, exit: V3<L>, r: &BoxRay<L>, t_max: L) -> (L::Mask, L) {
    // Per axis: t = (face − o)·(1/d). A NaN (0·inf: the ray runs in that face's plane, or a NaN
    // reciprocal) means the face does not bound the ray; `a.max_or_rhs(b)` is `b` when `a` is
    // NaN, so the reduction skips it. With `1/d = ±inf` and the origin strictly inside the slab
    // the faces give −inf and +inf: no bound either. Outside it the entry face gives +inf: a miss.
    // The reciprocals carry the widening (module doc); only the pad is left on the entry side.
    let near = ((entry.x - r.o_entry.x) * r.inv_near.x).max_or_rhs(
        ((entry.y - r.o_entry.y) * r.inv_near.y)
            .max_or_rhs(((entry.z - r.o_entry.z) * r.inv_near.z).max_or_rhs(r.t_min)),
    );
    let far = ((exit.x - r.o_exit.x) * r.inv_far.x).min_or_rhs(
        ((exit.y - r.o_exit.y) * r.inv_far.y)
            .min_or_rhs(((exit.z - r.o_exit.z) * r.inv_far.z).min_or_rhs(t_max)),
    );
    let near = near - r.pad;
    (near.le(far), near)
}

/// A coherent packet's frustum: one `f32x8` test of all eight children of a node that rejects a
/// child only when every valid lane of the packet would reject it in [`slab`]. It lets a packet
/// skip the per-child, per-lane tests of children no ray enters (most of them, for coherent
/// primary rays).
///
/// Built from f32 lanes whose direction signs agree on every axis (one entry face per axis for
/// the whole packet). Per axis, a lane's entry distance is `fl(fl(b − o)·r)` with `r` its
/// widened entry reciprocal (likewise its exit distance); correctly rounded operations are
/// monotone, so the distance at the packet's extreme origin, multiplied by the smallest and the
/// largest of the lanes' reciprocals, bounds every lane's rounded distance: no widening of its
/// own. The entry side is lowered by the largest of the lanes' pads. Axes where some lane has
/// a non-finite reciprocal do not bound the frustum; a NaN anywhere only loosens the test (it
/// is skipped by the reductions, and a NaN comparison keeps the child).
#[derive(Clone, Copy, Debug)]
pub struct Frustum {
    /// Per axis: whether the lanes' directions are negative (the entry face is then the upper
    /// one, rows 3–5, and the exit face the lower one, rows 0–2).
    neg: [bool; 3],
    /// Per axis: whether it bounds the frustum (every valid lane's reciprocals are finite).
    bounded: [bool; 3],
    /// Per axis: the origin (with its slack) that gives the smallest entry distance, the one
    /// that gives the largest exit distance, then the smallest and largest entry reciprocals and
    /// the smallest and largest exit reciprocals.
    axis: [[f32; 6]; 3],
    /// The smallest `t_min` (−inf where some lane's is NaN).
    t_min: f32,
    /// The largest pad.
    pad: f32,
}

impl Frustum {
    /// The frustum of the valid lanes of `r`, or `None` when their direction signs differ on
    /// some axis, no lane is valid, or the lanes are not f32.
    pub fn new<L: Lanes>(r: &BoxRay<L>) -> Option<Self> {
        if <L::Scalar as Scalar>::UNIT_ROUNDOFF != f64::from(f32::EPSILON) / 2.0 {
            return None;
        }
        let valid = r.valid.bitmask();
        if valid == 0 {
            return None;
        }
        let axes = |v: V3<L>| [v.x, v.y, v.z];
        let (inv_near, inv_far) = (axes(r.inv_near), axes(r.inv_far));
        let (o_entry, o_exit) = (axes(r.o_entry), axes(r.o_exit));
        let neg = r.neg.map(|m| m.bitmask() & valid);
        if neg.iter().any(|&n| n != 0 && n != valid) {
            return None;
        }
        let neg = neg.map(|n| n != 0);
        // (b − o)·(1/d) decreases with o when 1/d > 0: the smallest entry distance comes from
        // the largest entry origin, the largest exit distance from the smallest exit origin;
        // the other way round when 1/d < 0. So per axis one origin's smallest lane is needed
        // and the other's largest.
        let o_least = |k: usize| if neg[k] { o_entry[k] } else { o_exit[k] };
        let o_most = |k: usize| if neg[k] { o_exit[k] } else { o_entry[k] };
        // Horizontal reductions over the valid lanes, sixteen at once. No lane used is NaN:
        // t_min's NaN lanes become −inf, reciprocals are used only where all are finite, and
        // valid origins are finite.
        let t_min = L::select(!r.t_min.ge(r.t_min), L::splat(f32::NEG_INFINITY), r.t_min);
        let (least, most) = extremes8(
            [
                t_min,
                r.pad,
                o_least(0),
                o_least(1),
                o_least(2),
                o_most(0),
                o_most(1),
                o_most(2),
            ],
            r.valid,
        );
        let (inv_least, inv_most) = extremes8(
            [
                inv_near[0],
                inv_near[1],
                inv_near[2],
                inv_far[0],
                inv_far[1],
                inv_far[2],
                t_min,
                t_min,
            ],
            r.valid,
        );
        let mut f = Self {
            neg,
            bounded: [false; 3],
            axis: [[0.0; 6]; 3],
            t_min: least[0],
            pad: most[1],
        };
        let finite = |x: L| L::select(r.valid, x, L::zero()).is_finite().all();
        for k in 0..3 {
            f.bounded[k] = finite(inv_near[k]) && finite(inv_far[k]);
            if !f.bounded[k] {
                continue;
            }
            let (o_near, o_far) = if neg[k] {
                (least[2 + k], most[5 + k])
            } else {
                (most[5 + k], least[2 + k])
            };
            f.axis[k] = [
                o_near,
                o_far,
                inv_least[k],
                inv_most[k],
                inv_least[3 + k],
                inv_most[3 + k],
            ];
        }
        Some(f)
    }

    /// The lanes' direction octant: bit `k` set where axis `k` is negative (the index of
    /// [`octoray_core::bvh::Bvh8Node::order`]'s octants).
    pub fn octant(&self) -> u32 {
        self.neg[0] as u32 | (self.neg[1] as u32) << 1 | (self.neg[2] as u32) << 2
    }

    /// Bit `s` set unless child `s` of the node (its rows: lower x, y, z, upper x, y, z) is missed
    /// by every valid lane within `[t_min, t_max]`; `t_max` at least every live lane's (NaN: no
    /// bound).
    #[inline(always)]
    pub fn children(&self, rows: &[[f32; 8]; 9], t_max: f32) -> u32 {
        let (mut near, mut far) = (f32x8::splat(self.t_min), f32x8::splat(t_max));
        self.axis_range(0, rows, &mut near, &mut far);
        self.axis_range(1, rows, &mut near, &mut far);
        self.axis_range(2, rows, &mut near, &mut far);
        (!(near - f32x8::splat(self.pad)).gt(far)).bitmask()
    }

    /// Narrows the children's `[near, far]` by axis `k`'s slabs (when the axis bounds the
    /// frustum).
    #[inline(always)]
    fn axis_range(&self, k: usize, rows: &[[f32; 8]; 9], near: &mut f32x8, far: &mut f32x8) {
        if !self.bounded[k] {
            return;
        }
        let [o_near, o_far, n_lo, n_hi, f_lo, f_hi] = self.axis[k];
        let s = f32x8::splat;
        let (entry, exit) = if self.neg[k] {
            (rows[3 + k], rows[k])
        } else {
            (rows[k], rows[3 + k])
        };
        let a = f32x8::from(entry) - s(o_near);
        let b = f32x8::from(exit) - s(o_far);
        // Products are monotone in each factor: the extremes are at the reciprocal's ends.
        *near = (a * s(n_lo)).min_or_rhs(a * s(n_hi)).max_or_rhs(*near);
        *far = (b * s(f_lo)).max_or_rhs(b * s(f_hi)).min_or_rhs(*far);
    }
}

/// The smallest and the largest of the lanes set in `m` (not empty) of each of eight vectors
/// (`x[j]`'s in lane `j` of each result), as f32; lanes must not be NaN (a NaN lane gives its
/// vector's results no meaning, the others' stay exact).
///
/// A transpose brings lane `i` of every vector into one `f32x8`, and a tree of elementwise
/// `min`/`max` reduces those: sixteen reductions for the shuffles of one. Unset lanes repeat
/// the first set lane, and packets narrower than 8 are padded with repeats of their lanes: no
/// extreme changes.
#[inline(always)]
pub(super) fn extremes8<L: Lanes>(x: [L; 8], m: L::Mask) -> ([f32; 8], [f32; 8]) {
    let x = if m.all() {
        x
    } else {
        let first = m.bitmask().trailing_zeros() as usize % L::LANES;
        x.map(|q| L::select(m, q, L::splat_scalar(q.lane(first))))
    };
    // Lanes `8h..8h + 8` of the vectors, transposed: vector `i` holds lane `8h + i` of each.
    let half = |h: usize| {
        f32x8::transpose(x.map(|q| {
            f32x8::new(core::array::from_fn(|i| {
                q.lane((8 * h + i) % L::LANES.min(8 * h + 8)).to_f32()
            }))
        }))
    };
    let first_half = half(0);
    let (mut lo, mut hi) = (first_half, first_half);
    if L::LANES > 8 {
        let b = half(1);
        for i in 0..8 {
            (lo[i], hi[i]) = (lo[i].fast_min(b[i]), hi[i].fast_max(b[i]));
        }
    }
    for n in [4, 2, 1] {
        for i in 0..n {
            lo[i] = lo[i].fast_min(lo[i + n]);
            hi[i] = hi[i].fast_max(hi[i + n]);
        }
    }
    (lo[0].to_array(), hi[0].to_array())
}

/// The smallest (`max = false`) or largest lane of `x` among the lanes set in `m`, as f32 (+inf
/// or −inf when `m` is empty). Lanes must not be NaN (a NaN lane may or may not be skipped).
///
/// A tree of one-instruction compares: a packet waits for these reductions' latency, not for
/// their count, and a tree is shorter than a serial fold.
#[inline(always)]
pub(crate) fn extreme_lane<L: Lanes>(x: L, m: L::Mask, max: bool) -> f32 {
    let id = if max {
        f32::NEG_INFINITY
    } else {
        f32::INFINITY
    };
    let x = L::select(m, x, L::splat(id));
    let mut a = [id; MAX_LANES];
    for (i, a) in a.iter_mut().enumerate().take(L::LANES) {
        *a = x.lane(i).to_f32();
    }
    let mut n = L::LANES.next_power_of_two();
    while n > 1 {
        n /= 2;
        for i in 0..n {
            let (p, q) = (a[i], a[i + n]);
            a[i] = if (q > p) == max { q } else { p };
        }
    }
    a[0]
}
