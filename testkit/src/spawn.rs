//! Spawned rays over each tier's whole documented range: well-shaped triangles and spheres at
//! any scale, a hit, its surface, and rays leaving it on both sides, which must not re-hit.

use crate::Rng;
use octoray::hit::Hit;
use octoray::intersect;
use octoray::kernels::{Exact, MollerTrumbore, StableSphere, Watertight};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, Sphere, VertexTriangle};
use octoray::shading::Shade;

/// A tier's closest hit of one ray on one triangle.
pub type TriangleTier = fn(&Ray, &VertexTriangle) -> Option<Hit>;

fn standard(r: &Ray, t: &VertexTriangle) -> Option<Hit> {
    intersect::<f32, MollerTrumbore>(r, &PackedTriangle::from(*t))
}
fn f64_standard(r: &Ray, t: &VertexTriangle) -> Option<Hit> {
    intersect::<f64, MollerTrumbore>(r, &PackedTriangle::from(*t))
}

/// The triangle tiers, each with the scale exponents (base 10) of its documented range: the
/// standard tier 1e-14…1e12, the watertight tier 1e-19…1e18.5, the exact tier 1e-30…1e35 (every
/// finite input; these are the scales at which a well-shaped triangle's hit point is finite), f64
/// 1e-37…1e18.5.
pub const TRIANGLE_TIERS: [(&str, TriangleTier, f32, f32); 5] = [
    ("standard", standard, -14.0, 12.0),
    (
        "watertight",
        |r, t| intersect::<f32, Watertight>(r, t),
        -19.0,
        18.5,
    ),
    ("exact", |r, t| intersect::<f32, Exact>(r, t), -30.0, 35.0),
    ("f64", f64_standard, -37.0, 18.5),
    (
        "f64 watertight",
        |r, t| intersect::<f64, Watertight>(r, t),
        -37.0,
        18.5,
    ),
];

/// What one spawn case found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpawnCount {
    /// Hits whose surface was checked.
    pub hits: usize,
    /// Rays spawned from them.
    pub spawned: usize,
}

/// Spawns rays from the surface of a hit (at least 0.1 rad off the plane; into both sides with
/// `through`, else only the ray's side) and returns an error naming the first failure: a normal
/// that is not unit, finite and facing the ray, or a spawned ray that hits the primitive again.
fn spawn_rays(
    rng: &mut Rng,
    ray: &Ray,
    surf: octoray::shading::Surface,
    through: bool,
    rehit: impl Fn(&Ray) -> Option<Hit>,
    what: &str,
    count: &mut SpawnCount,
) -> Result<(), String> {
    let n = surf.normal;
    if !(n.is_finite() && (n.length() - 1.0).abs() < 1e-6 && n.dot(ray.dir) <= 0.0) {
        return Err(format!("{what}: normal {n:?} for {ray:?}"));
    }
    count.hits += 1;
    let mut w = rng.vec3(1.0).normalize();
    if w.dot(n) < 0.0 {
        w = -w;
    }
    if w.dot(n) < 0.1 {
        return Ok(());
    }
    for dir in if through { vec![w, -w] } else { vec![w] } {
        count.spawned += 1;
        let spawn = Ray::new(surf.spawn(dir), dir);
        if let Some(h) = rehit(&spawn) {
            return Err(format!("{what}: {spawn:?} re-hit at t = {}", h.t));
        }
    }
    Ok(())
}

/// One triangle case for `tier` at a random scale of its range: a well-shaped triangle, a ray
/// aimed inside it from a few triangle sizes away, and, on a hit, spawns from its surface.
pub fn triangle_case(
    rng: &mut Rng,
    (name, hit_with, lo, hi): (&str, TriangleTier, f32, f32),
    count: &mut SpawnCount,
) -> Result<(), String> {
    let e = rng.range(lo, hi);
    let s = libm::powf(10.0, e);
    let away = libm::powf(10.0, rng.range(0.0, 1.0));
    let c = rng.vec3(s * away);
    let v = [c + rng.vec3(s), c + rng.vec3(s), c + rng.vec3(s)];
    let tri = VertexTriangle::new(v[0], v[1], v[2]);
    let target =
        v[0] + (v[1] - v[0]) * rng.range(0.05, 0.45) + (v[2] - v[0]) * rng.range(0.05, 0.45);
    let o = target + rng.vec3(3.0 * s);
    let ray = Ray::new(o, target - o);
    let Some(hit) = hit_with(&ray, &tri) else {
        return Ok(());
    };
    let what = format!("{name} at scale 1e{e}, {tri:?}");
    spawn_rays(
        rng,
        &ray,
        tri.surface(&ray, &hit),
        true,
        |r| hit_with(r, &tri),
        &what,
        count,
    )
}

/// One sphere case: a radius of 1e-18…1e15, its centre 1 to 1e8 radii from the origin, a ray
/// from 2–100 radii away; on a hit, spawns outward from its surface (inward rays meet the far
/// side), tested by the f32 and f64 tiers.
pub fn sphere_case(rng: &mut Rng, count: &mut SpawnCount) -> Result<(), String> {
    let r = libm::powf(10.0, rng.range(-18.0, 15.0));
    let k = rng.range(0.0, 8.0);
    let c = rng.vec3(1.0).normalize() * (r * libm::powf(10.0, k));
    let s = PackedSphere::new(c, r);
    let o = c + rng.vec3(1.0).normalize() * (r * rng.range(2.0, 100.0));
    // Far from the origin f32 may round the origin into the sphere (its grid is coarser than r
    // there): then the hit is the exit, and "outward" is not the ray's side.
    if (o.as_dvec3() - c.as_dvec3()).length() < 1.5 * f64::from(r) {
        return Ok(());
    }
    let ray = Ray::new(o, (c + rng.vec3(r) - o).normalize());
    let Some(h) = intersect::<f32, StableSphere>(&ray, &s) else {
        return Ok(());
    };
    let surf = Sphere::new(c, r).surface(&ray, &h);
    let rehit = |sp: &Ray| {
        intersect::<f32, StableSphere>(sp, &s).or_else(|| intersect::<f64, StableSphere>(sp, &s))
    };
    let what = format!("sphere r {r}, centre 1e{k} radii out");
    spawn_rays(rng, &ray, surf, false, rehit, &what, count)
}
