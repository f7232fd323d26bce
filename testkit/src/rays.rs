//! Ray sets shared by the BVH and box-test suites.

use crate::Rng;
use octoray::glam::Vec3;
use octoray::prim::Ray;

/// Coherent groups of 16 rays (every width's packets inside one group): one origin region and
/// one direction octant per group, aimed near one target, as camera packets are, so packet
/// traversal takes its frustum path. Some groups are axis-parallel (the same signed zero in
/// every lane), some lanes have their own ranges, a NaN `t_min` or a NaN direction.
pub fn coherent_rays(
    rng: &mut Rng,
    targets: &[Vec3],
    off: Vec3,
    s: f32,
    groups: usize,
) -> Vec<Ray> {
    let mut out = Vec::with_capacity(16 * groups);
    for _ in 0..groups {
        let o = if rng.below(2) == 0 {
            off + rng.vec3(0.5 * s)
        } else {
            off + rng.vec3(3.0 * s)
        };
        let target = targets[(rng.next_u64() % targets.len() as u64) as usize];
        let mut base = target - o;
        let flat = rng.below(4) == 0;
        if flat {
            // One component zero in every lane, with one sign for the group.
            let k = (rng.next_u64() % 3) as usize;
            let mut d = base.to_array();
            d[k] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
            base = Vec3::from(d);
        }
        let spread = [0.0, 1e-3, 0.05][(rng.next_u64() % 3) as usize];
        for _ in 0..16 {
            let origin = o + rng.vec3(spread * s);
            let jitter = rng.vec3(spread * base.length());
            // The group's signs on every axis (zero components stay the group's zero).
            let dir = Vec3::from(core::array::from_fn::<f32, 3, _>(|k| {
                let b = base[k];
                if b == 0.0 {
                    b
                } else {
                    (b + jitter[k]).abs().copysign(b)
                }
            }));
            let (mut t_min, t_max) = match rng.next_u64() % 6 {
                0 => (rng.range(0.0, 0.5), rng.range(0.5, 2.0)),
                1 => (0.0, 1.0),
                _ => (0.0, f32::INFINITY),
            };
            if rng.below(40) == 0 {
                t_min = f32::NAN;
            }
            let dir = if rng.below(40) == 0 {
                Vec3::new(f32::NAN, 1.0, 0.0)
            } else {
                dir
            };
            out.push(Ray::with_range(origin, dir, t_min, t_max));
        }
    }
    out
}
