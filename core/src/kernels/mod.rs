//! The accuracy tiers as kernel types, so that one query loop ([`crate::query`]) serves every
//! tier, primitive and lane width.
//!
//! | tier | kernel | primitive | contract |
//! |---|---|---|---|
//! | standard | [`MollerTrumbore`] | [`PackedTriangle`] | [`crate::kernels::triangle::moller_trumbore`] |
//! | watertight | [`Watertight`] | [`VertexTriangle`] | [`crate::kernels::triangle::watertight`] |
//! | exact | [`Exact`] | [`VertexTriangle`] | [`crate::kernels::triangle::exact`] |
//! | exact, each crossing once | [`ExactCrossing`] | [`VertexTriangle`] | [`crate::kernels::triangle::crossing`] |
//! | f64 | the standard, watertight and sphere kernels at `L = f64`, `f64x4`, `f64x8`  | same | same math, f64 rounding |
//! | sphere stable | [`StableSphere`] | [`PackedSphere`] | [`crate::kernels::sphere::stable`] |
//! | sphere naive | [`NaiveSphere`] | [`PackedSphere`] | [`crate::kernels::sphere::naive`] |
//!
//! The f64 tier reads the same f32 primitives and rays (widened exactly) and computes in f64;
//! reported `t` is rounded once to f32 when read out as a [`crate::hit::Hit`], and only hits whose `t`
//! is representable as a finite f32 are reported. Its contract: `|t − t_exact| ≤ 2·ε·scale` in
//! the standard tier's terms (measured ≤ 1.0: the final rounding to f32), no overflow or
//! underflow for coordinates whose products fit f64 (tested from 1e-40 to 1e19), and the same
//! bit-identity across widths and builds as the f32 tiers. Its inputs are still f32: a scene whose
//! *coordinates* need more than f32 precision needs f64 primitives, which octoray does not have
//! yet.

// The kernel bodies and their helpers here carry
// `#[cfg_attr(not(debug_assertions), inline(always))]`: forced into the walks in optimised builds,
// left to the compiler where debug assertions are on (tests, dev builds), whose compile time
// forced copies of these bodies into every walk dominate (docs/build-flags.md). The lane
// arithmetic they call (`crate::lanes`) is always forced.

#[cfg(feature = "sphere")]
pub mod sphere;
#[cfg(feature = "triangle")]
pub mod triangle;

use crate::lanes::{Lanes, V3};
#[cfg(feature = "sphere")]
use crate::prim::PackedSphere;
use crate::prim::RayLanes;
use crate::prim::{Affine64, One, Primitive, Words};

use crate::hit::LanesHit;
#[cfg(feature = "triangle")]
use crate::prim::{PackedTriangle, VertexTriangle};

/// A ray-primitive test at lane width `L`.
///
/// The body reads the primitive as lanes ([`Primitive::Lanes`]): one primitive broadcast to every
/// lane ([`Kernel::intersect`], a packet of rays) or one primitive per lane
/// ([`Kernel::intersect_lanes`] with [`Primitive::gather`], one ray broadcast against a block of
/// primitives, as BVH leaves are tested). Lane by lane the arithmetic is the same either way.
pub trait Kernel<L: Lanes> {
    /// The primitive layout the kernel reads.
    type Prim: Primitive;
    /// Per-ray precomputation, made once per query (for example the watertight shear).
    type Pre: Copy;
    /// The kernel decides `t ≤ t_max` exactly, not on its rounded `t`. Closest-hit queries then
    /// give it the caller's `t_max` and order its hits by the rounded `t` themselves: lowering
    /// `t_max` to an earlier hit's rounded `t` would cut off a hit whose rounded `t` is nearer
    /// but whose exact `t` is not, and the answer would depend on the order of the tests.
    ///
    /// A kernel with `EXACT_T_MAX = false` keeps every hit it reports at `t` for every
    /// `t_max ≥ t·(1 + 2⁻²⁰) + 2⁻¹²⁶`, with the same `t`, `u`, `v`: the queries and the BVH lower
    /// `t_max` to that bound of the running best (proptested in `tests/suite/queries.rs`).
    const EXACT_T_MAX: bool = false;
    /// Precomputes what depends on the ray only (not on `t_min`/`t_max`).
    fn prepare(ray: &RayLanes<L>) -> Self::Pre;
    /// Tests lane `i` of `ray` against lane `i` of `prim`.
    fn intersect_lanes(
        ray: &RayLanes<L>,
        pre: &Self::Pre,
        prim: &<Self::Prim as Primitive>::Lanes<L>,
    ) -> LanesHit<L>;
    /// Tests lane `i` of `ray` against primitive `i` of a source of words (one primitive
    /// broadcast, a slice, a SoA block: [`Words`]). The same as [`Kernel::intersect_lanes`] on
    /// [`Primitive::from_words`], which is the default; a kernel may read the words another way
    /// (the watertight tiers read them in the ray's axis order).
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn intersect_words<W: Words>(ray: &RayLanes<L>, pre: &Self::Pre, words: &W) -> LanesHit<L> {
        Self::intersect_lanes(ray, pre, &Self::Prim::from_words::<L, W>(words))
    }
    /// Tests every lane of `ray` against one primitive.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn intersect(ray: &RayLanes<L>, pre: &Self::Pre, prim: &Self::Prim) -> LanesHit<L> {
        Self::intersect_words(ray, pre, &One(prim))
    }
}

/// The point of a primitive nearest to a query point, in f64 from the f32 inputs: what point
/// queries report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The nearest point.
    pub point: [f64; 3],
    /// Barycentric weight of `v1` at it (triangles; 0 for spheres).
    pub u: f64,
    /// Barycentric weight of `v2` at it (triangles; 0 for spheres).
    pub v: f64,
    /// Its squared distance to the query point.
    pub dist2: f64,
}

/// Primitives a point query can measure: the nearest point of one, read from a source of words
/// ([`Words`]: a slice element or a block slot). Triangles:
/// [`crate::kernels::triangle::closest_point`]; spheres (their surface):
/// [`crate::kernels::sphere::closest_point`].
pub trait NearestPoint: Primitive {
    /// The point of the primitive in `words` nearest to `p`.
    fn nearest_point<W: Words>(words: &W, p: [f64; 3]) -> Nearest;
    /// Each lane's squared distance from `p` to a box around its primitive: a lower bound on
    /// [`NearestPoint::nearest_point`]'s, up to its f32 rounding (a few units of 2⁻²⁴, relative),
    /// for culling a block's primitives at once.
    fn dist2_bound<L: Lanes, W: Words>(words: &W, p: V3<L>) -> L;
    /// The point nearest to `p` of the primitive in `words` placed by `map` (object → world:
    /// an instance's primitive measured in world space). Triangles: the corners mapped, then
    /// [`NearestPoint::nearest_point`]'s test (plain f64 from there: a few units of 2⁻⁵² of the
    /// mapped triangle's extent); spheres: an ellipsoid
    /// ([`crate::kernels::sphere::closest_point`]).
    fn nearest_point_mapped<W: Words>(words: &W, map: &Affine64, p: [f64; 3]) -> Nearest;
    /// The point of `self` nearest to `p` ([`NearestPoint::nearest_point`] on one primitive).
    fn nearest(&self, p: [f64; 3]) -> Nearest {
        Self::nearest_point(&One(self), p)
    }
    /// The point of `self` placed by `map` nearest to `p`
    /// ([`NearestPoint::nearest_point_mapped`] on one primitive).
    fn nearest_mapped(&self, map: &Affine64, p: [f64; 3]) -> Nearest {
        Self::nearest_point_mapped(&One(self), map, p)
    }
}

/// Primitives a box query can test: does the primitive in `words` meet the closed box
/// `[lo, hi]`? Triangles: [`crate::kernels::triangle::box_overlap`]; spheres: the ball (its
/// centre's squared distance to the box at most its squared radius, in f64). A primitive that is
/// never hit meets no box.
pub trait MeetsBox: Primitive {
    /// Does the primitive in `words` meet `[lo, hi]`?
    fn meets_box<W: Words>(words: &W, lo: [f64; 3], hi: [f64; 3]) -> bool;
    /// Does the primitive in `words`, placed in the world by `to_world` (`to_object` its
    /// inverse: an instance's maps), meet the world box `[lo, hi]`? Triangles: the corners
    /// mapped, then [`MeetsBox::meets_box`]'s test; spheres: the ellipsoid
    /// ([`crate::kernels::sphere::box_overlap`]).
    fn meets_box_mapped<W: Words>(
        words: &W,
        to_world: &Affine64,
        to_object: &Affine64,
        lo: [f64; 3],
        hi: [f64; 3],
    ) -> bool;
    /// Does `self` meet `[lo, hi]` ([`MeetsBox::meets_box`] on one primitive)?
    fn meets(&self, lo: [f64; 3], hi: [f64; 3]) -> bool {
        Self::meets_box(&One(self), lo, hi)
    }
    /// Does `self`, placed by `to_world` (`to_object` its inverse), meet the world box
    /// `[lo, hi]` ([`MeetsBox::meets_box_mapped`] on one primitive)?
    fn meets_mapped(
        &self,
        to_world: &Affine64,
        to_object: &Affine64,
        lo: [f64; 3],
        hi: [f64; 3],
    ) -> bool {
        Self::meets_box_mapped(&One(self), to_world, to_object, lo, hi)
    }
}

/// [`MeetsBox`] for a triangle layout: its corners (`packed`: stored as `v0`, `e1`, `e2`),
/// mapped to the world by `to_world` when the triangle is placed.
#[cfg(feature = "triangle")]
macro_rules! triangle_meets_box {
    ($layout:ty, $packed:expr) => {
        impl MeetsBox for $layout {
            fn meets_box<W: Words>(words: &W, lo: [f64; 3], hi: [f64; 3]) -> bool {
                let c = corners(words, $packed);
                crate::kernels::triangle::box_overlap::triangle_meets_box(c, lo, hi)
            }
            fn meets_box_mapped<W: Words>(
                words: &W,
                to_world: &Affine64,
                _: &Affine64,
                lo: [f64; 3],
                hi: [f64; 3],
            ) -> bool {
                let c = corners(words, $packed).map(|x| to_world.apply(x));
                crate::kernels::triangle::box_overlap::triangle_meets_box(c, lo, hi)
            }
        }
    };
}
#[cfg(feature = "triangle")]
triangle_meets_box!(VertexTriangle, false);
#[cfg(feature = "triangle")]
triangle_meets_box!(PackedTriangle, true);

#[cfg(feature = "sphere")]
impl MeetsBox for PackedSphere {
    fn meets_box<W: Words>(words: &W, lo: [f64; 3], hi: [f64; 3]) -> bool {
        let c = [0, 1, 2].map(|k| words.word::<f32>(k));
        crate::kernels::sphere::box_overlap::ball_meets_box(c, words.word::<f32>(3), lo, hi)
    }
    fn meets_box_mapped<W: Words>(
        words: &W,
        _: &Affine64,
        to_object: &Affine64,
        lo: [f64; 3],
        hi: [f64; 3],
    ) -> bool {
        let c = [0, 1, 2].map(|k| words.word::<f32>(k));
        let r2 = words.word::<f32>(3);
        crate::kernels::sphere::box_overlap::mapped_ball_meets_box(c, r2, to_object, lo, hi)
    }
}

/// The squared distance from `p` to the box `[lo, hi]`, per lane (0 inside).
#[cfg_attr(not(debug_assertions), inline(always))]
fn box_dist2<L: Lanes>(lo: V3<L>, hi: V3<L>, p: V3<L>) -> L {
    let axis = |lo: L, hi: L, x: L| (lo - x).max_or_rhs(x - hi).max_or_rhs(L::zero());
    let (dx, dy, dz) = (
        axis(lo.x, hi.x, p.x),
        axis(lo.y, hi.y, p.y),
        axis(lo.z, hi.z, p.z),
    );
    dx * dx + dy * dy + dz * dz
}

/// `[lo, hi]` grown by 2⁻²² of its coordinates and the smallest normal f32: room for corners
/// rounded once (half an ulp each).
#[cfg(any(feature = "triangle", feature = "sphere"))]
#[cfg_attr(not(debug_assertions), inline(always))]
fn widened<L: Lanes>(lo: V3<L>, hi: V3<L>) -> [V3<L>; 2] {
    let grow = |x: L, s: f32| {
        x + (x.abs() * L::splat(1.0 / 4_194_304.0) + L::splat(f32::MIN_POSITIVE)) * L::splat(s)
    };
    let g = |v: V3<L>, s: f32| V3::new(grow(v.x, s), grow(v.y, s), grow(v.z, s));
    [g(lo, -1.0), g(hi, 1.0)]
}

/// Per lane, the smaller and the larger of three points' coordinates.
#[cfg(feature = "triangle")]
#[cfg_attr(not(debug_assertions), inline(always))]
fn min_max3<L: Lanes>(a: V3<L>, b: V3<L>, c: V3<L>) -> [V3<L>; 2] {
    let min = |x: L, y: L, z: L| x.min_or_rhs(y).min_or_rhs(z);
    let max = |x: L, y: L, z: L| x.max_or_rhs(y).max_or_rhs(z);
    [
        V3::new(min(a.x, b.x, c.x), min(a.y, b.y, c.y), min(a.z, b.z, c.z)),
        V3::new(max(a.x, b.x, c.x), max(a.y, b.y, c.y), max(a.z, b.z, c.z)),
    ]
}

/// The three corners of the triangle in `words`, in f64: a [`VertexTriangle`]'s vertices, or a
/// [`PackedTriangle`]'s `v0`, `v0 + e1`, `v0 + e2` (as the kernels read them).
#[cfg(feature = "triangle")]
#[cfg_attr(not(debug_assertions), inline(always))]
fn corners<W: Words>(words: &W, packed: bool) -> [[f64; 3]; 3] {
    let w = |k: usize| [0, 1, 2].map(|i| f64::from(words.word::<f32>(k + i)));
    let (v0, a, b) = (w(0), w(3), w(6));
    if !packed {
        return [v0, a, b];
    }
    let add = |e: [f64; 3]| core::array::from_fn(|k| v0[k] + e[k]);
    [v0, add(a), add(b)]
}

/// [`NearestPoint`]'s f64 tests for a triangle layout, inside its impl: its corners (`packed`:
/// stored as `v0`, `e1`, `e2`), mapped by `map` when the triangle is placed.
#[cfg(feature = "triangle")]
macro_rules! triangle_nearest_point {
    ($packed:expr) => {
        #[inline]
        fn nearest_point<W: Words>(words: &W, p: [f64; 3]) -> Nearest {
            crate::kernels::triangle::closest_point::nearest_on_triangle(corners(words, $packed), p)
        }
        #[inline]
        fn nearest_point_mapped<W: Words>(words: &W, map: &Affine64, p: [f64; 3]) -> Nearest {
            let c = corners(words, $packed).map(|x| map.apply(x));
            crate::kernels::triangle::closest_point::nearest_on_triangle(c, p)
        }
    };
}

#[cfg(feature = "triangle")]
impl NearestPoint for VertexTriangle {
    triangle_nearest_point!(false);
    /// The larger of the box's bound and the distance to the triangle's plane: with the
    /// stored unit normal `n` (rounded once from the exact one, each component within 2⁻²⁴)
    /// and `w = p − v₀` in f32, `|n·w|` is within `6·2⁻²⁴·|w|₁` of the exact plane distance,
    /// so `|n·w| − 2⁻²⁰·|w|₁` is below it.
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn dist2_bound<L: Lanes, W: Words>(words: &W, p: V3<L>) -> L {
        let v0 = words.word3(0);
        let [lo, hi] = min_max3(v0, words.word3(3), words.word3(6));
        let w = p - v0;
        let slack = (w.x.abs() + w.y.abs() + w.z.abs()) * L::splat(1.0 / 1_048_576.0);
        let plane = (words.word3::<L>(9).dot(w).abs() - slack).max_or_rhs(L::zero());
        box_dist2(lo, hi, p).max_or_rhs(plane * plane)
    }
}

#[cfg(feature = "triangle")]
impl NearestPoint for PackedTriangle {
    triangle_nearest_point!(true);
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn dist2_bound<L: Lanes, W: Words>(words: &W, p: V3<L>) -> L {
        let v0: V3<L> = words.word3(0);
        let [lo, hi] = min_max3(v0, v0 + words.word3(3), v0 + words.word3(6));
        let [lo, hi] = widened(lo, hi);
        box_dist2(lo, hi, p)
    }
}

#[cfg(feature = "sphere")]
impl NearestPoint for PackedSphere {
    #[inline]
    fn nearest_point<W: Words>(words: &W, p: [f64; 3]) -> Nearest {
        let c = [0, 1, 2].map(|i| f64::from(words.word::<f32>(i)));
        crate::kernels::sphere::closest_point::nearest_on_sphere(c, words.word::<f32>(3), p)
    }
    #[inline]
    fn nearest_point_mapped<W: Words>(words: &W, map: &Affine64, p: [f64; 3]) -> Nearest {
        let c = [0, 1, 2].map(|i| f64::from(words.word::<f32>(i)));
        let r2 = words.word::<f32>(3);
        crate::kernels::sphere::closest_point::nearest_on_mapped_sphere(c, r2, map, p)
    }
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn dist2_bound<L: Lanes, W: Words>(words: &W, p: V3<L>) -> L {
        // A sphere that is never hit (NaN radius) has a NaN box and a bound of 0: its exact
        // answer, infinitely far, leaves it out.
        let c: V3<L> = words.word3(0);
        let r = words.word::<L>(3).sqrt();
        let [lo, hi] = widened(c - V3::new(r, r, r), c + V3::new(r, r, r));
        box_dist2(lo, hi, p)
    }
}

/// Standard tier: Möller-Trumbore with delayed division ([`crate::kernels::triangle::moller_trumbore`]).
/// `CULL = true` ([`MollerTrumboreCulled`]) skips back faces: triangles whose normal `e1 × e2` points
/// along the ray (a counter-clockwise triangle seen from behind).
#[cfg(feature = "triangle")]
#[derive(Clone, Copy, Debug, Default)]
pub struct MollerTrumbore<const CULL: bool = false>;

/// Standard tier with back-face culling.
#[cfg(feature = "triangle")]
pub type MollerTrumboreCulled = MollerTrumbore<true>;

/// Watertight tier: Woop, Benthin & Wald 2013 plus a conservative δt bound
/// ([`crate::kernels::triangle::watertight`]); `CULL = true` ([`WatertightCulled`]) skips back faces.
#[cfg(feature = "triangle")]
#[derive(Clone, Copy, Debug, Default)]
pub struct Watertight<const CULL: bool = false>;

/// Watertight tier with back-face culling.
#[cfg(feature = "triangle")]
pub type WatertightCulled = Watertight<true>;

/// Exact tier: the watertight body with every edge sign and the range of `t` decided exactly
/// (a certified filter, exact arithmetic where it cannot decide;
/// [`crate::kernels::triangle::exact`]); `CULL = true` ([`ExactCulled`]) skips back faces.
#[cfg(feature = "triangle")]
#[derive(Clone, Copy, Debug, Default)]
pub struct Exact<const CULL: bool = false>;

/// Exact tier with back-face culling.
#[cfg(feature = "triangle")]
pub type ExactCulled = Exact<true>;

/// Exact tier with every tie broken once (a symbolic perturbation of the ray's origin,
/// [`crate::kernels::triangle::crossing`]): a ray through an edge or vertex of a closed mesh
/// crosses exactly one of the triangles there, and `t_min`/`t_max` are never met exactly. What
/// crossing counts and containment are built on.
#[cfg(feature = "triangle")]
#[derive(Clone, Copy, Debug, Default)]
pub struct ExactCrossing;

#[cfg(feature = "triangle")]
impl<const CULL: bool> Exact<CULL> {
    /// The lanes of `ray` that the exact tier decides past its filter against `tri` (in f64 or
    /// with exact arithmetic): what its fallback rate is measured with.
    pub fn fallback_lanes<L: Lanes>(ray: &RayLanes<L>, tri: &VertexTriangle) -> L::Mask {
        use crate::kernels::triangle::watertight::{sheared_body_traced, ShearedRay};
        sheared_body_traced::<L, CULL, true>(ray, &ShearedRay::new(ray), &tri.splat()).1
    }
}

/// Stable sphere (Ray Tracing Gems ch. 7, [`crate::kernels::sphere::stable`]).
#[cfg(feature = "sphere")]
#[derive(Clone, Copy, Debug, Default)]
pub struct StableSphere;

/// Naive textbook sphere quadratic ([`crate::kernels::sphere::naive`]), kept so the trade is visible.
#[cfg(feature = "sphere")]
#[derive(Clone, Copy, Debug, Default)]
pub struct NaiveSphere;

/// Implements [`Kernel`] for a kernel with no per-ray precomputation, by its intersect function.
macro_rules! kernel_without_prepare {
    ($(#[$cfg:meta])* [$($gen:tt)*] $ty:ty, $prim:ty, $lanes:ident, $f:expr) => {
        $(#[$cfg])*
        impl<$($gen)*> Kernel<$lanes> for $ty {
            type Prim = $prim;
            type Pre = ();
            #[cfg_attr(not(debug_assertions), inline(always))]
            fn prepare(_: &RayLanes<$lanes>) {}
            #[cfg_attr(not(debug_assertions), inline(always))]
            fn intersect_lanes(
                ray: &RayLanes<$lanes>,
                _: &(),
                prim: &<$prim as Primitive>::Lanes<$lanes>,
            ) -> LanesHit<$lanes> {
                $f(ray, prim)
            }
        }
    };
}

kernel_without_prepare!(#[cfg(feature = "triangle")] [L: Lanes, const CULL: bool] MollerTrumbore<CULL>, PackedTriangle, L,
    crate::kernels::triangle::moller_trumbore::intersect_lanes::<L, CULL>);
#[cfg(feature = "sphere")]
impl<L: Lanes> Kernel<L> for StableSphere {
    type Prim = PackedSphere;
    type Pre = crate::kernels::sphere::stable::SphereRay<L>;
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn prepare(ray: &RayLanes<L>) -> Self::Pre {
        crate::kernels::sphere::stable::SphereRay::new(ray)
    }
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn intersect_lanes(
        ray: &RayLanes<L>,
        pre: &Self::Pre,
        prim: &<PackedSphere as Primitive>::Lanes<L>,
    ) -> LanesHit<L> {
        crate::kernels::sphere::stable::intersect_lanes(ray, pre, prim)
    }
}
kernel_without_prepare!(#[cfg(feature = "sphere")] [L: Lanes] NaiveSphere, PackedSphere, L,
    crate::kernels::sphere::naive::intersect_lanes);

/// Implements [`Kernel`] for a tier on the watertight body (`$exact`: the exact tier).
macro_rules! sheared_kernel {
    ($ty:ident, $exact:literal) => {
        #[cfg(feature = "triangle")]
        impl<L: Lanes, const CULL: bool> Kernel<L> for $ty<CULL> {
            type Prim = VertexTriangle;
            type Pre = crate::kernels::triangle::watertight::ShearedRay<L>;
            const EXACT_T_MAX: bool = $exact;
            #[cfg_attr(not(debug_assertions), inline(always))]
            fn prepare(ray: &RayLanes<L>) -> Self::Pre {
                crate::kernels::triangle::watertight::ShearedRay::new(ray)
            }
            #[cfg_attr(not(debug_assertions), inline(always))]
            fn intersect_lanes(
                ray: &RayLanes<L>,
                pre: &Self::Pre,
                prim: &crate::prim::VertexLanes<L>,
            ) -> LanesHit<L> {
                crate::kernels::triangle::watertight::sheared_body::<L, CULL, $exact>(
                    ray, pre, prim,
                )
            }
            #[cfg_attr(not(debug_assertions), inline(always))]
            fn intersect_words<W: Words>(
                ray: &RayLanes<L>,
                pre: &Self::Pre,
                words: &W,
            ) -> LanesHit<L> {
                crate::kernels::triangle::watertight::sheared_words::<L, CULL, $exact, W>(
                    ray, pre, words,
                )
            }
        }
    };
}

sheared_kernel!(Watertight, false);
sheared_kernel!(Exact, true);

/// The exact tier's kernel, its hits then narrowed by the crossing rule.
#[cfg(feature = "triangle")]
impl<L: Lanes> Kernel<L> for ExactCrossing {
    type Prim = VertexTriangle;
    type Pre = <Exact as Kernel<L>>::Pre;
    const EXACT_T_MAX: bool = true;
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn prepare(ray: &RayLanes<L>) -> Self::Pre {
        <Exact as Kernel<L>>::prepare(ray)
    }
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn intersect_lanes(
        ray: &RayLanes<L>,
        pre: &Self::Pre,
        prim: &crate::prim::VertexLanes<L>,
    ) -> LanesHit<L> {
        let h = <Exact as Kernel<L>>::intersect_lanes(ray, pre, prim);
        crate::kernels::triangle::crossing::keep_crossings(ray, prim, h)
    }
    #[cfg_attr(not(debug_assertions), inline(always))]
    fn intersect_words<W: Words>(ray: &RayLanes<L>, pre: &Self::Pre, words: &W) -> LanesHit<L> {
        let h = <Exact as Kernel<L>>::intersect_words(ray, pre, words);
        if !crate::lanes::LaneMask::any(h.mask) {
            return h;
        }
        crate::kernels::triangle::crossing::keep_crossings(
            ray,
            &VertexTriangle::from_words::<L, W>(words),
            h,
        )
    }
}
