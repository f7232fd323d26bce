//! Watertight ray-triangle (Woop, Benthin & Wald 2013, "Watertight Ray/Triangle Intersection",
//! JCGT 2(1)) with pbrt-v4's conservative bound on `t`: one generic body for every lane width,
//! with the dominant axis chosen per lane. It reads [`VertexTriangle`] (the three vertices and the
//! unit normal): watertightness needs the shared vertices themselves, not rounded edges; the edge
//! test reads only the vertices, the normal only places the hit (a normal that does not match the
//! vertices moves `t`, never the decision).
//!
//! # Guarantees
//! - **Watertight:** the edge functions of a shared edge are computed from the same vertex values
//!   in the same order by both neighbours, with exact signs at zero (recomputed in f64 when any
//!   is exactly 0), so a ray through an edge or vertex of a closed mesh hits at least one of the
//!   triangles around it.
//! - **Same bits** across `f32` and `f32x4/x8/x16` and across builds (proptested), like the
//!   standard tier.
//! - **Range:** a hit is reported iff the edge test passes, the *exact* `t` is `≥ t_min`, and the
//!   reported `t` is `≤ t_max` (the plane-distance `t`, or the exact one on the lanes that report
//!   it; below). The `t_min` side is certified without a division (the sign of `N − t_min·D`
//!   against its error bound, or every vertex's depth against `t_min`, which keeps small distant
//!   triangles) and, on the lanes neither certificate decides, decided with exact arithmetic (the
//!   exact tier's predicates, [`crate::kernels::triangle::exact`], lane by lane, rare): a hit just
//!   in front of `t_min` is never lost, one just behind is never reported, for every finite input.
//!   The `t_max` side compares the reported `t`, as the standard tier does and as closest-hit
//!   queries order hits, so a hit reported at `t` stays a hit for every `t_max` a little above it
//!   ([`crate::kernels::Kernel::EXACT_T_MAX`]); the exact tier ([`crate::kernels::Exact`]) decides
//!   both sides exactly.
//! - **`t` error bound:** `t` is the plane distance `((v0 − o)·n)/(d·n)` from the stored unit
//!   normal ([`VertexTriangle::n`], formed in f64), in f32: with `ε = 2⁻²⁴`, `n` within an ulp of
//!   the exact normal and the plane through `v0` off by at most `ε·|p − v0|·|n|` at the hit point
//!   `p`, `|t − t_exact| ≤ 8·ε·max(|t|, reach)/|cos θ|` to first order (`reach = (|o − v0| +
//!   |v1 − v0| + |v2 − v0|)/|d|`, θ the angle between the ray and the normal): the standard tier's
//!   form without its `1/sin α`, so thin triangles cost nothing. The hit point `o + t·d` lies
//!   within `ε·(4|v0 − o| + 4|t·d| + |p − v0|)` of the plane.
//! - **Where the plane distance is not used:** where `d·n` disagrees in sign with the edge test's
//!   determinant (rays within about `ε` rad of the plane) or the quotient is not finite, `t` is
//!   the blend of the vertices' depths weighed by the edge functions, with the standard tier's
//!   bound `8·ε·max(|t|, reach)/(|cos θ|·sin α)` (α the smallest angle); at f64 widths always
//!   that blend (its error, `∝ 2⁻⁵³/sin α`, is below f32's resolution). Where the determinant is
//!   within its own error bound (a triangle that subtends less than about 2·10⁻³ rad seen from the
//!   origin, or a ray within ~1e-6 rad of the plane), `t ≥ t_min` is decided by the exact stage
//!   (f64 with a certified bound, exact arithmetic where that cannot decide) and `t` stays the
//!   plane distance. Where the kernel's products leave `[2⁻¹⁰⁰, 2¹⁰⁰]`, or the plane distance is
//!   not usable there, `t` is the exact `t` rounded, and `t ≤ t_max` is decided on it exactly.
//! - **Hits are finite** with `t ∈ [t_min, t_max]` (the reported `t` is clamped up to `t_min`
//!   where the exact `t` was certified above it). On lanes not given the exact `t`, `t` is raised
//!   to the ray's entry into the triangle's bounding box where it lies before it (grazing rays),
//!   which only moves it toward the exact `t`: no BVH box that holds the triangle is entered
//!   after a reported hit on it.
//!
//! # Limits
//! - **Overflow:** the products are of origin-relative coordinates with z normalised by the
//!   shear, so they overflow only when |v − o|² nears f32::MAX (~1e19), far later than the
//!   standard tier's ~7e12; overflow is a miss, never an inf/NaN hit. Use the f64 instantiation
//!   beyond that.
//! - **Underflow:** the edge functions are products of two sheared extents; where those go
//!   subnormal (triangles and distances below ~1e-19 from the origin's line) their computed signs
//!   can be wrong and a hit can be missed (`tests/suite/extremes.rs` documents 1e-30). The range
//!   and `t` are not affected (those lanes are decided exactly); for such scenes use the exact
//!   tier, which decides the edges exactly too.
//!
//! # Measured
//! - Zero escapes over 10⁵ rays aimed at the vertices and edges of closed jittered meshes centred
//!   at 0…1e6 (`tests/suite/watertight.rs`); in the trade report 0.000 % (report: `watertight, 8
//!   lanes`, crack rate) escape where the standard tier lets 1.540 % (report: `standard, 8
//!   lanes`, crack rate) through.
//! - `t` error at most 2.4·ε·max(|t|, reach)/|cos θ| (p50 0 ulp, p99 27 ulp on random cases);
//!   the hit point off the plane by p99 ≤ 1.6 f32 steps on thin triangles (aspect 1e2 to 1e4)
//!   and ≤ 0.4 on short rays along long trim (the accuracy report's off-plane table).
//! - The range decisions against the oracle: `tests/suite/exact.rs` and the thin-triangle
//!   reproducer in `tests/suite/hostile.rs`.

use crate::hit::{within_box, LanesHit};
use crate::kernels::triangle::exact::{cross3, dot3, resolve, sub3, LaneQuery};
use crate::lanes::V3;
use crate::lanes::{LaneMask, Lanes, Scalar, MAX_LANES};
use crate::prim::{Permuted, Primitive, VertexLanes, Words};
use crate::prim::{RayLanes, VertexTriangle};

/// One axis per lane, as two masks (`x`, `y`; neither set means `z`).
#[derive(Clone, Copy, Debug)]
pub struct Axis<L: Lanes> {
    is_x: L::Mask,
    is_y: L::Mask,
}

impl<L: Lanes> Axis<L> {
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn pick(self, v: V3<L>) -> L {
        L::select(self.is_x, v.x, L::select(self.is_y, v.y, v.z))
    }
}

/// Per-ray precomputation: the axis permutation and shear of Woop et al.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay<L: Lanes> {
    kx: Axis<L>,
    ky: Axis<L>,
    kz: Axis<L>,
    sx: L,
    sy: L,
    sz: L,
    /// Lanes whose shear factors carry a relative rounding error only (normal, or exactly zero
    /// from a zero direction component): the filters' bounds hold there.
    safe: L::Mask,
    /// The origin in each lane's axis order: `(o[kx], o[ky], o[kz])`.
    origin: V3<L>,
    /// The direction in each lane's axis order (for the plane distance).
    dir: V3<L>,
    /// `[kx, ky, kz]` when every lane shares them (single rays, coherent packets): the kernel
    /// then reads the vertices in that order ([`Permuted`]) instead of blending per lane.
    shared_axes: Option<[usize; 3]>,
}

impl<L: Lanes> ShearedRay<L> {
    /// Chooses per lane `kz = argmax |d|` (ties to the lower axis), `kx`, `ky` the next two
    /// cyclically, swapped when `d[kz] < 0` to keep the winding; and the shear
    /// `Sx = d[kx]/d[kz]`, `Sy = d[ky]/d[kz]`, `Sz = 1/d[kz]` that maps the ray onto +z.
    #[cfg_attr(not(debug_assertions), inline(always))]
    pub fn new(ray: &RayLanes<L>) -> Self {
        let d = ray.dir;
        let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
        let z_is_x = ax.ge(ay) & ax.ge(az);
        let z_is_y = !z_is_x & ay.ge(az);
        let z_is_z = !(z_is_x | z_is_y);
        let kz = Axis::<L> {
            is_x: z_is_x,
            is_y: z_is_y,
        };
        // Cyclic successors: kz = x → (y, z); kz = y → (z, x); kz = z → (x, y).
        let dz = kz.pick(d);
        let swap = dz.lt(L::zero());
        let (kx0, ky0) = (
            Axis::<L> {
                is_x: z_is_z,
                is_y: z_is_x,
            },
            Axis::<L> {
                is_x: z_is_y,
                is_y: z_is_z,
            },
        );
        let choose = |a: Axis<L>, b: Axis<L>| Axis::<L> {
            is_x: (swap & b.is_x) | (!swap & a.is_x),
            is_y: (swap & b.is_y) | (!swap & a.is_y),
        };
        let (kx, ky) = (choose(kx0, ky0), choose(ky0, kx0));
        let one = L::splat(1.0);
        let (dx, dy) = (kx.pick(d), ky.pick(d));
        let (sx, sy, sz) = (dx / dz, dy / dz, one / dz);
        let normal = L::splat(f32::MIN_POSITIVE);
        let zero = L::zero();
        let safe = (sx.abs().ge(normal) | !dx.ne(zero))
            & (sy.abs().ge(normal) | !dy.ne(zero))
            & sz.abs().ge(normal)
            & sz.is_finite();
        let same = |m: L::Mask| m.all() || m.none();
        let shared_axes = (same(z_is_x) && same(z_is_y) && same(swap)).then(|| {
            let kz = if z_is_x.all() {
                0
            } else if z_is_y.all() {
                1
            } else {
                2
            };
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if swap.all() {
                [ky, kx, kz]
            } else {
                [kx, ky, kz]
            }
        });
        Self {
            kx,
            ky,
            kz,
            sx,
            sy,
            sz,
            safe,
            origin: V3::new(
                kx.pick(ray.origin),
                ky.pick(ray.origin),
                kz.pick(ray.origin),
            ),
            dir: V3::new(dx, dy, dz),
            shared_axes,
        }
    }

    /// `v` in each lane's axis order; `v` itself when it was read in that order already
    /// (`PERMUTED`, [`Permuted`]).
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn in_axis_order<const PERMUTED: bool>(&self, v: V3<L>) -> V3<L> {
        if PERMUTED {
            v
        } else {
            self.permute(v)
        }
    }

    /// `v` in each lane's axis order, `(v[kx], v[ky], v[kz])`, by per-lane blends.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn permute(&self, v: V3<L>) -> V3<L> {
        V3::new(self.kx.pick(v), self.ky.pick(v), self.kz.pick(v))
    }
}

/// Tests every lane of `ray` against one triangle (precomputing the shear each call; queries
/// hoist it with [`ShearedRay::new`] and [`intersect_sheared`]).
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect<L: Lanes>(ray: &RayLanes<L>, tri: &VertexTriangle) -> LanesHit<L> {
    intersect_sheared(ray, &ShearedRay::new(ray), tri)
}

/// Tests every lane of `ray`, sheared by `sh`, against one triangle, two-sided.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_sheared<L: Lanes>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexTriangle,
) -> LanesHit<L> {
    intersect_sheared_lanes::<L, false>(ray, sh, &tri.splat())
}

/// Tests lane `i` of `ray`, sheared by `sh`, against lane `i` of `tri`; with `CULL`, back faces
/// (the normal `(v1 − v0) × (v2 − v0)` points along the ray) are misses.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_sheared_lanes<L: Lanes, const CULL: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> LanesHit<L> {
    sheared_body::<L, CULL, false>(ray, sh, tri)
}

/// Former name of [`intersect_sheared_lanes`].
#[deprecated(
    since = "0.1.0",
    note = "renamed `intersect_sheared_lanes`: it tests one triangle per lane"
)]
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_sheared_with<L: Lanes, const CULL: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> LanesHit<L> {
    intersect_sheared_lanes::<L, CULL>(ray, sh, tri)
}

#[cfg_attr(not(debug_assertions), inline(always))]
fn max3<L: Lanes>(a: L, b: L, c: L) -> L {
    a.max_or_rhs(b).max_or_rhs(c)
}

#[cfg_attr(not(debug_assertions), inline(always))]
fn min3<L: Lanes>(a: L, b: L, c: L) -> L {
    a.min_or_rhs(b).min_or_rhs(c)
}

/// Every lane set when `b`, none otherwise.
#[cfg_attr(not(debug_assertions), inline(always))]
fn all_if<L: Lanes>(b: bool) -> L::Mask {
    L::first_lanes(if b { L::LANES } else { 0 })
}

/// `k·u` (u the unit roundoff of the lanes' scalar).
#[cfg_attr(not(debug_assertions), inline(always))]
fn ulps<L: Lanes>(k: f64) -> L {
    L::splat_scalar(L::Scalar::from_f64(k * L::Scalar::UNIT_ROUNDOFF))
}

/// The body of the watertight and exact tiers. `EXACT = false`: the watertight tier, edge signs as
/// computed (exact at zero). `EXACT = true`: the exact tier, edge signs certified by a bound or
/// recomputed exactly. Both decide `t ≥ t_min` exactly; the exact tier decides `t ≤ t_max` exactly
/// too, the watertight tier on its rounded `t`.
///
/// Error bounds (standard model, `u` the unit roundoff; *safe* lanes are those where no product
/// can under- or overflow, checked below; every other lane goes to the exact predicates):
/// - Sheared coordinates: `|Âx − Ax| ≤ γ₄·Rx` with `Rx = max|a[kx]| + |Sx|·max|a[kz]|` over the
///   three vertices (rounding of `v − o`, of `Sx`, of the product and of the difference), and
///   `|Âx| ≤ (1 + γ₄)·Rx`; likewise `y`.
/// - Edge functions: `|û − U| ≤ 2γ₄(2 + γ₄)·Rx·Ry + 2γ₂(1 + γ₄)²·Rx·Ry < 21u·Rx·Ry`; the
///   computed bound `22u·R̂x·R̂y` covers the rounding of `R̂x`, `R̂y` too (`δe`).
/// - Scaled depths: `|ẑ − Az| ≤ γ₃·|Az|`; `D̂ = û + v̂ + ŵ` (all of one sign) is off by
///   `δD ≤ 3δe + 2u·|D̂|`; `N̂ = û·ẑa + v̂·ẑb + ŵ·ẑc` by `δN ≤ 3Z·(δe + 6u·E)` (`E`, `Z` the largest
///   `|û|`, `|ẑ|`). With `D̂ > δD` (so `D > 0` after normalising signs), `t ≥ b` for a bound `b`
///   when `N̂ − b·D̂ > δN + |b|·δD` plus the rounding of that expression (`3u·(|N̂| + |b|·|D̂|)`):
///   no division.
/// - `t` is also the barycentric mean of the depths, with weights `≥ −β`, `β = δe/(|D̂| − δD)`
///   (0 for the exact tier's certified signs), so it lies within `(4u + 6β)·Z` of
///   `[min ẑ, max ẑ]`: this decides small distant triangles, where the first bound is loose.
///   Compared after multiplying through by `|D̂| − δD`, again without a division.
/// - Each computed comparison `fl(x) > y` is strict with the error terms padded (constants
///   rounded up by 1 %, `5u` for the depths), so it implies the exact inequality.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn sheared_body<L: Lanes, const CULL: bool, const EXACT: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> LanesHit<L> {
    sheared_body_traced::<L, CULL, EXACT>(ray, sh, tri).0
}

/// [`sheared_body`] on primitives read from `words`: in the shared axis order when every lane
/// has the same one ([`Permuted`], no blends), per lane otherwise. The same bits either way.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn sheared_words<L: Lanes, const CULL: bool, const EXACT: bool, W: Words>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    words: &W,
) -> LanesHit<L> {
    match sh.shared_axes {
        Some(axes) => {
            // `min(2)`: the axes are 0, 1, 2 by construction; clamped once here (invariant in a
            // leaf's loop), the permuted reads need no bounds check each.
            let axes = axes.map(|a| a.min(2));
            let tri = VertexTriangle::from_words::<L, _>(&Permuted { words, axes });
            body::<L, CULL, EXACT, true>(ray, sh, &tri).0
        }
        None => body::<L, CULL, EXACT, false>(ray, sh, &VertexTriangle::from_words(words)).0,
    }
}

/// [`sheared_body`], also returning the lanes decided by exact arithmetic.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn sheared_body_traced<L: Lanes, const CULL: bool, const EXACT: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> (LanesHit<L>, L::Mask) {
    body::<L, CULL, EXACT, false>(ray, sh, tri)
}

/// What the edge test leaves for the rest of the body: the vertices relative to the origin
/// (`a`, `b`, `c`, in the lane's axis order), the scaled barycentrics, their sum, the lanes that
/// pass, and for the exact tier the lanes its predicates decide and the edge functions' bound.
#[derive(Clone, Copy)]
struct Edges<L: Lanes> {
    a: V3<L>,
    b: V3<L>,
    c: V3<L>,
    u: L,
    v: L,
    w: L,
    det: L,
    mask: L::Mask,
    exact_lanes: L::Mask,
    de: L,
    de_safe: L::Mask,
    /// The largest `|a[kz]|` of the three vertices (the unscaled depth).
    depth: L,
}

/// The body; `PERMUTED`: `tri`'s coordinates are already in the order `sh.shared_axes`.
#[cfg_attr(not(debug_assertions), inline(always))]
fn body<L: Lanes, const CULL: bool, const EXACT: bool, const PERMUTED: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> (LanesHit<L>, L::Mask) {
    let e = edge_test::<L, CULL, EXACT, PERMUTED>(ray, sh, tri);
    if e.mask.none() && e.exact_lanes.none() {
        return (LanesHit::miss(e.mask), e.exact_lanes);
    }
    range::<L, CULL, EXACT, PERMUTED>(ray, sh, tri, e)
}

/// The bound δe on the edge functions' error and the lanes where it holds (doc above), from
/// the vertices relative to the origin and their largest unscaled depth.
#[cfg_attr(not(debug_assertions), inline(always))]
fn edge_bound<L: Lanes>(sh: &ShearedRay<L>, [a, b, c]: [V3<L>; 3], depth: L) -> (L, L::Mask) {
    let rx = max3(a.x.abs(), b.x.abs(), c.x.abs()) + sh.sx.abs() * depth;
    let ry = max3(a.y.abs(), b.y.abs(), c.y.abs()) + sh.sy.abs() * depth;
    let rxy = rx * ry;
    let (lo, hi) = (L::splat(SAFE_MIN), L::splat(SAFE_MAX));
    let safe = sh.safe & rx.min_or_rhs(ry).ge(lo) & rxy.ge(lo) & rxy.le(hi);
    (ulps::<L>(22.0) * rxy, safe)
}

/// The edge test: which lanes' rays pass inside the triangle (the watertight tier: as computed,
/// exact at zero; the exact tier: certified, its undecided lanes in `exact_lanes`).
#[cfg_attr(not(debug_assertions), inline(always))]
fn edge_test<L: Lanes, const CULL: bool, const EXACT: bool, const PERMUTED: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
) -> Edges<L> {
    let zero = L::zero();
    // Vertices permuted so the ray runs along +z (kz; kx, ky keep the winding), relative to the
    // origin, then sheared so the ray runs along the z axis itself: the hit test becomes a 2D
    // point-in-triangle test at (0, 0).
    let p = |v: V3<L>| sh.in_axis_order::<PERMUTED>(v);
    let a = p(tri.v0) - sh.origin;
    let b = p(tri.v1) - sh.origin;
    let c = p(tri.v2) - sh.origin;
    let ax = a.x - sh.sx * a.z;
    let ay = a.y - sh.sy * a.z;
    let bx = b.x - sh.sx * b.z;
    let by = b.y - sh.sy * b.z;
    let cx = c.x - sh.sx * c.z;
    let cy = c.y - sh.sy * c.z;

    // Scaled barycentrics: the 2D edge functions of (0, 0) against edges BC, CA, AB.
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;

    let mut mask;
    // Lanes the exact tier decides with the exact predicates (none for the watertight tier).
    let mut exact_lanes = ray.active & !ray.active;
    // The bound δe on the edge functions' error (doc above): the exact tier needs it to decide
    // the edges, the watertight tier only for the t range (computed there, after the early out).
    let mut de = zero;
    let mut de_safe = exact_lanes;
    let depth = max3(a.z.abs(), b.z.abs(), c.z.abs());
    if EXACT {
        (de, de_safe) = edge_bound(sh, [a, b, c], depth);
        let (hi, lo) = (max3(u, v, w), min3(u, v, w));
        let mixed = hi.gt(de) & lo.lt(-de);
        let inside = lo.gt(de) | hi.lt(-de);
        exact_lanes = ray.active & !(de_safe & (mixed | inside));
        mask = ray.active & de_safe & inside;
    } else {
        // An exactly zero edge function may have the wrong sign from rounding; recompute those
        // lanes with exact products (f64 for f32 lanes) so neighbours agree on which side the ray
        // passes.
        let fix = ray.active & !(u.ne(zero) & v.ne(zero) & w.ne(zero));
        if fix.any() {
            u = L::select(fix, L::diff_of_products_wide(cx, by, cy, bx), u);
            v = L::select(fix, L::diff_of_products_wide(ax, cy, ay, cx), v);
            w = L::select(fix, L::diff_of_products_wide(bx, ay, by, ax), w);
        }
        let mixed = (u.lt(zero) | v.lt(zero) | w.lt(zero)) & (u.gt(zero) | v.gt(zero) | w.gt(zero));
        mask = ray.active & !mixed;
    }
    let det = u + v + w;
    mask = mask & det.ne(zero) & det.is_finite();
    if CULL {
        // With kx, ky swapped when d[kz] < 0 the winding seen along the ray is preserved: a front
        // face (normal against the ray) has det > 0, for every choice of axes (tested).
        mask = mask & det.gt(zero);
    }
    Edges {
        a,
        b,
        c,
        u,
        v,
        w,
        det,
        mask,
        exact_lanes,
        de,
        de_safe,
        depth,
    }
}

/// The rest of the body on the lanes the edge test leaves: the range of `t`, decided by the
/// certificates (and the exact stage where they cannot), the reported `t` and its box clamp.
#[cfg_attr(not(debug_assertions), inline(always))]
fn range<L: Lanes, const CULL: bool, const EXACT: bool, const PERMUTED: bool>(
    ray: &RayLanes<L>,
    sh: &ShearedRay<L>,
    tri: &VertexLanes<L>,
    e: Edges<L>,
) -> (LanesHit<L>, L::Mask) {
    let zero = L::zero();
    let p = |v: V3<L>| sh.in_axis_order::<PERMUTED>(v);
    let Edges {
        a,
        b,
        c,
        u,
        v,
        w,
        det,
        mut mask,
        exact_lanes,
        mut de,
        mut de_safe,
        depth,
    } = e;
    let (az, bz, cz) = (a.z, b.z, c.z);

    // Scaled distance: the z of the hit point is the barycentric blend of the sheared z's;
    // t = N/D with the numerator's sign normalised so that D > 0.
    let (azs, bzs, czs) = (sh.sz * az, sh.sz * bz, sh.sz * cz);
    let t_num = u * azs + v * bzs + w * czs;
    let abs_det = det.abs();
    let num = L::select(det.lt(zero), -t_num, t_num);

    let (t_min, t_max) = (ray.t_min, ray.t_max);
    let inf = L::splat(f32::INFINITY);
    if !EXACT {
        (de, de_safe) = edge_bound(sh, [a, b, c], depth);
    }
    // max |ẑ| = |Sz|·max |a[kz]| exactly: rounding is monotone.
    let max_z = sh.sz.abs() * depth;
    let max_e = max3(u.abs(), v.abs(), w.abs());
    let err_d = L::splat(3.01) * de + ulps::<L>(2.01) * abs_det;
    let room = abs_det - err_d;
    let me = max_z * max_e;
    // The filter's window: products normal and finite (`scaled`), and D̂ clear of its error
    // bound. Lanes outside it have their range decided by the exact stage.
    let scaled = de_safe
        & max_z.ge(L::splat(SAFE_MIN))
        & me.ge(L::splat(SAFE_MIN))
        & me.le(L::splat(SAFE_MAX));
    let safe = scaled & room.gt(L::splat(0.01) * err_d);
    // Watertight lanes whose t_max the exact stage decides: where the reported t is not finite,
    // and lanes outside the safe window that keep no t of their own (the exact stage's loop).
    let mut max_untested = ray.active & !ray.active;
    // Watertight lanes whose reported t is the plane distance.
    let mut plane_ok = max_untested;
    // The watertight tier's reported t (the edge test has decided; this places the hit). At f32
    // widths the plane distance `((v0 − o)·n)/(d·n)` from the stored unit normal (formed in f64
    // when the triangle was stored): its error does not grow as the triangle thins, so the hit
    // point lies on the plane to a few f32 steps (doc above). The blend N/D of the depths where
    // `d·n` is not of the sign the edge test's `D` implies (a ray all but in the plane: a front
    // face has D > 0 and d·n < 0) or the quotient is not finite, and at f64 widths, where the
    // blend's error (∝ 2⁻⁵³/sin α) is below f32's resolution for any triangle f32 can hold.
    let mut t_report = zero;
    if !EXACT {
        t_report = if L::Scalar::UNIT_ROUNDOFF < f32::EPSILON as f64 / 2.0 {
            t_num / det
        } else {
            let n = p(tri.n);
            let d = sh.dir;
            let an = a.x * n.x + a.y * n.y + a.z * n.z;
            let dn = d.x * n.x + d.y * n.y + d.z * n.z;
            let tp = an / dn;
            let ok = ((dn.lt(zero) & det.gt(zero)) | (dn.gt(zero) & det.lt(zero))) & tp.is_finite();
            plane_ok = ok;
            if (mask & !ok).any() {
                L::select(ok, tp, t_num / det)
            } else {
                tp
            }
        };
        // The watertight tier compares its reported t with t_max (as the standard tier does, and
        // as closest-hit queries order hits): far hits leave here, before the range
        // certificates. Lanes outside the safe window report the exact t, so their t_max is
        // decided exactly on that same t instead: they skip this test. So a hit reported at `t`
        // stays a hit for every `t_max` at or above `t`, which the queries' and the BVH's cull
        // by the running best relies on.
        max_untested = !t_report.is_finite();
        mask = mask & (t_report.le(t_max) | max_untested | !safe);
        if mask.none() {
            return (LanesHit::miss(mask), exact_lanes);
        }
    }
    // Is t in [t_min, t_max]? Two certificates (doc above), both free of divisions: the signs of
    // N − t_b·D, and (where that leaves lanes open) the depth interval.
    let err_n = L::splat(3.01) * max_z * (de + ulps::<L>(6.01) * max_e);
    let err_nd = err_d + ulps::<L>(3.01) * abs_det;
    let err_n3 = err_n + ulps::<L>(3.01) * num.abs();
    let slack = |b: L| err_n3 + b.abs() * err_nd;
    // The exact tier certifies t within [t_min, t_max] ∩ [−f32::MAX, f32::MAX]: an exact t just
    // beyond f32's range is a miss though its rounded t may not be (NaN bounds stay NaN: a miss).
    let (t_min, t_max) = if EXACT {
        let max = L::splat(f32::MAX);
        (
            L::select(t_min.lt(-max), -max, t_min),
            L::select(t_max.gt(max), max, t_max),
        )
    } else {
        (t_min, t_max)
    };
    let (at_min, at_max) = (t_min * abs_det, t_max * abs_det);
    let (s_min, s_max) = (slack(t_min), slack(t_max));
    let mut above_min = (num - at_min).gt(s_min) | t_min.le(-inf);
    let mut below_min = (at_min - num).gt(s_min);
    let mut below_max = (at_max - num).gt(s_max) | t_max.ge(inf) | all_if::<L>(!EXACT);
    let mut above_max = (num - at_max).gt(s_max) & all_if::<L>(EXACT);
    if (mask & !((above_min | below_min) & (below_max | above_max))).any() {
        // Depth interval, scaled by `room`: the weights are ≥ −δe/room (0 for the exact tier).
        let beta_e = if EXACT {
            zero
        } else {
            L::splat(6.01) * de * max_z
        };
        let ez = ulps::<L>(5.01) * max_z * room + beta_e;
        let (z_min, z_max) = (min3(azs, bzs, czs), max3(azs, bzs, czs));
        above_min = above_min | ((z_min - t_min) * room).gt(ez);
        below_min = below_min | ((t_min - z_max) * room).gt(ez);
        below_max = below_max | ((t_max - z_max) * room).gt(ez);
        above_max = above_max | ((z_min - t_max) * room).gt(ez);
    }
    let decided = safe & (above_min | below_min) & (below_max | above_max) & !max_untested;
    let in_range = decided & above_min & below_max;
    // Lanes whose range the filter cannot decide: exactly, from the lane's inputs.
    let undecided = mask & !decided;
    mask = mask & in_range;
    if mask.none() && undecided.none() && exact_lanes.none() {
        return (LanesHit::miss(mask), exact_lanes);
    }
    let (mut u_out, mut v_out, mut scale) = (v, w, det);
    let todo = undecided | exact_lanes;
    // Lanes whose t the exact stage supplies.
    let mut exact_t = 0u32;
    let mut te = [0.0f64; MAX_LANES];
    if todo.any() {
        let mut bits = todo.bitmask();
        let safe_bits = safe.bitmask();
        let untested_bits = max_untested.bitmask();
        // Outside the window only because D̂ is not clear of its bound (a triangle that subtends
        // less than about 2·10⁻³ rad from the origin, or a ray all but in its plane), with the
        // plane distance as t: that t does not depend on D̂, so such a lane keeps it and its
        // rounded t_max test (a lane that fails it is a miss: the mask above kept it only for
        // this stage), and the exact stage decides t ≥ t_min alone.
        let (keeps_bits, far_bits) = if EXACT {
            (0, 0)
        } else {
            let keeps = scaled & plane_ok & !safe & !max_untested;
            let below = t_report.le(t_max);
            ((keeps & below).bitmask(), (keeps & !below).bitmask())
        };
        let (mut keep, mut exact_bary) = (0u32, 0u32);
        let (mut ue, mut ve) = ([0.0f64; MAX_LANES], [0.0f64; MAX_LANES]);
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let f = |p: V3<L>| p.lane(i).map(Scalar::to_f32);
            // The vertices as given: undo the permutation of a permuted read.
            let vertex = |p: V3<L>| match sh.shared_axes {
                Some(axes) if PERMUTED => {
                    let (q, mut v) = (f(p), [0.0; 3]);
                    for k in 0..3 {
                        v[axes[k]] = q[k];
                    }
                    v
                }
                _ => f(p),
            };
            let whole = (exact_lanes.bitmask() >> i) & 1 == 1;
            if (far_bits >> i) & 1 == 1 {
                continue;
            }
            let keeps = (keeps_bits >> i) & 1 == 1;
            // Outside the window, and with no t of its own: t and t_max from the exact stage.
            let unsafe_lane = (safe_bits >> i) & 1 == 0 && !keeps;
            // The watertight tier decided its edges and its rounded t_max test already; where its
            // products over- or underflowed that rounded t is meaningless, so t_max is decided
            // exactly there too.
            let Some(r) = resolve(&LaneQuery {
                o: f(ray.origin),
                d: f(ray.dir),
                v: [vertex(tri.v0), vertex(tri.v1), vertex(tri.v2)],
                t_min: t_min.lane(i).to_f64(),
                t_max: t_max.lane(i).to_f64(),
                edges: whole,
                cull: CULL,
                check_max: EXACT || unsafe_lane || (untested_bits >> i) & 1 == 1,
                needs_t: whole || unsafe_lane,
            }) else {
                continue;
            };
            keep |= 1 << i;
            // The exact tier's lanes, and lanes whose filter values over- or underflowed, take t
            // from the exact stage; the exact tier's lanes take the barycentrics too (the
            // watertight tier keeps its own, which agree with its edge test).
            if whole || unsafe_lane {
                exact_t |= 1 << i;
                te[i] = r.t;
            }
            if whole {
                exact_bary |= 1 << i;
                (ue[i], ve[i]) = (r.b1.clamp(0.0, 1.0), r.b2.clamp(0.0, 1.0));
            }
        }
        mask = mask | L::mask_from_bits(keep);
        let from = |x: &[f64; MAX_LANES]| L::from_fn(|i| L::Scalar::from_f64(x[i % MAX_LANES]));
        if exact_bary != 0 {
            let sel = L::mask_from_bits(exact_bary);
            u_out = L::select(sel, from(&ue), u_out);
            v_out = L::select(sel, from(&ve), v_out);
            scale = L::select(sel, L::splat(1.0), scale);
        }
    }
    // The reported t (the edge test and the range have decided; this places the hit). The
    // watertight tier: `t_report` above. The exact tier: the plane distance
    // `((v0 − o)·n)/(d·n)`, lane by lane in f64 from the f32 inputs (the differences exact,
    // `n = (v1 − v0) × (v2 − v0)` and both dot products within a few units of 2⁻⁵³), rounded
    // once: within about an ulp of the exact t unless `d·n` cancels to ~2⁻²⁹ of its terms,
    // whatever the triangle's shape (the blend stands only where that quotient is not finite).
    // Per lane, so every width gives the same bits. The exact stage's own t on its lanes.
    // `+ 0` maps −0 to +0 (and nothing else): one canonical zero for every query.
    let (exact_bits, exact_t) = (exact_t, L::mask_from_bits(exact_t));
    let mut t = if EXACT {
        plane_t(
            mask & !exact_t,
            sh.origin,
            (p(tri.v0), p(tri.v1), p(tri.v2)),
            sh.dir,
            t_num / det,
        )
    } else {
        t_report
    } + zero;
    if exact_bits != 0 {
        t = L::select(
            exact_t,
            L::from_fn(|i| L::Scalar::from_f64(te[i % MAX_LANES])),
            t,
        );
    }
    // The exact t is in range; the rounded one may sit just outside: clamp (toward the exact).
    let t = L::select(t.lt(t_min), t_min, t);
    let t = L::select(t.gt(t_max), t_max, t);
    // An empty range (t_min > t_max) is a miss: the watertight tier's two sides are decided
    // differently (exact t ≥ t_min, rounded t ≤ t_max), so they alone could both pass.
    mask = mask & t.le(L::splat(f32::MAX)) & t.ge(L::splat(-f32::MAX)) & t_min.le(t_max);
    // On grazing rays the plane distance can lie before the triangle's box (its error grows as
    // 1/|cos θ|): raised to the box's entry, so no tree's box test culls the hit (`within_box`;
    // t ≥ t_min is decided exactly here already). `a`, `b`, `c` are the vertices relative to
    // the origin in the lane's axis order, `sh.dir` the direction in it (the box's entry does
    // not depend on the axis order). The exact tier's t, and the exact t a watertight lane took
    // from the exact stage, are within an ulp of the exact t already.
    let (t, mask) = if EXACT {
        (t, mask)
    } else {
        let (t, raised) = within_box::<L, false, 3>(
            &RayLanes {
                dir: sh.dir,
                ..*ray
            },
            mask & !exact_t,
            t,
            [a, b, c],
        );
        (t, raised | (mask & exact_t))
    };
    let hit = LanesHit {
        mask,
        t,
        u: u_out,
        v: v_out,
        scale,
    };
    (hit, todo)
}

/// The plane distance `((v0 − o)·n)/(d·n)` in f64 on the lanes of `mask` (the origin, the
/// vertices and `d` in one axis order), rounded to the lanes' scalar; `fallback` where it is
/// not finite and on the other lanes.
#[cfg_attr(not(debug_assertions), inline(always))]
fn plane_t<L: Lanes>(
    mask: L::Mask,
    origin: V3<L>,
    (v0, v1, v2): (V3<L>, V3<L>, V3<L>),
    dir: V3<L>,
    fallback: L,
) -> L {
    let mut bits = mask.bitmask();
    if bits == 0 {
        return fallback;
    }
    let (mut out, mut ok) = ([L::Scalar::from_f64(0.0); MAX_LANES], 0u32);
    let mut put = |i: usize, t: f64| {
        let t = L::Scalar::from_f64(t);
        if t.to_f64().is_finite() {
            out[i] = t;
            ok |= 1 << i;
        }
    };
    if L::LANES == 1 {
        let f = |v: V3<L>| v.lane(0).map(Scalar::to_f64);
        put(0, plane_distance(f(v0), f(v1), f(v2), f(dir), f(origin)));
    } else {
        // Every lane of every coordinate widened once: a lane read by a variable index costs a
        // store and a load each time (824 against 639 instructions per 8-lane test).
        let wide = |v: V3<L>| -> [[f64; MAX_LANES]; 3] {
            let lanes = |c: L| {
                core::array::from_fn(|i| {
                    if i < L::LANES {
                        c.lane(i).to_f64()
                    } else {
                        0.0
                    }
                })
            };
            [lanes(v.x), lanes(v.y), lanes(v.z)]
        };
        let (w0, w1, w2, wd, wo) = (wide(v0), wide(v1), wide(v2), wide(dir), wide(origin));
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let f = |w: &[[f64; MAX_LANES]; 3]| [w[0][i], w[1][i], w[2][i]];
            put(i, plane_distance(f(&w0), f(&w1), f(&w2), f(&wd), f(&wo)));
        }
    }
    L::select(
        L::mask_from_bits(ok),
        L::from_fn(|i| out[i % MAX_LANES]),
        fallback,
    )
}

/// `((p0 − o)·n)/(d·n)` with `n = (p1 − p0) × (p2 − p0)`, in f64.
#[cfg_attr(not(debug_assertions), inline(always))]
fn plane_distance(p0: [f64; 3], p1: [f64; 3], p2: [f64; 3], d: [f64; 3], o: [f64; 3]) -> f64 {
    let n = cross3(sub3(p1, p0), sub3(p2, p0));
    dot3(sub3(p0, o), n) / dot3(d, n)
}

/// Magnitudes inside `[SAFE_MIN, SAFE_MAX]` keep every product of the filters normal and finite.
const SAFE_MIN: f32 = 7.888_609e-31; // 2^-100
const SAFE_MAX: f32 = 1.267_650_6e30; // 2^100
