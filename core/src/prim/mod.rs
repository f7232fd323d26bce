//! What a kernel reads: rays ([`Ray`], and [`RayLanes`] for a packet), primitive layouts
//! ([`triangle`](PackedTriangle), [`sphere`](PackedSphere)) as lanes, and their bounds.
//!
//! A kernel body reads its primitive as *lanes*: the same primitive broadcast to every lane (a
//! packet of rays against one primitive, [`Primitive::splat`]) or up to `L::LANES` primitives one
//! per lane (one ray against a block of primitives, [`Primitive::gather`], the way a BVH leaf is
//! tested). Both feed the same generic body, so every lane's answer is the same bits either way.
//!
//! [`Primitive::bounds`] gives a box that contains the primitive exactly as the kernels read it
//! (for [`PackedTriangle`], `v0 + e1` and `v0 + e2` are not rounded: the box is widened by an ulp
//! to hold the exact sums). A primitive with a non-finite coordinate has no bounds: no kernel can
//! hit it, and the BVH builder leaves it out.

mod ray;
#[cfg(feature = "sphere")]
mod sphere;
#[cfg(feature = "triangle")]
mod triangle;

pub use ray::{Ray, RayLanes};
#[cfg(feature = "sphere")]
pub use sphere::{PackedSphere, Sphere, SphereLanes};
#[cfg(feature = "triangle")]
pub use triangle::{EdgeLanes, PackedTriangle, VertexLanes, VertexTriangle};

use crate::lanes::{Lanes, V3};

/// An axis-aligned box, `lo ≤ hi` componentwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub lo: [f32; 3],
    /// Largest corner.
    pub hi: [f32; 3],
}

impl Aabb {
    /// The empty box (`lo = +inf`, `hi = −inf`): the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
    };

    /// The smallest box holding both.
    #[inline]
    pub fn union(self, o: Self) -> Self {
        Self {
            lo: core::array::from_fn(|k| self.lo[k].min(o.lo[k])),
            hi: core::array::from_fn(|k| self.hi[k].max(o.hi[k])),
        }
    }

    /// Grows the box to hold point `p`.
    #[inline]
    pub fn grow(self, p: [f32; 3]) -> Self {
        self.union(Self { lo: p, hi: p })
    }

    /// Half the surface area (`xy + yz + zx`); 0 for an empty or flat box.
    #[inline]
    pub fn half_area(&self) -> f32 {
        let e: [f32; 3] = core::array::from_fn(|k| (self.hi[k] - self.lo[k]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }

    /// The centre (rounded).
    #[inline]
    pub fn center(&self) -> [f32; 3] {
        core::array::from_fn(|k| self.lo[k] * 0.5 + self.hi[k] * 0.5)
    }

    /// True when `lo ≤ hi` on every axis and every coordinate is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        (0..3).all(|k| self.lo[k].is_finite() && self.hi[k].is_finite() && self.lo[k] <= self.hi[k])
    }
}

/// One ulp toward −inf (`x` finite).
#[inline]
fn down(x: f32) -> f32 {
    x.next_down()
}

/// One ulp toward +inf (`x` finite).
#[inline]
fn up(x: f32) -> f32 {
    x.next_up()
}

/// A primitive layout: plain `f32` data (`bytemuck::Pod`) that a kernel reads as lanes.
pub trait Primitive: Copy + bytemuck::Pod {
    /// The layout's fields as lanes (one primitive per lane, or one broadcast to all).
    type Lanes<L: Lanes>: Copy;
    /// `self` in every lane.
    fn splat<L: Lanes>(&self) -> Self::Lanes<L>;
    /// `prims[i]` in lane `i` for `i < prims.len()` (at most `L::LANES`); the other lanes hold a
    /// zero primitive, which no kernel hits (callers also mask them off).
    fn gather<L: Lanes>(prims: &[Self]) -> Self::Lanes<L>;
    /// A box holding the primitive exactly as the kernels read it; `None` when a coordinate is
    /// not finite (such a primitive can never be hit).
    fn bounds(&self) -> Option<Aabb>;
}

/// Most lanes any [`Lanes`] type has.
const MAX_LANES: usize = 16;

/// The first `min(len, 16)` primitives, then zero primitives: a fixed-size copy, so that reading
/// lane `i` needs no bounds check and no branch.
#[inline(always)]
fn padded<P: bytemuck::Pod>(prims: &[P]) -> [P; MAX_LANES] {
    let mut a = [P::zeroed(); MAX_LANES];
    let n = prims.len().min(MAX_LANES);
    a[..n].copy_from_slice(&prims[..n]);
    a
}

/// Field `k` (in `f32` units) of each primitive, one per lane.
#[inline(always)]
fn field<L: Lanes, P: bytemuck::Pod>(prims: &[P; MAX_LANES], k: usize) -> L {
    let n = core::mem::size_of::<P>() / 4;
    let flat: &[f32] = bytemuck::cast_slice(prims);
    L::from_fn(|i| <L::Scalar as crate::lanes::Scalar>::from_f32(flat[i * n + k]))
}

/// Three `f32` fields starting at `k` as a lane vector.
#[inline(always)]
fn field3<L: Lanes, P: bytemuck::Pod>(prims: &[P; MAX_LANES], k: usize) -> V3<L> {
    V3::new(field(prims, k), field(prims, k + 1), field(prims, k + 2))
}
