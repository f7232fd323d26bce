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
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

impl Hit {
    /// A scene's answer as six words, the way the C ABI reports it: the bits of `t`, `u` and
    /// `v`, then the primitive, geometry and instance; a miss as the bits of `f32::INFINITY`,
    /// two zeros and three `u32::MAX`.
    pub fn words(hit: Option<Hit>) -> [u32; 6] {
        match hit {
            Some(h) => [
                h.t.to_bits(),
                h.u.to_bits(),
                h.v.to_bits(),
                h.prim,
                h.geom,
                h.inst,
            ],
            None => [f32::INFINITY.to_bits(), 0, 0, u32::MAX, u32::MAX, u32::MAX],
        }
    }
}

/// FNV-1a (64-bit) over 32-bit words, each fed as its four little-endian bytes: a digest that
/// shows two runs gave the same bits (the determinism test, the demo, the C ABI's examples and
/// the Cortex-M firmware print it). It detects differences; it is not a cryptographic hash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Self::new()
    }
}

impl Digest {
    /// The empty digest (FNV-1a's offset basis).
    pub const fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    /// Adds one word.
    pub fn word(&mut self, w: u32) {
        for b in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    }

    /// Adds a kernel's answer: the bits of `t`, `u`, `v` and the primitive of a hit, or one
    /// word `u32::MAX` for a miss.
    pub fn hit(&mut self, hit: Option<Hit>) {
        match hit {
            None => self.word(u32::MAX),
            Some(h) => {
                for w in [h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.prim] {
                    self.word(w);
                }
            }
        }
    }

    /// Adds a scene's answer: its six [`Hit::words`].
    pub fn placed_hit(&mut self, hit: Option<Hit>) {
        for w in Hit::words(hit) {
            self.word(w);
        }
    }

    /// The digest of everything added.
    pub const fn value(self) -> u64 {
        self.0
    }
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
        let r = r2.sqrt();
        let corner = |r: L| V3::new(r - f.x, r - f.y, r - f.z);
        within_box::<L, true, 2>(ray, mask, t, [corner(-r), corner(r)])
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

/// `t` raised, on the lanes of `mask`, to the ray's entry into the primitive's box, the box of
/// `points` (relative to the ray's origin: a triangle's vertices, a sphere's two corners); lanes
/// whose raised `t` passes `t_max` are dropped from the mask. With `EXIT` (kernels that decide
/// `t ≥ t_min` on their rounded `t`), lanes whose ray leaves that box before `t_min` are
/// dropped too.
///
/// Per axis the points' distances along the ray are `p·(1/d)`; their smallest is where the ray
/// enters that axis' slab and their largest where it leaves it, whichever the direction's sign
/// (axes where they are not finite, a zero or tiny direction component, bound nothing).
/// The exact hit point lies in the primitive, so the exact `t` lies between the box's entry and
/// exit: raising `t` moves it toward the exact `t` (never past it by more than the entry's three
/// roundings, `3ε` of it), and a dropped lane's exact `t` is before `t_min` (but for those
/// roundings). A float tier's `t` can lie outside the box's span on grazing rays, where its
/// error grows as `1/|cos θ|`; the box test of a tree grows every box by a slack far larger
/// than those roundings, so after this no box that holds the whole primitive is entered after
/// a reported `t`, or left before `t_min` by a ray that reports a hit in it: a walk that culls
/// boxes by the best `t` and by `t_min` never culls a hit brute force reports. Raising `t` keeps
/// the kernels' `t_max` rule ([`crate::kernels::Kernel::EXACT_T_MAX`]): a hit reported at `t`
/// is reported, at the same `t`, for every `t_max` at or above it.
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[inline(always)]
pub(crate) fn within_box<L: Lanes, const EXIT: bool, const N: usize>(
    ray: &RayLanes<L>,
    mask: L::Mask,
    t: L,
    points: [V3<L>; N],
) -> (L, L::Mask) {
    let one = L::splat(1.0);
    let (mut entry, mut exit) = (L::splat(f32::NEG_INFINITY), L::splat(f32::INFINITY));
    for (inv, k) in [
        (one / ray.dir.x, 0),
        (one / ray.dir.y, 1),
        (one / ray.dir.z, 2),
    ] {
        let at = |p: V3<L>| [p.x, p.y, p.z][k] * inv;
        let (mut near, mut far) = (at(points[0]), at(points[0]));
        for &p in &points[1..] {
            let x = at(p);
            (near, far) = (near.min_or_rhs(x), far.max_or_rhs(x));
        }
        entry = L::select(near.is_finite(), near, entry).max_or_rhs(entry);
        if EXIT {
            exit = L::select(far.is_finite(), far, exit).min_or_rhs(exit);
        }
    }
    let mut mask = mask;
    if EXIT {
        mask = mask & !exit.lt(ray.t_min);
    }
    let raise = mask & entry.gt(t);
    if raise.none() {
        return (t, mask);
    }
    let t = L::select(raise, entry, t);
    (t, mask & !(raise & !t_in_range(ray, t)))
}

/// The range check every kernel ends with: `t` is a finite f32 value (for f64 lanes: within
/// `±f32::MAX`, so it stays finite when read out as f32) inside `[t_min, t_max]` (a kernel
/// written outside this crate ends with it too).
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[inline(always)]
pub fn t_in_range<L: Lanes>(ray: &RayLanes<L>, t: L) -> L::Mask {
    t.le(L::splat(f32::MAX)) & t.ge(L::splat(-f32::MAX)) & t.ge(ray.t_min) & t.le(ray.t_max)
}
