//! The walk of one packet: the active mask goes down the tree together, a coherent packet's
//! frustum first and its children in the node's order for the packet's direction octant (an
//! incoherent packet's sorted by the entry distance of their first entering lane); few lanes
//! left continue ray by ray ([`super::single`]).

use super::epilog::PacketBest;
use super::leaf::{Leaf, Members, Prims};
use super::single::trace_single_outlined;
use super::slab::{extreme_lane, slab, BoxRay, Frustum};
use arrayvec::ArrayVec;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref, STACK, WIDTH};
use octoray_core::hit::{barycentrics, HitFilter};
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{LaneMask, Lanes, Scalar, V3};
use octoray_core::prim::RayLanes;
use octoray_core::query::ClosestHit;
use wide::{f32x8, u32x8};

/// A stack entry: a child slot's reference (`count == 0`: inner node) and where the ray enters.
#[derive(Clone, Copy)]
struct Entry<N> {
    child: u32,
    count: u32,
    near: N,
}

/// Bit `s` set where slot `s` of a node (its rows: lo x, y, z, hi x, y, z, child, count) is
/// empty: `child == EMPTY` is a validated tree's only child reference with its sign bit set, so
/// one movemask of the child row finds them all.
#[cfg_attr(not(debug_assertions), inline(always))]
fn empty_slots(rows: &[[f32; WIDTH]; 9]) -> u32 {
    f32x8::from(rows[6]).to_bitmask()
}

/// Live lanes at or below which a packet continues ray by ray: a quarter of the lanes, at most
/// 2, for packets of 16 and for packets of 8 without a frustum; never for a coherent packet of 8
/// (with a frustum) or of 4, which run faster as a packet to the end than with each remaining
/// lane's setup for the single-ray walk (`docs/scenes.md`).
#[cfg_attr(not(debug_assertions), inline(always))]
fn hybrid_threshold<L: Lanes>(coherent: bool) -> u32 {
    if L::LANES >= 16 || (L::LANES >= 8 && !coherent) {
        (L::LANES as u32 / 4).min(2)
    } else {
        0
    }
}

/// The largest of the lanes of `x` set in `m` as f32 (NaN when one of them is NaN; −inf when
/// `m` is empty).
#[cfg_attr(not(debug_assertions), inline(always))]
fn largest<L: Lanes>(x: L, m: L::Mask) -> f32 {
    if (m & !x.ge(x)).any() {
        return f32::NAN;
    }
    extreme_lane(x, m, true)
}

/// A packet (`br` prepared from `rays`) down the tree of `nodes` from node `start` (0: the root), its leaves
/// handled by `leaf`; `best` carries the hits so far in and the best ones out. `ANY` stops
/// lanes at their first hit.
#[allow(clippy::too_many_arguments)] // the walk's state
#[inline]
pub(crate) fn packet_walk<L: Lanes, T: Leaf<L>, F: HitFilter, const ANY: bool>(
    nodes: &[Bvh8Node],
    leaf: &T,
    pre: &T::Pre,
    rays: &RayLanes<L>,
    br: &BoxRay<L>,
    start: u32,
    best: &mut PacketBest<L>,
    filter: &mut F,
    ray_base: u32,
) {
    if nodes.is_empty() || br.valid.none() {
        return;
    }
    // Coherent f32 packets test a node's eight boxes against the packet's frustum first, and
    // the packet lane by lane only against the children that pass.
    let frustum = Frustum::new(br);
    let octant = frustum.as_ref().map(Frustum::octant);
    let nan = L::splat(f32::NAN);
    let mut stack = ArrayVec::<Entry<L>, STACK>::new();
    stack.push(Entry {
        child: start,
        count: 0,
        near: L::select(br.valid, L::splat(f32::NEG_INFINITY), nan),
    });
    // The frustum's t_max: the largest valid lane's `cull`, recomputed when `cull` has moved.
    let mut cull_max = f32::NAN;
    best.moved = true;
    let threshold = hybrid_threshold::<L>(frustum.is_some());
    while let Some(e) = stack.pop() {
        let mut live = e.near.le(best.cull);
        if ANY {
            live = live & !best.mask;
        }
        let bits = live.bitmask();
        if bits == 0 {
            continue;
        }
        if bits.count_ones() <= threshold {
            // Few lanes left here: finish this subtree ray by ray.
            let mut b = bits;
            while b != 0 {
                let i = b.trailing_zeros() as usize;
                b &= b - 1;
                let rl = rays.broadcast_lane(i);
                let lane_br =
                    BoxRay::with_slack(&RayLanes::<f32x8>::broadcast(&rays.ray(i)), br.slack);
                let mut one = best.lane(i);
                let hit = trace_single_outlined::<L, T, F, ANY>(
                    nodes,
                    leaf,
                    &leaf.prepare(&rl),
                    &rl,
                    &lane_br,
                    (e.child, e.count),
                    &mut one,
                    filter,
                    ray_base + i as u32,
                );
                if ANY {
                    if hit {
                        best.mask = best.mask | L::mask_from_bits(1 << i);
                    }
                } else if let Some(o) = one {
                    best.set(L::mask_from_bits(1 << i), &o, rays.t_max);
                }
            }
            continue;
        }
        if e.count > 0 {
            leaf.packet::<F, ANY>(
                pre,
                e.child as usize,
                e.count as usize,
                rays,
                live,
                best,
                filter,
                ray_base,
            );
            continue;
        }
        let node = &nodes[e.child as usize];
        let passed = match &frustum {
            Some(f) => {
                if best.moved {
                    cull_max = largest(best.cull, br.valid);
                    best.moved = false;
                }
                f.children(bytemuck::cast_ref(node), cull_max)
            }
            None => u32::MAX,
        };
        // The used children the frustum keeps.
        let todo = passed & !empty_slots(bytemuck::cast_ref(node)) & ((1 << WIDTH) - 1);
        // Child `s`'s entry distances where a live lane enters it (NaN elsewhere), if one does.
        let enter = |s: usize| {
            let lo = V3::splat([node.lo[0][s], node.lo[1][s], node.lo[2][s]]);
            let hi = V3::splat([node.hi[0][s], node.hi[1][s], node.hi[2][s]]);
            let (m, near) = slab(lo, hi, br, best.cull);
            let m = m & live;
            m.any().then(|| (m, L::select(m, near, nan)))
        };
        match octant {
            // A coherent packet: the node's order for its octant. Bit `j` set where the
            // octant's `j`-th slot is to be tested; the last pushed first, so that the nearest
            // is popped first.
            Some(o) if !ANY => {
                let order = u32x8::new(node.order).unbounded_shr_scalar(3 * o) & u32x8::splat(7);
                let mut bits = (u32x8::splat(todo).unbounded_shr(order) << 31u32).to_bitmask();
                while bits != 0 {
                    let j = 31 - bits.leading_zeros() as usize;
                    bits &= !(1 << j);
                    let s = (node.order[j & (WIDTH - 1)] >> (3 * o) & 7) as usize;
                    if let Some((_, near)) = enter(s) {
                        stack.push(Entry {
                            child: node.child[s],
                            count: node.count[s],
                            near,
                        });
                    }
                }
            }
            _ => push_sorted::<L, ANY>(node, todo, enter, &mut stack),
        }
    }
}

/// Pushes the children `todo` of `node` that `enter` finds some live lane entering (with its
/// entry distances) for a packet without a frustum: sorted by the entry distance of the first
/// entering lane (a representative ray), the nearest last so that it is popped first.
/// Occlusion needs no order: children go on as they come. The order affects speed only, never
/// the answer.
#[cfg_attr(not(debug_assertions), inline(always))]
fn push_sorted<L: Lanes, const ANY: bool>(
    node: &Bvh8Node,
    todo: u32,
    enter: impl Fn(usize) -> Option<(L::Mask, L)>,
    stack: &mut ArrayVec<Entry<L>, STACK>,
) {
    let mut nears = [L::splat(f32::NAN); WIDTH];
    let mut keys = [0.0f32; WIDTH];
    let mut order = [0u8; WIDTH];
    let mut n = 0;
    let mut todo = todo;
    while todo != 0 {
        let s = todo.trailing_zeros() as usize;
        todo &= todo - 1;
        let Some((m, near)) = enter(s) else {
            continue;
        };
        nears[s] = near;
        let key = if ANY {
            0.0
        } else {
            near.lane(m.bitmask().trailing_zeros() as usize).to_f32()
        };
        keys[s] = key;
        let mut j = n;
        while !ANY && j > 0 && keys[order[j - 1] as usize] < key {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = s as u8;
        n += 1;
    }
    for &s in &order[..n] {
        let s = s as usize;
        stack.push(Entry {
            child: node.child[s],
            count: node.count[s],
            near: nears[s],
        });
    }
}

/// A packet through geometry `bvh` (hits reported as geometry `geom` of instance `inst`) from
/// the root, `best` carried in and out.
#[cfg_attr(not(debug_assertions), inline(always))]
pub(crate) fn run_packet<
    L: Lanes,
    K: Kernel<L>,
    F: HitFilter,
    const ANY: bool,
    const MANY: bool,
>(
    bvh: Bvh8Ref<'_, K::Prim>,
    (geom, inst, members): (u32, u32, Members<'_>),
    node: u32,
    rays: &RayLanes<L>,
    best: &mut PacketBest<L>,
    filter: &mut F,
    ray_base: u32,
) {
    if bvh.nodes().is_empty() {
        return;
    }
    let br = BoxRay::new(rays);
    if br.valid.none() {
        return;
    }
    let leaf = Prims::<L, K, MANY> {
        bvh,
        geom,
        inst,
        members,
    };
    packet_walk::<L, _, F, ANY>(
        bvh.nodes(),
        &leaf,
        &leaf.prepare(rays),
        rays,
        &br,
        node,
        best,
        filter,
        ray_base,
    );
}

/// The packet's best hits as reported.
pub(crate) fn packet_result<L: Lanes>(b: &PacketBest<L>) -> ClosestHit<L> {
    let (u, v) = barycentrics(b.u, b.v, b.scale);
    ClosestHit {
        mask: b.mask,
        t: b.t,
        u,
        v,
        prim: b.prim,
        geom: b.geom,
        inst: b.inst,
    }
}
