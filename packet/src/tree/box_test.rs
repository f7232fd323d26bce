//! The conservative box test: the slab test never rejects a box a ray meets (decided exactly by
//! the oracle, on boxes at a ray's decision edge, every scale, huge and signed-zero directions),
//! and a coherent packet's frustum never drops a child some lane's slab test keeps. These are
//! what make the walks equal brute force (`tests/suite/bvh.rs`).
extern crate std;
use octoray_testkit as testkit;
use std::vec::Vec;

use super::slab::{extreme_lane, extremes8, slab, BoxRay, Frustum};
use octoray_core::glam::Vec3;
use octoray_core::lanes::{LaneMask, Lanes, V3};
use octoray_core::prim::{Ray, RayLanes};
use proptest::prelude::*;
use testkit::Rng;
use wide::{f32x16, f32x4, f32x8};

/// Eight vectors of `L` with values of every scale and sign, ±0 and ±inf, and a non-empty mask:
/// [`extremes8`]'s smallest and largest set lane of each equal [`extreme_lane`]'s.
fn extremes_agree<L: Lanes<Scalar = f32>>(rng: &mut Rng) -> Result<(), TestCaseError> {
    let value = |rng: &mut Rng| match rng.below(8) {
        0 => 0.0,
        1 => -0.0,
        2 => f32::INFINITY,
        3 => f32::NEG_INFINITY,
        _ => rng.range(-1.0, 1.0) * 10f32.powf(rng.range(-30.0, 30.0)),
    };
    let x: [L; 8] = core::array::from_fn(|_| L::from_fn(|_| value(rng)));
    let all = ((1u64 << L::LANES) - 1) as u32;
    let bits = (rng.next_u64() as u32 | 1 << rng.below(L::LANES as u64)) & all;
    let m = L::mask_from_bits(bits);
    let (least, most) = extremes8(x, m);
    for j in 0..8 {
        prop_assert_eq!(least[j], extreme_lane(x[j], m, false), "least of {}", j);
        prop_assert_eq!(most[j], extreme_lane(x[j], m, true), "most of {}", j);
    }
    Ok(())
}

proptest! {
    #![proptest_config(octoray_testkit::cases::proptest_config(4096))]
    /// The frustum's batched reductions give every vector's extremes over the set lanes, at
    /// widths 4, 8 and 16 (the padding of narrow packets and the unset lanes change nothing).
    #[test]
    fn batched_extremes_equal_one_reduction_per_vector(seed in any::<u64>()) {
        let mut rng = Rng(seed);
        extremes_agree::<f32x4>(&mut rng)?;
        extremes_agree::<f32x8>(&mut rng)?;
        extremes_agree::<f32x16>(&mut rng)?;
    }

    /// The packet frustum never drops a child some valid lane's slab test keeps: random nodes
    /// (boxes at any scale, empty slots, flat boxes) against coherent packets (shared signs,
    /// zero components, NaN ranges and directions in some lanes), every t_max.
    #[test]
    #[allow(clippy::needless_range_loop)] // children are columns of the node's rows
    fn frustum_keeps_every_child_a_lane_enters(seed in any::<u64>()) {
        let mut rng = Rng(seed);
        let s = 10f32.powf(rng.range(-6.0, 6.0));
        let off = rng.vec3(1.0) * 10f32.powf(rng.range(-3.0, 6.0));
        let target = off + rng.vec3(s);
        let rays = testkit::rays::coherent_rays(&mut rng, &[target], off, s, 1);
        let rays = &rays[..8];
        let packet = RayLanes::<f32x8>::load(rays);
        let br = BoxRay::new(&packet);
        let Some(f) = Frustum::new(&br) else {
            // Only when no lane is valid (the group shares its signs).
            prop_assert!(br.valid.none());
            return Ok(());
        };
        let valid: Vec<usize> = (0..8).filter(|i| (br.valid.bitmask() >> i) & 1 == 1).collect();
        // Boxes at the decision boundary of some lane: around, or with a face through, a point
        // of that lane's ray, nudged by 0 to 2^-14 of its magnitude, some of them points or
        // flat; and empty slots.
        let mut node = [[0.0f32; 8]; 9];
        let mut t_at = [0.0f32; 8];
        for c in 0..8 {
            if rng.below(10) == 0 {
                for k in 0..3 {
                    node[k][c] = f32::INFINITY;
                    node[3 + k][c] = f32::NEG_INFINITY;
                }
                continue;
            }
            let r = rays[valid[(rng.next_u64() % valid.len() as u64) as usize]];
            let t = rng.range(0.0, 2.0) * s / r.dir.length().max(1e-30);
            t_at[c] = t;
            let p = r.at(t);
            let m = p.abs().max_element().max(f32::MIN_POSITIVE);
            let nudge = [0.0, 1.0 / 1_048_576.0, 1.0 / 131_072.0, 1.0 / 16_384.0]
                [(rng.next_u64() % 4) as usize];
            let p = p + rng.vec3(m * nudge);
            let e = match rng.next_u64() % 4 {
                0 => Vec3::ZERO,
                1 => rng.vec3(m * 1e-6).abs(),
                _ => rng.vec3(s * 0.01).abs(),
            };
            let face = rng.below(2) == 0;
            for k in 0..3 {
                let (lo, hi) = if face { (p[k], p[k] + e[k]) } else { (p[k] - e[k], p[k] + e[k]) };
                node[k][c] = lo;
                node[3 + k][c] = hi;
            }
            if rng.below(2) == 0 {
                // Beside the ray on one axis, at the edge of what the slab test keeps: the
                // origin's slack plus a few multiples of the widening.
                let k = (rng.next_u64() % 3) as usize;
                let slack = r.origin.abs().max_element() / 131_072.0;
                let gap = slack + m * 3.6e-7 * rng.range(0.0, 4.0);
                if rng.below(2) == 0 {
                    node[k][c] = p[k] + gap;
                    node[3 + k][c] = p[k] + gap + e[k];
                } else {
                    node[k][c] = p[k] - gap - e[k];
                    node[3 + k][c] = p[k] - gap;
                }
            }
        }
        for round in 0..4 {
            // Per-lane bounds (a closest-hit packet's `cull`): infinite, at a child's point,
            // just before or after it, or NaN; the frustum gets the largest (NaN if any is).
            let cull: [f32; 8] = core::array::from_fn(|_| {
                let t = t_at[(rng.next_u64() % 8) as usize];
                match (rng.next_u64() + round) % 6 {
                    0 => f32::INFINITY,
                    1 => t,
                    2 => t * (1.0 - 1.0 / 1_048_576.0),
                    3 => t * (1.0 + 1.0 / 1_048_576.0),
                    4 if rng.below(8) == 0 => f32::NAN,
                    _ => t * 0.5,
                }
            });
            let t_max = valid.iter().fold(f32::NEG_INFINITY, |m, &i| {
                if m.is_nan() || cull[i].is_nan() { f32::NAN } else { m.max(cull[i]) }
            });
            let passed = f.children(&node, t_max);
            for c in 0..8 {
                let lo = V3::<f32x8>::splat([node[0][c], node[1][c], node[2][c]]);
                let hi = V3::<f32x8>::splat([node[3][c], node[4][c], node[5][c]]);
                let lanes = slab(lo, hi, &br, f32x8::from(cull)).0.bitmask();
                prop_assert!(
                    lanes == 0 || (passed >> c) & 1 == 1,
                    "child {c} dropped, lanes {lanes:#b} enter, t_max {t_max}"
                );
            }
        }
    }
}

/// One case of [`slab_test_keeps_every_box_the_ray_meets`]: a ray and a box at its decision edge,
/// or `None` when the draw is unusable. The ray's point `p` is computed in f64 and rounded once,
/// so the exact crossing distances lie between f32 values (from a representable `t` they would
/// all round back to it).
fn slab_case(rng: &mut Rng) -> Option<(Ray, Vec3, Vec3)> {
    // Box scale, distance to the box, direction length; a quarter of the cases with huge
    // directions and distances in the subnormal range of t (where a rounding is off by up to
    // 2⁻¹⁵⁰ whatever the value).
    let (s, dist, len) = if rng.below(4) == 0 {
        let len = 10f32.powf(rng.range(30.0, 37.0));
        let dist = len * 10f32.powf(rng.range(-40.0, -38.8));
        (dist * 10f32.powf(rng.range(-3.0, 0.0)), dist, len)
    } else {
        let s = 10f32.powf(rng.range(-6.0, 6.0));
        let dist = s * 10f32.powf(rng.range(0.0, 4.0));
        (s, dist, 10f32.powf(rng.range(-3.0, 3.0)))
    };
    // The origin at 0 (no origin slack), or small or large against the distance.
    let origin = match rng.below(3) {
        0 => Vec3::ZERO,
        1 => rng.vec3(dist * 1e-4),
        _ => {
            let m = dist * 10f32.powf(rng.range(-3.0, 1.0));
            rng.vec3(m)
        }
    };
    let unit = rng.vec3(1.0);
    if unit.length() < 1e-6 {
        return None;
    }
    let dir = unit * len;
    let t = f64::from(dist) / f64::from(unit.length()) / f64::from(len)
        * (1.0 + f64::from(rng.range(0.0, 1.0)));
    // A quarter of the boxes behind the origin, reached by a negative t_min (there the
    // reciprocals' widening moves distances the other way and the ray's pad covers it).
    let behind = rng.below(4) == 0;
    let t = if behind { -t } else { t };
    let p = (origin.as_dvec3() + dir.as_dvec3() * t).as_vec3();
    // Per axis: p on the lower face, the upper face, or inside.
    let (mut lo, mut hi) = (p, p);
    for k in 0..3 {
        let e = s * rng.range(0.0, 1.0);
        match rng.below(3) {
            0 => hi[k] = p[k] + e,
            1 => lo[k] = p[k] - e,
            _ => (lo[k], hi[k]) = (p[k] - e, p[k] + e),
        }
    }
    if rng.below(2) == 0 {
        // Through an edge: the ray enters axis a's slab and leaves axis b's at p (near and far
        // equal but for roundings).
        let a = rng.below(3) as usize;
        let b = (a + 1 + rng.below(2) as usize) % 3;
        let e = s * rng.range(0.0, 1.0);
        (lo[a], hi[a]) = if dir[a] >= 0.0 {
            (p[a], p[a] + e)
        } else {
            (p[a] - e, p[a])
        };
        (lo[b], hi[b]) = if dir[b] >= 0.0 {
            (p[b] - e, p[b])
        } else {
            (p[b], p[b] + e)
        };
    }
    // One face of one axis moved by 0 to 3 ulps either way.
    let k = rng.below(3) as usize;
    for _ in 0..rng.below(4) {
        match rng.below(4) {
            0 => lo[k] = lo[k].next_up(),
            1 => lo[k] = lo[k].next_down(),
            2 => hi[k] = hi[k].next_up(),
            _ => hi[k] = hi[k].next_down(),
        }
    }
    if lo[k] > hi[k] {
        return None;
    }
    // Ranges ending at the box, just before it, or not at all; behind the origin, ranges
    // starting at the box, just after it, or well before it, and ending at 0, past the box or
    // nowhere.
    let t = t as f32;
    let (t_min, t_max) = if behind {
        let t_min = match rng.below(3) {
            0 => t,
            1 => t.next_up(),
            _ => t * 2.0,
        };
        let t_max = match rng.below(3) {
            0 => f32::INFINITY,
            1 => 0.0,
            _ => t * 0.5,
        };
        (t_min, t_max)
    } else {
        let t_max = match rng.below(4) {
            0 => f32::INFINITY,
            1 => t,
            2 => t.next_down(),
            _ => t * 2.0,
        };
        (0.0, t_max)
    };
    Some((Ray::with_range(origin, dir, t_min, t_max), lo, hi))
}

proptest! {
    #![proptest_config(octoray_testkit::cases::proptest_config(8192))]
    /// The slab test keeps every box the ray meets, decided exactly (`oracle::box_meets`), on
    /// boxes at a ray's decision edge ([`slab_case`], 16 per seed): a corner, an edge or a face
    /// through a point of the ray, then moved by up to 3 ulps; every scale, huge directions,
    /// boxes behind the origin in a range with a negative `t_min`. It fails without the
    /// reciprocals' widening and without the pad's `t_min` term. (The pad's absolute part
    /// covers roundings in the subnormal range of `t`; on every case drawn here the
    /// reciprocals' widening happens to cover them too.)
    #[test]
    fn slab_test_keeps_every_box_the_ray_meets(seed in any::<u64>()) {
        let mut rng = Rng(seed);
        for _ in 0..16 {
            let Some((ray, lo, hi)) = slab_case(&mut rng) else {
                continue;
            };
            let truth = testkit::oracle::box_meets(&ray, lo, hi);
            let br = BoxRay::<f32>::new(&RayLanes::single(&ray));
            let (lo3, hi3) = (V3::<f32>::splat(lo.to_array()), V3::<f32>::splat(hi.to_array()));
            let (kept, _) = slab(lo3, hi3, &br, ray.t_max);
            prop_assert!(
                truth != Some(true) || kept,
                "box {lo} {hi} rejected; ray {} {}, t_max {}",
                ray.origin,
                ray.dir,
                ray.t_max
            );
        }
    }
}

#[test]
fn slab_test_keeps_rays_in_a_face_plane_and_handles_signed_zero_and_subnormal_directions() {
    let lo = V3::<f32>::splat([0.0, 0.0, 0.0]);
    let hi = V3::<f32>::splat([1.0, 1.0, 1.0]);
    let ray = |o: Vec3, d: Vec3| BoxRay::<f32>::new(&RayLanes::single(&Ray::new(o, d)));
    // Along +z at x exactly on the lower (and then upper) x face, d.x = +0 and −0: (b − o)·(1/d)
    // is 0·inf = NaN there, which must not reject the box.
    for dx in [0.0f32, -0.0] {
        for x in [0.0f32, 1.0] {
            let mut r = ray(Vec3::new(x, 0.5, -1.0), Vec3::new(dx, 0.0, 1.0));
            // The slack moves o off the plane; put it back exactly on the face.
            r.o_entry.x = x;
            r.o_exit.x = x;
            let (m, near) = slab(lo, hi, &r, f32::INFINITY);
            assert!(m, "face-plane ray at x = {x}, d.x = {dx:?} lost the box");
            assert!(near <= 1.0);
        }
    }
    // Parallel to a face and outside the slab, on either side, with +0 and −0: rejected.
    for x in [2.0f32, -1.0] {
        for dx in [0.0f32, -0.0] {
            let r = ray(Vec3::new(x, 0.5, -1.0), Vec3::new(dx, 0.0, 1.0));
            assert!(!slab(lo, hi, &r, f32::INFINITY).0, "x = {x}, d.x = {dx:?}");
        }
    }
    // An empty slot's inverted box (lo = +inf, hi = −inf) is never entered, in any octant.
    let (elo, ehi) = (
        V3::<f32>::splat([f32::INFINITY; 3]),
        V3::<f32>::splat([f32::NEG_INFINITY; 3]),
    );
    for d in [
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(-1.0, 2.0, -3.0),
        Vec3::new(0.0, -0.0, 1.0),
    ] {
        assert!(
            !slab(elo, ehi, &ray(Vec3::splat(0.5), d), f32::INFINITY).0,
            "{d}"
        );
    }
    // Entered through the upper faces (every component negative): the same answers.
    let r = ray(Vec3::new(0.5, 0.5, 2.0), Vec3::new(-0.0, -0.0, -1.0));
    let (m, near) = slab(lo, hi, &r, f32::INFINITY);
    assert!(m && (near - 1.0).abs() < 1e-4, "near = {near}");
    assert!(!slab(lo, hi, &r, 0.5).0);
    // A subnormal direction component (1/d overflows): that axis does not bound the ray.
    let r = ray(Vec3::new(0.5, 0.5, -1.0), Vec3::new(1e-40, 0.0, 1.0));
    assert!(slab(lo, hi, &r, f32::INFINITY).0);
    // Starting inside the box, and the range cut off before the box.
    let r = ray(Vec3::new(0.5, 0.5, 0.5), Vec3::new(1.0, 2.0, 3.0));
    assert!(slab(lo, hi, &r, f32::INFINITY).0);
    let r = ray(Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.0, 0.0, 1.0));
    assert!(!slab(lo, hi, &r, 0.5).0);
    // NaN and zero directions are never valid.
    assert!(!ray(Vec3::ZERO, Vec3::ZERO).valid);
    assert!(!ray(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z).valid);
}
