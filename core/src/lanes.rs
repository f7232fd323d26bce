//! The lane abstraction every octoray kernel body is written against.
//!
//! A kernel is written once, generic over [`Lanes`], and instantiated at `f32` (one ray: the
//! *scalar twin*) and at `wide::f32x4`, `f32x8`, `f32x16` (packets). The trait exposes only
//! operations that are IEEE-exact on every `wide` backend (`+ - * /`, `sqrt`, comparisons,
//! `abs`, negation, selection), so the same body gives the same bits at every width and on every
//! build. It deliberately has no `mul_add` and no `recip`: `wide` fuses the first only on FMA
//! builds and approximates the second on x86.

use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};
use wide::{f32x16, f32x4, f32x8, u32x16, u32x4, u32x8};

/// A per-lane boolean: `bool` for one lane, an all-ones/all-zeros lane pattern for `wide` types.
pub trait LaneMask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
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

/// `LANES` values of `f32` processed together, with only IEEE-exact operations.
///
/// Implemented for `f32` (one lane, [`Self::Mask`] = `bool`) and for `wide::f32x4`, `f32x8`
/// and `f32x16`. `wide` chooses its backend at compile time: `f32x8` is one AVX register when
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

    /// Every lane set to `x`.
    fn splat(x: f32) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Lane `i` (`i < LANES`).
    fn lane(self, i: usize) -> f32;
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
}

impl Lanes for f32 {
    const LANES: usize = 1;
    type Mask = bool;
    type Index = u32;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        libm::sqrtf(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
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
        f32::is_finite(self)
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

/// Implements [`LaneMask`] and [`Lanes`] for one `wide` float type; the mask is the float type
/// itself (all-ones or all-zeros per lane), the index type the `u32` vector of the same width.
macro_rules! impl_wide_lanes {
    ($f:ident, $u:ident, $n:literal) => {
        impl LaneMask for $f {
            #[inline(always)]
            fn any(self) -> bool {
                $f::any(self)
            }
            #[inline(always)]
            fn all(self) -> bool {
                $f::all(self)
            }
            #[inline(always)]
            fn bitmask(self) -> u32 {
                self.to_bitmask()
            }
        }

        impl Lanes for $f {
            const LANES: usize = $n;
            type Mask = $f;
            type Index = $u;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                $f::splat(x)
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
                $f::new(core::array::from_fn(f))
            }
            #[inline(always)]
            fn lane(self, i: usize) -> f32 {
                self.as_array()[i]
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $f::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $f::abs(self)
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> Self {
                self.simd_lt(rhs)
            }
            #[inline(always)]
            fn le(self, rhs: Self) -> Self {
                self.simd_le(rhs)
            }
            #[inline(always)]
            fn gt(self, rhs: Self) -> Self {
                self.simd_gt(rhs)
            }
            #[inline(always)]
            fn ge(self, rhs: Self) -> Self {
                self.simd_ge(rhs)
            }
            #[inline(always)]
            fn ne(self, rhs: Self) -> Self {
                self.simd_ne(rhs)
            }
            #[inline(always)]
            fn is_finite(self) -> Self {
                $f::is_finite(self)
            }
            #[inline(always)]
            fn select(m: Self, a: Self, b: Self) -> Self {
                m.select(a, b)
            }
            #[inline(always)]
            fn first_lanes(n: usize) -> Self {
                let idx = $f::new(core::array::from_fn(|i| i as f32));
                idx.simd_lt($f::splat(n.min($n) as f32))
            }
            #[inline(always)]
            fn splat_index(i: u32) -> $u {
                $u::splat(i)
            }
            #[inline(always)]
            fn select_index(m: Self, a: $u, b: $u) -> $u {
                let m: $u = bytemuck::cast(m);
                m.select(a, b)
            }
            #[inline(always)]
            fn index_lane(idx: $u, i: usize) -> u32 {
                idx.as_array()[i]
            }
        }
    };
}

impl_wide_lanes!(f32x4, u32x4, 4);
impl_wide_lanes!(f32x8, u32x8, 8);
impl_wide_lanes!(f32x16, u32x16, 16);
