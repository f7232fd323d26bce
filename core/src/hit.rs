//! What a kernel answers: the per-lane hit record and the range checks every kernel ends with.
//! The leaf of the kernel layer: the algorithms (`moller_trumbore`, `watertight`, …) import it,
//! and [`crate::kernels`] (the tiers) sits above them.

use crate::lanes::Lanes;
#[cfg(any(feature = "triangle", feature = "sphere"))]
use crate::lanes::{LaneMask, V3};
use crate::prim::RayLanes;

/// A hit: the ray parameter, the barycentrics of `v1` and `v2` (zero for spheres), the index of
/// the primitive in its geometry's slice (zero for single-primitive tests), and which geometry
/// and instance of a scene it belongs to (both zero outside a scene: one slice, placed once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit, finite and inside `[t_min, t_max]`.
    pub t: f32,
    /// Barycentric weight of `v1` (triangles).
    pub u: f32,
    /// Barycentric weight of `v2` (triangles).
    pub v: f32,
    /// Index of the primitive hit.
    pub prim: u32,
    /// The scene's geometry the primitive belongs to (0 outside a scene).
    pub geom: u32,
    /// The scene's instance the ray met it through (0 outside a scene).
    pub inst: u32,
}

/// A hit a kernel reported, shown to a [`HitFilter`] before it counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Index of the primitive in the slice its tree was built from.
    pub prim: u32,
    /// Its geometry in a scene, as [`Hit::geom`].
    pub geom: u32,
    /// The instance, as [`Hit::inst`].
    pub inst: u32,
    /// Ray parameter, rounded to f32 as [`Hit::t`] is.
    pub t: f32,
    /// Barycentric weight of `v1`, as [`Hit::u`].
    pub u: f32,
    /// Barycentric weight of `v2`, as [`Hit::v`].
    pub v: f32,
    /// Which ray: its index in the caller's slice, its lane in a packet, 0 for a single ray.
    pub ray: u32,
}

impl Candidate {
    /// The candidate a filter sees for `hit` of ray `ray` (the same fields, and which ray).
    #[inline(always)]
    pub fn from_hit(hit: &Hit, ray: u32) -> Self {
        Self {
            prim: hit.prim,
            geom: hit.geom,
            inst: hit.inst,
            t: hit.t,
            u: hit.u,
            v: hit.v,
            ray,
        }
    }
}

/// Caller code that accepts or rejects candidate hits (alpha testing, decals, shadow catchers):
/// a closure `FnMut(&Candidate) -> bool`, or [`AcceptAll`] (the walks without a filter, at no
/// cost: its checks are compiled out).
///
/// The walks ask the filter about a candidate only when it would change the answer (nearer than
/// the best so far, or, for occlusion, the first hit), in no fixed order, possibly more than
/// once. A filter that answers as a function of the candidate alone gives the answer of brute
/// force over the accepted hits, bit for bit, under the usual tie rule.
pub trait HitFilter {
    /// True when the filter accepts every hit (the walks then skip it entirely).
    const ACCEPTS_ALL: bool = false;
    /// Does the hit count?
    fn accept(&mut self, hit: &Candidate) -> bool;
}

/// The filter that accepts every hit: what the walks without `_with` use.
#[derive(Clone, Copy, Debug, Default)]
pub struct AcceptAll;

impl HitFilter for AcceptAll {
    const ACCEPTS_ALL: bool = true;
    #[inline(always)]
    fn accept(&mut self, _: &Candidate) -> bool {
        true
    }
}

impl<F: FnMut(&Candidate) -> bool> HitFilter for F {
    #[inline(always)]
    fn accept(&mut self, hit: &Candidate) -> bool {
        self(hit)
    }
}

/// Per-lane result of one ray-primitive test: `mask` marks the lanes that hit; the fields are
/// meaningful only there.
///
/// The barycentrics are returned as numerators over a common denominator (`u/scale`,
/// `v/scale`), so a closest-hit query divides once, for the winning hit, instead of once per
/// test; [`LanesHit::barycentrics`] divides. Spheres report `u = v = 0`, `scale = 1`.
#[derive(Clone, Copy, Debug)]
pub struct LanesHit<L: Lanes> {
    /// Lanes that hit.
    pub mask: L::Mask,
    /// Ray parameter.
    pub t: L,
    /// Numerator of the barycentric weight of `v1`.
    pub u: L,
    /// Numerator of the barycentric weight of `v2`.
    pub v: L,
    /// Common denominator of `u` and `v`.
    pub scale: L,
}

impl<L: Lanes> LanesHit<L> {
    /// No lane hits.
    #[inline(always)]
    pub fn miss(mask: L::Mask) -> Self {
        let zero = L::zero();
        Self {
            mask,
            t: zero,
            u: zero,
            v: zero,
            scale: L::splat(1.0),
        }
    }

    /// The barycentric weights of `v1` and `v2`: `(u/scale, v/scale)`, one correctly rounded
    /// division each, with −0 made +0.
    #[inline(always)]
    pub fn barycentrics(&self) -> (L, L) {
        barycentrics(self.u, self.v, self.scale)
    }
}

/// `(u/scale + 0, v/scale + 0)`: the barycentrics every query reports (one correctly rounded
/// division each; `+ 0` makes −0 into +0, the one canonical zero, and changes nothing else).
#[inline(always)]
pub fn barycentrics<L: Lanes>(u: L, v: L, scale: L) -> (L, L) {
    (u / scale + L::zero(), v / scale + L::zero())
}

/// The sphere kernels' answer from their two roots (`near ≤ far`, or NaN): the nearer root in
/// range, else the farther (an origin inside the sphere), on the lanes of `mask`; `f` is the
/// origin relative to the centre and `r2` the squared radius.
#[cfg(feature = "sphere")]
#[inline(always)]
pub(crate) fn nearest_root_in_range<L: Lanes>(
    ray: &RayLanes<L>,
    mask: L::Mask,
    (near, far): (L, L),
    f: V3<L>,
    r2: L,
) -> LanesHit<L> {
    let near_ok = t_in_range(ray, near);
    let far_ok = t_in_range(ray, far);
    let mask = mask & (near_ok | far_ok);
    // `+ 0`: the canonical zero (−0 becomes +0).
    let t = L::select(near_ok, near, far) + L::zero();
    // Near tangency the roots' error grows as the discriminant cancels: a root before the
    // sphere's box is raised to the box's entry (`within_box`), whose faces relative to the
    // origin are −f ∓ r. Their `t ≥ t_min` is decided on the rounded root, so a ray that
    // leaves the box before `t_min` is a miss too.
    let (t, mask) = if mask.any() {
        let (c, r) = (V3::new(-f.x, -f.y, -f.z), r2.sqrt());
        let (lo, hi) = (
            V3::new(c.x - r, c.y - r, c.z - r),
            V3::new(c.x + r, c.y + r, c.z + r),
        );
        within_box::<L, true>(ray, mask, t, (lo, hi), ray.dir)
    } else {
        (t, mask)
    };
    LanesHit {
        mask,
        t,
        u: L::zero(),
        v: L::zero(),
        scale: L::splat(1.0),
    }
}

/// `t` raised, on the lanes of `mask`, to the ray's entry into the primitive's box, whose
/// faces relative to the ray's origin span `lo`..`hi` (per axis, the entry face over that
/// axis' direction; axes where that is not finite, a zero or overflowing direction, bound
/// nothing); lanes whose raised `t` passes `t_max` are dropped from the mask. With `EXIT`
/// (kernels that decide `t ≥ t_min` on their rounded `t`), lanes whose ray leaves that box
/// before `t_min` are dropped too.
///
/// The exact hit point lies in the primitive, so the exact `t` lies between the box's entry and
/// exit: raising `t` moves it toward the exact `t` (never past it by more than the entry's two
/// roundings, `2ε` of it), and a dropped lane's exact `t` is before `t_min` (but for those
/// roundings). A float tier's `t` can lie outside the box's span on grazing rays, where its
/// error grows as `1/|cos θ|`; the box test of a tree grows every box by a slack far larger
/// than those roundings, so after this no box that holds the whole primitive is entered after
/// a reported `t`, or left before `t_min` by a ray that reports a hit in it: a walk that culls
/// boxes by the best `t` and by `t_min` never culls a hit brute force reports. Raising `t` keeps
/// the kernels' `t_max` rule ([`crate::kernels::Kernel::EXACT_T_MAX`]): a hit reported at `t`
/// is reported, at the same `t`, for every `t_max` at or above it.
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[inline(always)]
pub(crate) fn within_box<L: Lanes, const EXIT: bool>(
    ray: &RayLanes<L>,
    mask: L::Mask,
    t: L,
    (lo, hi): (V3<L>, V3<L>),
    dir: V3<L>,
) -> (L, L::Mask) {
    let zero = L::zero();
    // Entering through the upper face where the direction is negative; ±0 and overflowing
    // quotients give ±inf or NaN: that axis bounds nothing.
    let axis = |near: bool, lo: L, hi: L, d: L| {
        let neg = d.lt(zero);
        let e = if near {
            L::select(neg, hi, lo)
        } else {
            L::select(neg, lo, hi)
        } / d;
        let none = L::splat(if near {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        });
        L::select(e.is_finite(), e, none)
    };
    let entry = axis(true, lo.x, hi.x, dir.x)
        .max_or_rhs(axis(true, lo.y, hi.y, dir.y))
        .max_or_rhs(axis(true, lo.z, hi.z, dir.z));
    let raise = mask & entry.gt(t);
    let mut mask = mask;
    if EXIT {
        let exit = axis(false, lo.x, hi.x, dir.x)
            .min_or_rhs(axis(false, lo.y, hi.y, dir.y))
            .min_or_rhs(axis(false, lo.z, hi.z, dir.z));
        mask = mask & !exit.lt(ray.t_min);
    }
    if raise.none() {
        return (t, mask);
    }
    let t = L::select(raise, entry, t);
    (t, mask & !(raise & !t_in_range(ray, t)))
}

/// The box of three points, per axis the smallest and the largest coordinate.
#[cfg(feature = "triangle")]
#[inline(always)]
pub(crate) fn span3<L: Lanes>(a: V3<L>, b: V3<L>, c: V3<L>) -> (V3<L>, V3<L>) {
    let lo = |a: L, b: L, c: L| a.min_or_rhs(b).min_or_rhs(c);
    let hi = |a: L, b: L, c: L| a.max_or_rhs(b).max_or_rhs(c);
    (
        V3::new(lo(a.x, b.x, c.x), lo(a.y, b.y, c.y), lo(a.z, b.z, c.z)),
        V3::new(hi(a.x, b.x, c.x), hi(a.y, b.y, c.y), hi(a.z, b.z, c.z)),
    )
}

/// The range check every kernel ends with: `t` is a finite f32 value (for f64 lanes: within
/// `±f32::MAX`, so it stays finite when read out as f32) inside `[t_min, t_max]` (a kernel
/// written outside this crate ends with it too).
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[inline(always)]
pub fn t_in_range<L: Lanes>(ray: &RayLanes<L>, t: L) -> L::Mask {
    t.le(L::splat(f32::MAX)) & t.ge(L::splat(-f32::MAX)) & t.ge(ray.t_min) & t.le(ray.t_max)
}
