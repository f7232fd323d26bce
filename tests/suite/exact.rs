//! The exact tier against the exact big-integer oracle with the margin at zero: on every case of
//! every family the hit/miss answer is the oracle's (a hit whose exact `t` is beyond ±f32::MAX
//! is a miss, as for every tier), a hit's `t` lies in `[t_min, t_max]` and its
//! barycentrics are in `[0, 1]`. Families: random, aimed at vertices and edges, grazing 1e-3 to
//! 1e-9 rad, long thin triangles of aspect 1e2 to 1e5, translated and scaled from 1e-20 to 1e30,
//! and `t_min`/`t_max` placed exactly at (and one f32 step around) the exact hit.
#![cfg(feature = "triangle")]
use octoray::hit::Hit;
use octoray::intersect;
use octoray::kernels::{Exact, ExactCulled};
use octoray::prim::{Ray, RayLanes, VertexTriangle};
use octoray_testkit as testkit;
use std::cmp::Ordering;
use testkit::accuracy::*;
use testkit::cases::cases;
use testkit::oracle;

/// Checks every case; returns (exact hits, lanes decided by exact arithmetic).
fn check(name: &str, cases: &[TriCase]) -> (usize, usize) {
    let (mut hits, mut fallbacks) = (0, 0);
    for c in cases {
        let tri = VertexTriangle::new(c.v[0], c.v[1], c.v[2]);
        let truth = oracle::triangle(&c.ray, c.v);
        let want = truth.hit_finite();
        let got: Option<Hit> = intersect::<f32, Exact>(&c.ray, &tri);
        assert_eq!(got.is_some(), want, "{name}: {c:?}, exact t {}", truth.t);
        fallbacks += usize::from(<Exact>::fallback_lanes::<f32>(
            &RayLanes::single(&c.ray),
            &tri,
        ));
        if let Some(h) = got {
            hits += 1;
            assert!(
                h.t >= c.ray.t_min && h.t <= c.ray.t_max,
                "{name}: t {} {c:?}",
                h.t
            );
            for b in [h.u, h.v, 1.0 - h.u - h.v] {
                assert!(
                    (-1e-6..=1.0 + 1e-6).contains(&b),
                    "{name}: barycentric {b} {c:?}"
                );
            }
            // Culling keeps exactly the front faces: the normal against the ray.
            let front = c.ray.dir.dot((c.v[1] - c.v[0]).cross(c.v[2] - c.v[0]));
            let culled = intersect::<f32, ExactCulled>(&c.ray, &tri);
            if front.abs() > 1e-3 * c.ray.dir.length() {
                assert_eq!(culled.is_some(), front < 0.0, "{name}: culling {c:?}");
            }
        }
    }
    println!(
        "{name:>28}: {} cases, {hits} hits, {fallbacks} decided exactly ({:.3} %)",
        cases.len(),
        100.0 * fallbacks as f64 / cases.len() as f64
    );
    (hits, fallbacks)
}

#[test]
fn random_rays() {
    let (hits, _) = check("random", &random_cases(201, cases(100_000)));
    assert!(hits > cases(10_000));
}

#[test]
fn rays_aimed_at_vertices_and_edges() {
    let (hits, fallbacks) = check("vertices and edges", &edge_cases(202, cases(100_000)));
    assert!(hits > cases(10_000));
    // Aimed at f32 points of edges, a good share lands within rounding of an edge.
    assert!(fallbacks > cases(100));
}

#[test]
fn grazing_rays() {
    for (i, k) in (3..=9).enumerate() {
        let angle = 10f32.powi(-k);
        check(
            &format!("grazing 1e-{k} rad"),
            &grazing_cases(210 + i as u64, cases(10_000), angle),
        );
    }
}

#[test]
fn long_thin_triangles() {
    for (i, k) in (2..=5).enumerate() {
        let aspect = 10f32.powi(k);
        check(
            &format!("thin, aspect 1e{k}"),
            &thin_cases(220 + i as u64, cases(20_000), aspect),
        );
    }
}

#[test]
fn translated_and_scaled_from_1e_minus_20_to_1e30() {
    let mut seed = 230;
    for offset in [0.0f32, 1e-20, 1e-6, 1e3, 1e10, 1e20, 1e30] {
        for scale in [1e-20f32, 1e-6, 1.0, 1e6, 1e20, 1e30] {
            seed += 1;
            check(
                &format!("offset {offset:e} scale {scale:e}"),
                &translated_cases(seed, cases(2_000), offset, scale),
            );
        }
    }
}

/// The f32 values around the exact t: the largest ≤ it, and the smallest ≥ it.
fn floor_ceil(truth: &oracle::TriangleTruth) -> (f32, f32) {
    // `t_cmp(x)` orders the exact t relative to x.
    let mut x = truth.t as f32;
    while truth.t_cmp(x) == Ordering::Less {
        x = x.next_down();
    }
    while truth.t_cmp(x.next_up()) != Ordering::Less {
        x = x.next_up();
    }
    let ceil = if truth.t_cmp(x) == Ordering::Equal {
        x
    } else {
        x.next_up()
    };
    (x, ceil)
}

#[test]
fn t_min_and_t_max_at_the_hit() {
    let mut bounded = Vec::new();
    for c in random_cases(240, cases(10_000))
        .into_iter()
        .chain(edge_cases(241, cases(10_000)))
        .chain(thin_cases(242, cases(10_000), 1e3))
    {
        let truth = oracle::triangle(&c.ray, c.v);
        if !truth.hit_finite() || truth.t.abs() >= 1e38 {
            continue;
        }
        let (lo, hi) = floor_ceil(&truth);
        // Each bound exactly at, just inside and just outside the hit.
        for (t_min, t_max) in [
            (lo, f32::INFINITY),
            (hi, f32::INFINITY),
            (hi.next_up(), f32::INFINITY),
            (0.0, hi),
            (0.0, lo),
            (0.0, lo.next_down()),
            (lo, hi),
        ] {
            let ray = Ray {
                t_min,
                t_max,
                ..c.ray
            };
            bounded.push(TriCase { ray, v: c.v });
        }
    }
    let (hits, fallbacks) = check("t_min/t_max at the hit", &bounded);
    assert!(hits > cases(25_000) && fallbacks > cases(2_500));
}
