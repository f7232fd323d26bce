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

mod affine;
mod ray;
#[cfg(feature = "sphere")]
mod sphere;
#[cfg(feature = "triangle")]
mod triangle;

pub(crate) use affine::invert3;
#[cfg(feature = "sphere")]
pub(crate) use affine::symmetric_eigen;
pub use affine::Affine64;
pub use ray::{Ray, RayLanes};
#[cfg(feature = "sphere")]
pub use sphere::{PackedSphere, Sphere, SphereLanes};
#[cfg(feature = "triangle")]
pub use triangle::{EdgeLanes, PackedTriangle, VertexLanes, VertexTriangle};

use crate::lanes::{Lanes, MAX_LANES, V3};

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

    /// [`Aabb::union`] of boxes without NaN (the builder's): plain compares, one instruction
    /// per bound on x86 where `f32::min`'s NaN rule takes three.
    #[cfg(feature = "alloc")]
    #[inline]
    pub(crate) fn union_finite(self, o: Self) -> Self {
        let (lo, hi) = (self.lo, self.hi);
        Self {
            lo: core::array::from_fn(|k| if o.lo[k] < lo[k] { o.lo[k] } else { lo[k] }),
            hi: core::array::from_fn(|k| if o.hi[k] > hi[k] { o.hi[k] } else { hi[k] }),
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

    /// The box with infinite bounds moved to `±f32::MAX`: the bounds of a finite primitive that
    /// reaches past f32's range (a sphere at `f32::MAX`, a packed triangle whose `v0 + e1`
    /// overflows). The builder's slack turns such a bound back into an infinity in every node
    /// above it, so the tree still holds every hit; the box stays finite for the builder's
    /// centroids.
    #[inline]
    pub fn clamped(self) -> Self {
        let c = |x: f32| x.clamp(-f32::MAX, f32::MAX);
        Self {
            lo: self.lo.map(c),
            hi: self.hi.map(c),
        }
    }

    /// The common part of both boxes, or `None` when they do not meet.
    #[inline]
    pub fn intersect(self, o: Self) -> Option<Self> {
        let b = Self {
            lo: core::array::from_fn(|k| self.lo[k].max(o.lo[k])),
            hi: core::array::from_fn(|k| self.hi[k].min(o.hi[k])),
        };
        (0..3).all(|k| b.lo[k] <= b.hi[k]).then_some(b)
    }

    /// The largest coordinate magnitude (0 for the empty box).
    #[inline]
    pub fn magnitude(&self) -> f32 {
        (0..3).fold(0.0f32, |m, k| m.max(self.lo[k].abs()).max(self.hi[k].abs()))
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

/// Primitives per SoA block: a BVH leaf stores its primitives in blocks of `BLOCK`, word by word
/// (row `w` of a block holds word `w` of its `BLOCK` primitives), so that one ray is tested
/// against a block with one vector load per word instead of a gather.
pub const BLOCK: usize = 8;

/// A primitive layout: plain `f32` data (`bytemuck::Pod`, [`Primitive::WORDS`] words; `Send`
/// and `Sync`, so builds can share it between threads) that a kernel reads as lanes.
pub trait Primitive: Copy + bytemuck::Pod + Send + Sync {
    /// The layout's fields as lanes (one primitive per lane, or one broadcast to all).
    type Lanes<L: Lanes>: Copy;
    /// `f32` words per primitive (the layout is `WORDS` plain `f32`s).
    const WORDS: usize = core::mem::size_of::<Self>() / 4;
    /// Four bytes naming the layout in stored scenes ([`crate::scene::SceneRef::to_words`]), so
    /// that words stored for one layout are refused as another of the same size; `0` (the
    /// default) for an unnamed layout, which stored scenes then tell apart by size alone.
    const TAG: u32 = 0;
    /// The largest leaf the BVH builder makes of this layout (1 to [`BLOCK`]; one block's worth
    /// for primitives, one for a scene's instances, whose leaves each enter a tree).
    const LEAF: usize = BLOCK;
    /// `self` in every lane.
    #[inline(always)]
    fn splat<L: Lanes>(&self) -> Self::Lanes<L> {
        Self::from_words::<L, _>(&One(self))
    }
    /// The lanes of primitives read word by word from `words` (lane `i` holds primitive `i` of
    /// the source). The one body behind [`Primitive::splat`], [`Primitive::gather`] and
    /// [`Primitive::load_block`].
    fn from_words<L: Lanes, W: Words>(words: &W) -> Self::Lanes<L>;
    /// `prims[i]` in lane `i` for `i < prims.len()` (at most `L::LANES`); the other lanes hold a
    /// zero primitive, which no kernel hits (callers also mask them off).
    #[inline(always)]
    fn gather<L: Lanes>(prims: &[Self]) -> Self::Lanes<L> {
        Self::from_words::<L, _>(&Rows(padded(prims)))
    }
    /// Primitives `first..` of a SoA block (`block` is its [`Primitive::WORDS`] rows) in lanes
    /// `0..`; lanes past the block's end hold zero words. At [`BLOCK`] or more lanes `first` is
    /// 0 (one call reads the whole block, one vector load per word at `BLOCK` lanes).
    ///
    /// # Panics
    /// When `block` has fewer than `WORDS` rows.
    #[inline(always)]
    fn load_block<L: Lanes>(block: &[[f32; BLOCK]], first: usize) -> Self::Lanes<L> {
        debug_assert!(first == 0 || L::LANES < BLOCK);
        Self::from_words::<L, _>(&BlockRows::new::<Self>(block, first))
    }
    /// Primitive `i` of a SoA block.
    #[inline(always)]
    fn from_block(block: &[[f32; BLOCK]], i: usize) -> Self {
        let mut p = Self::zeroed();
        let w: &mut [f32] = bytemuck::cast_slice_mut(core::slice::from_mut(&mut p));
        for (k, x) in w.iter_mut().enumerate() {
            *x = block[k][i];
        }
        p
    }
    /// Writes `prims` (at most [`BLOCK`]) into a SoA block's rows, zero words after them.
    ///
    /// # Panics
    /// When `prims.len() > BLOCK` or `block` has fewer than `WORDS` rows.
    fn write_block(prims: &[Self], block: &mut [[f32; BLOCK]]) {
        assert!(
            prims.len() <= BLOCK,
            "octoray: a block holds {BLOCK} primitives"
        );
        for row in block[..Self::WORDS].iter_mut() {
            *row = [0.0; BLOCK];
        }
        for (i, p) in prims.iter().enumerate() {
            let w: &[f32] = bytemuck::cast_slice(core::slice::from_ref(p));
            for (k, &x) in w.iter().enumerate() {
                block[k][i] = x;
            }
        }
    }
    /// A box holding the primitive exactly as the kernels read it; `None` when a coordinate is
    /// not finite (such a primitive can never be hit).
    fn bounds(&self) -> Option<Aabb>;
    /// A box holding every point of the primitive (as the kernels read it) with
    /// `lo ≤ x[axis] ≤ hi`, or `None` when no point has: what a spatial split keeps of the
    /// primitive on each side of its plane. The default is [`Primitive::bounds`] cut to the
    /// slab; triangles clip the triangle itself, so the box shrinks with the part.
    fn clip(&self, axis: usize, lo: f32, hi: f32) -> Option<Aabb> {
        let mut b = self.bounds()?;
        b.lo[axis] = b.lo[axis].max(lo);
        b.hi[axis] = b.hi[axis].min(hi);
        (b.lo[axis] <= b.hi[axis]).then_some(b)
    }
    /// [`Primitive::clip`] to each slab between consecutive `planes` (slab `i`: `planes[i] ≤
    /// x[axis] ≤ planes[i + 1]`, for `i < out.len()`; `planes` holds one more), into `out[i]`:
    /// the same boxes. Triangles find each plane's edge crossings once for the two slabs it
    /// bounds.
    fn clip_slabs(&self, axis: usize, planes: &[f32], out: &mut [Option<Aabb>]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = match (planes.get(i), planes.get(i + 1)) {
                (Some(&lo), Some(&hi)) => self.clip(axis, lo, hi),
                _ => None,
            };
        }
    }
}

/// The largest f32 at or below `x` (not NaN; −inf below f32's range): `x` rounded to nearest,
/// then one step down where that went above, branch-free (the step is taken about half the
/// time, so a branch would mispredict).
#[cfg(feature = "triangle")]
#[inline(always)]
fn f32_at_or_below(x: f64) -> f32 {
    let f = x as f32;
    let b = f.to_bits();
    // One step toward −inf: +0 to the negative subnormal, magnitudes up below zero, down above.
    let stepped = match (b, b >> 31) {
        (0, _) => 0x8000_0001,
        (_, 1) => b + 1,
        _ => b - 1,
    };
    if f as f64 > x {
        f32::from_bits(stepped)
    } else {
        f
    }
}

/// The smallest f32 at or above `x` (not NaN; +inf above f32's range): the mirror of
/// [`f32_at_or_below`] (negation is exact and both roundings are symmetric).
#[cfg(feature = "triangle")]
#[inline(always)]
fn f32_at_or_above(x: f64) -> f32 {
    -f32_at_or_below(-x)
}

/// A box holding the part of triangle `p` (f64 points, exact copies of the kernels' points)
/// with `lo ≤ x[axis] ≤ hi`, or `None` when no point has (or a coordinate is not finite).
#[cfg(feature = "triangle")]
fn clip_triangle(p: [[f64; 3]; 3], axis: usize, lo: f32, hi: f32) -> Option<Aabb> {
    let mut out = [None];
    clip_triangle_slabs(p, axis, &[lo, hi], &mut out);
    out[0]
}

/// A box of points in f64 (`lo`, `hi`), empty as [`NONE`].
#[cfg(feature = "triangle")]
type Span = ([f64; 3], [f64; 3]);

/// The empty [`Span`].
#[cfg(feature = "triangle")]
const NONE: Span = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

/// Grows `b` to hold `q` (not NaN: plain compares, one instruction each on x86).
#[cfg(feature = "triangle")]
#[inline(always)]
fn add(b: &mut Span, q: [f64; 3]) {
    for (k, &x) in q.iter().enumerate() {
        b.0[k] = if x < b.0[k] { x } else { b.0[k] };
        b.1[k] = if x > b.1[k] { x } else { b.1[k] };
    }
}

/// The box of the edges' crossings of the plane `x[axis] = plane` (each crossing on it exactly
/// in `axis`).
#[cfg(feature = "triangle")]
#[inline(always)]
fn plane_crossings(p: &[[f64; 3]; 3], axis: usize, plane: f64) -> Span {
    let mut b = NONE;
    for i in 0..3 {
        let (a, c) = (p[i], p[(i + 1) % 3]);
        if (a[axis] < plane) != (c[axis] < plane) {
            let s = (plane - a[axis]) / (c[axis] - a[axis]);
            // The plane's coordinate exactly (chosen per component, not stored at a runtime
            // index: that store and the array's reload would stall store forwarding).
            let q: [f64; 3] = core::array::from_fn(|j| {
                let x = a[j] + s * (c[j] - a[j]);
                if j == axis {
                    plane
                } else {
                    x
                }
            });
            add(&mut b, q);
        }
    }
    b
}

/// [`clip_triangle`] for each slab between consecutive `planes` (slab `i`: `planes[i] ≤ x[axis]
/// ≤ planes[i + 1]`, for `i < out.len()`), into `out[i]`: the same boxes, each plane's edge
/// crossings found once for the two slabs it bounds.
///
/// A part's corners are the vertices inside the slab and the edges' crossings of its two
/// planes. A crossing takes the plane's coordinate exactly and the others within a few f64 ulps
/// of the triangle's largest coordinate `m`; the box is grown by `m·2⁻⁴⁰` (far above that
/// error) and rounded outward to f32, so it holds the exact part.
#[cfg(feature = "triangle")]
fn clip_triangle_slabs(p: [[f64; 3]; 3], axis: usize, planes: &[f32], out: &mut [Option<Aabb>]) {
    // A triangle that is not finite (never hit): nothing.
    if !p.iter().flatten().all(|x| x.is_finite()) {
        out.fill(None);
        return;
    }
    let m = p.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let grow = m * (1.0 / (1u64 << 40) as f64);
    let (down, up) = (
        |x: f64| f32_at_or_below(x - grow),
        |x: f64| f32_at_or_above(x + grow),
    );
    let crossings = |plane: f64| plane_crossings(&p, axis, plane);
    let mut below = crossings(planes.first().map_or(f64::NAN, |&x| x as f64));
    for (i, o) in out.iter_mut().enumerate() {
        let (lo, hi) = (
            planes[i] as f64,
            planes.get(i + 1).map_or(f64::NAN, |&x| x as f64),
        );
        let above = crossings(hi);
        // NaN planes or an empty slab: nothing.
        *o = None;
        if lo <= hi {
            let mut b = below;
            add(&mut b, above.0);
            add(&mut b, above.1);
            for v in p {
                if lo <= v[axis] && v[axis] <= hi {
                    add(&mut b, v);
                }
            }
            // A part reaching past f32's range (a packed triangle's `v0 + e1`) ends at
            // ±f32::MAX, as its bounds do.
            *o = (b.0[0] <= b.1[0]).then(|| {
                Aabb {
                    lo: [down(b.0[0]), down(b.0[1]), down(b.0[2])],
                    hi: [up(b.1[0]), up(b.1[1]), up(b.1[2])],
                }
                .clamped()
            });
        }
        below = above;
    }
}

/// A source of primitives' `f32` words for [`Primitive::from_words`]: word `k` of the primitive
/// in each lane. The crate implements it for one primitive broadcast (what [`Primitive::splat`]
/// reads, also from a SoA block), for primitives one after another (what [`Primitive::gather`]
/// reads), for SoA blocks (what [`Primitive::load_block`] reads) and, for layouts of points, for
/// any of them with the axes of every point permuted; a custom [`crate::kernels::Kernel`] reads its
/// primitive through it.
pub trait Words {
    /// Word `k` of each lane's primitive.
    fn word<L: Lanes>(&self, k: usize) -> L;
    /// Words `k..k + 3` as a lane vector.
    #[inline(always)]
    fn word3<L: Lanes>(&self, k: usize) -> V3<L> {
        V3::new(self.word(k), self.word(k + 1), self.word(k + 2))
    }
}

impl<W: Words> Words for &W {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        (**self).word(k)
    }
}

/// One primitive in every lane.
pub(crate) struct One<'a, P>(pub &'a P);

impl<P: bytemuck::Pod> Words for One<'_, P> {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        let flat: &[f32] = bytemuck::cast_slice(core::slice::from_ref(self.0));
        L::splat(flat[k])
    }
}

/// Primitive `i` of a SoA block in every lane (a packet of rays against one primitive of a
/// BVH leaf): each word broadcast straight from its row. For the scene walks; not part of the
/// API.
#[doc(hidden)]
pub struct BlockLane<'a> {
    rows: &'a [[f32; BLOCK]],
    i: usize,
}

impl<'a> BlockLane<'a> {
    /// Primitive `i` of a SoA block of `P`.
    ///
    /// # Panics
    /// When `block` has fewer than `P::WORDS` rows or `i >= BLOCK`.
    #[inline(always)]
    pub fn new<P: Primitive>(block: &'a [[f32; BLOCK]], i: usize) -> Self {
        assert!(i < BLOCK, "octoray: a block holds {BLOCK} primitives");
        Self {
            rows: &block[..P::WORDS],
            i,
        }
    }
}

impl Words for BlockLane<'_> {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        L::splat(self.rows[k][self.i])
    }
}

/// The words of `words` with the axes of every point permuted: word `3j + i` is the source's
/// word `3j + axes[i]`. For layouts made of points and vectors (the vertices and normal of a
/// [`VertexTriangle`]): a kernel that works in a ray-dependent axis order (the watertight shear)
/// reads its points already in that order, when every lane shares it, at no cost (the loads'
/// addresses change, not their number).
#[cfg(feature = "triangle")]
pub(crate) struct Permuted<W> {
    /// The source.
    pub words: W,
    /// Source axis of each axis of the result (a permutation of `0, 1, 2`).
    pub axes: [usize; 3],
}

#[cfg(feature = "triangle")]
impl<W: Words> Words for Permuted<W> {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        self.words.word(k - k % 3 + self.axes[k % 3])
    }
}

/// Primitives one after another, padded to 16 (the most lanes) with zero primitives so that reading
/// lane `i` needs no bounds check and no branch.
pub(crate) struct Rows<P>([P; MAX_LANES]);

impl<P: bytemuck::Pod> Words for Rows<P> {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        let n = core::mem::size_of::<P>() / 4;
        let flat: &[f32] = bytemuck::cast_slice(&self.0);
        L::from_fn(|i| <L::Scalar as crate::lanes::Scalar>::from_f32(flat[i * n + k]))
    }
}

/// A SoA block's rows, read from primitive `first` on. For the scene walks; not part of the API.
#[doc(hidden)]
pub struct BlockRows<'a> {
    rows: &'a [[f32; BLOCK]],
    first: usize,
}

impl<'a> BlockRows<'a> {
    /// Primitives `first..` of a SoA block of `P` ([`Primitive::load_block`]'s source).
    ///
    /// # Panics
    /// When `block` has fewer than `P::WORDS` rows.
    #[inline(always)]
    pub fn new<P: Primitive>(block: &'a [[f32; BLOCK]], first: usize) -> Self {
        Self {
            rows: &block[..P::WORDS],
            first,
        }
    }
}

impl Words for BlockRows<'_> {
    #[inline(always)]
    fn word<L: Lanes>(&self, k: usize) -> L {
        let row = &self.rows[k];
        // At BLOCK or more lanes `first` is 0 (a block fills one call): a plain load.
        let first = if L::LANES >= BLOCK { 0 } else { self.first };
        L::from_fn(|i| {
            let j = first + i;
            <L::Scalar as crate::lanes::Scalar>::from_f32(if j < BLOCK { row[j] } else { 0.0 })
        })
    }
}

/// The first `min(len, 16)` primitives, then zero primitives.
#[inline(always)]
fn padded<P: bytemuck::Pod>(prims: &[P]) -> [P; MAX_LANES] {
    let mut a = [P::zeroed(); MAX_LANES];
    let n = prims.len().min(MAX_LANES);
    a[..n].copy_from_slice(&prims[..n]);
    a
}

#[cfg(all(test, feature = "triangle"))]
mod tests {
    extern crate std;
    use super::{f32_at_or_above, f32_at_or_below};

    /// The outward roundings equal `next_down`/`next_up` of the nearest f32 where it lies past
    /// `x`: at f64 values between and on f32s of every scale and sign, ±0, the subnormals and
    /// beyond f32's range.
    #[test]
    fn outward_roundings_bracket_every_value() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut values = std::vec![
            0.0f64,
            -0.0,
            f64::from(f32::MAX) * 2.0,
            -f64::from(f32::MAX) * 2.0
        ];
        for _ in 0..200_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let f = f32::from_bits(seed as u32);
            if !f.is_finite() {
                continue;
            }
            let g = f as f64;
            // The f32 itself, and points a little off it either way (halfway included).
            let ulp = (f.next_up() as f64 - g)
                .abs()
                .max((g - f.next_down() as f64).abs());
            let frac = (seed >> 40) as f64 / (1u64 << 24) as f64;
            values.extend([
                g,
                g + ulp * frac,
                g - ulp * frac,
                g + ulp / 2.0,
                g - ulp / 2.0,
            ]);
        }
        for x in values {
            let n = x as f32;
            let below = if n as f64 > x { n.next_down() } else { n };
            let above = if (n as f64) < x { n.next_up() } else { n };
            assert_eq!(f32_at_or_below(x).to_bits(), below.to_bits(), "{x:e}");
            assert_eq!(f32_at_or_above(x).to_bits(), above.to_bits(), "{x:e}");
            assert!(
                f32_at_or_below(x) as f64 <= x && f32_at_or_above(x) as f64 >= x,
                "{x:e}"
            );
        }
    }
}
