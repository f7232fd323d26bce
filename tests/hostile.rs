//! Regression tests for hostile-input findings (issue 13): each failed before its fix.
#![cfg(feature = "triangle")]

use octoray::core::kernel::{Fast, Kernel};
use octoray::core::query::{any_hit, closest_hit};
use octoray::core::{LaneMask, Lanes, RayLanes};
use octoray::glam::Vec3;
use octoray::packet::{f32x16, f32x4, f32x8};
use octoray::{PackedTriangle, Ray};

/// The fast tier's answer at every width, lane 0 of a one-ray packet: (closest hit, any hit).
fn fast_at<L: Lanes>(ray: &Ray, tri: &PackedTriangle) -> (bool, bool)
where
    Fast: Kernel<L, Prim = PackedTriangle>,
{
    let p = RayLanes::<L>::load(&[*ray]);
    (
        closest_hit::<L, Fast>(&p, &[*tri]).lane(0).is_some(),
        any_hit::<L, Fast>(&p, &[*tri]).bitmask() & 1 == 1,
    )
}

fn fast_everywhere(ray: &Ray, tri: &PackedTriangle) -> [(bool, bool); 4] {
    [
        fast_at::<f32>(ray, tri),
        fast_at::<f32x4>(ray, tri),
        fast_at::<f32x8>(ray, tri),
        fast_at::<f32x16>(ray, tri),
    ]
}

#[test]
fn fast_tier_huge_triangle_missed_by_1e19_is_a_miss() {
    // |det| ≥ 2¹²⁶: x86's reciprocal estimate was 0, so u, v, t became ±0 and "hit" at t = 0.
    let v = Vec3::new;
    let tri = PackedTriangle::new(v(0.0, 0.0, 0.0), v(1e19, 0.0, 0.0), v(0.0, 1e19, 0.0));
    let ray = Ray::new(v(-1e19, -1e19, 1e-3), v(0.0, 0.0, -1.0));
    assert_eq!(fast_everywhere(&ray, &tri), [(false, false); 4]);
}

#[test]
fn fast_tier_ray_pointing_away_with_a_huge_direction_is_a_miss() {
    let v = Vec3::new;
    let tri = PackedTriangle::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
    let ray = Ray::new(v(0.2, 0.2, 1.0), v(0.0, 0.0, 1e38));
    assert_eq!(fast_everywhere(&ray, &tri), [(false, false); 4]);
    // The same triangle straight ahead is still hit.
    let ray = Ray::new(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0));
    assert_eq!(fast_everywhere(&ray, &tri), [(true, true); 4]);
}

#[test]
fn fast_tier_zero_area_triangle_is_a_miss() {
    // Found by the BVH equality proptest: det of a collinear triangle is rounding noise, and
    // the 1997 form reported a hit with u = v = 0 far from the segment.
    let v = Vec3::new;
    let tri = PackedTriangle {
        v0: [3.103771e-5, 8.0877e-6, -7.3246883e-6],
        e1: [-1.0795788e-5, 2.421395e-6, -4.754189e-6],
        e2: [-5.3978947e-6, 1.2106975e-6, -2.3770945e-6],
    };
    let ray = Ray::with_range(
        v(-1.8581011e-5, 1.0074473e-7, 1.5549276e-5),
        v(4.961872e-5, 7.986955e-6, -2.2873965e-5),
        0.005034685,
        0.9611403,
    );
    assert_eq!(fast_everywhere(&ray, &tri), [(false, false); 4]);
}
