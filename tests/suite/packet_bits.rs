//! Packet kernels == scalar twins, bit for bit, lane by lane, at widths 4, 8 and 16, on random
//! and adversarial inputs and on packets of every partial length. Run on the default build and
//! with `-C target-cpu=native` (see `.ci/run`).
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray_testkit as testkit;

use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::kernels::{Exact, Kernel, MollerTrumbore, NaiveSphere, StableSphere, Watertight};
use octoray::lanes::{LaneMask, Lanes, Scalar};
use octoray::prim::{PackedTriangle, Ray, RayLanes, VertexTriangle};
use octoray::{f32x16, f32x4, f32x8, query};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use testkit::strategies::*;
use wide::{f64x4, f64x8};

type Bits = (u64, u64, u64);

fn bits<L: Lanes>(t: L, u: L, v: L, i: usize) -> Bits {
    (
        t.lane(i).to_f64().to_bits(),
        u.lane(i).to_f64().to_bits(),
        v.lane(i).to_f64().to_bits(),
    )
}

fn hit_bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.prim))
}

fn lane_bit<M: LaneMask>(m: M, i: usize) -> bool {
    (m.bitmask() >> i) & 1 == 1
}

/// Every packet of `rays` (the last partial) against every primitive with kernel `K` at width
/// `L`, and the closest/any queries, compared lane by lane with the one-lane twin `S`: the hit
/// mask, and the bits of t, u, v (and the primitive index) wherever a lane hits.
fn check_kernel<L, S, K, P>(rays: &[Ray], prims: &[P]) -> Result<(), TestCaseError>
where
    L: Lanes,
    S: Lanes<Scalar = L::Scalar>,
    K: Kernel<L, Prim = P> + Kernel<S, Prim = P>,
    P: Copy + std::fmt::Debug,
{
    for chunk in rays.chunks(L::LANES) {
        let p = RayLanes::<L>::load(chunk);
        let pre = <K as Kernel<L>>::prepare(&p);
        let twins: Vec<RayLanes<S>> = chunk.iter().map(RayLanes::<S>::single).collect();
        for (k, prim) in prims.iter().enumerate() {
            let h = <K as Kernel<L>>::intersect(&p, &pre, prim);
            for i in 0..L::LANES {
                let twin = twins.get(i).and_then(|s| {
                    let th = <K as Kernel<S>>::intersect(s, &<K as Kernel<S>>::prepare(s), prim);
                    lane_bit(th.mask, 0).then(|| bits(th.t, th.u, th.v, 0))
                });
                let lane = lane_bit(h.mask, i).then(|| bits(h.t, h.u, h.v, i));
                prop_assert_eq!(
                    lane,
                    twin,
                    "lane {} prim {} {:?} ray {:?}",
                    i,
                    k,
                    prim,
                    chunk.get(i)
                );
                if lane.is_some() {
                    let (r, t) = (&chunk[i], h.t.lane(i).to_f64());
                    prop_assert!(
                        t.abs() <= f64::from(f32::MAX)
                            && t >= f64::from(r.t_min)
                            && t <= f64::from(r.t_max),
                        "bad t {} for {:?}",
                        t,
                        r
                    );
                }
            }
        }
        let closest = query::closest::<L, K>(&p, prims);
        let any = query::occluded::<L, K>(&p, prims);
        for i in 0..L::LANES {
            let twin = twins
                .get(i)
                .and_then(|s| query::closest::<S, K>(s, prims).lane(0));
            prop_assert_eq!(
                hit_bits(closest.lane(i)),
                hit_bits(twin),
                "closest lane {}",
                i
            );
            if closest.lane(i).is_some() {
                prop_assert_eq!(closest.t.lane(i).to_f64().to_bits(), {
                    let s = &twins[i];
                    query::closest::<S, K>(s, prims)
                        .t
                        .lane(0)
                        .to_f64()
                        .to_bits()
                });
            }
            let twin_any = twins
                .get(i)
                .is_some_and(|s| lane_bit(query::occluded::<S, K>(s, prims), 0));
            prop_assert_eq!(lane_bit(any, i), twin_any, "any lane {}", i);
            // What any-hit reports must agree with closest-hit.
            prop_assert_eq!(lane_bit(any, i), closest.lane(i).is_some());
        }
    }
    Ok(())
}

/// One kernel at all its widths on the same rays, plus every partial packet length 1..=16.
fn all_widths<K, P>(rays: &[Ray], prims: &[P]) -> Result<(), TestCaseError>
where
    K: Kernel<f32, Prim = P>
        + Kernel<f32x4, Prim = P>
        + Kernel<f32x8, Prim = P>
        + Kernel<f32x16, Prim = P>,
    K: Kernel<f64, Prim = P> + Kernel<f64x4, Prim = P> + Kernel<f64x8, Prim = P>,
    P: Copy + std::fmt::Debug,
{
    check_kernel::<f32x4, f32, K, P>(rays, prims)?;
    check_kernel::<f32x8, f32, K, P>(rays, prims)?;
    check_kernel::<f32x16, f32, K, P>(rays, prims)?;
    // The f64 tier: the same bodies at f64 lanes against the f64 scalar twin.
    check_kernel::<f64x4, f64, K, P>(rays, prims)?;
    check_kernel::<f64x8, f64, K, P>(rays, prims)?;
    for n in 1..=rays.len().min(16) {
        check_kernel::<f32x16, f32, K, P>(&rays[..n], prims)?;
        check_kernel::<f32x8, f32, K, P>(&rays[..n.min(8)], prims)?;
        check_kernel::<f32x4, f32, K, P>(&rays[..n.min(4)], prims)?;
        check_kernel::<f64x8, f64, K, P>(&rays[..n.min(8)], prims)?;
    }
    Ok(())
}

fn check_all_widths_triangles(rays: &[Ray], tris: &[[Vec3; 3]]) -> Result<(), TestCaseError> {
    all_widths::<MollerTrumbore, PackedTriangle>(rays, &pack_triangles(tris))?;
    let verts: Vec<VertexTriangle> = tris
        .iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect();
    all_widths::<Watertight, VertexTriangle>(rays, &verts)?;
    all_widths::<Exact, VertexTriangle>(rays, &verts)
}

fn check_all_widths_spheres(rays: &[Ray], spheres: &[(Vec3, f32)]) -> Result<(), TestCaseError> {
    let packed = pack_spheres(spheres);
    all_widths::<StableSphere, _>(rays, &packed)?;
    all_widths::<NaiveSphere, _>(rays, &packed)
}

proptest! {
    #![proptest_config(octoray_testkit::cases::proptest_config(400))]

    /// Adversarial triangles and rays aimed at their vertices, edges, interiors, grazing, or
    /// anywhere; scenes scaled to huge and tiny coordinates; NaN/Inf sprinkled in.
    #[test]
    fn triangle_packets_equal_scalar_twin_bitwise(
        tris in prop::collection::vec(triangle(), 1..6),
        specs in prop::collection::vec(ray_spec(), 1..40),
        s in scale(),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|sp| aim_at_triangle(sp, &tris, s)).collect();
        check_all_widths_triangles(&rays, &tris)?;
    }

    /// Plain random rays and triangles in a box (the common case).
    #[test]
    fn triangle_packets_equal_scalar_twin_bitwise_random(
        tris in prop::collection::vec((tame(), tame(), tame()).prop_map(|(a, b, c)| [a, b, c]), 1..12),
        rays in prop::collection::vec((tame(), tame()).prop_map(|(o, d)| Ray::new(o, d)), 1..40),
    ) {
        check_all_widths_triangles(&rays, &tris)?;
    }

    /// Coherent packets: every lane's direction has the same dominant axis and signs (each of the
    /// watertight shear's six axis orders), so the sheared tiers read the vertices in the shared
    /// order instead of blending per lane; rays aimed at points in and around the triangles
    /// (their edges and vertices included), so hits and exact-stage lanes occur.
    #[test]
    fn coherent_packets_equal_scalar_twin_bitwise(
        tris in prop::collection::vec((tame(), tame(), tame()).prop_map(|(a, b, c)| [a, b, c]), 1..8),
        axis in 0usize..3,
        negative in any::<bool>(),
        side in (-0.9f32..0.9, -0.9f32..0.9),
        aims in prop::collection::vec((0usize..8, prop_oneof![Just(0.0f32), Just(0.5), -0.2f32..1.2], prop_oneof![Just(0.0f32), Just(0.5), -0.2f32..1.2], (-0.01f32..0.01, -0.01f32..0.01), 0.5f32..20.0), 1..40),
    ) {
        let rays: Vec<Ray> = aims
            .iter()
            .map(|&(j, b1, b2, (jx, jy), dist)| {
                let mut d = [0.0f32; 3];
                d[axis] = if negative { -1.0 } else { 1.0 };
                d[(axis + 1) % 3] = side.0 + jx;
                d[(axis + 2) % 3] = side.1 + jy;
                let d = Vec3::from(d);
                let t = tris[j % tris.len()];
                let p = t[0] + (t[1] - t[0]) * b1 + (t[2] - t[0]) * b2;
                Ray::new(p - d * dist, d)
            })
            .collect();
        check_all_widths_triangles(&rays, &tris)?;
    }

    /// Spheres near, far (1e2..1e6 radii away), huge, tiny and invalid; origins on the surface,
    /// rays skimming the rim.
    #[test]
    fn sphere_packets_equal_scalar_twin_bitwise(
        spheres in prop::collection::vec(sphere(), 1..6),
        specs in prop::collection::vec(sphere_ray_spec(), 1..40),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|sp| aim_at_sphere(sp, &spheres)).collect();
        check_all_widths_spheres(&rays, &spheres)?;
    }
}

/// Hand-picked cases the generators only reach by chance: exact vertex and edge hits on a shared
/// edge, a ray in the plane, t exactly at t_max and t_min.
#[test]
fn named_edge_cases_equal_scalar_twin() {
    let v = Vec3::new;
    let tris = [
        [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
        [v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)],
    ];
    let rays = vec![
        Ray::new(v(0.5, 0.5, 1.0), v(0.0, 0.0, -1.0)), // shared edge
        Ray::new(v(0.0, 0.0, 1.0), v(0.0, 0.0, -1.0)), // vertex
        Ray::new(v(1.0, 0.0, 1.0), v(0.0, 0.0, -1.0)), // shared vertex
        Ray::new(v(-1.0, 0.2, 0.0), v(1.0, 0.0, 0.0)), // in the plane
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 0.0, 1.0), // t == t_max
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 1.0, 2.0), // t == t_min
        Ray::with_range(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0), 0.0, 0.99999994), // just short
        Ray::new(v(0.2, 0.2, 0.0), v(0.0, 0.0, -1.0)), // origin on the surface
    ];
    let packed = pack_triangles(&tris);
    check_all_widths_triangles(&rays, &tris).unwrap();
    // And the expected answers, so this test is not only self-consistency.
    let h: Vec<Option<Hit>> = rays
        .iter()
        .map(|r| {
            query::closest::<f32, MollerTrumbore>(&RayLanes::<f32>::single(r), &packed).lane(0)
        })
        .collect();
    assert_eq!(h[0].map(|h| h.t), Some(1.0));
    assert_eq!(h[1].map(|h| (h.t, h.prim)), Some((1.0, 0)));
    assert_eq!(
        h[2].map(|h| (h.t, h.prim)),
        Some((1.0, 0)),
        "tie goes to the lower index"
    );
    assert_eq!(h[3], None, "a ray in the plane is a miss");
    assert_eq!(
        h[4].map(|h| h.t),
        Some(1.0),
        "t == t_max is inside the closed range"
    );
    assert_eq!(
        h[5].map(|h| h.t),
        Some(1.0),
        "t == t_min is inside the closed range"
    );
    assert_eq!(h[6], None);
    assert_eq!(h[7].map(|h| h.t), Some(0.0));
}

/// `RayLanes::<L>::load` of `rays` (its first `LANES` at most): lane `i` holds ray `i`'s eight
/// values exactly (widened for f64 lanes) and is active; the lanes past the slice are zero and
/// inactive.
fn loaded_lane_by_lane<L: Lanes>(rays: &[Ray]) -> Result<(), TestCaseError> {
    let p = RayLanes::<L>::load(rays);
    let n = rays.len().min(L::LANES);
    prop_assert_eq!(p.active.bitmask(), ((1u64 << n) - 1) as u32);
    for i in 0..L::LANES {
        let got = [
            p.origin.x, p.origin.y, p.origin.z, p.dir.x, p.dir.y, p.dir.z, p.t_min, p.t_max,
        ]
        .map(|x| x.lane(i).to_f64().to_bits());
        let want = rays.get(i).filter(|_| i < n).map_or([0.0; 8], |r| {
            let (o, d) = (r.origin, r.dir);
            [o.x, o.y, o.z, d.x, d.y, d.z, r.t_min, r.t_max]
        });
        prop_assert_eq!(got, want.map(|x| f64::from(x).to_bits()), "lane {}", i);
    }
    Ok(())
}

proptest! {
    #![proptest_config(octoray_testkit::cases::proptest_config(400))]

    /// Packets of every length from 0 to past the width, at every width and lane type, from
    /// rays of any bits (NaN, ±inf, ±0, subnormals included).
    #[test]
    fn packets_load_each_ray_into_its_lane(
        words in prop::collection::vec(any::<[u32; 8]>(), 0..20),
    ) {
        let rays: Vec<Ray> = words
            .iter()
            .map(|w| {
                let f = w.map(f32::from_bits);
                let v = |k: usize| Vec3::new(f[k], f[k + 1], f[k + 2]);
                Ray::with_range(v(0), v(3), f[6], f[7])
            })
            .collect();
        loaded_lane_by_lane::<f32x4>(&rays)?;
        loaded_lane_by_lane::<f32x8>(&rays)?;
        loaded_lane_by_lane::<f32x16>(&rays)?;
        loaded_lane_by_lane::<f64x4>(&rays)?;
        loaded_lane_by_lane::<f64x8>(&rays)?;
    }
}
