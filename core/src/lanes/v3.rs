//! A 3-vector of lanes, with the operation order every kernel relies on for bit equality.

use super::Lanes;
use core::ops::{Add, Mul, Neg, Sub};

/// Three lane vectors: one 3-vector per lane (SoA). `V3<f32>` is an ordinary vector.
///
/// `dot` is `(x·x' + y·y') + z·z'` and `cross` is `(y·z' − z·y', z·x' − x·z', x·y' − y·x')`,
/// in that order at every width: never reassociate these, the scalar twins depend on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<L> {
    /// x lanes.
    pub x: L,
    /// y lanes.
    pub y: L,
    /// z lanes.
    pub z: L,
}

impl<L: Lanes> V3<L> {
    /// Builds from three lane values.
    #[inline(always)]
    pub fn new(x: L, y: L, z: L) -> Self {
        Self { x, y, z }
    }

    /// Every lane set to `v`.
    #[inline(always)]
    pub fn splat(v: [f32; 3]) -> Self {
        Self::new(L::splat(v[0]), L::splat(v[1]), L::splat(v[2]))
    }

    /// Dot product, `(x·x' + y·y') + z·z'`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Per-lane selection.
    #[inline(always)]
    pub fn select(m: L::Mask, a: Self, b: Self) -> Self {
        Self::new(
            L::select(m, a.x, b.x),
            L::select(m, a.y, b.y),
            L::select(m, a.z, b.z),
        )
    }

    /// Lane `i` as an array.
    #[inline(always)]
    pub fn lane(self, i: usize) -> [L::Scalar; 3] {
        [self.x.lane(i), self.y.lane(i), self.z.lane(i)]
    }
}

impl<L: Lanes> Add for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<L: Lanes> Sub for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<L: Lanes> Mul<L> for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: L) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<L: Lanes> Neg for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}
