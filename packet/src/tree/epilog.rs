//! What happens to a hit, apart from the test: the filter's verdict and the closest-hit
//! update, for single rays and packets alike.

use octoray_core::hit::{Candidate, Hit, HitFilter, LanesHit};
use octoray_core::lanes::{LaneMask, Lanes, Scalar};

/// A hit of one ray (the best so far, or a candidate): barycentric numerators over `scale`,
/// like the kernels', and where it lies (primitive, geometry, instance).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Best<S> {
    pub t: S,
    pub u: S,
    pub v: S,
    pub scale: S,
    /// Index in the tree's primitive order (what the tie rule compares).
    pub id: u32,
    /// Index in its geometry.
    pub prim: u32,
    pub geom: u32,
    pub inst: u32,
}

impl<S: Scalar> Best<S> {
    /// Lane `i` of a kernel's answer `h`, as the hit on tree primitive `id` (primitive `prim` of
    /// geometry `geom`) of instance `inst`.
    #[inline(always)]
    pub fn lane<L: Lanes<Scalar = S>>(
        h: &LanesHit<L>,
        i: usize,
        id: u32,
        (prim, geom, inst): (u32, u32, u32),
    ) -> Self {
        Self {
            t: h.t.lane(i),
            u: h.u.lane(i),
            v: h.v.lane(i),
            scale: h.scale.lane(i),
            id,
            prim,
            geom,
            inst,
        }
    }

    /// The hit as reported.
    #[inline(always)]
    pub fn hit(&self) -> Hit {
        // As `kernel::barycentrics`: one division, then −0 made +0 (the same bits: rounding to
        // f32 commutes with the sign).
        Hit {
            t: self.t.to_f32(),
            u: (self.u / self.scale).to_f32() + 0.0,
            v: (self.v / self.scale).to_f32() + 0.0,
            prim: self.prim,
            geom: self.geom,
            inst: self.inst,
        }
    }
}

/// `Best::geom` of a hit whose geometry is found after the walk.
pub(crate) const UNPLACED: u32 = u32::MAX;

/// Does a hit at `t` on primitive `id` of instance `inst` replace `best`? Nearer `t`, or equal
/// `t` and a lower (instance, primitive).
#[inline(always)]
pub(crate) fn better<S: Scalar>(t: S, inst: u32, id: u32, best: &Option<Best<S>>) -> bool {
    match best {
        None => true,
        Some(b) => t < b.t || (t == b.t && (inst, id) < (b.inst, b.id)),
    }
}

/// The `t` bound of box tests and kernel calls: the ray's `t_max`, or once there is a hit, its
/// `t` loosened ([`Lanes::loosen`]) so that a later hit at the same `t` is still seen (the tie
/// rule decides).
#[inline(always)]
pub(crate) fn bound<S: Scalar + Lanes>(t_max: S, best: &Option<Best<S>>) -> S {
    match best {
        Some(b) => b.t.loosen(t_max),
        None => t_max,
    }
}

/// Does `filter` accept `hit` for ray `ray`? It sees the values [`Best::hit`] would report.
#[inline(always)]
pub(crate) fn accepts<S: Scalar, F: HitFilter>(filter: &mut F, hit: &Best<S>, ray: u32) -> bool {
    F::ACCEPTS_ALL || filter.accept(&Candidate::from_hit(&hit.hit(), ray))
}

/// Per-lane state of a packet walk: the best hits, and the `t` bound of its box tests.
pub(crate) struct PacketBest<L: Lanes> {
    pub mask: L::Mask,
    pub t: L,
    pub u: L,
    pub v: L,
    pub scale: L,
    pub id: L::Index,
    pub prim: L::Index,
    pub geom: L::Index,
    pub inst: L::Index,
    /// Per lane: `t_max`, or once there is a hit, its `t` loosened (as [`bound`]).
    pub cull: L,
    /// Set when `cull` moved (the frustum recomputes its bound then).
    pub moved: bool,
    /// Set when a lane's best hit may have its geometry left to find after the walk.
    pub unplaced: bool,
}

impl<L: Lanes> PacketBest<L> {
    /// No hit yet, for rays whose `t_max` is `t_max`.
    #[inline(always)]
    pub fn new(t_max: L) -> Self {
        Self {
            mask: L::first_lanes(0),
            t: t_max,
            u: L::zero(),
            v: L::zero(),
            scale: L::splat(1.0),
            id: L::splat_index(0),
            prim: L::splat_index(0),
            geom: L::splat_index(0),
            inst: L::splat_index(0),
            cull: t_max,
            moved: true,
            unplaced: false,
        }
    }

    /// Lane `i`'s best hit.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<Best<L::Scalar>> {
        ((self.mask.bitmask() >> i) & 1 == 1).then(|| Best {
            t: self.t.lane(i),
            u: self.u.lane(i),
            v: self.v.lane(i),
            scale: self.scale.lane(i),
            id: L::index_lane(self.id, i),
            prim: L::index_lane(self.prim, i),
            geom: L::index_lane(self.geom, i),
            inst: L::index_lane(self.inst, i),
        })
    }

    /// Makes `b` the best hit of the lanes in `m` (rays whose `t_max` is `t_max`).
    #[inline(always)]
    pub fn set(&mut self, m: L::Mask, b: &Best<L::Scalar>, t_max: L) {
        self.mask = self.mask | m;
        self.t = L::select(m, L::splat_scalar(b.t), self.t);
        self.u = L::select(m, L::splat_scalar(b.u), self.u);
        self.v = L::select(m, L::splat_scalar(b.v), self.v);
        self.scale = L::select(m, L::splat_scalar(b.scale), self.scale);
        self.id = L::select_index(m, L::splat_index(b.id), self.id);
        self.prim = L::select_index(m, L::splat_index(b.prim), self.prim);
        self.geom = L::select_index(m, L::splat_index(b.geom), self.geom);
        self.inst = L::select_index(m, L::splat_index(b.inst), self.inst);
        self.cull = L::select(m, self.t.loosen(t_max), self.cull);
        self.moved = true;
        self.unplaced |= b.geom == UNPLACED;
    }
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
