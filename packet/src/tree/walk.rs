//! The walks of one tree: one ray, one packet, a slice of rays. What a walk does at a leaf is a
//! [`Leaf`]: test primitives ([`Prims`], here) or enter instances (the scene's top level).

use super::epilog::{accepts, better, bound, Best, PacketBest};
use super::single::{trace_single, trace_single_outlined};
use super::slab::{extreme_lane, slab, BoxRay, Frustum};
use arrayvec::ArrayVec;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref, STACK, WIDTH};
use octoray_core::hit::{barycentrics, AcceptAll, Hit, HitFilter};
use octoray_core::kernels::Kernel;
use octoray_core::lanes::{LaneMask, Lanes, Scalar, V3};
use octoray_core::prim::{BlockLane, BlockRows, Ray, RayLanes, BLOCK};
use octoray_core::query::ClosestHit;
use octoray_core::scene::{Geometry, Member};
use wide::f32x8;

/// What a walk does with the slots `first..first + count` of a leaf.
pub(crate) trait Leaf<L: Lanes> {
    /// What the leaf tests need of a ray or packet, computed once per walk.
    type Pre;
    /// Prepares `rays` (one ray broadcast, or a packet).
    fn prepare(&self, rays: &RayLanes<L>) -> Self::Pre;
    /// One ray (`rl`, broadcast to every lane) against the slots: `best` carries the hit so far
    /// in and the best one out, `t_bound` its [`bound`] (kept equal to it). With `ANY`, returns
    /// `true` at the first accepted hit.
    #[allow(clippy::too_many_arguments)] // the walk's state, passed down once per leaf
    fn single<F: HitFilter, const ANY: bool>(
        &self,
        pre: &Self::Pre,
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        t_bound: &mut L::Scalar,
        filter: &mut F,
        ray_id: u32,
    ) -> bool;
    /// The lanes `live` of a packet against the slots: updates `best` (with `ANY`, a lane's
    /// first accepted hit finishes it).
    #[allow(clippy::too_many_arguments)] // as `single`
    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        pre: &Self::Pre,
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    );
}

/// A tree's leaves: primitives tested with kernel `K`, hits reported for instance `inst` (and
/// geometry `geom` when the tree holds one; with `MANY`, a tree of several geometries, each
/// hit's is found in `members` and counts only where that geometry's mask shares a bit with
/// `mask`: a separate instantiation, so a tree of one geometry pays nothing for it).
pub(crate) struct Prims<'a, L: Lanes, K: Kernel<L>, const MANY: bool> {
    pub bvh: Bvh8Ref<'a, K::Prim>,
    pub geom: u32,
    pub inst: u32,
    pub members: Members<'a>,
}

/// The geometries of a tree of several (empty `members`: one, reported as `Prims::geom`).
#[derive(Clone, Copy)]
pub(crate) struct Members<'a> {
    pub members: &'a [Member],
    pub geoms: &'a [Geometry],
    /// The query's mask and the instance's.
    pub mask: u32,
    /// Every member admitted by `mask`: without a filter, a hit's geometry is found only once
    /// the walk is done ([`UNPLACED`], then [`Members::place`]).
    pub all_admitted: bool,
}

/// `Best::geom` of a hit whose geometry is found after the walk.
pub(crate) const UNPLACED: u32 = u32::MAX;

impl Members<'_> {
    /// One geometry: nothing to find.
    pub const ONE: Self = Members {
        members: &[],
        geoms: &[],
        mask: u32::MAX,
        all_admitted: true,
    };

    /// Geometry and primitive of the tree's primitive `id`, or `None` where the geometry's mask
    /// keeps its hits out.
    #[inline]
    pub fn place(&self, id: u32) -> Option<(u32, u32)> {
        // Members start at 0 in increasing order (validated): the last one starting at or
        // before `id`.
        let k = self.members.partition_point(|x| x.first_prim <= id).max(1) - 1;
        let member = self.members.get(k)?;
        let g = self.geoms.get(member.geom as usize)?;
        (g.mask & self.mask != 0).then(|| (member.geom, id.wrapping_sub(member.first_prim)))
    }
}

impl<L: Lanes, K: Kernel<L>, const MANY: bool> Prims<'_, L, K, MANY> {
    /// Geometry and primitive of the tree's primitive `id` for a walk with filter `F`, or
    /// `None` where the geometry's mask keeps its hits out; `(UNPLACED, id)` when that is left
    /// until the walk is done (no filter, every member admitted).
    #[inline(always)]
    fn place<F: HitFilter>(&self, id: u32) -> Option<(u32, u32)> {
        let m = &self.members;
        if !MANY {
            return Some((self.geom, id));
        }
        if F::ACCEPTS_ALL && m.all_admitted {
            return Some((UNPLACED, id));
        }
        m.place(id)
    }
}

impl<L: Lanes, K: Kernel<L>, const MANY: bool> Leaf<L> for Prims<'_, L, K, MANY> {
    type Pre = K::Pre;

    #[inline(always)]
    fn prepare(&self, rays: &RayLanes<L>) -> K::Pre {
        K::prepare(rays)
    }

    #[inline(always)]
    fn single<F: HitFilter, const ANY: bool>(
        &self,
        pre: &K::Pre,
        first: usize,
        count: usize,
        rl: &RayLanes<L>,
        best: &mut Option<Best<L::Scalar>>,
        t_bound: &mut L::Scalar,
        filter: &mut F,
        ray_id: u32,
    ) -> bool {
        let bvh = self.bvh;
        let t_max = rl.t_max.lane(0);
        let mut ray = *rl;
        // One block at a time (a leaf starts a block: `first` is a multiple of BLOCK); at fewer
        // than BLOCK lanes, a block in several calls. A leaf holds at least one slot, so each
        // loop runs its body before it tests (at BLOCK lanes or more the inner one runs once).
        let end = first + count;
        let mut at = first;
        loop {
            let block = bvh.block_of(at);
            let in_block = (end - at).min(BLOCK);
            let mut sub = 0;
            loop {
                ray.active = L::first_lanes(in_block - sub);
                if !K::EXACT_T_MAX {
                    ray.t_max = L::splat_scalar(*t_bound);
                }
                let rows = BlockRows::new::<K::Prim>(block, sub);
                let h = K::intersect_words(&ray, pre, &rows);
                let mut bits = h.mask.bitmask();
                if ANY && F::ACCEPTS_ALL && bits != 0 && (!MANY || self.members.all_admitted) {
                    return true;
                }
                let mut moved = false;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let id = bvh.ids()[at + sub + i];
                    let Some((geom, prim)) = self.place::<F>(id) else {
                        continue;
                    };
                    let hit = Best::lane(&h, i, id, (prim, geom, self.inst));
                    if (ANY || better(hit.t, hit.inst, hit.id, best))
                        && accepts(filter, &hit, ray_id)
                    {
                        if ANY {
                            return true;
                        }
                        *best = Some(hit);
                        moved = true;
                    }
                }
                if moved {
                    *t_bound = bound(t_max, best);
                }
                sub += L::LANES;
                if L::LANES >= BLOCK || sub >= in_block {
                    break;
                }
            }
            at += BLOCK;
            if at >= end {
                break;
            }
        }
        false
    }

    #[inline(always)]
    fn packet<F: HitFilter, const ANY: bool>(
        &self,
        pre: &K::Pre,
        first: usize,
        count: usize,
        rays: &RayLanes<L>,
        live: L::Mask,
        best: &mut PacketBest<L>,
        filter: &mut F,
        ray_base: u32,
    ) {
        let bvh = self.bvh;
        let mut ray = *rays;
        ray.active = live;
        for k in first..first + count {
            ray.t_max = if K::EXACT_T_MAX {
                rays.t_max
            } else {
                best.cull
            };
            let prim = BlockLane::new::<K::Prim>(bvh.block_of(k), k % BLOCK);
            let h = K::intersect_words(&ray, pre, &prim);
            if h.mask.none() {
                continue;
            }
            let id = bvh.ids()[k];
            let Some((geom, local)) = self.place::<F>(id) else {
                continue;
            };
            let mut m = h.mask & (!best.mask | h.t.lt(best.t));
            let tie = h.mask & best.mask & !h.t.ne(best.t);
            if tie.any() {
                let mut lower = 0;
                let mut tb = tie.bitmask();
                while tb != 0 {
                    let i = tb.trailing_zeros() as usize;
                    tb &= tb - 1;
                    if (self.inst, id) < (L::index_lane(best.inst, i), L::index_lane(best.id, i)) {
                        lower |= 1 << i;
                    }
                }
                m = m | (tie & L::mask_from_bits(lower));
            }
            if !F::ACCEPTS_ALL {
                let (mut mb, mut keep) = (m.bitmask(), 0);
                while mb != 0 {
                    let i = mb.trailing_zeros() as usize;
                    mb &= mb - 1;
                    let hit = Best::lane(&h, i, id, (local, geom, self.inst));
                    if accepts(filter, &hit, ray_base + i as u32) {
                        keep |= 1 << i;
                    }
                }
                m = m & L::mask_from_bits(keep);
            }
            best.mask = best.mask | m;
            best.t = L::select(m, h.t, best.t);
            best.u = L::select(m, h.u, best.u);
            best.v = L::select(m, h.v, best.v);
            best.scale = L::select(m, h.scale, best.scale);
            best.id = L::select_index(m, L::splat_index(id), best.id);
            best.prim = L::select_index(m, L::splat_index(local), best.prim);
            best.geom = L::select_index(m, L::splat_index(geom), best.geom);
            best.unplaced |= geom == UNPLACED && m.any();
            best.inst = L::select_index(m, L::splat_index(self.inst), best.inst);
            if ANY {
                ray.active = ray.active & !best.mask;
                if ray.active.none() {
                    break;
                }
            } else {
                best.cull = L::select(m, best.t.loosen(rays.t_max), best.cull);
                best.moved = true;
            }
        }
    }
}

/// A stack entry: a child slot's reference (`count == 0`: inner node) and where the ray enters.
#[derive(Clone, Copy)]
struct Entry<N> {
    child: u32,
    count: u32,
    near: N,
}

/// `t` rounded to f32 and moved up by an ulp: an f32 box bound no smaller than `t`.
#[inline(always)]
pub(crate) fn f32_bound<S: Scalar>(t: S) -> f32 {
    let x = t.to_f32();
    if x.is_nan() {
        x
    } else {
        x.next_up()
    }
}

/// Bit `s` set where slot `s` of a node (its rows: lo x, y, z, hi x, y, z, child, count) is
/// empty: `child == EMPTY` is a validated tree's only child reference with its sign bit set, so
/// one movemask of the child row finds them all.
#[inline(always)]
fn empty_slots(rows: &[[f32; WIDTH]; 9]) -> u32 {
    f32x8::from(rows[6]).to_bitmask()
}

/// One ray through geometry `bvh` (hits reported as geometry `geom` of instance `inst`) from
/// the root, `best` carried in and out: prepares the ray for [`trace_single`].
#[allow(clippy::too_many_arguments)] // the walk's state
#[inline(always)]
pub(crate) fn run_single<
    L: Lanes,
    K: Kernel<L>,
    F: HitFilter,
    const ANY: bool,
    const MANY: bool,
>(
    bvh: Bvh8Ref<'_, K::Prim>,
    (geom, inst, members): (u32, u32, Members<'_>),
    ray: &Ray,
    best: &mut Option<Best<L::Scalar>>,
    filter: &mut F,
    ray_id: u32,
) -> bool {
    if bvh.nodes().is_empty() {
        return false;
    }
    let rl = RayLanes::<L>::broadcast(ray);
    let br = BoxRay::new(&RayLanes::<f32x8>::broadcast(ray));
    if br.valid.none() {
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
        &leaf.prepare(&rl),
        &rl,
        &br,
        (0, 0),
        best,
        filter,
        ray_id,
    )
}

/// One ray through one tree from the root (geometry 0, instance 0).
fn single<L: Lanes, K: Kernel<L>, F: HitFilter, const ANY: bool>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
    ray_id: u32,
) -> (bool, Option<Best<L::Scalar>>) {
    let mut best = None;
    let any = run_single::<L, K, F, ANY, false>(
        bvh,
        (0, 0, Members::ONE),
        ray,
        &mut best,
        filter,
        ray_id,
    );
    (any, best)
}

/// Closest hit of one ray, leaves tested `L::LANES` primitives at a time with kernel `K`
/// (`L = f32x8` or `f32x16` for the f32 tiers, `f64x4`/`f64x8` for the f64 tier). `prim` is the
/// index in the slice the tree was built from.
pub fn closest_ray<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, ray: &Ray) -> Option<Hit> {
    closest_ray_with::<L, K, _>(bvh, ray, &mut AcceptAll)
}

/// [`closest_ray`] counting only the hits `filter` accepts (the candidate's `ray` is 0).
pub fn closest_ray_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
) -> Option<Hit> {
    single::<L, K, F, false>(bvh, ray, filter, 0)
        .1
        .map(|b| b.hit())
}

/// Does one ray hit anything in `[t_min, t_max]` (occlusion)? Stops at the first hit.
pub fn occluded_ray<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, ray: &Ray) -> bool {
    occluded_ray_with::<L, K, _>(bvh, ray, &mut AcceptAll)
}

/// [`occluded_ray`] counting only the hits `filter` accepts (any-hit with a filter: alpha-tested
/// shadows).
pub fn occluded_ray_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    ray: &Ray,
    filter: &mut F,
) -> bool {
    single::<L, K, F, true>(bvh, ray, filter, 0).0
}

/// Live lanes at or below which a packet continues ray by ray: a quarter of the lanes, at most
/// 2, for packets of 16 and for packets of 8 without a frustum; never for a coherent packet of 8
/// (with a frustum) or of 4, which run faster as a packet to the end than with each remaining
/// lane's setup for the single-ray walk (`docs/scenes.md`).
#[inline(always)]
fn hybrid_threshold<L: Lanes>(coherent: bool) -> u32 {
    if L::LANES >= 16 || (L::LANES >= 8 && !coherent) {
        (L::LANES as u32 / 4).min(2)
    } else {
        0
    }
}

/// The largest of the lanes of `x` set in `m` as f32 (NaN when one of them is NaN; −inf when
/// `m` is empty).
#[inline(always)]
fn largest<L: Lanes>(x: L, m: L::Mask) -> f32 {
    if (m & !x.ge(x)).any() {
        return f32::NAN;
    }
    extreme_lane(x, m, true)
}

/// A packet (`br` prepared from `rays`) down the tree of `nodes` from the root, its leaves
/// handled by `leaf`; `best` carries the hits so far in and the best ones out. `ANY` stops
/// lanes at their first hit.
#[allow(clippy::too_many_arguments)] // the walk's state
pub(crate) fn packet_walk<L: Lanes, T: Leaf<L>, F: HitFilter, const ANY: bool>(
    nodes: &[Bvh8Node],
    leaf: &T,
    pre: &T::Pre,
    rays: &RayLanes<L>,
    br: &BoxRay<L>,
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
    let nan = L::splat(f32::NAN);
    let mut stack = ArrayVec::<Entry<L>, STACK>::new();
    stack.push(Entry {
        child: 0,
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
        // Children entered by some live lane: their entry distances, and slot indices sorted
        // farthest first by key (then pushed, so the nearest is popped first).
        let mut nears = [nan; WIDTH];
        let mut keys = [0.0f32; WIDTH];
        let mut order = [0u8; WIDTH];
        let mut n = 0;
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
        // The used children the frustum keeps, one at a time.
        let mut todo = passed & !empty_slots(bytemuck::cast_ref(node)) & ((1 << WIDTH) - 1);
        while todo != 0 {
            let s = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let lo = V3::splat([node.lo[0][s], node.lo[1][s], node.lo[2][s]]);
            let hi = V3::splat([node.hi[0][s], node.hi[1][s], node.hi[2][s]]);
            let (m, near) = slab(lo, hi, br, best.cull);
            let m = m & live;
            let mb = m.bitmask();
            if mb == 0 {
                continue;
            }
            // Sort key: the entry distance of the first lane that enters (a representative ray
            // of a coherent packet; the order affects speed only, never the answer).
            nears[s] = L::select(m, near, nan);
            let key = if ANY {
                0.0
            } else {
                nears[s].lane(mb.trailing_zeros() as usize).to_f32()
            };
            keys[s] = key;
            let mut j = n;
            // Occlusion needs no order: children go onto the stack as they come.
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
}

/// A packet through geometry `bvh` (hits reported as geometry `geom` of instance `inst`) from
/// the root, `best` carried in and out.
#[inline(always)]
pub(crate) fn run_packet<
    L: Lanes,
    K: Kernel<L>,
    F: HitFilter,
    const ANY: bool,
    const MANY: bool,
>(
    bvh: Bvh8Ref<'_, K::Prim>,
    (geom, inst, members): (u32, u32, Members<'_>),
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
        best,
        filter,
        ray_base,
    );
}

/// A packet through one tree from the root (geometry 0, instance 0).
fn packet<L: Lanes, K: Kernel<L>, F: HitFilter, const ANY: bool>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
    ray_base: u32,
) -> PacketBest<L> {
    let mut best = PacketBest::new(rays.t_max);
    run_packet::<L, K, F, ANY, false>(bvh, (0, 0, Members::ONE), rays, &mut best, filter, ray_base);
    best
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

/// Closest hit per lane of a packet with kernel `K`. Lane by lane equal to
/// [`octoray_core::query::closest`] over the slice the tree was built from (the `prim` lanes are
/// indices into that slice). Lanes that miss hold `t = t_max` and zero barycentrics.
pub fn closest_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> ClosestHit<L> {
    closest_packet_with::<L, K, _>(bvh, rays, &mut AcceptAll)
}

/// [`closest_packet`] counting only the hits `filter` accepts (the candidate's `ray` is its
/// lane).
pub fn closest_packet_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
) -> ClosestHit<L> {
    packet_hits::<L, K, F>(bvh, rays, filter, 0)
}

fn packet_hits<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
    ray_base: u32,
) -> ClosestHit<L> {
    packet_result(&packet::<L, K, F, false>(bvh, rays, filter, ray_base))
}

/// Closest `t` per lane of a packet: the mask of lanes that hit and their nearest `t`, equal to
/// [`closest_packet`]'s.
pub fn closest_t_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> (L::Mask, L) {
    let b = packet::<L, K, AcceptAll, false>(bvh, rays, &mut AcceptAll, 0);
    (b.mask, b.t)
}

/// Lanes of a packet that hit anything in `[t_min, t_max]` (occlusion).
pub fn occluded_packet<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
) -> L::Mask {
    occluded_packet_with::<L, K, _>(bvh, rays, &mut AcceptAll)
}

/// [`occluded_packet`] counting only the hits `filter` accepts (the candidate's `ray` is its
/// lane).
pub fn occluded_packet_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &RayLanes<L>,
    filter: &mut F,
) -> L::Mask {
    packet::<L, K, F, true>(bvh, rays, filter, 0).mask
}

/// Do all rays of a chunk point into one octant (a coherent packet)?
pub(crate) fn coherent(rays: &[Ray]) -> bool {
    let octant = |r: &Ray| {
        (r.dir.x.is_sign_negative() as u8)
            | ((r.dir.y.is_sign_negative() as u8) << 1)
            | ((r.dir.z.is_sign_negative() as u8) << 2)
    };
    rays.iter().all(|r| octant(r) == octant(&rays[0]))
}

/// The closest-hit slice loop of a tree or a scene: chunks of `L::LANES` rays that share a
/// direction octant go to `packet`, the others ray by ray to `single` (each given the index of
/// its first ray).
#[track_caller]
pub(crate) fn closest_slice<L: Lanes, F: HitFilter>(
    rays: &[Ray],
    out: &mut [Option<Hit>],
    filter: &mut F,
    mut packet: impl FnMut(&RayLanes<L>, &mut F, u32) -> PacketBest<L>,
    mut single: impl FnMut(&Ray, &mut F, u32) -> Option<Best<L::Scalar>>,
) {
    check_len("closest", rays.len(), out.len());
    for (c, (chunk, out)) in rays
        .chunks(L::LANES)
        .zip(out.chunks_mut(L::LANES))
        .enumerate()
    {
        let base = (c * L::LANES) as u32;
        if chunk.len() > 1 && coherent(chunk) {
            let h = packet_result(&packet(&RayLanes::load(chunk), filter, base));
            for (i, o) in out.iter_mut().enumerate() {
                *o = h.lane(i);
            }
        } else {
            for (i, (r, o)) in chunk.iter().zip(out).enumerate() {
                *o = single(r, filter, base + i as u32).map(|b| b.hit());
            }
        }
    }
}

/// The occlusion slice loop of a tree or a scene, chunks picked as [`closest_slice`] picks
/// them.
#[track_caller]
pub(crate) fn occluded_slice<L: Lanes, F: HitFilter>(
    rays: &[Ray],
    out: &mut [bool],
    filter: &mut F,
    mut packet: impl FnMut(&RayLanes<L>, &mut F, u32) -> L::Mask,
    mut single: impl FnMut(&Ray, &mut F, u32) -> bool,
) {
    check_len("occluded", rays.len(), out.len());
    for (c, (chunk, out)) in rays
        .chunks(L::LANES)
        .zip(out.chunks_mut(L::LANES))
        .enumerate()
    {
        let base = (c * L::LANES) as u32;
        if chunk.len() > 1 && coherent(chunk) {
            let m = packet(&RayLanes::load(chunk), filter, base).bitmask();
            for (i, o) in out.iter_mut().enumerate() {
                *o = (m >> i) & 1 == 1;
            }
        } else {
            for (i, (r, o)) in chunk.iter().zip(out).enumerate() {
                *o = single(r, filter, base + i as u32);
            }
        }
    }
}

/// Closest hit of every ray: `out[i]` for `rays[i]`. Chunks of `L::LANES` rays that share a
/// direction octant are traced as packets, the others ray by ray; the answers are the same
/// either way.
///
/// # Panics
/// When `out.len() != rays.len()`.
#[track_caller]
pub fn closest<L: Lanes, K: Kernel<L>>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [Option<Hit>],
) {
    closest_with::<L, K, _>(bvh, rays, out, &mut AcceptAll);
}

/// [`closest`] counting only the hits `filter` accepts (the candidate's `ray` is the ray's index
/// in `rays`).
///
/// # Panics
/// When `out.len() != rays.len()`, or `rays.len() > u32::MAX`.
#[track_caller]
pub fn closest_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [Option<Hit>],
    filter: &mut F,
) {
    closest_slice::<L, F>(
        rays,
        out,
        filter,
        |r, f, base| packet::<L, K, F, false>(bvh, r, f, base),
        |r, f, id| single::<L, K, F, false>(bvh, r, f, id).1,
    );
}

/// Occlusion of every ray: `out[i]` for `rays[i]`, packets or single rays as
/// [`closest`] picks them.
///
/// # Panics
/// When `out.len() != rays.len()`.
#[track_caller]
pub fn occluded<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray], out: &mut [bool]) {
    occluded_with::<L, K, _>(bvh, rays, out, &mut AcceptAll);
}

/// [`occluded`] counting only the hits `filter` accepts (the candidate's `ray` is the ray's
/// index in `rays`).
///
/// # Panics
/// When `out.len() != rays.len()`, or `rays.len() > u32::MAX`.
#[track_caller]
pub fn occluded_with<L: Lanes, K: Kernel<L>, F: HitFilter>(
    bvh: Bvh8Ref<'_, K::Prim>,
    rays: &[Ray],
    out: &mut [bool],
    filter: &mut F,
) {
    occluded_slice::<L, F>(
        rays,
        out,
        filter,
        |r, f, base| packet::<L, K, F, true>(bvh, r, f, base).mask,
        |r, f, id| single::<L, K, F, true>(bvh, r, f, id).0,
    );
}

/// Panics unless `out` has one entry per ray and the rays can be numbered by `u32`.
#[track_caller]
fn check_len(what: &str, rays: usize, out: usize) {
    assert_eq!(
        out, rays,
        "octoray {what}: out has {out} entries for {rays} rays"
    );
    assert!(
        u32::try_from(rays).is_ok(),
        "octoray {what}: {rays} rays; rays are numbered by u32"
    );
}
