//! Sphere layouts: [`Sphere`] (centre and radius) and [`PackedSphere`] (what the sphere kernels
//! read), and their lanes.

use super::{down, up, Aabb, Primitive, Words};
use crate::lanes::{Lanes, V3};
use glam::Vec3;

/// A sphere given by centre and radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius; only a finite radius `> 0` can be hit.
    pub radius: f32,
}

impl Sphere {
    /// A sphere from centre and radius.
    pub fn new(center: Vec3, radius: f32) -> Self {
        Self { center, radius }
    }
}

/// A sphere in exactly what the sphere kernel reads: centre and squared radius (16 bytes,
/// `bytemuck`-castable).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PackedSphere {
    /// Centre.
    pub center: [f32; 3],
    /// Squared radius; a value that is not a finite normal f32 `> 0` (NaN, as
    /// [`PackedSphere::new`] stores it, but also ±0, subnormals, negatives, +inf) is a sphere
    /// that is never hit, by every kernel and the BVH alike.
    pub radius_sq: f32,
}

impl PackedSphere {
    /// Packs a sphere. Usable radii are those whose square is a normal, finite f32: from
    /// [`PackedSphere::MIN_RADIUS`] (≈ 1.08e-19) to [`PackedSphere::MAX_RADIUS`] (≈ 1.84e19). A
    /// radius outside that range, not finite, or not `> 0` is stored as `radius_sq = NaN`, which
    /// every kernel treats as a miss (below the range r² would be 0 or subnormal: a sphere that
    /// silently shrinks or vanishes).
    pub fn new(center: Vec3, radius: f32) -> Self {
        let r2 = radius * radius;
        let radius_sq = if radius > 0.0 && r2.is_finite() && r2 >= f32::MIN_POSITIVE {
            r2
        } else {
            f32::NAN
        };
        Self {
            center: center.to_array(),
            radius_sq,
        }
    }
}

impl PackedSphere {
    /// The smallest radius whose square is a normal f32 (`√f32::MIN_POSITIVE`, rounded up).
    pub const MIN_RADIUS: f32 = 1.084_202_2e-19;
    /// The largest radius whose square is finite (`√f32::MAX`, rounded down).
    pub const MAX_RADIUS: f32 = 1.844_674_3e19;
}

impl From<Sphere> for PackedSphere {
    fn from(s: Sphere) -> Self {
        Self::new(s.center, s.radius)
    }
}

/// [`PackedSphere`] as lanes: centre and squared radius.
#[derive(Clone, Copy, Debug)]
pub struct SphereLanes<L> {
    /// Centre.
    pub center: V3<L>,
    /// Squared radius (NaN: never hit).
    pub radius_sq: L,
}

impl Primitive for PackedSphere {
    type Lanes<L: Lanes> = SphereLanes<L>;
    const TAG: u32 = u32::from_le_bytes(*b"PSph");
    #[inline(always)]
    fn from_words<L: Lanes, W: Words>(w: &W) -> SphereLanes<L> {
        SphereLanes {
            center: w.word3(0),
            radius_sq: w.word(3),
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        // The kernels' rule: a squared radius that is not a finite normal f32 is never hit.
        let r2 = self.radius_sq;
        if !(r2 >= f32::MIN_POSITIVE && r2.is_finite() && self.center.iter().all(|c| c.is_finite()))
        {
            return None;
        }
        // r = √r² rounded up by an ulp, then every face moved outward by an ulp.
        let r = up(libm::sqrtf(r2));
        let b = Aabb {
            lo: core::array::from_fn(|k| down(self.center[k] - r)),
            hi: core::array::from_fn(|k| up(self.center[k] + r)),
        };
        // A finite sphere that reaches past f32's range is still hit: its box is clamped.
        Some(b.clamped())
    }
}
