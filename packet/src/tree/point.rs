//! Point queries on one tree: [`closest_point`], the primitive nearest to a point within a
//! radius, and [`nearest_within`], the k nearest; nearest boxes first.

use super::all_hits::{insert_sorted, AllHits};
use arrayvec::ArrayVec;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref, PAD, STACK};
use octoray_core::glam::Vec3;
use octoray_core::kernels::{Nearest, NearestPoint};
use octoray_core::lanes::{Lanes, V3};
use octoray_core::prim::{Affine64, BlockLane, BlockRows, BLOCK};
use wide::{f32x8, u32x8};

/// The primitive nearest to a query point, and the point on it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointHit {
    /// The nearest point (computed in f64, rounded to f32).
    pub point: Vec3,
    /// Its distance to the query point (rounded to f32).
    pub dist: f32,
    /// Barycentric weight of `v1` at the point (triangles; 0 for spheres).
    pub u: f32,
    /// Barycentric weight of `v2` at the point (triangles; 0 for spheres).
    pub v: f32,
    /// Index of the primitive in the slice the tree was built from (in a scene: in its
    /// geometry).
    pub prim: u32,
    /// Its geometry (0 in a one-tree query).
    pub geom: u32,
    /// Its instance path (0 in a one-tree query).
    pub inst: u32,
}

/// Where a primitive of a scene lies: its instance path, geometry and index in the geometry,
/// ordered in that order (the order ties in distance are broken in, and box queries list in).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Place {
    /// The instance path it is reached through.
    pub inst: u32,
    /// Its geometry.
    pub geom: u32,
    /// Its index in the geometry's primitives.
    pub prim: u32,
}

impl Place {
    /// Primitive `id` of a one-tree query.
    fn prim(id: u32) -> Self {
        Self {
            inst: 0,
            geom: 0,
            prim: id,
        }
    }
}

/// A stack entry: a child's reference and count (as in [`octoray_core::bvh::Bvh8Node`]) and a
/// lower bound on its box's squared distance.
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    count: u32,
    d2: f32,
}

/// The best so far: its answer and place, the squared radius before the first one.
pub(crate) struct Best {
    found: Option<(Nearest, Place)>,
    d2: f64,
    /// The f32 bound a box's rounded squared distance is compared with: `d2` raised by 2⁻¹⁹,
    /// more than the box distance's rounding (a few units of 2⁻²⁴), so no box is skipped that
    /// could hold a nearer primitive.
    cull: f32,
}

/// What a point walk gathers: offered every primitive whose box is near enough, it says how
/// near a box must be to still matter.
pub(crate) trait Sink {
    /// The f32 bound a box's rounded squared distance is compared with (raised above the exact
    /// bound by more than the box distance's rounding, so no box that matters is skipped).
    fn cull(&self) -> f32;
    /// Offers the primitive at `at`, its nearest point `n`.
    fn offer(&mut self, n: Nearest, at: Place);
}

/// `d2` raised by 2⁻¹⁹, more than a box distance's rounding (a few units of 2⁻²⁴).
pub(crate) fn cull_of(d2: f64) -> f32 {
    (d2 * (1.0 + 1.0 / 524_288.0)) as f32
}

impl Sink for Best {
    fn cull(&self) -> f32 {
        self.cull
    }

    /// Keeps `n` at `at` when nearer, or as near and of a lower place (within the radius: at
    /// most `d2` before the first).
    fn offer(&mut self, n: Nearest, at: Place) {
        if !n.dist2.is_finite() {
            return;
        }
        let better = match self.found {
            None => n.dist2 <= self.d2,
            Some((b, bat)) => n.dist2 < b.dist2 || (n.dist2 == b.dist2 && at < bat),
        };
        if better {
            *self = Self::new(Some((n, at)), n.dist2);
        }
    }
}

impl Best {
    /// Nothing found yet within `max_dist`.
    pub fn within(max_dist: f32) -> Self {
        Self::new(None, f64::from(max_dist) * f64::from(max_dist))
    }

    /// The answer.
    pub fn hit(&self) -> Option<PointHit> {
        self.found.map(|(n, at)| point_hit(&n, at))
    }

    /// The best `found` at squared distance `d2`.
    fn new(found: Option<(Nearest, Place)>, d2: f64) -> Self {
        Self {
            found,
            d2,
            cull: cull_of(d2),
        }
    }
}

/// The reported form of the nearest point `n` of the primitive at `at`.
fn point_hit(n: &Nearest, at: Place) -> PointHit {
    let f = |x: [f64; 3]| Vec3::from_array(x.map(|c| c as f32));
    PointHit {
        point: f(n.point),
        dist: Lanes::sqrt(n.dist2) as f32,
        u: n.u as f32 + 0.0,
        v: n.v as f32 + 0.0,
        prim: at.prim,
        geom: at.geom,
        inst: at.inst,
    }
}

/// The nearest `out.len()` primitives within a radius, in order of their reported distance,
/// then place.
pub(crate) struct KNearest<'o> {
    out: &'o mut [PointHit],
    found: AllHits,
    r2: f64,
    cull: f32,
}

impl Sink for KNearest<'_> {
    fn cull(&self) -> f32 {
        self.cull
    }

    fn offer(&mut self, n: Nearest, at: Place) {
        if !n.dist2.is_finite() || n.dist2 > self.r2 {
            return;
        }
        if self.out.is_empty() {
            // No room: one primitive within the radius is an answer left out; stop looking.
            self.found.complete = false;
            self.cull = -1.0;
            return;
        }
        let place = |h: &PointHit| (h.inst, h.geom, h.prim);
        let order =
            |a: &PointHit, b: &PointHit| a.dist.total_cmp(&b.dist).then(place(a).cmp(&place(b)));
        insert_sorted(self.out, &mut self.found, point_hit(&n, at), order);
        if self.found.stored == self.out.len() {
            self.found.complete = false;
            // Full: only primitives as near as the last one kept still matter (its distance
            // rounded; an ulp above it covers every exact distance that rounds to it).
            let last = f64::from(self.out[self.found.stored - 1].dist.next_up());
            self.cull = self.cull.min(cull_of(last * last));
        }
    }
}

/// The primitive of `bvh` nearest to `point` whose distance is at most `max_dist`, the point on
/// it, its barycentrics and distance (`None` when none is that near, for a non-finite point and
/// for a NaN or negative `max_dist`; `f32::INFINITY` is no limit). Ties in distance go to the
/// lower primitive index. Triangles are surfaces and spheres their surface: a point inside a
/// sphere is at its distance from the surface.
///
/// # Accuracy
/// Each primitive's distance is computed in f64 from the f32 inputs
/// ([`octoray_core::kernels::NearestPoint`]): the nearest primitive is the exact one unless
/// another's squared distance is within a few units of 2⁻⁵² of it, relative; the point and
/// distance round to f32 within about an ulp of the exact ones.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::Bvh8, glam::Vec3, prim::VertexTriangle};
/// use octoray_packet::tree::closest_point;
/// let tris = [VertexTriangle::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0))];
/// let bvh = Bvh8::build(&tris);
/// let hit = closest_point(bvh.as_ref(), Vec3::new(0.5, 0.5, 3.0), f32::INFINITY).unwrap();
/// assert_eq!((hit.point, hit.dist, hit.u, hit.v), (Vec3::new(0.5, 0.5, 0.0), 3.0, 0.25, 0.25));
/// assert!(closest_point(bvh.as_ref(), Vec3::new(0.5, 0.5, 3.0), 2.5).is_none());
/// # }
/// ```
pub fn closest_point<P: NearestPoint>(
    bvh: Bvh8Ref<'_, P>,
    point: Vec3,
    max_dist: f32,
) -> Option<PointHit> {
    if !point.is_finite() || max_dist.is_nan() || max_dist < 0.0 {
        return None;
    }
    let mut best = Best::within(max_dist);
    walk(bvh, point, &mut best);
    best.hit()
}

/// The `out.len()` primitives of `bvh` nearest to `point` within `radius` (inclusive;
/// `f32::INFINITY`: the k nearest), as [`closest_point`] reports each, in order of `dist`, then
/// index; each primitive once. `stored` says how many were written; `complete` is true when the
/// buffer was not filled (they are then all those within `radius`) and false when it was (more
/// may lie within `radius`, none nearer than the last: once the buffer is full the walk looks
/// only as far as its last hit, which is what makes the k nearest cheap); an empty buffer is
/// complete when no primitive lies within `radius`. Nothing for a non-finite point or a NaN or
/// negative radius.
///
/// ```
/// # #[cfg(all(feature = "triangle", feature = "alloc"))] {
/// use octoray_core::{bvh::Bvh8, glam::Vec3, prim::VertexTriangle};
/// use octoray_packet::tree::{nearest_within, PointHit};
/// // Unit triangles at x = 0, 1, …, 9.
/// let tris: Vec<_> = (0..10)
///     .map(|i| {
///         let x = i as f32;
///         VertexTriangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0))
///     })
///     .collect();
/// let bvh = Bvh8::build(&tris);
/// let mut out = [PointHit::default(); 3];
/// let found = nearest_within(bvh.as_ref(), Vec3::new(4.2, 0.1, 0.1), 2.0, &mut out);
/// assert_eq!((found.stored, found.complete), (3, false));
/// assert_eq!(out.map(|h| h.prim), [4, 5, 3]);
/// # }
/// ```
pub fn nearest_within<P: NearestPoint>(
    bvh: Bvh8Ref<'_, P>,
    point: Vec3,
    radius: f32,
    out: &mut [PointHit],
) -> AllHits {
    let mut sink = KNearest::new(out, radius);
    if point.is_finite() && radius >= 0.0 {
        walk(bvh, point, &mut sink);
    }
    sink.found
}

impl<'o> KNearest<'o> {
    /// None found yet within `radius`, room for `out.len()`.
    pub fn new(out: &'o mut [PointHit], radius: f32) -> Self {
        let r2 = f64::from(radius) * f64::from(radius);
        Self {
            found: AllHits {
                stored: 0,
                complete: true,
            },
            out,
            r2,
            cull: cull_of(r2),
        }
    }

    /// What was stored.
    pub fn found(&self) -> AllHits {
        self.found
    }
}

/// The walk of one tree with its primitives measured directly.
fn walk<P: NearestPoint>(bvh: Bvh8Ref<'_, P>, point: Vec3, sink: &mut impl Sink) {
    let p = point.to_array().map(f64::from);
    let mut leaves = PrimLeaves {
        bvh,
        p,
        q: V3::splat(point.to_array()),
        to_world: None,
        sink,
    };
    point_walk(bvh.nodes(), 0, &mut leaves);
}

/// What a point walk does at one tree's leaves, and where it stands.
pub(crate) trait PointLeaves {
    /// The query point in the tree's space.
    fn point(&self) -> V3<f32x8>;
    /// The bound a box's rounded squared distance (in the tree's space) is compared with.
    fn cull(&self) -> f32;
    /// Visits the slots `first..first + count`.
    fn leaf(&mut self, first: u32, count: u32);
}

/// A tree's primitives offered to a sink: measured from `p` as they are, or, placed by
/// `to_world` (an instance's), in world space from the world point `p`.
pub(crate) struct PrimLeaves<'a, 's, P, S> {
    pub bvh: Bvh8Ref<'a, P>,
    pub p: [f64; 3],
    /// `p` in the tree's space, for its box tests.
    pub q: V3<f32x8>,
    pub to_world: Option<&'s Affine64>,
    pub sink: &'s mut S,
}

impl<P: NearestPoint, S: Sink> PointLeaves for PrimLeaves<'_, '_, P, S> {
    fn point(&self) -> V3<f32x8> {
        self.q
    }

    fn cull(&self) -> f32 {
        self.sink.cull()
    }

    /// Offers the leaf's primitives: a block at a time, those whose box is near enough.
    fn leaf(&mut self, first: u32, count: u32) {
        let bvh = self.bvh;
        let first = first as usize;
        let end = (first + count as usize).min(bvh.ids().len());
        let mut start = first;
        while start < end {
            let block = bvh.block_of(start);
            let bound = P::dist2_bound(&BlockRows::new::<P>(block, 0), self.q);
            let lanes = (1u32 << (end - start).min(BLOCK)) - 1;
            let mut near = bound.simd_le(f32x8::splat(self.sink.cull())).to_bitmask() & lanes;
            let bound = bound.to_array();
            while near != 0 {
                let i = near.trailing_zeros() as usize;
                near &= near - 1;
                let id = bvh.ids()[start + i];
                if id == PAD || bound[i] > self.sink.cull() {
                    continue;
                }
                let words = BlockLane::new::<P>(block, i);
                let n = match self.to_world {
                    None => P::nearest_point(&words, self.p),
                    Some(map) => P::nearest_point_mapped(&words, map, self.p),
                };
                self.sink.offer(n, Place::prim(id));
            }
            start += BLOCK;
        }
    }
}

/// The walk of a tree of `nodes` from node `start` (0: the root): boxes near enough for
/// `leaves`, nearest child next, every near leaf visited.
pub(crate) fn point_walk(nodes: &[Bvh8Node], start: u32, leaves: &mut impl PointLeaves) {
    if nodes.is_empty() {
        return;
    }
    let q = leaves.point();
    let mut stack = ArrayVec::<Entry, STACK>::new();
    stack.push(Entry {
        child: start,
        count: 0,
        d2: 0.0,
    });
    while let Some(e) = stack.pop() {
        if e.d2 > leaves.cull() {
            continue;
        }
        if e.count > 0 {
            leaves.leaf(e.child, e.count);
            continue;
        }
        let Some(node) = nodes.get(e.child as usize) else {
            continue;
        };
        // Squared distance to each slot's box (empty slots: +inf); the near ones, far first.
        let axis = |a: usize, x: f32x8| {
            let (lo, hi) = (f32x8::from(node.lo[a]), f32x8::from(node.hi[a]));
            (lo - x).max(x - hi).max(f32x8::ZERO)
        };
        let (dx, dy, dz) = (axis(0, q.x), axis(1, q.y), axis(2, q.z));
        let d2v = dx * dx + dy * dy + dz * dz;
        let near_mask = d2v.simd_le(f32x8::splat(leaves.cull()));
        let mut near = near_mask.to_bitmask();
        if near == 0 {
            continue;
        }
        // The nearest child is visited next (pushed last); the others, in slot order, wait
        // with their distance, which is checked again when they are popped.
        let d2 = d2v.to_array();
        // Non-negative floats order as their bits: the nearest kept slot by an integer
        // minimum, the others set to the largest key.
        let keep: u32x8 = bytemuck::cast(near_mask);
        let keys = (bytemuck::cast::<_, u32x8>(d2v) & keep) | !keep;
        let nearest = (keys.simd_eq(u32x8::splat(keys.reduce_min())).to_bitmask() & near)
            .trailing_zeros() as usize;
        near &= !(1 << nearest);
        let entry = |s: usize| Entry {
            child: node.child[s],
            count: node.count[s],
            d2: d2[s],
        };
        // A validated tree is at most MAX_DEPTH deep, so the stack never fills.
        while near != 0 {
            let s = near.trailing_zeros() as usize;
            near &= near - 1;
            let _ = stack.try_push(entry(s));
        }
        let _ = stack.try_push(entry(nearest));
    }
}
