//! The tier recommender against the extremes: whatever it picks must pass the extreme case its
//! scene describes (hit, with the position error within the budget).
#![cfg(all(feature = "triangle", feature = "sphere"))]

use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::intersect;
use octoray::kernels::{Exact, MollerTrumbore, Watertight};
use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
use octoray::recommend::{recommend, SceneSpec, TierChoice};

fn run(tier: TierChoice, ray: &Ray, tri: [Vec3; 3]) -> Option<Hit> {
    let packed = PackedTriangle::new(tri[0], tri[1], tri[2]);
    let verts = VertexTriangle::new(tri[0], tri[1], tri[2]);
    match tier {
        TierChoice::Standard => intersect::<f32, MollerTrumbore>(ray, &packed),
        TierChoice::Watertight => intersect::<f32, Watertight>(ray, &verts),
        TierChoice::F64 => intersect::<f64, MollerTrumbore>(ray, &packed),
        TierChoice::WatertightF64 => intersect::<f64, Watertight>(ray, &verts),
        TierChoice::Exact => intersect::<f32, Exact>(ray, &verts),
    }
}

/// A right triangle of legs `size` at `offset` and a ray down onto it from `size` above, at the
/// quarter point: exact t = 1.
fn case(offset: f32, size: f32) -> (Ray, [Vec3; 3], SceneSpec) {
    let o = Vec3::splat(offset);
    let tri = [
        o,
        o + Vec3::new(size, 0.0, 0.0),
        o + Vec3::new(0.0, size, 0.0),
    ];
    let ray = Ray::new(
        o + Vec3::new(size / 4.0, size / 4.0, size),
        Vec3::new(0.0, 0.0, -size),
    );
    let spec = SceneSpec {
        bounds_min: o,
        bounds_max: o + Vec3::splat(size),
        smallest_feature: size,
        error_budget: size * 1e-3,
        closed_meshes: false,
    };
    (ray, tri, spec)
}

#[test]
fn recommendations_pass_their_extreme_case() {
    let cases = [
        ("unit scene", case(0.0, 1.0), TierChoice::Standard),
        ("translated 1e6", case(1e6, 1e3), TierChoice::Standard),
        (
            "size 1e13 (standard overflows)",
            case(0.0, 1e13),
            TierChoice::Watertight,
        ),
        (
            "size 1e-16 (standard underflows)",
            case(0.0, 1e-16),
            TierChoice::Watertight,
        ),
        (
            "size 1e-30 (f32 underflows)",
            case(0.0, 1e-30),
            TierChoice::F64,
        ),
        (
            "8-unit features at 1e6 (f32 error too large)",
            case(1e6, 8.0),
            TierChoice::F64,
        ),
    ];
    for (name, (ray, tri, spec), want) in cases {
        let r = recommend(&spec).unwrap();
        println!("{name}: {r}");
        assert_eq!(r.tier, want, "{name}: {r}");
        assert!(r.meets_budget, "{name}: {r}");
        let hit = run(r.tier, &ray, tri)
            .unwrap_or_else(|| panic!("{name}: the recommended tier missed ({r})"));
        let err = (f64::from(hit.t) - 1.0).abs() * f64::from(ray.dir.length());
        assert!(
            err <= f64::from(spec.error_budget),
            "{name}: error {err:e} over budget"
        );
    }
}

#[test]
fn closed_meshes_get_the_watertight_tier_and_impossible_budgets_say_so() {
    let (_, _, mut spec) = case(0.0, 1.0);
    spec.closed_meshes = true;
    assert_eq!(recommend(&spec).unwrap().tier, TierChoice::Watertight);
    spec.error_budget = 1e-30;
    let r = recommend(&spec).unwrap();
    // Closed meshes never get the (leaky) standard kernel, at any precision.
    assert_eq!(r.tier, TierChoice::WatertightF64);
    assert!(!r.meets_budget);
    assert!(r.to_string().contains("no tier meets the budget"), "{r}");
}

#[test]
fn features_lost_to_f32_input_quantization_are_reported_not_promised() {
    // A 1e-3 triangle at 1e6: the f32 vertices (spacing 1/16 there) collapse; no tier can hit it.
    let (ray, tri, spec) = case(1e6, 1e-3);
    let r = recommend(&spec).unwrap();
    assert!(!r.meets_budget, "{r}");
    assert!(r.to_string().contains("translate the scene"), "{r}");
    assert_eq!(
        run(r.tier, &ray, tri),
        None,
        "the collapsed triangle really is lost"
    );
}

#[test]
fn closed_meshes_far_from_the_origin_get_a_watertight_tier_at_f64() {
    // A closed mesh at 1e6 with a budget of 8e-3 was answered "F64" (the standard
    // kernel at f64, which leaks ~1 % of crack rays).
    for (at, feature, budget) in [
        (1e6f32, 8.0f32, 8e-3f32),
        (1e5, 1.0, 1e-4),
        (1e7, 100.0, 1e-1),
    ] {
        let (ray, tri, mut spec) = case(at, feature);
        spec.closed_meshes = true;
        spec.error_budget = budget;
        let r = recommend(&spec).unwrap();
        assert!(
            matches!(r.tier, TierChoice::Watertight | TierChoice::WatertightF64),
            "{r}"
        );
        assert!(
            run(r.tier, &ray, tri).is_some(),
            "{r}: the recommended tier missed"
        );
        spec.closed_meshes = false;
        assert_ne!(recommend(&spec).unwrap().tier, TierChoice::WatertightF64);
    }
}

#[test]
fn invalid_scene_descriptions_are_errors() {
    use octoray::recommend::SpecError;
    let (_, _, good) = case(0.0, 1.0);
    let mut s = good;
    s.bounds_min.x = f32::NAN;
    assert_eq!(recommend(&s), Err(SpecError::NonFiniteBounds));
    let mut s = good;
    s.bounds_max.y = f32::INFINITY;
    s.error_budget = f32::INFINITY;
    assert_eq!(recommend(&s), Err(SpecError::NonFiniteBounds));
    let mut s = good;
    std::mem::swap(&mut s.bounds_min, &mut s.bounds_max);
    s.bounds_min.x += 1.0;
    assert_eq!(recommend(&s), Err(SpecError::InvertedBounds));
    for f in [0.0, -0.0, -1.0, f32::NAN, f32::INFINITY] {
        let mut s = good;
        s.smallest_feature = f;
        assert!(
            matches!(recommend(&s), Err(SpecError::BadFeature(_))),
            "{f}"
        );
    }
    for b in [-0.5, -1.0, f32::NAN, f32::INFINITY] {
        let mut s = good;
        s.error_budget = b;
        assert!(matches!(recommend(&s), Err(SpecError::BadBudget(_))), "{b}");
        assert!(recommend(&s).unwrap_err().to_string().contains("budget"));
    }
}

#[test]
fn no_error_budget_gets_the_exact_tier_at_every_scale() {
    // "Closed meshes, no error budget to spend": the exact tier, near the origin and
    // far from it, and it hits each scene's extreme case, including coordinates beyond the
    // watertight tier's range (1e20) and below f32's products (1e-25).
    for (at, size) in [
        (0.0f32, 1.0f32),
        (1e6, 8.0),
        (0.0, 1e-25),
        (0.0, 1e20),
        (1e3, 1e-2),
    ] {
        for closed in [true, false] {
            let (ray, tri, mut spec) = case(at, size);
            spec.closed_meshes = closed;
            spec.error_budget = 0.0;
            let r = recommend(&spec).unwrap();
            assert_eq!(r.tier, TierChoice::Exact, "{r}");
            assert!(!r.meets_budget && r.to_string().contains("exact"), "{r}");
            let h = run(r.tier, &ray, tri).unwrap_or_else(|| panic!("{r}: missed at {at:e}"));
            // The exact t of the (rounded) f32 inputs: 1 where the coordinates are exact.
            let exact = octoray_testkit::oracle::triangle(&ray, tri).t;
            assert!(
                (f64::from(h.t) - exact).abs() <= 1e-6 * exact,
                "{r}: t {}",
                h.t
            );
        }
    }
}
