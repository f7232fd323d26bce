//! Exact arithmetic on f32 inputs, for the rare lanes a filter cannot decide.
//!
//! Every finite f32 is `m·2^e` with an integer `|m| < 2^24` and `−149 ≤ e ≤ 104`, so a product of
//! up to four f32 values is an integer `M < 2^96` times `2^E` with `−596 ≤ E ≤ 416`. [`ExactSum`]
//! holds a sum of such products exactly, as one two's-complement fixed-point integer with its
//! lowest bit at `2^−596` (18 limbs of 64 bits: room for the largest product, `2^512`, times 512
//! terms, plus the sign). No rounding happens anywhere, so the sign of a sum is the exact sign of
//! the polynomial it stands for; the ratio of two sums converts to f64 within 3 ulps (f64).
//! Plain integer code: no allocation, no FMA, the same bits on every build.

use core::cmp::Ordering;

const LIMBS: usize = 18;
/// Bit position of `2^0` in the fixed-point integer.
const ORIGIN: i32 = 596;

/// `x = m·2^e` exactly, `|m| < 2^24` (`None` for NaN and ±∞).
#[inline]
fn split(x: f32) -> Option<(bool, u32, i32)> {
    if !x.is_finite() {
        return None;
    }
    let bits = x.to_bits();
    let neg = bits >> 31 == 1;
    let exp = ((bits >> 23) & 0xff) as i32;
    let frac = bits & 0x7f_ffff;
    Some(if exp == 0 {
        (neg, frac, -149)
    } else {
        (neg, frac | 0x80_0000, exp - 150)
    })
}

/// An exact sum of products of f32 values (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExactSum {
    limbs: [u64; LIMBS],
}

impl Default for ExactSum {
    fn default() -> Self {
        Self::ZERO
    }
}

impl ExactSum {
    /// The empty sum.
    pub const ZERO: Self = Self { limbs: [0; LIMBS] };

    /// Adds `±M·2^(pos − ORIGIN)` (`M < 2^96`, `0 ≤ pos`, `pos + 96 < 64·LIMBS − 10`).
    fn add_at(&mut self, neg: bool, m: u128, pos: u32) {
        let (idx, sh) = ((pos / 64) as usize, pos % 64);
        // m << sh spans at most 160 bits: three limbs.
        let lo = (m << sh) as u64;
        let mid = ((m << sh) >> 64) as u64;
        let hi = if sh == 0 { 0 } else { (m >> (128 - sh)) as u64 };
        let parts = [lo, mid, hi];
        if neg {
            let mut borrow = false;
            for (k, limb) in self.limbs[idx..].iter_mut().enumerate() {
                let p = if k < 3 { parts[k] } else { 0 };
                if k >= 3 && !borrow {
                    break;
                }
                let (a, b1) = limb.overflowing_sub(p);
                let (a, b2) = a.overflowing_sub(borrow as u64);
                *limb = a;
                borrow = b1 | b2;
            }
        } else {
            let mut carry = false;
            for (k, limb) in self.limbs[idx..].iter_mut().enumerate() {
                let p = if k < 3 { parts[k] } else { 0 };
                if k >= 3 && !carry {
                    break;
                }
                let (a, c1) = limb.overflowing_add(p);
                let (a, c2) = a.overflowing_add(carry as u64);
                *limb = a;
                carry = c1 | c2;
            }
        }
    }

    /// Adds the exact product of one to four finite f32 values (`false`, nothing added, when a
    /// factor is NaN or infinite).
    pub fn add_product(&mut self, factors: &[f32]) -> bool {
        debug_assert!(!factors.is_empty() && factors.len() <= 4);
        let (mut neg, mut m, mut e) = (false, 1u128, 0i32);
        for &x in factors {
            let Some((n, mx, ex)) = split(x) else {
                return false;
            };
            neg ^= n;
            m *= mx as u128;
            e += ex;
        }
        if m != 0 {
            self.add_at(neg, m, (e + ORIGIN) as u32);
        }
        true
    }

    /// `self + other`.
    pub fn plus(&self, other: &Self) -> Self {
        let mut out = *self;
        let mut carry = false;
        for (a, b) in out.limbs.iter_mut().zip(other.limbs) {
            let (s, c1) = a.overflowing_add(b);
            let (s, c2) = s.overflowing_add(carry as u64);
            *a = s;
            carry = c1 | c2;
        }
        out
    }

    /// `−self`.
    pub fn negated(&self) -> Self {
        let mut out = Self::ZERO;
        let mut carry = true;
        for (o, a) in out.limbs.iter_mut().zip(self.limbs) {
            let (s, c) = (!a).overflowing_add(carry as u64);
            *o = s;
            carry = c;
        }
        out
    }

    fn is_negative(&self) -> bool {
        self.limbs[LIMBS - 1] >> 63 == 1
    }

    /// The exact sign of the sum.
    pub fn sign(&self) -> Ordering {
        if self.is_negative() {
            Ordering::Less
        } else if self.limbs.iter().all(|&l| l == 0) {
            Ordering::Equal
        } else {
            Ordering::Greater
        }
    }

    /// `self · x` for a finite f32 `x` whose product with every term keeps at most four f32
    /// factors (a sum of products of three, times one more). `None` when `x` is not finite.
    pub fn times(&self, x: f32) -> Option<Self> {
        let (neg_x, m, e) = split(x)?;
        let neg = self.is_negative();
        let mag = if neg { self.negated() } else { *self };
        // mag · m: limb by limb with a 64-bit carry (m < 2^24, so nothing leaves the top).
        let mut prod = Self::ZERO;
        let mut carry = 0u64;
        for (p, a) in prod.limbs.iter_mut().zip(mag.limbs) {
            let full = a as u128 * m as u128 + carry as u128;
            *p = full as u64;
            carry = (full >> 64) as u64;
        }
        // · 2^e: every term of a three-factor sum sits at bit ≥ 596 − 447 = 149, so a right
        // shift by at most 149 drops only zeros.
        let shifted = if e >= 0 {
            prod.shl(e as u32)
        } else {
            prod.shr((-e) as u32)
        };
        Some(if neg != neg_x {
            shifted.negated()
        } else {
            shifted
        })
    }

    fn shl(&self, s: u32) -> Self {
        let (w, b) = ((s / 64) as usize, s % 64);
        let mut out = Self::ZERO;
        for i in (w..LIMBS).rev() {
            let lo = self.limbs[i - w];
            let below = if b > 0 && i > w {
                self.limbs[i - w - 1] >> (64 - b)
            } else {
                0
            };
            out.limbs[i] = if b > 0 { (lo << b) | below } else { lo };
        }
        out
    }

    fn shr(&self, s: u32) -> Self {
        let (w, b) = ((s / 64) as usize, s % 64);
        let mut out = Self::ZERO;
        for i in 0..LIMBS - w {
            let hi = self.limbs[i + w];
            let above = if b > 0 && i + w + 1 < LIMBS {
                self.limbs[i + w + 1] << (64 - b)
            } else {
                0
            };
            out.limbs[i] = if b > 0 { (hi >> b) | above } else { hi };
        }
        out
    }

    /// `(negative, mantissa, exponent)` with `|self| ≈ mantissa·2^exponent`, the mantissa the top
    /// 128 bits rounded down (relative error below 2^−63), or `None` for zero.
    fn top(&self) -> Option<(bool, f64, i32)> {
        let neg = self.is_negative();
        let mag = if neg { self.negated() } else { *self };
        let i = mag.limbs.iter().rposition(|&l| l != 0)?;
        let lo = if i > 0 { mag.limbs[i - 1] } else { 0 };
        let m = ((mag.limbs[i] as u128) << 64) | lo as u128;
        // The u128 → f64 conversion rounds to nearest: one more 2^−53 relative.
        Some((neg, m as f64, 64 * (i as i32 - 1) - ORIGIN))
    }

    /// The ratio `self / den` as f64 (NaN when `den` is zero): a relative error below
    /// `3·2^−53` (two conversions and the division), `±0` for a zero numerator.
    pub fn ratio(&self, den: &Self) -> f64 {
        let Some((nd, md, ed)) = den.top() else {
            return f64::NAN;
        };
        let Some((nn, mn, en)) = self.top() else {
            return 0.0;
        };
        let q = libm::scalbn(mn / md, en - ed);
        if nn != nd {
            -q
        } else {
            q
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_and_signs_are_exact() {
        // (1 + 2^-23)·(1 − 2^-23) − 1 = −2^-46, far below f32 and f64 resolution at this size.
        let a = 1.0 + f32::EPSILON;
        let b = 1.0 - f32::EPSILON;
        let mut s = ExactSum::ZERO;
        s.add_product(&[a, b]);
        s.add_product(&[-1.0]);
        assert_eq!(s.sign(), Ordering::Less);
        s.add_product(&[f32::EPSILON, f32::EPSILON]);
        assert_eq!(s.sign(), Ordering::Equal);
        // Extremes: the largest and smallest products of four cancel exactly.
        let mut s = ExactSum::ZERO;
        let tiny = f32::from_bits(1);
        s.add_product(&[f32::MAX, f32::MAX, f32::MAX, f32::MAX]);
        s.add_product(&[tiny, tiny, tiny, tiny]);
        s.add_product(&[-f32::MAX, f32::MAX, f32::MAX, f32::MAX]);
        assert_eq!(s.sign(), Ordering::Greater);
        s.add_product(&[-tiny, tiny, tiny, tiny]);
        assert_eq!(s.sign(), Ordering::Equal);
        assert!(!s.add_product(&[f32::NAN]));
    }

    #[test]
    fn times_and_ratio() {
        let mut s = ExactSum::ZERO;
        s.add_product(&[3.0, 5.0, 7.0]);
        s.add_product(&[-1.0e-30, 2.0, 4.0]);
        let neg = s.negated();
        assert_eq!(neg.plus(&s).sign(), Ordering::Equal);
        let st = s.times(-0.25).unwrap();
        let mut want = ExactSum::ZERO;
        want.add_product(&[-0.25, 3.0, 5.0, 7.0]);
        want.add_product(&[0.25, 1.0e-30, 2.0, 4.0]);
        assert_eq!(st, want);
        let tiny = f32::from_bits(3);
        let st = s.times(tiny).unwrap();
        let mut want = ExactSum::ZERO;
        want.add_product(&[tiny, 3.0, 5.0, 7.0]);
        want.add_product(&[-tiny, 1.0e-30, 2.0, 4.0]);
        assert_eq!(st, want);
        let mut d = ExactSum::ZERO;
        d.add_product(&[2.0]);
        let r = s.ratio(&d);
        assert!((r - (105.0 - 8.0e-30_f32 as f64) / 2.0).abs() <= 1e-13);
        let mut big = ExactSum::ZERO;
        big.add_product(&[f32::MAX, f32::MAX, f32::MAX]);
        let mut small = ExactSum::ZERO;
        small.add_product(&[tiny, tiny, -tiny]);
        let r = big.ratio(&small);
        let want = -(f32::MAX as f64).powi(3) / (27.0 * libm::exp2(-447.0));
        assert!((r / want - 1.0).abs() < 1e-15, "{r} {want}");
        assert!((small.ratio(&big) * want - 1.0).abs() < 1e-15);
        assert_eq!(ExactSum::ZERO.ratio(&big), 0.0);
        assert!(small.ratio(&ExactSum::ZERO).is_nan());
    }
}
