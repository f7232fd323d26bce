//! The walk of one ray: children tested eight at once, ordered by the node's order for the
//! ray's direction octant, the hit ones left-packed and kept as one stack entry.

use super::epilog::f32_bound;
use super::epilog::{bound, Best};
use super::leaf::{Leaf, Members, Prims};
use super::slab::{slab_planes, BoxRay};
use arrayvec::ArrayVec;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref, MAX_DEPTH, WIDTH};
use octoray_core::hit::HitFilter;
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{Lanes, V3};
use octoray_core::prim::{Ray, RayLanes};
use wide::{f32x8, u32x8};

/// The children of one node that a ray enters and has not visited yet: one stack entry of the
/// walk (each row one vector store), the children gathered near-first, `live` the positions
/// still to visit (never 0 on the stack).
#[derive(Clone, Copy)]
struct Siblings {
    child: u32x8,
    count: u32x8,
    near: f32x8,
    live: u32,
}

/// `LEFT_PACK[m]`: the positions of the bits set in `m`, in increasing order, then 0s: the
/// shuffle that moves the lanes `m` selects to the front.
static LEFT_PACK: [[u32; WIDTH]; 256] = {
    let mut t = [[0; WIDTH]; 256];
    let mut m = 0;
    while m < 256 {
        let (mut i, mut n) = (0, 0);
        while i < WIDTH {
            if m >> i & 1 == 1 {
                t[m][n] = i as u32;
                n += 1;
            }
            i += 1;
        }
        m += 1;
    }
    t
};

/// The children of `node` that the ray enters (the slab test's `hit` lanes; an empty slot among
/// them leads to the next pop), near-first for octant `octant`: (how many, children, counts,
/// entry distances).
///
/// The node's order for the octant permutes the hit mask; the left-pack table turns the
/// permuted mask into the shuffle that gathers the hit children in that order (one index
/// vector, then one shuffle per row).
///
/// Without `near_first` (occlusion, where any order finds a hit) the order is the slots from the
/// last down: it finds an occluder in fewer steps than the octant order (`docs/notes/speed.md`).
#[cfg_attr(not(debug_assertions), inline(always))]
fn ordered(
    node: &Bvh8Node,
    hit: u32x8,
    near: f32x8,
    octant: u32,
    near_first: bool,
) -> (u32, u32x8, u32x8, f32x8) {
    let order = if near_first {
        (u32x8::new(node.order).unbounded_shr_scalar(3 * octant)) & u32x8::splat(7)
    } else {
        u32x8::new([7, 6, 5, 4, 3, 2, 1, 0])
    };
    let bits = hit.shuffle(order).to_bitmask();
    let idx = order.shuffle(u32x8::new(LEFT_PACK[bits as usize & 0xff]));
    (
        bits.count_ones(),
        u32x8::new(node.child).shuffle(idx),
        u32x8::new(node.count).shuffle(idx),
        near.shuffle(idx),
    )
}

/// One valid ray (`rl`, broadcast to every lane; `br.valid` set) down the tree of `nodes` from
/// the slot reference `start` (child, count), its leaves handled by `leaf`. `best` carries the
/// hit so far in and the final one out. With `ANY`, returns at the first accepted hit (`true`).
///
/// Each node's eight boxes are tested at once on the entry and exit faces picked once per ray
/// ([`slab_planes`]). One child hit: it is visited next. More: they are gathered in the node's
/// order for the ray's octant ([`Bvh8Node::order`]; occlusion: the last slot first), the first visited
/// next and the others kept as one stack entry; a nearer hit drops the stacked children the
/// ray enters beyond it. The order affects speed only, never the answer.
#[allow(clippy::too_many_arguments)] // the walk's state, passed down once per ray
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn trace_single<L: Lanes, T: Leaf<L>, F: HitFilter, const ANY: bool>(
    nodes: &[Bvh8Node],
    leaf: &T,
    pre: &T::Pre,
    rl: &RayLanes<L>,
    br: &BoxRay<f32x8>,
    start: (u32, u32),
    best: &mut Option<Best<L::Scalar>>,
    filter: &mut F,
    ray_id: u32,
) -> bool {
    // Node tests use `slab_planes`, which leaves `valid` to the caller: every caller passes a
    // valid ray.
    debug_assert!(br.valid.all());
    let t_max = rl.t_max.lane(0);
    // Per axis, the entry face's row (0–2 lower, 3–5 upper) and the exit face's, and the octant.
    let neg = [br.neg[0].any(), br.neg[1].any(), br.neg[2].any()];
    let face = |k: usize| if neg[k] { (3 + k, k) } else { (k, 3 + k) };
    let (fx, fy, fz) = (face(0), face(1), face(2));
    let octant = neg[0] as u32 | (neg[1] as u32) << 1 | (neg[2] as u32) << 2;
    // One entry per level holding siblings: a validated tree is at most MAX_DEPTH deep, so
    // pushes never fail.
    let mut stack = ArrayVec::<Siblings, { MAX_DEPTH + 1 }>::new();
    let (mut child, mut count) = start;
    // The kernels' `t_max` ([`bound`]: the best hit's `t` loosened) and the box tests' bound.
    let mut t_bound = bound(t_max, best);
    let mut cull = f32_bound(t_bound);
    loop {
        if count > 0 {
            let found = leaf.single::<F, ANY>(
                pre,
                child as usize,
                count as usize,
                rl,
                best,
                &mut t_bound,
                filter,
                ray_id,
            );
            if ANY && found {
                return true;
            }
            let moved = f32_bound(t_bound);
            if !ANY && moved != cull {
                // A nearer hit: drop the stacked children that the ray enters beyond it, so
                // that pops test nothing. (A NaN bound, from a NaN `t_max`, drops nothing.)
                let keep = f32x8::splat(moved);
                stack.retain(|s| {
                    s.live &= !s.near.simd_gt(keep).to_bitmask();
                    s.live != 0
                });
            }
            cull = moved;
        } else if let Some(node) = nodes.get(child as usize) {
            // An empty slot's reference, `EMPTY`, names no node (a validated tree has fewer
            // than 2³¹): a slot whose box the ray enters though it is empty leads here and on
            // to the next pop, so the slab test needs no empty-slot mask.
            let rows: &[[f32; WIDTH]; 9] = bytemuck::cast_ref(node);
            let row = |i: usize| f32x8::from(rows[i]);
            let (mask, near) = slab_planes(
                V3::new(row(fx.0), row(fy.0), row(fz.0)),
                V3::new(row(fx.1), row(fy.1), row(fz.1)),
                br,
                f32x8::splat(cull),
            );
            let hit = mask.to_bits();
            let bits = hit.to_bitmask();
            if bits & bits.wrapping_sub(1) == 0 {
                if bits != 0 {
                    // One child: visit it next.
                    let s = bits.trailing_zeros() as usize & (WIDTH - 1);
                    (child, count) = (node.child[s], node.count[s]);
                    continue;
                }
            } else {
                let (len, c, k, n) = ordered(node, hit, near, octant, !ANY);
                (child, count) = (c.as_array()[0], k.as_array()[0]);
                stack.push(Siblings {
                    child: c,
                    count: k,
                    near: n,
                    // Position 0 is visited now.
                    live: (1 << len) - 2,
                });
                continue;
            }
        }
        // Pop the nearest sibling left: every one left is entered before the best hit.
        let Some(top) = stack.last_mut() else {
            break;
        };
        let live = top.live;
        let i = live.trailing_zeros() as usize & (WIDTH - 1);
        (child, count) = (top.child.as_array()[i], top.count.as_array()[i]);
        top.live = live & live.wrapping_sub(1);
        if top.live == 0 {
            stack.pop();
        }
    }
    false
}

/// [`trace_single`] as a call of its own: the packet walk's switch to single rays, which would
/// otherwise inline the whole single-ray walk into the packet walk's loop.
#[allow(clippy::too_many_arguments)] // as `trace_single`
#[inline(never)]
pub(crate) fn trace_single_outlined<L: Lanes, T: Leaf<L>, F: HitFilter, const ANY: bool>(
    nodes: &[Bvh8Node],
    leaf: &T,
    pre: &T::Pre,
    rl: &RayLanes<L>,
    br: &BoxRay<f32x8>,
    start: (u32, u32),
    best: &mut Option<Best<L::Scalar>>,
    filter: &mut F,
    ray_id: u32,
) -> bool {
    trace_single::<L, T, F, ANY>(nodes, leaf, pre, rl, br, start, best, filter, ray_id)
}

/// One valid ray prepared for the walk of a tree tested with kernel `K`: its lanes, its box ray
/// and the kernel's precomputation.
pub(crate) struct Prepared<L: Lanes, K: Kernel<L>> {
    rl: RayLanes<L>,
    br: BoxRay<f32x8>,
    pre: K::Pre,
}

impl<L: Lanes, K: Kernel<L>> Prepared<L, K> {
    /// `ray` prepared; `None` when no kernel can hit anything with it (a non-finite or zero
    /// direction, a non-finite origin).
    #[cfg_attr(not(debug_assertions), inline(always))]
    pub(crate) fn new(ray: &Ray) -> Option<Self> {
        let br = BoxRay::new(&RayLanes::<f32x8>::broadcast(ray));
        if br.valid.none() {
            return None;
        }
        let rl = RayLanes::<L>::broadcast(ray);
        Some(Self {
            pre: K::prepare(&rl),
            rl,
            br,
        })
    }
}

/// The prepared ray `p` through geometry `bvh` (hits reported as geometry `geom` of instance
/// `inst`) from node `node` (0: the root), `best` carried in and out ([`trace_single`]).
#[allow(clippy::too_many_arguments)] // the walk's state
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn run_prepared<
    L: Lanes,
    K: Kernel<L>,
    F: HitFilter,
    const ANY: bool,
    const MANY: bool,
>(
    bvh: Bvh8Ref<'_, K::Prim>,
    (geom, inst, members): (u32, u32, Members<'_>),
    node: u32,
    p: &Prepared<L, K>,
    best: &mut Option<Best<L::Scalar>>,
    filter: &mut F,
    ray_id: u32,
) -> bool {
    if bvh.nodes().is_empty() {
        return false;
    }
    let leaf = Prims::<L, K, MANY> {
        bvh,
        geom,
        inst,
        members,
    };
    trace_single::<L, _, F, ANY>(
        bvh.nodes(),
        &leaf,
        &p.pre,
        &p.rl,
        &p.br,
        (node, 0),
        best,
        filter,
        ray_id,
    )
}

/// One ray through geometry `bvh` (hits reported as geometry `geom` of instance `inst`) from
/// node `node` (0: the root), `best` carried in and out: prepares the ray ([`Prepared`]) for
/// [`run_prepared`].
#[allow(clippy::too_many_arguments)] // the walk's state
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn run_single<
    L: Lanes,
    K: Kernel<L>,
    F: HitFilter,
    const ANY: bool,
    const MANY: bool,
>(
    bvh: Bvh8Ref<'_, K::Prim>,
    place: (u32, u32, Members<'_>),
    node: u32,
    ray: &Ray,
    best: &mut Option<Best<L::Scalar>>,
    filter: &mut F,
    ray_id: u32,
) -> bool {
    if bvh.nodes().is_empty() {
        return false;
    }
    match Prepared::<L, K>::new(ray) {
        Some(p) => run_prepared::<L, K, F, ANY, MANY>(bvh, place, node, &p, best, filter, ray_id),
        None => false,
    }
}
