//! The hostile-input fuzz harness: seeded random cases with NaN, ±inf, ±0, subnormal,
//! 1e38 and `f32::MAX` values mixed into otherwise scene-like geometry, through every public entry
//! point — every triangle and sphere tier at widths 1/4/8/16 (f32) and 4 (f64), the three query
//! kinds, the packet crate's batch calls, ingest, the spawn helpers, the recommender, and BVH
//! build and traversal — checking the invariants:
//!
//! - no panic (contract panics are tested elsewhere: these cases respect every contract);
//! - a reported hit has finite `t ∈ [t_min, t_max]`, finite `u, v ≥ 0` and `u + v ≤ 1 + 2⁻²⁰`;
//! - lane by lane, packets equal the scalar twin on every tier;
//! - no triangle hit where the exact big-integer oracle says miss, beyond the tier's documented
//!   margin (barycentric band `64·ε·condition`, or `t` outside the range by less than its error
//!   bound); degenerate cases (for the oracle: no plane crossing) are never hits;
//! - the BVH's answers equal brute force; spawn helpers return finite points for finite input.
//!
//! `cargo test --test suite fuzz::` runs the fast slice (a few seconds); the large run is
//! `cargo test --release --test suite fuzz:: -- --ignored` (10⁷ cases per entry point).
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]
use octoray_testkit as testkit;

use octoray::bvh::Bvh8;
use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::kernels::{
    Exact, ExactCulled, Kernel, MollerTrumbore, MollerTrumboreCulled, NaiveSphere, StableSphere,
    Watertight, WatertightCulled,
};
use octoray::lanes::{LaneMask, Lanes, Scalar};
use octoray::prim::{PackedSphere, PackedTriangle, Primitive, Ray, RayLanes, VertexTriangle};
use octoray::query::{closest, closest_t, occluded};
use octoray::recommend::{recommend, SceneSpec};
use octoray::shading::offset::{offset_ray_origin, sphere_hit_point, triangle_hit_point};
use octoray::tree::{closest_packet, closest_ray as bvh_closest};
use octoray::{f32x16, f32x4, f32x8, ingest};
use testkit::accuracy::TriCase;
use testkit::{oracle, Rng};
use wide::f64x4;

const EPS: f64 = 1.0 / 16_777_216.0;

/// A hostile f32 one time in four, else a value of random sign and magnitude 10^[−20, 20].
fn value(rng: &mut Rng) -> f32 {
    let sign = if rng.below(2) == 0 { 1.0 } else { -1.0 };
    if rng.below(4) == 0 {
        return match rng.below(12) {
            0 => 0.0,
            1 => -0.0,
            2 => f32::NAN,
            3 => f32::INFINITY,
            4 => f32::NEG_INFINITY,
            5 => sign * 1e-45,
            6 => sign * f32::from_bits(1 + (rng.next_u64() as u32 & 0x7f_ffff)),
            7 => sign * f32::MAX,
            8 => sign * 1e38,
            9 => sign * 1e-30,
            10 => sign * f32::MIN_POSITIVE,
            _ => sign * 3e19,
        };
    }
    sign * 10f32.powf(rng.range(-20.0, 20.0))
}

/// A point: hostile components now and then, else near `center` at `scale`.
fn point(rng: &mut Rng, center: Vec3, scale: f32) -> Vec3 {
    let mut p = center + rng.vec3(scale);
    for k in 0..3 {
        if rng.below(12) == 0 {
            p[k] = value(rng);
        }
    }
    p
}

/// A scene-like case: a triangle at a random scale and offset (or hostile), a ray aimed near it
/// (or anywhere, or hostile), a random range.
fn case(rng: &mut Rng) -> (Ray, [Vec3; 3]) {
    let scale = 10f32.powf(rng.range(-8.0, 8.0));
    let center = if rng.below(3) == 0 {
        Vec3::ZERO
    } else {
        rng.vec3(1.0) * 10f32.powf(rng.range(-8.0, 12.0))
    };
    let mut v = [
        point(rng, center, scale),
        point(rng, center, scale),
        point(rng, center, scale),
    ];
    match rng.below(10) {
        // Zero area: collinear (the third vertex on the line of the first two) or repeated.
        0 => v[2] = v[0] + (v[1] - v[0]) * rng.range(-1.0, 2.0),
        1 => v[2] = v[rng.below(2) as usize],
        // Huge geometry (products beyond f32 range; |det| past 2¹²⁶).
        2 => {
            let k = 10f32.powf(rng.range(17.0, 20.0));
            v = v.map(|p| p * k);
        }
        _ => {}
    }
    let origin = point(rng, center, scale * 4.0);
    let target = match rng.below(4) {
        0 => v[rng.below(3) as usize],
        1 => v[0] + (v[1] - v[0]) * rng.range(0.0, 1.0),
        2 => (v[0] + v[1] + v[2]) / 3.0,
        _ => point(rng, center, scale),
    };
    let mut dir = target - origin;
    if rng.below(10) == 0 {
        dir = Vec3::new(value(rng), value(rng), value(rng));
    }
    match rng.below(20) {
        0 => dir *= 10f32.powf(rng.range(-40.0, 38.0)),
        1 => dir = dir.normalize_or_zero() * 10f32.powf(rng.range(36.0, 38.0)),
        _ => {}
    }
    let (t_min, t_max) = match rng.below(8) {
        0 => (value(rng), value(rng)),
        1 => (rng.range(0.0, 0.9), rng.range(0.9, 2.0)),
        2 => (0.0, 1.0),
        _ => (0.0, f32::INFINITY),
    };
    (Ray::with_range(origin, dir, t_min, t_max), v)
}

/// The shape invariants of a reported hit.
fn check_hit(h: &Hit, ray: &Ray, what: &str) {
    assert!(
        h.t.is_finite() && h.t >= ray.t_min && h.t <= ray.t_max,
        "{what}: t = {} outside [{}, {}] for {ray:?}",
        h.t,
        ray.t_min,
        ray.t_max
    );
    assert!(
        h.u.is_finite() && h.v.is_finite() && h.u >= 0.0 && h.v >= 0.0,
        "{what}: u = {}, v = {} for {ray:?}",
        h.u,
        h.v
    );
    assert!(
        f64::from(h.u) + f64::from(h.v) <= 1.0 + 1.0 / 1_048_576.0,
        "{what}: u + v = {} for {ray:?}",
        h.u + h.v
    );
}

/// Distance from `p` to the triangle `v` (closed, possibly degenerate), in f64.
fn point_triangle_distance(p: octoray::glam::DVec3, v: [octoray::glam::DVec3; 3]) -> f64 {
    let seg = |a: octoray::glam::DVec3, b: octoray::glam::DVec3| {
        let ab = b - a;
        let l = ab.length_squared();
        let s = if l > 0.0 {
            ((p - a).dot(ab) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + ab * s - p).length()
    };
    let edges = seg(v[0], v[1]).min(seg(v[1], v[2])).min(seg(v[2], v[0]));
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    if n.length_squared() == 0.0 {
        return edges;
    }
    // Inside the prism over the triangle: the distance to the plane.
    let inside = (0..3).all(|k| {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        (b - a).cross(p - a).dot(n) >= 0.0
    });
    if inside {
        ((p - v[0]).dot(n) / n.length()).abs()
    } else {
        edges
    }
}

/// Cases outside the kernels' documented range: products underflow where `ρ²·|t| < 1e-30`
/// (`ρ` the vertices' largest distance from the ray's line, `t` the plane distance in units of
/// `d`: the watertight contract), where `|d|·max|v − o| < 1e-30` (subnormal directions: the
/// standard tier's contract), or an edge's square is subnormal (the recommender's
/// `smallest_feature ≥ 1e-12`). Counted, not checked.
static OUT_OF_RANGE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn underflow_regime(ray: &Ray, v: [Vec3; 3]) -> bool {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let dd = d.length_squared();
    // ρ: distance of each vertex from the ray's line; depth: its t along the ray.
    let rho = v
        .iter()
        .map(|p| (p.as_dvec3() - o).cross(d).length() / dd.sqrt())
        .fold(0.0, f64::max);
    let depth = v
        .iter()
        .map(|p| ((p.as_dvec3() - o).dot(d) / dd).abs())
        .fold(0.0, f64::max);
    let edge = (0..3)
        .map(|k| (v[(k + 1) % 3] - v[k]).as_dvec3().length())
        .fold(f64::INFINITY, f64::min);
    let reach = v
        .iter()
        .map(|p| (p.as_dvec3() - o).length())
        .fold(0.0, f64::max);
    rho * rho * depth < 1e-30 || (edge > 0.0 && edge * edge < 1e-30) || reach * dd.sqrt() < 1e-30
}

/// The exact oracle's verdict on a reported triangle hit: allowed unless the exact answer is a
/// miss by more than the tier's documented margin.
fn check_oracle(ray: &Ray, v: [Vec3; 3], packed: bool, t: f32, what: &str) {
    if underflow_regime(ray, v) {
        OUT_OF_RANGE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        return;
    }
    let truth = if packed {
        oracle::triangle_packed(ray, v)
    } else {
        oracle::triangle(ray, v)
    };
    if truth.degenerate {
        // Non-finite input: a miss by contract. A zero-area triangle or a ray parallel to the
        // plane: the barycentric margin is unbounded there, so the check is geometric: the
        // reported point must lie within the tiers' rounding of the triangle.
        let finite = [ray.origin, ray.dir, v[0], v[1], v[2]]
            .iter()
            .all(|p| p.is_finite());
        assert!(finite, "{what}: hit with non-finite input: {ray:?} {v:?}");
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let p = o + d * f64::from(t);
        let scale = o.abs().max_element()
            + (d * f64::from(t)).abs().max_element()
            + v.iter()
                .map(|x| x.as_dvec3().abs().max_element())
                .fold(0.0, f64::max);
        let dist = point_triangle_distance(p, v.map(|x| x.as_dvec3()));
        assert!(
            dist <= 64.0 * EPS * scale,
            "{what}: hit at t = {t} lies {dist:e} from a degenerate case (scale {scale:e}): {ray:?} {v:?}"
        );
        return;
    }
    if truth.hit {
        return;
    }
    let c = TriCase { ray: *ray, v };
    let margin = c.margin();
    let near_edge = truth.edge_distance() <= margin || !margin.is_finite();
    // The exact t in range (exact comparisons), or outside it by less than the t error bound
    // (32·ε·scale covers every tier).
    use std::cmp::Ordering::{Greater, Less};
    let above_min = ray.t_min == f32::NEG_INFINITY || truth.t_cmp(ray.t_min) != Less;
    let below_max = ray.t_max == f32::INFINITY || truth.t_cmp(ray.t_max) != Greater;
    // Needle triangles: Ng = e1 × e2 carries a relative error of ε/sin α (α the angle at v0),
    // which the contracts state as a 1/sin α factor on the t bound.
    let sin_a = sin_smallest_angle(v);
    // An exact t beyond f64's range (a ray all but parallel to the plane) has no finite bound.
    let slack = if truth.t.is_finite() {
        32.0 * EPS * c.t_scale(truth.t) / sin_a
    } else {
        f64::INFINITY
    };
    let near_range = (above_min && below_max)
        || (truth.t >= f64::from(ray.t_min) - slack && truth.t <= f64::from(ray.t_max) + slack)
        || !slack.is_finite();
    let inside = truth.bary.iter().all(|b| *b >= 0.0);
    // The watertight tiers' edge signs are the computed ones, each within its documented bound
    // `21u·Rx·Ry` of the exact 2D edge function (`wᵢ/d[kz]`): where a wrong-signed one lies
    // inside it (a ray all but in the plane, whose sheared coordinates cancel), the barycentric
    // margin above can understate that bound.
    let near_edge = near_edge || !packed && edge_within_bound(ray, v, &truth, what);
    assert!(
        (inside || near_edge) && near_range,
        "{what}: reported t = {t}, but the exact answer is a miss (bary {:?}, margin {margin:e}, t {}) for {ray:?} {v:?}",
        truth.bary,
        truth.t
    );
}

/// Is every exact edge function whose sign disagrees with the others' majority within the
/// watertight tiers' documented bound `21u·Rx·Ry` (u = 2⁻⁵³ for the f64 tier, 2⁻²⁴ else)?
fn edge_within_bound(ray: &Ray, v: [Vec3; 3], truth: &oracle::TriangleTruth, what: &str) -> bool {
    let u = if what.starts_with("f64") {
        f64::EPSILON / 2.0
    } else {
        EPS
    };
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let kz = (0..3)
        .max_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
        .unwrap_or(0);
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    let a = v.map(|p| p.as_dvec3() - o);
    let depth = a.iter().map(|p| p[kz].abs()).fold(0.0, f64::max);
    let r =
        |k: usize| a.iter().map(|p| p[k].abs()).fold(0.0, f64::max) + (d[k] / d[kz]).abs() * depth;
    // 22u with 1 % to spare for computing Rx, Ry in f64 from the f32 inputs.
    let bound = 22.0 * 1.01 * u * r(kx) * r(ky);
    let positive = truth.volumes.iter().filter(|w| **w > 0.0).count();
    let minority_sign = if positive >= 2 { -1.0 } else { 1.0 };
    truth
        .volumes
        .iter()
        .filter(|w| **w * minority_sign > 0.0)
        .all(|w| (w / d[kz]).abs() <= bound)
}

/// Tier `K` on one ray through the scalar twin and the packets of `L`, with `others` in the other
/// lanes; exact tiers must agree lane for lane. Returns the scalar answer.
fn tier<S: Lanes, L: Lanes, K, P: Primitive>(
    ray: &Ray,
    others: &[Ray],
    prim: &P,
    exact: bool,
    what: &str,
) -> Option<Hit>
where
    K: Kernel<L, Prim = P> + Kernel<S, Prim = P>,
{
    let s = RayLanes::<S>::single(ray);
    let prims = core::slice::from_ref(prim);
    let scalar = closest::<S, K>(&s, prims).lane(0);
    let mut rays = vec![*ray];
    rays.extend(others.iter().take(L::LANES - 1));
    let p = RayLanes::<L>::load(&rays);
    let ph = closest::<L, K>(&p, prims);
    let (pm, pt) = closest_t::<L, K>(&p, prims);
    let pa = occluded::<L, K>(&p, prims).bitmask();
    for (i, r) in rays.iter().enumerate() {
        let h = ph.lane(i);
        if let Some(h) = &h {
            check_hit(h, r, what);
            assert_eq!(
                Lanes::lane(pt, i).to_f32().to_bits(),
                h.t.to_bits(),
                "{what}: closest_t"
            );
        }
        assert_eq!(
            (pm.bitmask() >> i) & 1 == 1,
            h.is_some(),
            "{what}: closest_t mask"
        );
        assert_eq!((pa >> i) & 1 == 1, h.is_some(), "{what}: occluded");
    }
    if exact {
        let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
        assert_eq!(
            bits(ph.lane(0)),
            bits(scalar),
            "{what}: packet != scalar twin for {ray:?}"
        );
    }
    scalar
}

/// One case through every entry point.
fn run_case(rng: &mut Rng, others: &[Ray]) {
    let (ray, v) = case(rng);
    let packed = PackedTriangle::new(v[0], v[1], v[2]);
    let verts = VertexTriangle::new(v[0], v[1], v[2]);
    let mut hits: Vec<(Option<Hit>, bool, &str)> = vec![];
    hits.push((
        tier::<f32, f32x8, MollerTrumbore, _>(&ray, others, &packed, true, "standard x8"),
        true,
        "standard",
    ));
    tier::<f32, f32x4, MollerTrumbore, _>(&ray, others, &packed, true, "standard x4");
    tier::<f32, f32x16, MollerTrumbore, _>(&ray, others, &packed, true, "standard x16");
    hits.push((
        tier::<f32, f32x8, MollerTrumboreCulled, _>(&ray, others, &packed, true, "culled"),
        true,
        "culled",
    ));
    hits.push((
        tier::<f32, f32x8, Watertight, _>(&ray, others, &verts, true, "watertight x8"),
        false,
        "watertight",
    ));
    tier::<f32, f32x16, Watertight, _>(&ray, others, &verts, true, "watertight x16");
    tier::<f32, f32x4, WatertightCulled, _>(&ray, others, &verts, true, "watertight culled x4");
    // The exact tier: the oracle's answer on every case, no margin, no range exemption.
    let exact = tier::<f32, f32x8, Exact, _>(&ray, others, &verts, true, "exact x8");
    tier::<f32, f32x16, ExactCulled, _>(&ray, others, &verts, true, "exact culled x16");
    let truth = oracle::triangle(&ray, v);
    assert_eq!(
        exact.is_some(),
        truth.hit_finite(),
        "exact tier != oracle: {ray:?} {v:?}"
    );
    hits.push((
        tier::<f64, f64x4, MollerTrumbore, _>(&ray, others, &packed, true, "f64 standard"),
        true,
        "f64",
    ));
    hits.push((
        tier::<f64, f64x4, Watertight, _>(&ray, others, &verts, true, "f64 watertight"),
        false,
        "f64 wt",
    ));
    for (h, is_packed, what) in hits {
        if let Some(h) = h {
            check_hit(&h, &ray, what);
            check_oracle(&ray, v, is_packed, h.t, what);
            // Spawn helpers: finite point for finite input.
            let (p, err) = triangle_hit_point(&verts, h.u, h.v);
            assert!(p.is_finite(), "{what}: hit point {p:?}");
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let o = offset_ray_origin(p, err, n, -ray.dir);
            assert!(
                o.is_finite() || !err.is_finite() && o == p,
                "{what}: spawn {o:?}"
            );
        }
    }

    // Spheres.
    let (c, r) = (
        v[0],
        if rng.below(2) == 0 {
            value(rng)
        } else {
            (v[1] - v[0]).length()
        },
    );
    let sph = PackedSphere::new(c, r);
    for (h, what) in [
        (
            tier::<f32, f32x8, StableSphere, _>(&ray, others, &sph, true, "sphere x8"),
            "sphere",
        ),
        (
            tier::<f32, f32x16, StableSphere, _>(&ray, others, &sph, true, "sphere x16"),
            "sphere",
        ),
        (
            tier::<f32, f32x4, NaiveSphere, _>(&ray, others, &sph, true, "naive x4"),
            "naive",
        ),
        (
            tier::<f64, f64x4, StableSphere, _>(&ray, others, &sph, true, "sphere f64"),
            "sphere f64",
        ),
    ] {
        if let Some(h) = h {
            check_hit(&h, &ray, what);
            assert!(
                sph.radius_sq.is_finite() && r.is_finite(),
                "{what}: hit on a bad sphere"
            );
            let (p, _) = sphere_hit_point(&ray, h.t, c, r);
            assert!(
                p.is_finite(),
                "{what}: sphere hit point {p:?} (t {}, r {r})",
                h.t
            );
        }
    }

    // Recommender: an answer or an error, never a panic; answers are finite.
    let spec = SceneSpec {
        bounds_min: v[0].min(v[1]),
        bounds_max: v[0].max(v[1]),
        smallest_feature: value(rng),
        error_budget: value(rng),
        closed_meshes: rng.below(2) == 0,
    };
    if let Ok(rec) = recommend(&spec) {
        assert!(
            rec.scale.is_finite() || rec.scale == f32::INFINITY,
            "{rec:?}"
        );
        let _ = rec.to_string();
    }
}

/// Ingest with random lengths and indices: errors, never panics; outputs have the right length.
fn run_ingest(rng: &mut Rng) {
    let n = rng.below(20) as usize;
    let positions: Vec<[f32; 3]> = (0..n)
        .map(|_| [value(rng), value(rng), value(rng)])
        .collect();
    let k = rng.below(30) as usize;
    let indices: Vec<u32> = (0..k)
        .map(|_| match rng.below(8) {
            0 => u32::MAX,
            1 => n as u32,
            _ => rng.below(n.max(1) as u64) as u32,
        })
        .collect();
    if let Ok(t) = ingest::pack_triangles_vec(&positions, &indices) {
        assert_eq!(t.len(), k / 3);
    }
    if let Ok(t) = ingest::pack_vertex_triangles_vec(&positions, &indices) {
        assert_eq!(t.len(), k / 3);
    }
    let radii: Vec<f32> = (0..rng.below(20)).map(|_| value(rng)).collect();
    if let Ok(s) = ingest::pack_spheres_vec(&positions, &radii) {
        assert_eq!(s.len(), n);
    }
    let flat: Vec<f32> = (0..rng.below(12)).map(|_| value(rng)).collect();
    let _ = ingest::positions_from_flat(&flat);
}

/// BVH answers that differ from brute force where nearest is undecidable at the tier's accuracy.
static DECIDED_WITHIN_ERROR: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// Sine of the triangle's smallest angle: `2·area / (longest edge · second longest)`.
fn sin_smallest_angle(v: [Vec3; 3]) -> f64 {
    let v = v.map(|p| p.as_dvec3());
    let mut l = [
        (v[1] - v[0]).length(),
        (v[2] - v[1]).length(),
        (v[0] - v[2]).length(),
    ];
    l.sort_by(f64::total_cmp);
    (v[1] - v[0]).cross(v[2] - v[0]).length() / (l[2] * l[1])
}

/// The tiers' documented t error bound for hit `h` of ray `r`: `8·ε·t_scale/sin α`, α the
/// smallest angle.
fn t_bound(r: &Ray, verts: &[VertexTriangle], h: Hit) -> f64 {
    let t = verts[h.prim as usize];
    let v = [t.v0, t.v1, t.v2].map(Vec3::from);
    8.0 * EPS * TriCase { ray: *r, v }.t_scale(f64::from(h.t)) / sin_smallest_angle(v)
}

fn key(h: Option<Hit>) -> Option<(u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.prim))
}

/// A hostile scene through the BVH: build never panics, answers equal brute force.
fn run_bvh(rng: &mut Rng) -> usize {
    let n = 1 + rng.below(64) as usize;
    let cases: Vec<(Ray, [Vec3; 3])> = (0..n).map(|_| case(rng)).collect();
    let verts: Vec<VertexTriangle> = cases
        .iter()
        .map(|(_, v)| VertexTriangle::new(v[0], v[1], v[2]))
        .collect();
    let tree = Bvh8::build(&verts);
    let rays: Vec<Ray> = cases.iter().map(|c| c.0).collect();
    for chunk in rays.chunks(8) {
        let p = RayLanes::<f32x8>::load(chunk);
        let brute = closest::<f32x8, Watertight>(&p, &verts);
        let packet = closest_packet::<f32x8, Watertight>(tree.as_ref(), &p);
        for (i, r) in chunk.iter().enumerate() {
            // Below 1e-30 the kernels' products underflow (directions ~1e30 times the scene):
            // their t is then off by more than the boxes' slack, the BVH contract's stated
            // exception (the kernels' contracts state the range).
            let tiny = |h: Option<Hit>| {
                h.is_some_and(|h| {
                    let t = verts[h.prim as usize];
                    h.t.abs() < 1e-30 || underflow_regime(r, [t.v0, t.v1, t.v2].map(Vec3::from))
                })
            };
            if tiny(brute.lane(i)) || tiny(packet.lane(i)) {
                OUT_OF_RANGE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                continue;
            }
            let want = brute.lane(i);
            for (got, how) in [
                (packet.lane(i), "packet"),
                (bvh_closest::<f32x8, Watertight>(tree.as_ref(), r), "single"),
            ] {
                if key(got) == key(want) {
                    continue;
                }
                // Allowed only where nearest is undecidable at the tier's accuracy (the BVH
                // contract): both hits, their t within the kernels' t error bounds.
                // A hit on one side only: allowed where that hit lies within its t error bound
                // of t_min or t_max (the range end is undecidable at the tier's accuracy).
                let near_end = |h: Hit| {
                    let b = t_bound(r, &verts, h);
                    (f64::from(h.t) - f64::from(r.t_max)).abs() <= b
                        || (f64::from(h.t) - f64::from(r.t_min)).abs() <= b
                        || !b.is_finite()
                };
                match (got, want) {
                    (None, Some(h)) | (Some(h), None) if near_end(h) => {
                        DECIDED_WITHIN_ERROR.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        continue;
                    }
                    _ => {}
                }
                let (Some(g), Some(w)) = (got, want) else {
                    let detail = |h: Option<Hit>| {
                        h.map(|h| {
                            let t = verts[h.prim as usize];
                            format!("prim {}: {t:?}, bounds {:?}", h.prim, t.bounds())
                        })
                    };
                    panic!(
                        "bvh {how}: {got:?} vs brute force {want:?} for {r:?}\n  brute's {:?}\n  bvh's {:?}\n  stats {:?}",
                        detail(want),
                        detail(got),
                        tree.stats()
                    );
                };
                let bound = |h: Hit| t_bound(r, &verts, h);
                let (gap, allowed) = ((f64::from(g.t) - f64::from(w.t)).abs(), bound(g) + bound(w));
                assert!(
                    gap <= allowed || !allowed.is_finite(),
                    "bvh {how}: {g:?} vs brute force {w:?}, t gap {gap:e} beyond the t error bounds {allowed:e} for {r:?}"
                );
                DECIDED_WITHIN_ERROR.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        }
    }
    beyond_first_hit(rng, &tree, &verts, &rays);
    rays.len()
}

/// Closest point, all hits and crossing counts on hostile geometry: closest point equals brute
/// force bit for bit; every hit reported is finite, in range, on a primitive of the tree, and
/// each once; paging gives what one large buffer gives.
fn beyond_first_hit(
    rng: &mut Rng,
    tree: &Bvh8<VertexTriangle>,
    verts: &[VertexTriangle],
    rays: &[Ray],
) {
    use octoray::kernels::{ExactCrossing, NearestPoint};
    use octoray::tree::{all_hits_ray, closest_point, crossings_ray};
    for r in rays.iter().take(4) {
        let p = if rng.below(2) == 0 {
            r.origin
        } else {
            let scale = 10f32.powi(rng.below(40) as i32 - 20);
            point(rng, Vec3::ZERO, scale)
        };
        let radius = [f32::INFINITY, rng.range(0.0, 4.0), f32::NAN, -1.0][rng.below(4) as usize];
        let q = p.to_array().map(f64::from);
        let mut want: Option<(f64, u32)> = None;
        if p.is_finite() && radius >= 0.0 {
            for (i, t) in verts.iter().enumerate() {
                let d = t.nearest(q).dist2;
                let limit = want.map_or(f64::from(radius) * f64::from(radius), |w| w.0);
                if d.is_finite() && (d < limit || want.is_none() && d <= limit) {
                    want = Some((d, i as u32));
                }
            }
        }
        let got = closest_point(tree.as_ref(), p, radius);
        assert_eq!(
            got.map(|h| h.prim),
            want.map(|w| w.1),
            "closest point {p:?} within {radius}: {:?} / {:?} {:?}",
            want.map(|w| (w.0, verts[w.1 as usize])),
            got.map(|h| (verts[h.prim as usize].nearest(q), verts[h.prim as usize])),
            got
        );
        let mut big = [Hit::default(); 80];
        let all = all_hits_ray::<f32x8, Watertight>(tree.as_ref(), r, None, &mut big);
        assert!(
            all.complete,
            "{} hits on {} triangles",
            all.stored,
            verts.len()
        );
        for (k, h) in big[..all.stored].iter().enumerate() {
            assert!((h.prim as usize) < verts.len());
            check_hit(h, r, "all hits");
            assert!(k == 0 || octoray::tree::hit_order(&big[k - 1], h).is_lt());
        }
        let (mut paged, mut page, mut after) = (vec![], [Hit::default(); 2], None);
        loop {
            let f = all_hits_ray::<f32x8, Watertight>(tree.as_ref(), r, after, &mut page);
            paged.extend_from_slice(&page[..f.stored]);
            if f.complete {
                break;
            }
            after = Some(page[f.stored - 1]);
        }
        assert_eq!(paged, big[..all.stored].to_vec(), "paged all hits {r:?}");
        let n = crossings_ray::<f32x8>(tree.as_ref(), r);
        let exact = all_hits_ray::<f32x8, ExactCrossing>(tree.as_ref(), r, None, &mut big);
        assert_eq!(n as usize, exact.stored, "crossings {r:?}");
        // The k nearest and the primitives in a box, on hostile geometry: brute force's.
        let q = r.origin.to_array().map(f64::from);
        let mut near = [octoray::tree::PointHit::default(); 3];
        let f = octoray::tree::nearest_within(tree.as_ref(), r.origin, f32::INFINITY, &mut near);
        let mut all: Vec<(f32, u32)> = verts
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let d = t.nearest(q).dist2;
                d.is_finite().then(|| (d.sqrt() as f32, i as u32))
            })
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if r.origin.is_finite() {
            let got: Vec<(f32, u32)> = near[..f.stored].iter().map(|h| (h.dist, h.prim)).collect();
            assert_eq!(got, all[..all.len().min(3)].to_vec(), "k nearest {r:?}");
        }
        use octoray::kernels::MeetsBox;
        let (lo, hi) = (r.origin - Vec3::splat(2.0), r.origin + Vec3::splat(2.0));
        let mut ids = [0u32; 80];
        let f = octoray::tree::overlapping(tree.as_ref(), lo, hi, None, &mut ids);
        let (l, h) = (lo.to_array().map(f64::from), hi.to_array().map(f64::from));
        let want: Vec<u32> = (0..verts.len() as u32)
            .filter(|&i| lo.cmple(hi).all() && verts[i as usize].meets(l, h))
            .collect();
        assert_eq!(ids[..f.stored].to_vec(), want, "overlapping {lo:?}..{hi:?}");
        // The generalized winding number on hostile geometry: within its tolerance of the exact
        // sum (each triangle once; rounding of a sum in another order), NaN off the finite points.
        let winding = octoray::bvh::WindingTree::new(tree.as_ref());
        let exact: f64 = verts
            .iter()
            .map(|t| {
                octoray::kernels::triangle::solid_angle::solid_angle(
                    [t.v0, t.v1, t.v2].map(|v| v.map(f64::from)),
                    q,
                )
            })
            .sum::<f64>()
            / (4.0 * std::f64::consts::PI);
        for tol in [0.0, 0.01] {
            let w = octoray::tree::generalized_winding_number(&winding, r.origin, tol);
            if r.origin.is_finite() {
                let slack = tol + 1e-13 * (verts.len() as f64 + 1.0);
                assert!(
                    (w - exact).abs() <= slack,
                    "winding {w} / {exact} at {:?}",
                    r.origin
                );
            } else {
                assert!(w.is_nan());
            }
        }
    }
}

/// The batch calls of the packet crate agree with the per-ray queries.
fn run_batch(rng: &mut Rng) {
    let n = rng.below(40) as usize;
    let cases: Vec<(Ray, [Vec3; 3])> = (0..n.max(1)).map(|_| case(rng)).collect();
    let tris: Vec<PackedTriangle> = cases
        .iter()
        .map(|(_, v)| PackedTriangle::new(v[0], v[1], v[2]))
        .collect();
    let rays: Vec<Ray> = cases.iter().map(|c| c.0).take(n).collect();
    let mut out = vec![None; rays.len()];
    octoray::closest::<f32x8, MollerTrumbore>(&rays, &tris, &mut out);
    let mut occ = vec![false; rays.len()];
    octoray::occluded::<f32x16, MollerTrumbore>(&rays, &tris, &mut occ);
    let mut ts = vec![None; rays.len()];
    octoray::closest_t::<f32x4, MollerTrumbore>(&rays, &tris, &mut ts);
    for (i, r) in rays.iter().enumerate() {
        let want = closest::<f32, MollerTrumbore>(&RayLanes::single(r), &tris).lane(0);
        assert_eq!(out[i], want, "batch closest, {r:?}");
        assert_eq!(occ[i], want.is_some(), "batch occluded, {r:?}");
        assert_eq!(ts[i], want.map(|h| h.t), "batch closest_t, {r:?}");
    }
}

/// Serialised trees that passed and failed validation, and queries run on the passed ones.
static TREES: [std::sync::atomic::AtomicUsize; 3] =
    [const { std::sync::atomic::AtomicUsize::new(0) }; 3];

/// A built tree, serialised, changed by up to four crafted hostile edits (shared subtrees, every
/// slot on one node, shared or oversized leaf ranges, `PAD` and out-of-range indices, nodes out of
/// order, back edges, rewritten slots and boxes, random bytes) or cut to a crafted shape (the
/// shared chain, a chain at and past the depth limit): validation answers without panicking, an
/// unchanged tree passes, and every query on a tree that passes tests each leaf block at most once
/// per ray and reports only indices below the caller's count, at finite `t` in range.
fn run_tree(rng: &mut Rng) {
    use octoray::bvh::{Bvh8Ref, MAX_DEPTH};
    use octoray::tree::{occluded_packet, occluded_ray};
    use std::sync::atomic::Ordering::Relaxed;
    use testkit::trees::{
        bushy_chain, chain, craft, shared_chain, take_leaf_tests, triangles, Counting, Slices,
    };
    let n = 1 + rng.below(150) as usize;
    let tris = triangles(rng, n);
    // The starting tree, and whether it is valid as it is.
    let (mut t, valid) = match rng.below(16) {
        0 => (shared_chain(2 + rng.below(70) as usize), false),
        1 | 2 => {
            let depth = MAX_DEPTH - 1 + rng.below(3) as usize;
            let t = if rng.below(2) == 0 {
                chain(depth)
            } else {
                bushy_chain(depth)
            };
            (t, depth <= MAX_DEPTH)
        }
        _ => (Slices::of(&Bvh8::build(&tris), n), true),
    };
    let edits = rng.below(5);
    let mut done = vec![];
    for _ in 0..edits {
        done.push(craft(rng, &mut t));
    }
    let checked = Bvh8Ref::<VertexTriangle>::new(&t.nodes, &t.blocks, &t.ids, t.prims);
    if edits == 0 {
        assert_eq!(checked.is_ok(), valid, "{checked:?} for an unchanged tree");
    }
    let Ok(bvh) = checked else {
        TREES[1].fetch_add(1, Relaxed);
        return;
    };
    TREES[0].fetch_add(1, Relaxed);
    let blocks = t.ids.len() / 8;
    for _ in 0..4 {
        let o = rng.vec3(3.0);
        let rays: Vec<Ray> = (0..8)
            .map(|_| Ray::with_range(o, rng.vec3(1.0) - o, 0.0, rng.range(0.5, 10.0)))
            .collect();
        take_leaf_tests();
        let single = closest_ray_counting(bvh, &rays[0]);
        let tests = take_leaf_tests();
        assert!(
            tests <= blocks,
            "{tests} leaf tests over {blocks} blocks after {done:?}"
        );
        if let Some(h) = single {
            assert!(
                (h.prim as usize) < t.prims,
                "prim {} of {} after {done:?}",
                h.prim,
                t.prims
            );
            check_hit(&h, &rays[0], "crafted tree");
        }
        let _ = occluded_ray::<f32x8, Counting>(bvh, &rays[1]);
        assert!(take_leaf_tests() <= blocks, "occlusion after {done:?}");
        let p = RayLanes::<f32x8>::load(&rays);
        let packet = closest_packet::<f32x8, Counting>(bvh, &p);
        let _ = occluded_packet::<f32x16, Counting>(bvh, &RayLanes::load(&rays));
        let tests = take_leaf_tests();
        assert!(
            tests <= 2 * (t.ids.len() + 8 * blocks),
            "{tests} packet leaf tests over {} slots after {done:?}",
            t.ids.len()
        );
        for (i, r) in rays.iter().enumerate() {
            if let Some(h) = packet.lane(i) {
                assert!(
                    (h.prim as usize) < t.prims,
                    "packet prim {} after {done:?}",
                    h.prim
                );
                check_hit(&h, r, "crafted tree, packet");
            }
        }
        // Point queries and every-hit walks on the crafted tree: indices in range, no panic,
        // each leaf slot tested at most once per walk.
        let h = octoray::tree::closest_point(bvh, rays[2].origin, f32::INFINITY);
        assert!(
            h.is_none_or(|h| (h.prim as usize) < t.prims),
            "closest point after {done:?}"
        );
        let mut page = [Hit::default(); 3];
        take_leaf_tests();
        let f = octoray::tree::all_hits_ray::<f32x8, Counting>(bvh, &rays[3], None, &mut page);
        assert!(take_leaf_tests() <= blocks, "all hits after {done:?}");
        for h in &page[..f.stored] {
            assert!((h.prim as usize) < t.prims, "all hits prim after {done:?}");
        }
        let _ = octoray::tree::crossings_ray::<f32x8>(bvh, &rays[4]);
        let mut near = [octoray::tree::closest_point(bvh, Vec3::ZERO, 1.0)
            .unwrap_or(octoray::tree::PointHit::default()); 4];
        let f = octoray::tree::nearest_within(bvh, rays[6].origin, 2.0, &mut near);
        assert!(near[..f.stored].iter().all(|h| (h.prim as usize) < t.prims));
        let mut ids = [0u32; 4];
        let (lo, hi) = (rays[7].origin - Vec3::ONE, rays[7].origin + Vec3::ONE);
        let f = octoray::tree::overlapping(bvh, lo, hi, None, &mut ids);
        assert!(ids[..f.stored].iter().all(|&i| (i as usize) < t.prims));
        let winding = octoray::bvh::WindingTree::new(bvh);
        let _ = octoray::tree::generalized_winding_number(&winding, rays[5].origin, 0.01);
        if let Ok(solid) = octoray::bvh::Solid::new(bvh, &tris[..t.prims.min(tris.len())]) {
            let _ = octoray::tree::contains::<f32x8>(solid, rays[5].origin);
        }
        TREES[2].fetch_add(1, Relaxed);
    }
}

/// Scenes of hostile geometry: triangle and sphere geometries from hostile cases, instances with
/// hostile transforms (NaN, ±inf, huge, subnormal and zero entries, singular and raw matrices),
/// masks, a filter, a refit to hostile vertices: every scene query (single, packet, slice,
/// filtered) equals brute force over the instanced primitives with finite hits in range; the
/// scene's slices, corrupted, are rejected or traced without a panic, the work bounded and every
/// index in range.
fn run_scene(rng: &mut Rng) {
    use octoray::scene::{Scene, SceneParts, SceneRef, Trace, Transform, TreeParts};
    let n_geoms = 1 + rng.below(4) as usize;
    let mut geoms: Vec<(bool, Vec<VertexTriangle>, Vec<PackedSphere>)> = Vec::new();
    let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
    for _ in 0..n_geoms {
        let n = 1 + rng.below(12) as usize;
        if rng.below(3) == 0 {
            let sp: Vec<PackedSphere> = (0..n)
                .map(|_| {
                    let (r, v) = case(rng);
                    PackedSphere::new(v[0], (v[1] - r.origin).length() * rng.range(0.0, 0.3))
                })
                .collect();
            let g = scene.add_spheres(&sp).unwrap();
            scene.set_geometry_mask(g, if rng.below(4) == 0 { 2 } else { !0 });
            geoms.push((true, vec![], sp));
        } else {
            let tris: Vec<VertexTriangle> = (0..n)
                .map(|_| {
                    let v = case(rng).1;
                    VertexTriangle::new(v[0], v[1], v[2])
                })
                .collect();
            let g = scene.add_triangles(&tris).unwrap();
            scene.set_geometry_mask(g, if rng.below(4) == 0 { 2 } else { !0 });
            geoms.push((false, tris, vec![]));
        }
    }
    // What a placement places: a set of geometries, or a group.
    #[derive(Debug, Clone)]
    enum Target {
        Set(Vec<u32>),
        Group(usize),
    }
    type Place = (Target, Transform, u32);
    let place = |rng: &mut Rng, groups: usize| -> Place {
        let target = if groups > 0 && rng.below(3) == 0 {
            Target::Group(rng.below(groups as u64) as usize)
        } else {
            let first = rng.below(n_geoms as u64) as usize;
            Target::Set(if rng.below(3) == 0 {
                (0..n_geoms)
                    .filter(|&g| geoms[g].0 == geoms[first].0)
                    .map(|g| g as u32)
                    .collect()
            } else {
                vec![first as u32]
            })
        };
        let mut t = Transform::IDENTITY;
        match rng.below(4) {
            0 => {}
            1 => {
                for row in &mut t.rows {
                    for x in row.iter_mut() {
                        *x = value(rng);
                    }
                }
            }
            _ => {
                for row in &mut t.rows {
                    for x in row.iter_mut() {
                        *x = if rng.below(8) == 0 {
                            value(rng)
                        } else {
                            rng.range(-2.0, 2.0)
                        };
                    }
                }
            }
        }
        let mask = if rng.below(4) == 0 { 1 } else { !0 };
        (target, t, mask)
    };
    // Now and then a chain of groups (each may hold the ones before it: three at most, so
    // paths stay within the levels allowed).
    let mut groups: Vec<Vec<Place>> = Vec::new();
    for g in 0..rng.below(4) as usize {
        let id = scene.add_group();
        let mut list = Vec::new();
        for _ in 0..1 + rng.below(4) {
            let p = place(rng, g);
            // Now and then the same placement several times (copies that multiply the work).
            let copies = if rng.below(6) == 0 {
                2 + rng.below(4)
            } else {
                1
            };
            for _ in 0..copies {
                match &p.0 {
                    Target::Set(set) => scene.add_to_group(id, set, p.1, p.2),
                    Target::Group(c) => scene.place_group(Some(id), *c as u32, p.1, p.2),
                };
                list.push(p.clone());
            }
        }
        groups.push(list);
    }
    let mut places: Vec<Place> = Vec::new();
    // Now and then nothing in the world: the groups are placed nowhere and nothing is hit.
    let world_instances = if rng.below(12) == 0 {
        0
    } else {
        1 + rng.below(10)
    };
    for _ in 0..world_instances {
        let p = place(rng, groups.len());
        match &p.0 {
            Target::Set(set) => scene.add_instance(set, p.1, p.2),
            Target::Group(c) => scene.place_group(None, *c as u32, p.1, p.2),
        };
        places.push(p);
    }
    // Now and then, a refit to hostile vertices first.
    if rng.below(3) == 0 {
        for (g, geo) in geoms.iter_mut().enumerate() {
            if !geo.0 {
                scene.commit().expect("commit");
                let old = geo.1.clone();
                for t in geo.1.iter_mut() {
                    let v = case(rng).1;
                    *t = VertexTriangle::new(v[0], v[1], v[2]);
                }
                // Left-out primitives that became finite are an error, and then nothing moved.
                // A refit leaves the scene stale until it is committed (the stale-parts case:
                // `Scene::parts` and `Scene::as_ref` refuse it).
                match scene.refit_triangles(g as u32, &geo.1) {
                    Ok(()) => assert!(!scene.is_committed(), "a refitted scene is stale"),
                    Err(_) => geo.1 = old,
                }
            }
        }
    }
    scene.commit().expect("commit");
    let r = scene.as_ref();
    let rays: Vec<Ray> = (0..16).map(|_| case(rng).0).collect();
    let mask = if rng.below(3) == 0 { 1 } else { !0 };
    // Brute force over the instance paths, depth first (a path's number is its `inst`).
    #[allow(clippy::too_many_arguments)]
    fn level(
        list: &[Place],
        groups: &[Vec<Place>],
        geoms: &[(bool, Vec<VertexTriangle>, Vec<PackedSphere>)],
        masks: &[u32],
        ray: &Ray,
        mask: u32,
        path: &mut u32,
        filter: &dyn Fn(u32, u32, &Hit) -> bool,
        best: &mut Option<Hit>,
    ) {
        for (target, t, m) in list {
            let obj = t.apply(ray);
            let set = match target {
                Target::Group(c) => {
                    level(
                        &groups[*c],
                        groups,
                        geoms,
                        masks,
                        &obj,
                        mask & m,
                        path,
                        filter,
                        best,
                    );
                    continue;
                }
                Target::Set(set) => set,
            };
            for &g in set {
                let geo = &geoms[g as usize];
                if m & masks[g as usize] & mask == 0 {
                    continue;
                }
                let n = if geo.0 { geo.2.len() } else { geo.1.len() };
                for k in 0..n {
                    let h = if geo.0 {
                        octoray::intersect::<f32, StableSphere>(&obj, &geo.2[k])
                    } else {
                        octoray::intersect::<f32, Watertight>(&obj, &geo.1[k])
                    };
                    let Some(mut h) = h else { continue };
                    (h.prim, h.geom, h.inst) = (k as u32, g, *path);
                    if filter(g, *path, &h) && best.is_none_or(|b| h.t < b.t) {
                        *best = Some(h);
                    }
                }
            }
            *path += 1;
        }
    }
    let masks: Vec<u32> = scene.geometries().iter().map(|g| g.mask).collect();
    let brute = |ray: &Ray, filter: &dyn Fn(u32, u32, &Hit) -> bool| {
        let mut best: Option<Hit> = None;
        let mut path = 0;
        level(
            &places, &groups, &geoms, &masks, ray, mask, &mut path, filter, &mut best,
        );
        best
    };
    let odd = |h: &Hit| (h.prim + h.inst).is_multiple_of(2);
    let mut out = vec![None; rays.len()];
    r.closest::<f32x8, Watertight, StableSphere>(&rays, mask, &mut out);
    for (k, ray) in rays.iter().enumerate() {
        let want = brute(ray, &|_, _, _| true);
        let single = r.closest_ray::<f32x8, Watertight, StableSphere>(ray, mask);
        assert_eq!(single, want, "scene single, {ray:?}, {places:?}");
        assert_eq!(out[k], want, "scene slice, {ray:?}");
        assert_eq!(
            r.occluded_ray::<f32x8, Watertight, StableSphere>(ray, mask),
            want.is_some(),
            "scene occluded, {ray:?}"
        );
        if let Some(h) = single {
            check_hit(&h, ray, "scene");
        }
        let fw = brute(ray, &|_, _, h| odd(h));
        let got = r.closest_ray_with::<f32x8, Watertight, StableSphere, _>(
            ray,
            mask,
            &mut crate::dyn_filter(&mut |c: &octoray::hit::Candidate| {
                (c.prim + c.inst).is_multiple_of(2)
            }),
        );
        assert_eq!(got, fw, "scene filtered, {ray:?}");
    }
    let p = RayLanes::<f32x16>::load(&rays);
    let packet = r.closest_packet::<f32x16, Watertight, StableSphere>(&p, mask);
    for (i, ray) in rays.iter().enumerate() {
        assert_eq!(packet.lane(i), out[i], "scene packet, {ray:?}");
    }
    // Box queries and crossing counts on hostile scenes: places in range, ascending, each once;
    // paging gives what one large buffer gives; crossings counted without a panic.
    for ray in rays.iter().take(4) {
        let half = Vec3::splat(10f32.powi(rng.below(8) as i32 - 4));
        let (lo, hi) = (ray.origin - half, ray.origin + half);
        let mut big = [octoray::scene::Place::default(); 256];
        let all = r.overlapping(lo, hi, mask, None, &mut big);
        for (k, p) in big[..all.stored].iter().enumerate() {
            let g = scene.geometries()[p.geom as usize];
            assert!(p.prim < g.prims, "box place {p:?}");
            assert!(
                k == 0 || big[k - 1] < *p,
                "box order {:?}",
                &big[..all.stored]
            );
        }
        let (mut paged, mut page, mut after) =
            (vec![], [octoray::scene::Place::default(); 2], None);
        loop {
            let f = r.overlapping(lo, hi, mask, after, &mut page);
            paged.extend_from_slice(&page[..f.stored]);
            if f.complete || paged.len() > 256 {
                break;
            }
            after = Some(page[f.stored - 1]);
        }
        if all.complete {
            assert_eq!(paged, big[..all.stored].to_vec(), "paged boxes {lo}..{hi}");
        }
        let _ = r.crossings_ray::<f32x8, StableSphere>(ray, mask);
    }
    check_work_bound(&r, &rays);
    duplicated_unbounded_entries(&r, &rays, rng);
    // The slices, corrupted: rejected, or traced within bounds.
    let parts = scene.parts();
    let copy = |t: &TreeParts<'_>| (t.nodes.to_vec(), t.blocks.to_vec(), t.ids.to_vec());
    let (mut tri, mut sph, mut top) = (
        copy(&parts.triangles),
        copy(&parts.spheres),
        copy(&parts.top),
    );
    let (mut g, mut tr, mut mb, mut ins, mut unb) = (
        parts.geometries.to_vec(),
        parts.trees.to_vec(),
        parts.members.to_vec(),
        parts.instances.to_vec(),
        parts.unbounded.to_vec(),
    );
    {
        let mut words: Vec<&mut u32> = Vec::new();
        for t in [&mut tri, &mut sph, &mut top] {
            words.extend(bytemuck::cast_slice_mut::<_, u32>(&mut t.0[..]).iter_mut());
            words.extend(t.2.iter_mut());
        }
        words.extend(bytemuck::cast_slice_mut::<_, u32>(&mut g[..]).iter_mut());
        words.extend(bytemuck::cast_slice_mut::<_, u32>(&mut tr[..]).iter_mut());
        words.extend(bytemuck::cast_slice_mut::<_, u32>(&mut mb[..]).iter_mut());
        words.extend(bytemuck::cast_slice_mut::<_, u32>(&mut ins[..]).iter_mut());
        words.extend(unb.iter_mut());
        for _ in 0..rng.below(4) {
            let k = rng.below(words.len() as u64) as usize;
            *words[k] = match rng.below(3) {
                0 => rng.next_u64() as u32,
                1 => *words[k] ^ (1 << rng.below(32)),
                _ => u32::MAX,
            };
        }
    }
    type Owned = (Vec<octoray::bvh::Bvh8Node>, Vec<[f32; 8]>, Vec<u32>);
    fn tp(t: &Owned) -> TreeParts<'_> {
        TreeParts {
            nodes: &t.0,
            blocks: &t.1,
            ids: &t.2,
        }
    }
    let bad = SceneParts {
        triangles: tp(&tri),
        spheres: tp(&sph),
        geometries: &g,
        trees: &tr,
        members: &mb,
        instances: &ins,
        top: tp(&top),
        unbounded: &unb,
    };
    if let Ok(b) = SceneRef::<VertexTriangle, PackedSphere>::new(bad) {
        let blocks: usize = tri.2.len() / 8;
        for ray in &rays[..4] {
            testkit::trees::take_leaf_tests();
            if let Some(h) = b.closest_ray::<f32x8, testkit::trees::Counting, StableSphere>(ray, !0)
            {
                check_hit(&h, ray, "corrupted scene");
                assert!((h.geom as usize) < g.len() && b.instance_path(h.inst).is_some());
            }
            let tests = testkit::trees::take_leaf_tests();
            let visits = tree_visits(&b, b.world());
            assert!(
                tests <= visits * blocks.max(1),
                "{tests} leaf tests over {blocks} blocks and {visits} visits of trees"
            );
        }
        let _ = b.closest_packet::<f32x8, Watertight, StableSphere>(&RayLanes::load(&rays), !0);
    }
    // The stored words, corrupted anywhere (header included) or cut short: rejected, or traced
    // within bounds.
    let mut words = r.to_words();
    for _ in 0..1 + rng.below(3) {
        let k = rng.below(words.len() as u64) as usize;
        words[k] = match rng.below(3) {
            0 => rng.next_u64() as u32,
            1 => words[k] ^ (1 << rng.below(32)),
            _ => u32::MAX,
        };
    }
    let cut = words.len() - rng.below(2) as usize * rng.below(words.len() as u64) as usize;
    if let Ok(b) = SceneRef::<VertexTriangle, PackedSphere>::from_words(&words[..cut]) {
        for ray in &rays[..4] {
            if let Some(h) = b.closest_ray::<f32x8, Watertight, StableSphere>(ray, !0) {
                check_hit(&h, ray, "corrupted stored scene");
                assert!((h.geom as usize) < b.geometries().len());
                assert!(b.instance_path(h.inst).is_some());
            }
        }
    }
}

/// A scene's rays stay within its entry bound: the leaf tests of each ray are within the visits
/// of geometry trees its levels allow (counted here, independently of the library) times the
/// blocks, those visits within the library's entry bound, and the default budget refuses the
/// scene exactly when that bound exceeds its length in words.
fn check_work_bound(s: &octoray::scene::SceneRef<'_, VertexTriangle, PackedSphere>, rays: &[Ray]) {
    use octoray::scene::Trace;
    let entries = s.entries_within(u64::MAX).expect("a finite bound");
    let visits = tree_visits(s, s.world());
    assert!(
        visits as u64 <= entries,
        "{visits} tree visits over {entries} entries"
    );
    let blocks = s.parts().triangles.ids.len() / 8;
    for ray in rays {
        testkit::trees::take_leaf_tests();
        s.closest_ray::<f32x8, testkit::trees::Counting, StableSphere>(ray, !0);
        let tests = testkit::trees::take_leaf_tests();
        assert!(
            tests <= visits * blocks.max(1),
            "{tests} leaf tests, {visits} visits"
        );
    }
    let words = s.parts().words();
    let default = octoray::scene::SceneRef::<VertexTriangle, PackedSphere>::new(s.parts());
    assert_eq!(
        default.err(),
        (entries > words).then_some(octoray::scene::SceneError::TooMuchWork { budget: words })
    );
}

/// The hostile shape the builder never makes: every level's unbounded list naming each of its
/// entries again (1-3 extra copies). Still a valid scene with the same answers; its entry bound
/// counts the copies and its rays stay within it.
fn duplicated_unbounded_entries(
    s: &octoray::scene::SceneRef<'_, VertexTriangle, PackedSphere>,
    rays: &[Ray],
    rng: &mut Rng,
) {
    use octoray::scene::{SceneParts, SceneRef, Trace, INSTANCES};
    use octoray_testkit::stored::{word, words, FIRST_UNBOUNDED, UNBOUNDED};
    let p = s.parts();
    if p.unbounded.is_empty() {
        return;
    }
    let copies = 2 + rng.below(3) as usize;
    let mut trees = p.trees.to_vec();
    let world_end = trees
        .iter()
        .find(|t| t.kind() == INSTANCES)
        .map_or(p.unbounded.len(), |t| words(t)[FIRST_UNBOUNDED] as usize);
    let repeat = |list: &[u32], out: &mut Vec<u32>| {
        for &k in list {
            out.extend(std::iter::repeat_n(k, copies));
        }
    };
    let mut unbounded = Vec::new();
    repeat(&p.unbounded[..world_end], &mut unbounded);
    for t in trees.iter_mut().filter(|t| t.kind() == INSTANCES) {
        let (u0, n) = (
            words(t)[FIRST_UNBOUNDED] as usize,
            words(t)[UNBOUNDED] as usize,
        );
        *word(t, FIRST_UNBOUNDED) = unbounded.len() as u32;
        *word(t, UNBOUNDED) = (n * copies) as u32;
        repeat(&p.unbounded[u0..u0 + n], &mut unbounded);
    }
    let parts = SceneParts {
        trees: &trees,
        unbounded: &unbounded,
        ..p
    };
    let dup = SceneRef::<VertexTriangle, PackedSphere>::new_bounded(parts, u64::MAX)
        .expect("copies of unbounded entries are a valid scene");
    assert!(dup.entries_within(u64::MAX) >= s.entries_within(u64::MAX));
    for ray in rays {
        assert_eq!(
            dup.closest_ray::<f32x8, Watertight, StableSphere>(ray, !0),
            s.closest_ray::<f32x8, Watertight, StableSphere>(ray, !0),
            "duplicated unbounded entries, {ray:?}"
        );
    }
    check_work_bound(&dup, rays);
}

/// The most visits of geometry trees a ray can make through `level` of a validated scene: each
/// used slot of its tree and each unbounded entry once, a group's visits below it.
fn tree_visits(
    s: &octoray::scene::SceneRef<'_, VertexTriangle, PackedSphere>,
    level: octoray::scene::Level<'_>,
) -> usize {
    let visits = |inst: u32| match s.instance_tree(inst) {
        Some((_, octoray::scene::TreeRef::Instances(l))) => tree_visits(s, l),
        _ => 1,
    };
    level
        .top
        .ids()
        .iter()
        // Padding slots name no instance.
        .filter(|&&k| (k as usize) < level.instances.len())
        .map(|&k| visits(level.first + k))
        .chain(level.unbounded.iter().map(|&i| visits(i)))
        .sum()
}

fn closest_ray_counting(bvh: octoray::bvh::Bvh8Ref<'_, VertexTriangle>, r: &Ray) -> Option<Hit> {
    bvh_closest::<f32x8, testkit::trees::Counting>(bvh, r)
}

/// Spawns over every tier's documented range, and spheres with `|d|·r` down to the underflow
/// limit against the exact oracle.
fn run_spawn_and_tiny_spheres(rng: &mut Rng) {
    use testkit::accuracy::{measure_spheres, tiny_sphere_cases, SphereTier};
    use testkit::spawn::{sphere_case, triangle_case, SpawnCount, TRIANGLE_TIERS};
    let mut count = SpawnCount::default();
    let tier = TRIANGLE_TIERS[rng.below(TRIANGLE_TIERS.len() as u64) as usize];
    triangle_case(rng, tier, &mut count).unwrap();
    sphere_case(rng, &mut count).unwrap();
    let cases = tiny_sphere_cases(rng.next_u64(), 4);
    for (tier, bound) in [(SphereTier::Stable, 8.0), (SphereTier::F64, 2.0)] {
        let s = measure_spheres(tier, &cases);
        assert!(
            s.wrong == 0 && s.bad_t == 0 && s.max_scaled() <= bound,
            "{}: {s:?} for {cases:?}",
            tier.name()
        );
    }
}

/// Runs `n` cases of every kind from `seed`; returns (cases, BVH rays).
fn fuzz(seed: u64, n: usize) -> (usize, usize) {
    let mut rng = Rng(seed);
    let others: Vec<Ray> = (0..15).map(|_| case(&mut rng).0).collect();
    let mut bvh_rays = 0;
    for i in 0..n {
        if i > 0 && i % 1_000_000 == 0 {
            eprintln!("fuzz: {i} cases clean");
        }
        run_case(&mut rng, &others);
        run_ingest(&mut rng);
        if i % 8 == 0 {
            run_batch(&mut rng);
            bvh_rays += run_bvh(&mut rng);
            run_spawn_and_tiny_spheres(&mut rng);
        }
        if i % 64 == 0 {
            run_tree(&mut rng);
            run_scene(&mut rng);
        }
    }
    (n, bvh_rays)
}

/// The crafted-tree counts, for the closing line.
fn trees() -> String {
    let [ok, bad, q] = TREES
        .each_ref()
        .map(|c| c.load(std::sync::atomic::Ordering::Relaxed));
    format!("{} crafted trees ({ok} accepted, {bad} rejected), {q} query rounds on accepted ones within the work bound", ok + bad)
}

#[test]
fn fuzz_fast_slice() {
    let (n, bvh) = fuzz(0x0c70_7a11, 20_000);
    let skipped = OUT_OF_RANGE.load(std::sync::atomic::Ordering::Relaxed);
    let within = DECIDED_WITHIN_ERROR.load(std::sync::atomic::Ordering::Relaxed);
    println!("{n} cases per entry point, {bvh} BVH rays ({within} answers differ from brute force within the t error bound); {skipped} hits outside the documented range (underflow) not oracle-checked; {}", trees());
}

#[test]
#[ignore = "10⁷ cases per entry point: cargo test --release --test suite fuzz:: -- --ignored --nocapture"]
fn fuzz_large_run() {
    let (n, bvh) = fuzz(0x5eed_0001, 10_000_000);
    let skipped = OUT_OF_RANGE.load(std::sync::atomic::Ordering::Relaxed);
    let within = DECIDED_WITHIN_ERROR.load(std::sync::atomic::Ordering::Relaxed);
    println!("{n} cases per entry point, {bvh} BVH rays: clean ({within} answers differ from brute force within the t error bound); {skipped} hits outside the documented range (underflow) not oracle-checked; {}", trees());
}
