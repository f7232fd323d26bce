//! [`Lanes`] and [`LaneMask`] for the `wide` types (feature `wide`).
//!
//! They live in this crate, not in `octoray-packet`, because of the orphan rule: an impl of a
//! trait for a type must sit in the crate of the trait or of the type, and here the trait is
//! ours and the types are `wide`'s. `octoray-packet` turns the feature on.

use super::{LaneMask, Lanes, Scalar};
use ::wide::{f32x16, f32x4, f32x8, f64x4, f64x8, u32x16, u32x4, u32x8, u64x4, u64x8};

/// Implements [`LaneMask`] and [`Lanes`] for one `wide` float type; the mask is the float type
/// itself (all-ones or all-zeros per lane), the index type the unsigned vector of the same width
/// (`u64` lanes for `f64` types; indices are stored zero-extended).
macro_rules! impl_wide_lanes {
    ($f:ident, $t:ident, $u:ident, $ut:ident, $n:literal $(, $columns:ident)?) => {
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
            type Scalar = $t;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                $f::splat(<$t as Scalar>::from_f32(x))
            }
            #[inline(always)]
            fn splat_scalar(x: $t) -> Self {
                $f::splat(x)
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> $t) -> Self {
                $f::new(core::array::from_fn(f))
            }
            #[inline(always)]
            fn lane(self, i: usize) -> $t {
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
                if n >= $n {
                    // All ones: 0 == 0 in every lane.
                    return $f::splat(0.0).simd_eq($f::splat(0.0));
                }
                let idx = $f::new(core::array::from_fn(|i| i as $t));
                idx.simd_lt($f::splat(n as $t))
            }
            #[inline(always)]
            fn xor_sign(self, s: Self) -> Self {
                self ^ (s & $f::splat(-0.0))
            }
            // x86's min/max instructions return the second operand when either is NaN: exactly
            // the trait's definition. Other backends keep the default compare-and-blend.
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            #[inline(always)]
            fn min_or_rhs(self, rhs: Self) -> Self {
                self.fast_min(rhs)
            }
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            #[inline(always)]
            fn max_or_rhs(self, rhs: Self) -> Self {
                self.fast_max(rhs)
            }
            $(
            #[inline(always)]
            fn columns8(n: usize, row: impl Fn(usize) -> [f32; 8]) -> [Self; 8] {
                $columns(n, row)
            }
            )?
            #[inline(always)]
            fn splat_index(i: u32) -> $u {
                $u::splat(i as $ut)
            }
            #[inline(always)]
            fn select_index(m: Self, a: $u, b: $u) -> $u {
                let m: $u = bytemuck::cast(m);
                m.select(a, b)
            }
            #[inline(always)]
            fn index_lane(idx: $u, i: usize) -> u32 {
                idx.as_array()[i] as u32
            }
        }
    };
}

impl_wide_lanes!(f32x4, f32, u32x4, u32, 4, columns_x4);
impl_wide_lanes!(f32x8, f32, u32x8, u32, 8, columns_x8);
impl_wide_lanes!(f32x16, f32, u32x16, u32, 16, columns_x16);
impl_wide_lanes!(f64x4, f64, u64x4, u64, 4);
impl_wide_lanes!(f64x8, f64, u64x8, u64, 8);

/// Rows `base..base + 8` of [`Lanes::columns8`]'s input (zero from `n` on), transposed: one
/// 8 × 8 shuffle network on AVX.
#[inline(always)]
fn transpose8(base: usize, n: usize, row: &impl Fn(usize) -> [f32; 8]) -> [f32x8; 8] {
    f32x8::transpose(core::array::from_fn(|i| {
        let i = base + i;
        f32x8::new(if i < n { row(i) } else { [0.0; 8] })
    }))
}

/// [`Lanes::columns8`] for `f32x8`.
#[inline(always)]
fn columns_x8(n: usize, row: impl Fn(usize) -> [f32; 8]) -> [f32x8; 8] {
    transpose8(0, n, &row)
}

/// [`Lanes::columns8`] for `f32x16`: rows 0–7 and 8–15 transposed apart, then joined.
#[inline(always)]
fn columns_x16(n: usize, row: impl Fn(usize) -> [f32; 8]) -> [f32x16; 8] {
    let (lo, hi) = (transpose8(0, n, &row), transpose8(8, n, &row));
    core::array::from_fn(|k| {
        let (a, b) = (lo[k].to_array(), hi[k].to_array());
        f32x16::new(core::array::from_fn(
            |i| if i < 8 { a[i] } else { b[i - 8] },
        ))
    })
}

/// [`Lanes::columns8`] for `f32x4`: each row's halves as two 4 × 4 transposes.
#[inline(always)]
fn columns_x4(n: usize, row: impl Fn(usize) -> [f32; 8]) -> [f32x4; 8] {
    let rows: [[f32; 8]; 4] = core::array::from_fn(|i| if i < n { row(i) } else { [0.0; 8] });
    let half = |h: usize| {
        f32x4::transpose(core::array::from_fn(|i| {
            f32x4::new(core::array::from_fn(|k| rows[i][4 * h + k]))
        }))
    };
    let (lo, hi) = (half(0), half(1));
    core::array::from_fn(|k| if k < 4 { lo[k] } else { hi[k - 4] })
}
