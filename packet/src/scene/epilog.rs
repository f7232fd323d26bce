//! What happens to a hit, apart from the test: the filter's verdict and the closest-hit
//! update, for single rays and packets alike.

use super::slab::loosen;
use octoray_core::hit::{Candidate, Hit, HitFilter};
use octoray_core::lanes::Scalar;

/// The best hit of one ray so far (barycentric numerators over `scale`, like the kernels').
#[derive(Clone, Copy, Debug)]
pub(super) struct Best<S> {
    pub t: S,
    pub u: S,
    pub v: S,
    pub scale: S,
    pub id: u32,
}

impl<S: Scalar> Best<S> {
    pub fn hit(&self) -> Hit {
        // As `kernel::barycentrics`: one division, then −0 made +0 (the same bits: rounding to
        // f32 commutes with the sign).
        Hit {
            t: self.t.to_f32(),
            u: (self.u / self.scale).to_f32() + 0.0,
            v: (self.v / self.scale).to_f32() + 0.0,
            prim: self.id,
        }
    }
}

/// Does a hit at `t` on primitive `id` replace `best`? Nearer `t`, or equal `t` and lower index.
#[inline(always)]
pub(super) fn better<S: Scalar>(t: S, id: u32, best: &Option<Best<S>>) -> bool {
    match best {
        None => true,
        Some(b) => t < b.t || (t == b.t && id < b.id),
    }
}

/// The `t` bound of box tests and kernel calls: the ray's `t_max`, or once there is a hit, its
/// `t` loosened so that a later hit at the same `t` is still seen (the tie rule decides).
#[inline(always)]
pub(super) fn bound<S: Scalar>(t_max: S, best: &Option<Best<S>>) -> S {
    match best {
        Some(b) => {
            let l = loosen(b.t);
            if l < t_max {
                l
            } else {
                t_max
            }
        }
        None => t_max,
    }
}

/// Does `filter` accept the kernel's hit at `t` on primitive `id` (barycentric numerators `u`,
/// `v` over `scale`) for ray `ray`? The candidate carries the values [`Best::hit`] would report.
#[inline(always)]
pub(super) fn accepts<S: Scalar, F: HitFilter>(
    filter: &mut F,
    t: S,
    (u, v, scale): (S, S, S),
    id: u32,
    ray: u32,
) -> bool {
    F::ACCEPTS_ALL
        || filter.accept(&Candidate {
            prim: id,
            t: t.to_f32(),
            u: (u / scale).to_f32() + 0.0,
            v: (v / scale).to_f32() + 0.0,
            ray,
        })
}
