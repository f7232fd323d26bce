//! Packet Möller-Trumbore against the textbook method (plane, then cross products).
//!
//! The two compute different roundings of the same geometry, so they may disagree for points
//! within rounding of an edge. The contract tested here: on well-conditioned cases they agree on
//! hit/miss whenever the exact hit point is clearly inside or clearly outside, and their `t`
//! agree within a relative tolerance. Disagreements inside the margin are counted and printed
//! (`cargo test --test suite packet_vs_textbook -- --nocapture`), not asserted.
//!
//! Margin. Inputs lie in [-10, 10]³, edges are at least 0.5 long, the triangle is not skinny
//! (|n| ≥ 0.05·|e1||e2|) and the ray meets the plane at |cos θ| ≥ 0.05. Then the f32 error of a
//! barycentric coordinate in either method is a few ε·|p − a_i|²/|n| from the edge tests plus
//! ε·|o|/(edge·|cos θ|) from forming p: at most ≈ 1e-4 here. A margin of 1e-3 (ten times that)
//! on the exact barycentrics therefore separates rounding from geometry.
#![cfg(all(feature = "triangle", feature = "sphere"))]
use octoray_testkit as testkit;

use glam::DVec3;
use octoray::kernels::MollerTrumbore;
use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
use octoray::textbook::{self, InsideTest};
use octoray::{closest, f32x8};
use testkit::Rng;

const MARGIN: f64 = 1e-3;
/// t agreement. The textbook forms `t = −((o − a1)·n)/(d·n)` and the kernel `t = (s·Ng)/det` with
/// `s = o − v0`, `Ng = e1 × e2`, `det = −(d·Ng)`: the same roundings in the same order up to exact
/// negations, so their t must be bit-equal (glam's `cross`/`dot` use the kernel's operation
/// order). The relative tolerance is 0.
const T_REL_TOL: f64 = 0.0;

/// Exact-enough (f64) barycentrics (b0, b1, b2) of the plane hit point, and t.
fn reference(ray: &Ray, tri: &VertexTriangle) -> (f64, [f64; 3]) {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let [a, b, c] = tri.vertices().map(|v| v.as_dvec3());
    let n = (b - a).cross(c - a);
    let t = (a - o).dot(n) / d.dot(n);
    let p = o + d * t;
    let nn = n.dot(n);
    let bary = |x: DVec3, y: DVec3| (x - p).cross(y - p).dot(n) / nn;
    (t, [bary(b, c), bary(c, a), bary(a, b)])
}

/// Well-conditioned random cases (see the module doc): half aimed inside the triangle, half at
/// barycentrics anywhere in [-0.5, 1.5].
fn cases(seed: u64, n: usize) -> Vec<(Ray, VertexTriangle)> {
    let mut rng = Rng(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (v0, v1, v2) = (rng.vec3(10.0), rng.vec3(10.0), rng.vec3(10.0));
        let (e1, e2) = (v1 - v0, v2 - v0);
        let nrm = e1.cross(e2);
        if e1.length() < 0.5
            || e2.length() < 0.5
            || (v2 - v1).length() < 0.5
            || nrm.length() < 0.05 * e1.length() * e2.length()
        {
            continue;
        }
        let (mut u, mut v) = (rng.range(-0.5, 1.5), rng.range(-0.5, 1.5));
        if out.len() % 2 == 0 {
            (u, v) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
        }
        let o = rng.vec3(10.0);
        let d = v0 + e1 * u + e2 * v - o;
        if d.normalize().dot(nrm.normalize()).abs() < 0.05 {
            continue;
        }
        out.push((Ray::new(o, d), VertexTriangle::new(v0, v1, v2)));
    }
    out
}

#[test]
fn moller_trumbore_agrees_with_the_textbook_outside_the_margin() {
    let cases = cases(0x5eed_0c70_7a11, 100_000);
    let (mut clear_hits, mut clear_misses, mut in_margin, mut in_margin_disagree) = (0, 0, 0, 0);
    let mut max_rel_t = 0.0f64;
    // Each ray against its own triangle through the 8-lane packet path.
    let mut packet_hits = vec![None; cases.len()];
    for ((ray, tri), out) in cases.iter().zip(packet_hits.chunks_mut(1)) {
        closest::<f32x8, MollerTrumbore>(
            std::slice::from_ref(ray),
            &[PackedTriangle::from(*tri)],
            out,
        );
    }
    for ((ray, tri), mt) in cases.iter().zip(&packet_hits) {
        let (t_ref, b) = reference(ray, tri);
        let tb = textbook::intersect_triangle(ray, tri, InsideTest::Full);
        let min_b = b[0].min(b[1]).min(b[2]);
        if min_b.abs() < MARGIN || t_ref.abs() < 1e-3 {
            in_margin += 1;
            if tb.is_some() != mt.is_some() {
                in_margin_disagree += 1;
            }
            continue;
        }
        let inside = min_b > 0.0 && t_ref >= 0.0;
        assert_eq!(
            tb.is_some(),
            inside,
            "textbook wrong: {ray:?} {tri:?} b={b:?} t={t_ref}"
        );
        assert_eq!(
            mt.is_some(),
            inside,
            "MT wrong: {ray:?} {tri:?} b={b:?} t={t_ref}"
        );
        if let (Some(tb), Some(mt)) = (tb, mt) {
            clear_hits += 1;
            let rel = (f64::from(tb.t) - f64::from(mt.t)).abs() / t_ref.abs();
            max_rel_t = max_rel_t.max(rel);
            assert!(
                rel <= T_REL_TOL,
                "t differs by {rel:e}: textbook {} MT {}",
                tb.t,
                mt.t
            );
        } else {
            clear_misses += 1;
        }
    }
    println!(
        "packet MT vs textbook: {} cases, {clear_hits} clear hits, {clear_misses} clear misses, \
         max relative t difference {max_rel_t:.2e}; inside the {MARGIN} margin: {in_margin} cases, \
         {in_margin_disagree} hit/miss disagreements",
        cases.len()
    );
    assert!(
        clear_hits > 30_000 && clear_misses > 30_000,
        "the sweep must exercise both answers"
    );
}

#[test]
fn textbook_dominant_axis_shortcut_matches_full_test_outside_the_margin() {
    let (mut hits, mut disagreements) = (0, 0);
    for (ray, tri) in cases(42, 20_000) {
        let full = textbook::intersect_triangle(&ray, &tri, InsideTest::Full);
        let short = textbook::intersect_triangle(&ray, &tri, InsideTest::DominantAxis);
        let (_, b) = reference(&ray, &tri);
        hits += usize::from(full.is_some());
        if b.iter().all(|x| x.abs() > MARGIN) {
            assert_eq!(full.is_some(), short.is_some(), "{ray:?} {tri:?}");
        } else if full.is_some() != short.is_some() {
            disagreements += 1;
        }
    }
    println!("dominant-axis shortcut vs full test: {hits} hits of 20000, {disagreements} disagreements inside the margin");
    assert!(hits > 5_000);
}
