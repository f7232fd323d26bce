//! Regression tests for hostile-input findings: each failed before its fix.
#![cfg(feature = "triangle")]

use octoray::glam::Vec3;
use octoray::kernels::{Kernel, MollerTrumbore};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{PackedTriangle, Ray, RayLanes};
use octoray::query::{closest, occluded};
use octoray::{f32x16, f32x4, f32x8};

/// The Möller-Trumbore tier's answer at every width, lane 0 of a one-ray packet: (closest hit,
/// any hit). (These inputs were found against the removed fast tier; they stay as hostile
/// inputs for the tier that shares its layout.)
fn mt_at<L: Lanes>(ray: &Ray, tri: &PackedTriangle) -> (bool, bool)
where
    MollerTrumbore: Kernel<L, Prim = PackedTriangle>,
{
    let p = RayLanes::<L>::load(&[*ray]);
    (
        closest::<L, MollerTrumbore>(&p, &[*tri]).lane(0).is_some(),
        occluded::<L, MollerTrumbore>(&p, &[*tri]).bitmask() & 1 == 1,
    )
}

fn mt_everywhere(ray: &Ray, tri: &PackedTriangle) -> [(bool, bool); 4] {
    [
        mt_at::<f32>(ray, tri),
        mt_at::<f32x4>(ray, tri),
        mt_at::<f32x8>(ray, tri),
        mt_at::<f32x16>(ray, tri),
    ]
}

#[test]
fn huge_triangle_missed_by_1e19_is_a_miss() {
    // |det| ≥ 2¹²⁶: x86's reciprocal estimate was 0, so u, v, t became ±0 and "hit" at t = 0.
    let v = Vec3::new;
    let tri = PackedTriangle::new(v(0.0, 0.0, 0.0), v(1e19, 0.0, 0.0), v(0.0, 1e19, 0.0));
    let ray = Ray::new(v(-1e19, -1e19, 1e-3), v(0.0, 0.0, -1.0));
    assert_eq!(mt_everywhere(&ray, &tri), [(false, false); 4]);
}

#[test]
fn ray_pointing_away_with_a_huge_direction_is_a_miss() {
    let v = Vec3::new;
    let tri = PackedTriangle::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
    let ray = Ray::new(v(0.2, 0.2, 1.0), v(0.0, 0.0, 1e38));
    assert_eq!(mt_everywhere(&ray, &tri), [(false, false); 4]);
    // The same triangle straight ahead is still hit.
    let ray = Ray::new(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0));
    assert_eq!(mt_everywhere(&ray, &tri), [(true, true); 4]);
}

#[test]
fn zero_area_triangle_is_a_miss() {
    // Found by the BVH equality proptest: det of a collinear triangle is rounding noise, and
    // the 1997 form reported a hit with u = v = 0 far from the segment.
    let v = Vec3::new;
    let tri = PackedTriangle::from_edges(
        [3.103771e-5, 8.0877e-6, -7.3246883e-6],
        [-1.0795788e-5, 2.421395e-6, -4.754189e-6],
        [-5.3978947e-6, 1.2106975e-6, -2.3770945e-6],
    );
    let ray = Ray::with_range(
        v(-1.8581011e-5, 1.0074473e-7, 1.5549276e-5),
        v(4.961872e-5, 7.986955e-6, -2.2873965e-5),
        0.005034685,
        0.9611403,
    );
    assert_eq!(mt_everywhere(&ray, &tri), [(false, false); 4]);
}

use octoray::kernels::{Exact, MollerTrumboreCulled, Watertight};
use octoray::prim::VertexTriangle;
use octoray::query::closest_t;

/// `closest_t` and `closest` of `K` over `prims` for one ray: (t bits from each, u and v bits).
fn t_both<K: Kernel<f32x8>>(ray: &Ray, prims: &[K::Prim]) -> Option<(u32, u32, u32, u32)> {
    let p = RayLanes::<f32x8>::load(&[*ray]);
    let h = closest::<f32x8, K>(&p, prims).lane(0)?;
    let (m, t) = closest_t::<f32x8, K>(&p, prims);
    assert_eq!(m.bitmask() & 1, 1);
    Some((
        h.t.to_bits(),
        t.as_array()[0].to_bits(),
        h.u.to_bits(),
        h.v.to_bits(),
    ))
}

#[test]
fn closest_t_and_closest_hit_agree_on_the_sign_of_zero() {
    // Two coplanar triangles of opposite winding at z = 0, the ray starting on them: one
    // reported t = +0, the other −0, and the two queries kept different ones.
    let v = Vec3::new;
    let (a, b, c) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
    let ray = Ray::new(v(0.2, 0.2, 0.0), v(0.0, 0.0, -1.0));
    let packed = [PackedTriangle::new(a, b, c), PackedTriangle::new(a, c, b)];
    let verts = [VertexTriangle::new(a, b, c), VertexTriangle::new(a, c, b)];
    let got = t_both::<MollerTrumbore>(&ray, &packed);
    let (t1, t2, ..) = got.expect("the ray starts on the triangles: a hit at t = 0");
    assert_eq!((t1, t2), (0, 0), "t must be +0 from both queries");
    // The watertight and exact tiers decide t ∈ [t_min, t_max] exactly: the exact t is 0, in the
    // closed range, so they report it too, as +0 from both queries.
    let (t1, t2, ..) = t_both::<Watertight>(&ray, &verts).expect("exact t = 0 is in range");
    assert_eq!((t1, t2), (0, 0));
    let (t1, t2, ..) = t_both::<Exact>(&ray, &verts).expect("exact t = 0 is in range");
    assert_eq!((t1, t2), (0, 0));
}

#[test]
fn barycentrics_are_never_negative_zero() {
    // Rays aimed exactly at vertices and along edges, from both sides and both windings.
    let v = Vec3::new;
    let tri = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let mut checked = 0;
    for (i, w) in [[0, 1, 2], [0, 2, 1], [1, 2, 0], [2, 0, 1]]
        .iter()
        .enumerate()
    {
        let packed = [PackedTriangle::new(tri[w[0]], tri[w[1]], tri[w[2]])];
        let verts = [VertexTriangle::new(tri[w[0]], tri[w[1]], tri[w[2]])];
        for k in 0..=8 {
            let s = k as f32 / 8.0;
            for target in [v(s, 0.0, 0.0), v(0.0, s, 0.0), v(s, 1.0 - s, 0.0)] {
                for z in [1.0f32, -1.0] {
                    let ray = Ray::new(target + v(0.0, 0.0, z), v(0.0, 0.0, -z));
                    for got in [
                        t_both::<MollerTrumbore>(&ray, &packed),
                        t_both::<MollerTrumboreCulled>(&ray, &packed),
                        t_both::<Watertight>(&ray, &verts),
                    ]
                    .into_iter()
                    .flatten()
                    {
                        assert_ne!(got.2, 0x8000_0000, "u = -0 (winding {i}, {ray:?})");
                        assert_ne!(got.3, 0x8000_0000, "v = -0 (winding {i}, {ray:?})");
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 200, "only {checked} hits checked");
}

#[cfg(feature = "sphere")]
#[test]
fn spawn_helpers_stay_finite_and_tiny_spheres_are_documented() {
    use octoray::kernels::StableSphere;
    use octoray::prim::PackedSphere;
    use octoray::query::closest;
    use octoray::shading::offset::{offset_ray_origin, sphere_hit_point};
    let v = Vec3::new;
    // A real hit on a sphere of radius 2e-19: |p − c|² underflowed in f32 and gave NaN points.
    let (c, r) = (v(0.0, 0.0, 0.0), 2e-19f32);
    let ray = Ray::new(v(0.0, 0.0, -1e-18), v(0.0, 0.0, 1.0));
    let h = closest::<f32, StableSphere>(&RayLanes::single(&ray), &[PackedSphere::new(c, r)])
        .lane(0)
        .expect("a sphere of radius 2e-19 in range is hit");
    let (p, err) = sphere_hit_point(&ray, h.t, c, r);
    assert!(p.is_finite() && err.is_finite(), "{p:?} {err:?}");
    assert!((p.z + r).abs() <= 1e-25, "{p:?}");
    // The usable radius range.
    assert!(PackedSphere::new(c, PackedSphere::MIN_RADIUS).radius_sq >= f32::MIN_POSITIVE);
    assert!(PackedSphere::new(c, PackedSphere::MAX_RADIUS)
        .radius_sq
        .is_finite());
    assert!(PackedSphere::new(c, 5e-20).radius_sq.is_nan());
    assert!(PackedSphere::new(c, 2e19).radius_sq.is_nan());
    // offset_ray_origin at ±f32::MAX stays finite.
    let m = f32::MAX;
    for (p, n) in [
        (v(m, 0.0, 0.0), v(1.0, 0.0, 0.0)),
        (v(-m, -m, m), v(-1.0, -1.0, 1.0)),
    ] {
        let o = offset_ray_origin(p, Vec3::splat(1e30), n, n);
        assert!(o.is_finite(), "{p:?} -> {o:?}");
    }
}

#[cfg(feature = "sphere")]
#[test]
fn sphere_hit_point_is_finite_when_o_plus_t_d_overflows_f32() {
    // Found by the 10⁷ fuzz run: a huge direction made o + t·d infinite before re-projection.
    use octoray::shading::offset::sphere_hit_point;
    let v = Vec3::new;
    let ray = Ray::new(v(0.0, 0.0, -1.9e11), v(0.0, 0.0, 3.3e38));
    let (c, r) = (v(0.0, 0.0, 0.0), 9.45e10);
    let t = 2.0f32; // o + t·d overflows f32 (6.6e38)
    let (p, _) = sphere_hit_point(&ray, t, c, r);
    assert!(p.is_finite(), "{p:?}");
    assert!(
        (p.length() - r).abs() <= r * 1e-6,
        "re-projected onto the sphere: {p:?}"
    );
}

#[test]
fn watertight_keeps_the_thin_triangle_hit_of_the_reproducer() {
    // The thin-triangle reproducer: an exact hit at t ≈ 0.9995, far in front of the origin, that the
    // f32 watertight tier rejected because neither "provably in front" condition held.
    use octoray::intersect;
    let v = Vec3::new;
    let ray = Ray::new(
        v(1108.6238, 699.8606, 1299.9575),
        v(-10.165161, 0.1739502, 0.9506836),
    );
    let tri = VertexTriangle::new(
        v(2066.9294, 700.36707, 1299.9707),
        v(2088.1172, 700.38184, 1299.9851),
        v(1000.0, 700.0, 1301.0),
    );
    let f64_hit = intersect::<f64, Watertight>(&ray, &tri).expect("f64 watertight hits");
    let h = intersect::<f32, Watertight>(&ray, &tri).expect("f32 watertight must hit too");
    // The ray meets this needle at 0.13° (cos θ = 2.4e-3, sin α ≈ 1e-3), so the f32 t bound
    // 8ε·max(t, reach)/(|cos θ|·sin α) is about 40 here; measured off by 0.015.
    assert!((h.t - 0.9995).abs() < 0.05, "{h:?}");
    assert!((f64_hit.t - 0.9995).abs() < 1e-3, "{f64_hit:?}");
    for got in [
        closest::<f32x8, Watertight>(&RayLanes::load(&[ray; 3]), &[tri]).lane(2),
        closest::<f32x16, Watertight>(&RayLanes::load(&[ray]), &[tri]).lane(0),
    ] {
        assert_eq!(
            got.map(|g| g.t.to_bits()),
            Some(h.t.to_bits()),
            "packets agree"
        );
    }
    // The exact tier hits too, with the oracle's answer.
    let e = intersect::<f32, Exact>(&ray, &tri).expect("the exact tier hits");
    assert!((e.t - 0.9995).abs() < 0.05, "{e:?}");
}

#[test]
fn an_empty_range_is_a_miss_for_the_watertight_tier() {
    // Found by the 10⁷-case fuzz run: with t_min > t_max, a grazing hit whose rounded t passed
    // the (rounded) t_max test while its exact t passed the (exact) t_min test was reported at
    // t = t_max < t_min. Rebuilt here: grazing hits whose rounded t is well below the exact t,
    // with t_min at the exact t and t_max at the rounded one.
    use octoray::intersect;
    use octoray_testkit::{accuracy::grazing_cases, oracle};
    let mut found = 0;
    for c in grazing_cases(31, 4000, 1e-6) {
        let tri = VertexTriangle::new(c.v[0], c.v[1], c.v[2]);
        let Some(h) = intersect::<f32, Watertight>(&c.ray, &tri) else {
            continue;
        };
        let truth = oracle::triangle(&c.ray, c.v);
        let t_min = (truth.t as f32).next_down();
        if !(f64::from(h.t) < truth.t * (1.0 - 1e-4) && f64::from(t_min) <= truth.t) {
            continue;
        }
        found += 1;
        let ray = Ray::with_range(c.ray.origin, c.ray.dir, t_min, h.t);
        assert_eq!(intersect::<f32, Watertight>(&ray, &tri), None, "{ray:?}");
        assert_eq!(intersect::<f32, Exact>(&ray, &tri), None, "{ray:?}");
    }
    assert!(
        found > 0,
        "no grazing case with a rounded t below the exact one"
    );
}

#[test]
fn a_watertight_hit_whose_products_overflow_respects_t_max_exactly() {
    // Found by the 10⁷-case fuzz run: triangles at ~4e17 overflow the sheared products, so the
    // rounded t that passed the t_max test was meaningless; the exact t (1.4e19) lies far beyond
    // t_max and the hit was reported at t = t_max. Such lanes now decide t_max exactly.
    use octoray::intersect;
    let v = Vec3::new;
    let ray = Ray::with_range(
        v(0.0023017004, 0.009760706, -0.021290645),
        v(-0.0033352803, -0.012583714, 0.021618597),
        -9.220655e-16,
        27831841000000.0,
    );
    let tri = VertexTriangle::new(
        v(7.44384e16, -4.0556782e17, 2.5725868e17),
        v(-5.183034e16, 2.5198419e17, 3.613136e17),
        v(-3.4135957e17, 2.8992818e16, 3.295752e17),
    );
    assert_eq!(intersect::<f32, Watertight>(&ray, &tri), None);
    assert_eq!(intersect::<f32, Exact>(&ray, &tri), None);
    // With the range opened, both report the exact t, rounded.
    let far = Ray::new(ray.origin, ray.dir);
    for h in [
        intersect::<f32, Watertight>(&far, &tri),
        intersect::<f32, Exact>(&far, &tri),
    ] {
        let t = h.expect("the line meets the triangle").t;
        assert!((t / 1.3648488e19 - 1.0).abs() < 1e-6, "{t}");
    }
}

#[test]
fn a_nearer_hit_whose_rounded_t_overflows_is_not_cut_off_by_an_earlier_hit() {
    // Found by the 10⁷-case fuzz run (brute force and the BVH disagreed): a huge tilted triangle
    // (vertices at 2^50) whose numerator N overflows f32 while its edge functions do not. With
    // t_max lowered to an earlier hit, the rounded test `N ≤ t_max·|D|` (inf ≤ finite) cut it
    // off, though its exact t is nearer; with t_max = inf it passed. Such lanes now go on to the
    // exact stage.
    let v = Vec3::new;
    let big = 2f32.powi(50);
    let far = VertexTriangle::new(v(-1.0, -1.0, -1.0), v(3.0, -1.0, -1.0), v(-1.0, 3.0, -1.0));
    // The plane z = −x: the ray down from (0.5, 0.25, 1) meets it at z = −0.5, t = 1.5.
    let huge = VertexTriangle::new(
        v(-big, -big, big),
        v(2.0 * big, -big, -2.0 * big),
        v(-big, 2.0 * big, big),
    );
    let ray = Ray::new(v(0.5, 0.25, 1.0), v(0.0, 0.0, -1.0));
    let tris = [far, huge];
    let tree = octoray::bvh::Bvh8::build(&tris);
    for got in [
        closest::<f32, Watertight>(&RayLanes::single(&ray), &tris).lane(0),
        closest::<f32x8, Watertight>(&RayLanes::load(&[ray]), &tris).lane(0),
        closest::<f32x8, Exact>(&RayLanes::load(&[ray]), &tris).lane(0),
        octoray::tree::closest_ray::<f32x8, Watertight>(tree.as_ref(), &ray),
    ] {
        let h = got.expect("both triangles are hit");
        assert_eq!((h.prim, h.t), (1, 1.5), "{h:?}");
    }
}

#[test]
fn a_t_max_whose_scaled_bound_overflows_is_still_tested() {
    // Found by the 10⁷-case fuzz run: t_max = −2.7e17 times |D| ≈ 1e25 overflows, so the rounded
    // t_max test was skipped and nothing else tested t_max; the hit at exact t = 1 was reported
    // at t = t_max. Such lanes now decide t_max exactly.
    use octoray::intersect;
    let v = Vec3::new;
    let ray = Ray::with_range(
        v(-3.6111658e-6, 1.2424738e-6, 7.5966915e-7),
        v(-2191841000000.0, 1150781800000.0, 657631000000.0),
        -6.1908184e18,
        -2.6855149e17,
    );
    let tri = VertexTriangle::new(
        v(-2123935300000.0, 1064015560000.0, 0.0),
        v(-2282656400000.0, 1264370600000.0, 936148700000.0),
        v(-2168931700000.0, 1123959300000.0, 1036744460000.0),
    );
    assert_eq!(intersect::<f32, Watertight>(&ray, &tri), None);
    assert_eq!(intersect::<f32, Exact>(&ray, &tri), None);
    let open = Ray::new(ray.origin, ray.dir);
    let h = intersect::<f32, Watertight>(&open, &tri).expect("hit at t = 1");
    assert!((h.t - 1.0).abs() < 1e-5, "{h:?}");
}

#[cfg(feature = "sphere")]
#[test]
fn a_sphere_whose_discriminant_overflows_is_a_miss_not_a_hit_at_t_0() {
    // Found by the BVH equality proptest widened to scenes of 1e15: with a direction of 4e14
    // and r = 8e12, Δ/4 = a·(r² − |l|²) overflowed to +inf, so q = −inf and c/q = 0 came out as
    // a hit at t = 0 (the exact hit is at t ≈ 1.085, which the f64 tier finds). The naive kernel
    // calls an overflowed discriminant a miss; the stable kernel forms √(Δ/4) as √a·√(r² − |l|²),
    // which stays finite here, and finds the f64 tier's hit at every width.
    use octoray::kernels::{NaiveSphere, StableSphere};
    use octoray::prim::PackedSphere;
    use wide::f64x4;
    let v = Vec3::new;
    let ray = Ray::new(
        v(191157100000000.0, 234537280000000.0, -266347920000000.0),
        v(-255901110000000.0, -235034500000000.0, 213059740000000.0),
    );
    let centre = v(-89763625000000.0, -26305173000000.0, -29892054000000.0);
    let sphere = PackedSphere::new(centre, 8441108000000.0);
    let f64_lanes = closest::<f64x4, StableSphere>(&RayLanes::load(&[ray]), &[sphere]);
    let t = f64_lanes.lane(0).expect("the f64 tier hits").t;
    assert!((t - 1.085205).abs() < 1e-5, "{t}");
    fn at<L: Lanes, K: Kernel<L, Prim = octoray::prim::PackedSphere>>(
        ray: &Ray,
        s: &octoray::prim::PackedSphere,
    ) -> Option<octoray::hit::Hit> {
        closest::<L, K>(&RayLanes::load(&[*ray]), &[*s]).lane(0)
    }
    let stable = [
        at::<f32, StableSphere>(&ray, &sphere),
        at::<f32x4, StableSphere>(&ray, &sphere),
        at::<f32x8, StableSphere>(&ray, &sphere),
        at::<f32x16, StableSphere>(&ray, &sphere),
    ];
    for got in stable {
        let got = got.expect("the stable kernel hits").t;
        assert!((got - t).abs() <= 1e-5 * t, "{got} vs the f64 tier's {t}");
        assert_eq!(got.to_bits(), stable[0].unwrap().t.to_bits());
    }
    for got in [
        at::<f32x8, NaiveSphere>(&ray, &sphere),
        at::<f32x16, NaiveSphere>(&ray, &sphere),
    ] {
        assert_eq!(got, None);
    }
    // A true hit at this scale is still found where Δ/4 stays finite (|d|·r < 1.8e19).
    let aimed = Ray::new(ray.origin, (centre - ray.origin) * 1e-9);
    let h = at::<f32x8, StableSphere>(&aimed, &sphere).expect("aimed at the centre");
    let want = 1e9 * (1.0 - 8441108000000.0 / (centre - ray.origin).length());
    assert!((h.t / want - 1.0).abs() < 1e-5, "{h:?}, want {want}");
}

#[test]
fn a_standard_tier_triangle_below_the_underflow_limit_is_a_miss() {
    // Found by the BVH equality proptest widened to scenes of 1e-13: a ray aimed at a vertex of a
    // 2e-15 triangle with a direction of 3e-13. det and the edge numerators (products of three
    // such values, ~1e-42) were subnormal, the det-noise bound underflowed to 0, and the standard
    // tier reported a hit at the vertex that the exact oracle says misses (and that no box test
    // reaches). Below the documented range (|e1|₁·|e2|₁ or |d|₁·|e1|₁·|e2|₁ < 2⁻¹⁰⁰) it is a miss.
    let v = Vec3::new;
    let ray = Ray::new(
        v(1.1278359e-14, 2.5677057e-13, -2.4146066e-13),
        v(1.1400502e-13, -2.393295e-13, 1.948894e-13),
    );
    let (a, b, c) = (
        v(1.2336036e-13, 1.8192616e-14, -4.4999008e-14),
        v(1.2542997e-13, 1.5932981e-14, -4.3489307e-14),
        v(1.2528338e-13, 1.7441074e-14, -4.657126e-14),
    );
    let exact = closest::<f32x8, Exact>(&RayLanes::load(&[ray]), &[VertexTriangle::new(a, b, c)]);
    assert_eq!(exact.lane(0), None, "the exact tier: a miss");
    assert_eq!(
        mt_everywhere(&ray, &PackedTriangle::new(a, b, c)),
        [(false, false); 4]
    );
    // The same geometry scaled by 2⁴⁰ (exactly) is inside the range: the answers agree again.
    let k = 2f32.powi(40);
    let big = Ray::new(ray.origin * k, ray.dir * k);
    let (ba, bb, bc) = (a * k, b * k, c * k);
    let exact =
        closest::<f32x8, Exact>(&RayLanes::load(&[big]), &[VertexTriangle::new(ba, bb, bc)]);
    assert_eq!(exact.lane(0), None);
    assert_eq!(
        mt_everywhere(&big, &PackedTriangle::new(ba, bb, bc)),
        [(false, false); 4]
    );
    let centre = Ray::new(big.origin, (ba + bb + bc) / 3.0 - big.origin);
    assert_eq!(
        mt_everywhere(&centre, &PackedTriangle::new(ba, bb, bc)),
        [(true, true); 4]
    );
}

#[test]
fn a_watertight_t_0_tie_between_duplicates_goes_to_the_lower_index_through_the_bvh() {
    // Found by the BVH equality proptest widened to offsets of 1e33: twelve copies of a triangle
    // whose edge holds the ray's origin (exact t = 0). Their products leave the filter's safe
    // window, so the watertight tier took t = 0 from its exact stage but still decided t_max on
    // its rounded t (≈ 1e-8): with t_max lowered to the first copy's hit, the other copies were
    // cut off, and the BVH's packet walk (which meets the copies in another order) reported a
    // higher index than brute force. Such lanes now decide t_max exactly on the t they report.
    use wide::f64x4;
    let v =
        |x: u32, y: u32, z: u32| Vec3::new(f32::from_bits(x), f32::from_bits(y), f32::from_bits(z));
    let tri = VertexTriangle::new(
        v(1955296992, 1982526956, 1980547929),
        v(1955296988, 1982526956, 1980547929),
        v(1955296996, 1982526957, 1980547929),
    );
    let ray = Ray::new(
        v(1955296991, 1982526956, 1980547929),
        v(3948937216, 3934257152, 3942645760),
    );
    let tris = vec![tri; 12];
    for t_max in [f32::INFINITY, 1.0, 1e-30, 0.0] {
        let r = Ray::with_range(ray.origin, ray.dir, 0.0, t_max);
        let h = closest::<f64x4, Watertight>(&RayLanes::load(&[r]), &[tri]).lane(0);
        assert_eq!(
            h.map(|h| (h.t, h.u, h.v)),
            Some((0.0, 0.25, 0.0)),
            "t_max {t_max}"
        );
    }
    let tree = octoray::bvh::Bvh8::build(&tris);
    let p = RayLanes::<f64x4>::load(&[ray]);
    for got in [
        closest::<f64x4, Watertight>(&p, &tris).lane(0),
        octoray::tree::closest_packet::<f64x4, Watertight>(tree.as_ref(), &p).lane(0),
        octoray::tree::closest_ray::<f64x4, Watertight>(tree.as_ref(), &ray),
    ] {
        assert_eq!(got.map(|h| (h.t, h.prim)), Some((0.0, 0)));
    }
}

/// Untrusted trees: validation in linear time, every accepted tree a tree.
#[cfg(feature = "alloc")]
mod untrusted_trees {
    use octoray::bvh::{Bvh8, Bvh8Ref, BvhError, MAX_DEPTH, PAD};
    use octoray::f32x8;
    use octoray::glam::Vec3;
    use octoray::kernels::Watertight;
    use octoray::prim::{Primitive, Ray, RayLanes, VertexTriangle};
    use octoray::tree::{closest_packet, closest_ray, occluded_ray};
    use octoray_testkit::trees::{
        chain, shared_chain, take_leaf_tests, triangles, Counting, Slices,
    };
    use octoray_testkit::Rng;

    fn validate(t: &Slices) -> Result<Bvh8Ref<'_, VertexTriangle>, BvhError> {
        Bvh8Ref::new(&t.nodes, &t.blocks, &t.ids, t.prims)
    }

    #[test]
    fn a_shared_subtree_is_rejected_before_it_is_walked() {
        // Node i's slots 0 and 1 both named node i + 1: validation and every query walked 2ⁿ
        // paths (24 nodes took 34 ms to validate and 0.84 s per ray; 64 nodes did not return).
        // Now the second slot naming a node already numbered is an error, whatever the depth.
        for n in [2, 16, 24, 64] {
            let t = shared_chain(n);
            assert_eq!(
                validate(&t).unwrap_err(),
                BvhError::BadNodeRef { node: 0 },
                "{n} nodes"
            );
        }
        // The same nodes with every slot on one node.
        let mut t = shared_chain(8);
        for s in 0..8 {
            (t.nodes[0].child[s], t.nodes[0].count[s]) = (1, 0);
        }
        assert_eq!(validate(&t).unwrap_err(), BvhError::BadNodeRef { node: 0 });
    }

    #[test]
    fn a_chain_to_the_depth_limit_validates_and_one_past_it_does_not() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let t = chain(MAX_DEPTH);
        let bvh = validate(&t).expect("MAX_DEPTH nodes deep");
        assert_eq!(
            closest_ray::<f32x8, Watertight>(bvh, &ray).map(|h| h.prim),
            Some(0)
        );
        assert!(occluded_ray::<f32x8, Watertight>(bvh, &ray));
        assert_eq!(
            validate(&chain(MAX_DEPTH + 1)).unwrap_err(),
            BvhError::TooDeep
        );
    }

    #[test]
    fn the_fullest_stack_a_tree_of_the_depth_limit_allows_is_walked_without_a_panic() {
        use octoray::lanes::LaneMask;
        use octoray::tree::{closest_t_packet, occluded_packet};
        use octoray::{f32x16, f32x4};
        use octoray_testkit::trees::bushy_chain;
        let t = bushy_chain(MAX_DEPTH);
        assert_eq!(t.nodes.len(), 8 * (MAX_DEPTH - 1) + 1);
        let bvh = validate(&t).expect("a bushy chain at the depth limit");
        let ray = Ray::new(Vec3::new(0.1, 0.1, -5.0), Vec3::Z);
        assert_eq!(
            closest_ray::<f32x8, Watertight>(bvh, &ray).map(|h| h.prim),
            Some(0)
        );
        assert!(occluded_ray::<f32x8, Watertight>(bvh, &ray));
        let rays = [ray; 16];
        assert_eq!(
            closest_packet::<f32x16, Watertight>(bvh, &RayLanes::load(&rays))
                .mask
                .bitmask(),
            0xffff
        );
        assert_eq!(
            closest_t_packet::<f32x4, Watertight>(bvh, &RayLanes::load(&rays[..4]))
                .0
                .bitmask(),
            0xf
        );
        assert_eq!(
            occluded_packet::<f32x8, Watertight>(bvh, &RayLanes::load(&rays[..8])).bitmask(),
            0xff
        );
        assert_eq!(
            validate(&bushy_chain(MAX_DEPTH + 1)).unwrap_err(),
            BvhError::TooDeep
        );
    }

    #[test]
    fn nodes_out_of_build_order_or_unreached_are_rejected() {
        let tris = triangles(&mut Rng(7), 300);
        let tree = Bvh8::build(&tris);
        let ok = Slices::of(&tree, tris.len());
        assert!(validate(&ok).is_ok());
        assert!(ok.nodes.len() > 3, "{} nodes", ok.nodes.len());
        // Two nodes swapped: still a tree, but its nodes or leaves are out of build order.
        let mut t = ok.clone();
        t.nodes.swap(1, 2);
        assert!(
            matches!(
                validate(&t),
                Err(BvhError::BadNodeRef { .. } | BvhError::BadLeaf { .. })
            ),
            "{:?}",
            validate(&t).err()
        );
        // A node more than the tree reaches.
        let mut t = ok.clone();
        t.nodes.push(octoray::bvh::Bvh8Node::EMPTY);
        assert_eq!(
            validate(&t).unwrap_err(),
            BvhError::Unreachable {
                node: ok.nodes.len()
            }
        );
        // A block no leaf holds.
        let mut t = ok.clone();
        t.ids.extend([PAD; 8]);
        t.blocks.extend(vec![[0.0; 8]; VertexTriangle::WORDS]);
        assert_eq!(
            validate(&t).unwrap_err(),
            BvhError::UnusedBlocks { slot: ok.ids.len() }
        );
    }

    #[test]
    fn a_leaf_holding_pad_or_an_index_past_the_callers_slice_is_rejected() {
        // A one-triangle tree with ids[0] = PAD was accepted and closest_ray reported
        // prim 4294967295; an index past the caller's slice made the caller's own lookup panic.
        let mut t = chain(1);
        assert!(validate(&t).is_ok());
        t.ids[0] = PAD;
        assert_eq!(validate(&t).unwrap_err(), BvhError::BadIndex { slot: 0 });
        t.ids[0] = 1; // the caller has one primitive
        assert_eq!(validate(&t).unwrap_err(), BvhError::BadIndex { slot: 0 });
        t.prims = 2;
        let bvh = validate(&t).expect("index 1 of 2");
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert_eq!(
            closest_ray::<f32x8, Watertight>(bvh, &ray).map(|h| h.prim),
            Some(1)
        );
        // A padding slot that is not PAD.
        t.ids[3] = 0;
        assert_eq!(validate(&t).unwrap_err(), BvhError::BadIndex { slot: 3 });
    }

    #[test]
    fn a_query_on_a_validated_tree_tests_each_leaf_block_at_most_once() {
        let tris = triangles(&mut Rng(11), 2000);
        let tree = Bvh8::build(&tris);
        let t = Slices::of(&tree, tris.len());
        let bvh = validate(&t).unwrap();
        let blocks = t.slots() / 8;
        let mut rng = Rng(12);
        for _ in 0..64 {
            let o = rng.vec3(3.0);
            let rays: Vec<Ray> = (0..8).map(|_| Ray::new(o, rng.vec3(1.0) - o)).collect();
            take_leaf_tests();
            let _ = closest_ray::<f32x8, Counting>(bvh, &rays[0]);
            let single = take_leaf_tests();
            assert!(single <= blocks, "{single} leaf tests over {blocks} blocks");
            let _ = closest_packet::<f32x8, Counting>(bvh, &RayLanes::load(&rays));
            let packet = take_leaf_tests();
            assert!(
                packet <= t.slots() + 8 * blocks,
                "{packet} leaf tests over {} slots",
                t.slots()
            );
        }
    }
}

#[test]
fn a_triangle_with_a_nan_vertex_has_no_box_and_is_counted_as_skipped() {
    // min/max drop NaN: the box was finite and the build counted the triangle as a primitive.
    use octoray::prim::Primitive;
    let tri = VertexTriangle::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y);
    assert_eq!(tri.bounds(), None);
    let tri = VertexTriangle::new(Vec3::ZERO, Vec3::new(1.0, f32::NAN, 0.0), Vec3::Y);
    assert_eq!(tri.bounds(), None);
    #[cfg(feature = "alloc")]
    {
        let good = VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let s = octoray::bvh::Bvh8::build(&[tri, good]).stats();
        assert_eq!((s.prims, s.skipped), (1, 1));
    }
}

#[cfg(feature = "alloc")]
#[test]
fn a_batch_length_mismatch_points_at_the_callers_line() {
    // The scene batch calls panicked inside traverse.rs; now the panic names the caller's line.
    use std::sync::Mutex;
    static AT: Mutex<Option<String>> = Mutex::new(None);
    let tris = [VertexTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
    let tree = octoray::bvh::Bvh8::build(&tris);
    let rays = [Ray::new(Vec3::ZERO, Vec3::Z); 2];
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|info| {
        *AT.lock().unwrap() = info.location().map(|l| l.file().to_string());
    }));
    let closest = std::panic::catch_unwind(|| {
        let mut out = [None; 1];
        octoray::tree::closest::<f32x8, Watertight>(tree.as_ref(), &rays, &mut out)
    });
    let closest_at = AT.lock().unwrap().take();
    let occluded = std::panic::catch_unwind(|| {
        let mut out = [false; 3];
        octoray::tree::occluded::<f32x8, Watertight>(tree.as_ref(), &rays, &mut out)
    });
    let occluded_at = AT.lock().unwrap().take();
    std::panic::set_hook(hook);
    assert!(closest.is_err() && occluded.is_err());
    for at in [closest_at, occluded_at] {
        assert!(
            at.as_deref().is_some_and(|f| f.ends_with("hostile.rs")),
            "{at:?}"
        );
    }
}

#[test]
fn the_exact_tier_misses_where_the_exact_t_is_just_beyond_f32_max() {
    // Exact t = f32::MAX + 2¹⁰⁰ rounds to f32::MAX; the rounded t passed the `≤ f32::MAX` check
    // and the exact tier reported a hit that its contract calls a miss. Mirrored too.
    let m = f32::MAX;
    let far = 2f32.powi(100);
    for sign in [1.0f32, -1.0] {
        let z = sign * m;
        let tri = VertexTriangle::new(
            Vec3::new(-1.0, -1.0, z),
            Vec3::new(1.0, -1.0, z),
            Vec3::new(0.0, 1.0, z),
        );
        let dir = Vec3::new(0.0, 0.0, sign);
        for (origin_z, want) in [
            (-far, None),   // exact t = MAX + 2¹⁰⁰: a miss
            (0.0, Some(m)), // exact t = MAX: a hit
            (far, Some(m)), // exact t = MAX − 2¹⁰⁰, rounded to MAX
            (-m, None),     // exact t = 2·MAX
        ] {
            let ray = Ray::new(Vec3::new(0.0, 0.0, sign * origin_z), dir);
            let got = [
                octoray::intersect::<f32, Exact>(&ray, &tri),
                closest::<f32x16, Exact>(&RayLanes::load(&[ray]), &[tri]).lane(0),
                closest::<f32x4, Exact>(&RayLanes::load(&[ray]), &[tri]).lane(0),
            ];
            for (k, h) in got.iter().enumerate() {
                assert_eq!(
                    h.map(|h| h.t),
                    want,
                    "sign {sign}, origin {origin_z}, call {k}"
                );
            }
            #[cfg(feature = "alloc")]
            {
                let tree = octoray::bvh::Bvh8::build(&[tri]);
                let h = octoray::tree::closest_ray::<f32x8, Exact>(tree.as_ref(), &ray);
                assert_eq!(h.map(|h| h.t), want, "bvh, sign {sign}, origin {origin_z}");
            }
            // With t_min = MAX only the exact t = MAX is left.
            let r = Ray::with_range(ray.origin, ray.dir, m, f32::INFINITY);
            let h = octoray::intersect::<f32, Exact>(&r, &tri).map(|h| h.t);
            let want = want.filter(|_| origin_z == 0.0);
            assert_eq!(h, want, "t_min = MAX, origin {origin_z}");
        }
    }
}

#[cfg(feature = "sphere")]
#[test]
fn the_stable_sphere_misses_where_a_times_the_discriminant_would_underflow() {
    // a·(r² − |l|²) = 1e-34·(−1e-12) underflowed to −0, passed `≥ 0`, and the ray hit at
    // t = 1e17, about 10¹² radii from a sphere of radius 1e-18.
    use octoray::kernels::StableSphere;
    use octoray::prim::PackedSphere;
    let s = PackedSphere::new(Vec3::ZERO, 1e-18);
    let ray = Ray::new(Vec3::new(1e-6, 0.0, -1.0), Vec3::new(0.0, 0.0, 1e-17));
    assert_eq!(octoray::intersect::<f32, StableSphere>(&ray, &s), None);
    assert_eq!(octoray::intersect::<f64, StableSphere>(&ray, &s), None);
    let p = RayLanes::<f32x16>::load(&[ray]);
    assert_eq!(closest::<f32x16, StableSphere>(&p, &[s]).lane(0), None);
    // Aimed at the centre it is a hit, at the t the f64 tier finds (to f32 rounding).
    let ray = Ray::new(Vec3::new(0.0, 0.0, -1e-6), Vec3::new(0.0, 0.0, 1e-17));
    let want = octoray::intersect::<f64, StableSphere>(&ray, &s).expect("f64 hit");
    let got = octoray::intersect::<f32, StableSphere>(&ray, &s).expect("f32 hit");
    assert!(
        (got.t - want.t).abs() <= want.t * 1e-6,
        "{got:?} vs {want:?}"
    );
    // Below the documented direction range (|d|² subnormal) every test is a miss.
    let ray = Ray::new(Vec3::new(0.0, 0.0, -1e-6), Vec3::new(0.0, 0.0, 4e-20));
    assert_eq!(octoray::intersect::<f32, StableSphere>(&ray, &s), None);
}

#[cfg(all(feature = "sphere", feature = "alloc"))]
#[test]
fn a_hand_built_sphere_with_a_zero_or_subnormal_radius_sq_is_missed_by_brute_force_and_bvh_alike() {
    // radius_sq = 0 was hit at t = 5 by brute force and skipped by the BVH build.
    use octoray::kernels::{NaiveSphere, StableSphere};
    use octoray::prim::PackedSphere;
    let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    for r2 in [0.0, -0.0, 1e-40, -1.0, f32::INFINITY, f32::NAN] {
        let s = PackedSphere {
            center: [0.0; 3],
            radius_sq: r2,
        };
        let tree = octoray::bvh::Bvh8::build(&[s]);
        assert_eq!(tree.stats().skipped, 1, "radius_sq {r2}");
        let p = RayLanes::<f32x8>::load(&[ray]);
        let answers = [
            octoray::intersect_sphere(&ray, &s),
            closest::<f32x8, StableSphere>(&p, &[s]).lane(0),
            closest::<f32x8, NaiveSphere>(&p, &[s]).lane(0),
            octoray::intersect::<f64, StableSphere>(&ray, &s),
            octoray::tree::closest_ray::<f32x8, StableSphere>(tree.as_ref(), &ray),
        ];
        assert_eq!(answers, [None; 5], "radius_sq {r2}");
    }
    // The smallest normal radius_sq is a sphere, in both.
    let s = PackedSphere {
        center: [0.0; 3],
        radius_sq: f32::MIN_POSITIVE,
    };
    let tree = octoray::bvh::Bvh8::build(&[s]);
    let brute = octoray::intersect_sphere(&ray, &s).map(|h| h.t);
    let bvh = octoray::tree::closest_ray::<f32x8, StableSphere>(tree.as_ref(), &ray);
    assert!(brute.is_some());
    assert_eq!(bvh.map(|h| h.t), brute);
}

/// A finite sphere or packed triangle whose box reaches past f32's range (centre at
/// `−f32::MAX`; `v0 + e1` overflowing) is still in the tree: found by fuzzing a scene whose
/// instance carried a ray to `x = −f32::MAX`, where brute force hit a sphere the tree had left
/// out (its bounds overflowed to −inf and were taken for a non-finite primitive).
#[test]
fn primitives_reaching_past_f32_range_stay_in_the_tree() {
    use octoray::bvh::Bvh8;
    use octoray::kernels::StableSphere;
    use octoray::prim::{PackedSphere, Primitive};
    use octoray::tree::closest_ray;
    let s = PackedSphere::new(Vec3::new(-f32::MAX, 230_397.5, 5_327_692.5), 7.0e6);
    assert!(s.bounds().is_some());
    let ray = Ray::with_range(
        Vec3::new(-f32::MAX, 6.081_669_4e16, -0.001_379_594_4),
        Vec3::new(-0.000_404_012_48, -7.371_917e16, 2.733_531e-13),
        0.811_481_5,
        1.574_174_4,
    );
    let brute = closest::<f32, StableSphere>(&RayLanes::single(&ray), &[s]).lane(0);
    assert!(brute.is_some(), "the kernel hits it");
    let tree = Bvh8::build(&[s]);
    assert_eq!(
        closest_ray::<f32x8, StableSphere>(tree.as_ref(), &ray),
        brute
    );
    let t = PackedTriangle::from_edges(
        [f32::MAX * 0.75; 3],
        [f32::MAX * 0.5, 0.0, 0.0],
        [0.0, f32::MAX * 0.5, 0.0],
    );
    let b = t.bounds().expect("a finite packed triangle has bounds");
    assert_eq!(b.hi[0], f32::MAX);
}
