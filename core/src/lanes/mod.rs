//! The lane abstraction every octoray kernel body is written against.
//!
//! A kernel is written once, generic over [`Lanes`], and instantiated at `f32` (one ray: the
//! *scalar twin*) and at `wide::f32x4`, `f32x8`, `f32x16` (packets); the f64 tier instantiates
//! the same bodies at `f64`, `wide::f64x4` and `f64x8`. The trait exposes only
//! operations that are IEEE-exact on every `wide` backend (`+ - * /`, `sqrt`, comparisons,
//! `abs`, negation, selection), so the same body gives the same bits at every width and on every
//! build. It deliberately has no `mul_add` and no `recip`: `wide` fuses the first only on FMA
//! builds and approximates the second on x86.

pub mod exact;
mod v3;
#[cfg(feature = "wide")]
mod wide;

pub use v3::V3;

use core::fmt::Debug;
use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A per-lane boolean: `bool` for one lane, an all-ones/all-zeros lane pattern for `wide` types.
pub trait LaneMask:
    Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// True when at least one lane is set.
    fn any(self) -> bool;
    /// True when every lane is set.
    fn all(self) -> bool;
    /// True when no lane is set.
    #[inline(always)]
    fn none(self) -> bool {
        !self.any()
    }
    /// Bit `i` is lane `i`.
    fn bitmask(self) -> u32;
}

impl LaneMask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        self as u32
    }
}

/// A lane's element type: `f32` or `f64`.
pub trait Scalar:
    Copy + PartialOrd + Debug + Send + Sync + 'static + core::ops::Div<Output = Self>
{
    /// Exact widening (or identity) from `f32`.
    fn from_f32(x: f32) -> Self;
    /// Rounds to `f32` (correctly rounded; values beyond `f32::MAX` become infinite).
    fn to_f32(self) -> f32;
    /// Exact widening (or identity) to `f64`.
    fn to_f64(self) -> f64;
    /// Rounds from `f64`.
    fn from_f64(x: f64) -> Self;
    /// Unit roundoff `u` (2⁻²⁴ for f32, 2⁻⁵³ for f64): every basic operation's relative error.
    const UNIT_ROUNDOFF: f64;
    /// The smallest normal value (2⁻¹²⁶ for f32, 2⁻¹⁰²² for f64): below it a product loses its
    /// relative accuracy (its rounding error becomes absolute, up to half a subnormal step).
    const MIN_NORMAL: f64;
    /// `a·b − c·d` with the sign exact: for f32 computed in f64 (the products are exact there,
    /// the difference rounds once) and rounded back; for f64 by Kahan's algorithm on `fma`.
    fn diff_of_products_wide(a: Self, b: Self, c: Self, d: Self) -> Self;
}

impl Scalar for f32 {
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    const UNIT_ROUNDOFF: f64 = 1.0 / 16_777_216.0;
    const MIN_NORMAL: f64 = f32::MIN_POSITIVE as f64;
    #[inline(always)]
    fn diff_of_products_wide(a: f32, b: f32, c: f32, d: f32) -> f32 {
        (a as f64 * b as f64 - c as f64 * d as f64) as f32
    }
}

impl Scalar for f64 {
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x as f64
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x
    }
    const UNIT_ROUNDOFF: f64 = 1.0 / 9_007_199_254_740_992.0;
    const MIN_NORMAL: f64 = f64::MIN_POSITIVE;
    /// Kahan's algorithm with a correctly rounded `fma` (`libm::fma`, software, so the same bits
    /// on every build): `w = c·d`, `e = c·d − w` exactly, `f = a·b − w` rounded once, then
    /// `f − e`, whose relative error is at most 2u (Jeannerod, Louvet & Muller 2013), so its sign
    /// is the exact sign of `a·b − c·d` (0 exactly when the products are equal) — as long as no
    /// product under- or overflows (|products| between ~1e-290 and ~1e308, which f32-derived
    /// coordinates never leave).
    #[inline(always)]
    fn diff_of_products_wide(a: f64, b: f64, c: f64, d: f64) -> f64 {
        let w = c * d;
        let e = libm::fma(c, d, -w);
        let f = libm::fma(a, b, -w);
        f - e
    }
}

/// Most lanes any [`Lanes`] type has (`f32x16`): the size of fixed per-lane scratch arrays.
#[doc(hidden)]
pub const MAX_LANES: usize = 16;

/// `LANES` values of `f32` or `f64` processed together, with only IEEE-exact operations.
///
/// Implemented for `f32` and `f64` (one lane, [`Self::Mask`] = `bool`) and for `wide::f32x4`,
/// `f32x8`, `f32x16`, `f64x4` and `f64x8`. `wide` chooses its backend at compile time: `f32x8` is one AVX register when
/// built with `avx`, else two SSE halves; `f32x16` is one zmm register with `avx512f`.
pub trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Number of lanes.
    const LANES: usize;
    /// Per-lane boolean.
    type Mask: LaneMask;
    /// Per-lane `u32` (primitive indices).
    type Index: Copy;
    /// Element type (itself one lane).
    type Scalar: Scalar + Lanes<Scalar = Self::Scalar>;

    /// Every lane set to `x` (exactly widened from `f32`).
    fn splat(x: f32) -> Self;
    /// Every lane set to `x`.
    fn splat_scalar(x: Self::Scalar) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> Self::Scalar) -> Self;
    /// Lane `i` (`i < LANES`).
    fn lane(self, i: usize) -> Self::Scalar;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// Absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// `self < rhs` (false when either is NaN).
    fn lt(self, rhs: Self) -> Self::Mask;
    /// `self <= rhs` (false when either is NaN).
    fn le(self, rhs: Self) -> Self::Mask;
    /// `self > rhs` (false when either is NaN).
    fn gt(self, rhs: Self) -> Self::Mask;
    /// `self >= rhs` (false when either is NaN).
    fn ge(self, rhs: Self) -> Self::Mask;
    /// `self != rhs` (true when either is NaN).
    fn ne(self, rhs: Self) -> Self::Mask;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> Self::Mask;
    /// Per lane: `if m { a } else { b }`, bit-preserving.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// The first `n` lanes set (all when `n >= LANES`).
    fn first_lanes(n: usize) -> Self::Mask;

    /// Every index lane set to `i`.
    fn splat_index(i: u32) -> Self::Index;
    /// Per lane: `if m { a } else { b }` on indices.
    fn select_index(m: Self::Mask, a: Self::Index, b: Self::Index) -> Self::Index;
    /// Index lane `i`.
    fn index_lane(idx: Self::Index, i: usize) -> u32;

    /// Every lane zero.
    #[inline(always)]
    fn zero() -> Self {
        Self::splat(0.0)
    }

    /// The mask whose lane `i` is bit `i` of `bits`.
    #[inline(always)]
    fn mask_from_bits(bits: u32) -> Self::Mask {
        Self::from_fn(|i| Self::Scalar::from_f32(if (bits >> i) & 1 == 1 { 1.0 } else { 0.0 }))
            .gt(Self::zero())
    }

    /// `if self < rhs { self } else { rhs }` per lane: `rhs` when either is NaN (x86's `minps`
    /// rule, one instruction there; a compare and a blend elsewhere, with the same result).
    #[inline(always)]
    fn min_or_rhs(self, rhs: Self) -> Self {
        Self::select(self.lt(rhs), self, rhs)
    }

    /// A query's kernel `t_max` once it has a hit at `self`, per lane: `self` moved up by 2⁻²⁰ of
    /// itself and by the smallest normal f32, but never past `t_max` (`t_max` where that is NaN).
    /// A later hit at the same or a nearer rounded `t` is still reported (the tie rule decides
    /// between them) while far hits are cut off. The one rule of the slice queries and the walks,
    /// at every width, single rays included.
    #[inline(always)]
    fn loosen(self, t_max: Self) -> Self {
        (self + self.abs() * Self::splat(1.0 / 1_048_576.0) + Self::splat(f32::MIN_POSITIVE))
            .min_or_rhs(t_max)
    }

    /// `if self > rhs { self } else { rhs }` per lane: `rhs` when either is NaN (`maxps`).
    #[inline(always)]
    fn max_or_rhs(self, rhs: Self) -> Self {
        Self::select(self.gt(rhs), self, rhs)
    }

    /// `self` with its sign bit flipped where `s`'s sign bit is set (exact: `−self` where `s`
    /// is negative or −0, `self` elsewhere).
    fn xor_sign(self, s: Self) -> Self;

    /// Eight values per lane, lane `i` from `row(i)` for `i < n` and zero beyond: the transpose
    /// of `n` rows of eight `f32` (a packet's rays) into eight lane vectors, with register
    /// shuffles where the type has them (`f32x4`, `f32x8`, `f32x16` on x86).
    #[inline(always)]
    fn columns8(n: usize, row: impl Fn(usize) -> [f32; 8]) -> [Self; 8] {
        let rows: [[f32; 8]; MAX_LANES] = core::array::from_fn(|i| {
            if i < n.min(Self::LANES) {
                row(i)
            } else {
                [0.0; 8]
            }
        });
        core::array::from_fn(|k| Self::from_fn(|i| Self::Scalar::from_f32(rows[i][k])))
    }

    /// `a·b − c·d` per lane with an exact sign ([`Scalar::diff_of_products_wide`]), lane by lane:
    /// slow, for rare fallbacks only.
    #[inline]
    fn diff_of_products_wide(a: Self, b: Self, c: Self, d: Self) -> Self {
        Self::from_fn(|i| {
            <Self::Scalar as Scalar>::diff_of_products_wide(
                a.lane(i),
                b.lane(i),
                c.lane(i),
                d.lane(i),
            )
        })
    }
}

/// Implements [`Lanes`] for a plain scalar: one lane, `bool` masks.
macro_rules! impl_scalar_lanes {
    ($t:ident, $sqrt:path) => {
        impl Lanes for $t {
            const LANES: usize = 1;
            type Mask = bool;
            type Index = u32;
            type Scalar = $t;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                <$t as Scalar>::from_f32(x)
            }
            #[inline(always)]
            fn splat_scalar(x: $t) -> Self {
                x
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> $t) -> Self {
                f(0)
            }
            #[inline(always)]
            fn lane(self, _i: usize) -> $t {
                self
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $t::abs(self)
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> bool {
                self < rhs
            }
            #[inline(always)]
            fn le(self, rhs: Self) -> bool {
                self <= rhs
            }
            #[inline(always)]
            fn gt(self, rhs: Self) -> bool {
                self > rhs
            }
            #[inline(always)]
            fn ge(self, rhs: Self) -> bool {
                self >= rhs
            }
            #[inline(always)]
            fn ne(self, rhs: Self) -> bool {
                self != rhs
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                $t::is_finite(self)
            }
            #[inline(always)]
            fn select(m: bool, a: Self, b: Self) -> Self {
                if m {
                    a
                } else {
                    b
                }
            }
            #[inline(always)]
            fn first_lanes(n: usize) -> bool {
                n >= 1
            }
            #[inline(always)]
            fn xor_sign(self, s: Self) -> Self {
                if s.is_sign_negative() {
                    -self
                } else {
                    self
                }
            }
            #[inline(always)]
            fn splat_index(i: u32) -> u32 {
                i
            }
            #[inline(always)]
            fn select_index(m: bool, a: u32, b: u32) -> u32 {
                if m {
                    a
                } else {
                    b
                }
            }
            #[inline(always)]
            fn index_lane(idx: u32, _i: usize) -> u32 {
                idx
            }
        }
    };
}

impl_scalar_lanes!(f32, libm::sqrtf);
impl_scalar_lanes!(f64, libm::sqrt);
