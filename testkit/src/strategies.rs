//! proptest generators: random and adversarial rays, triangles and spheres.

use octoray::glam::Vec3;
use octoray::prim::{PackedSphere, PackedTriangle, Ray, VertexTriangle};
use proptest::prelude::*;

/// A float from a mix that includes what breaks kernels: normal range mostly, then huge,
/// tiny and subnormal magnitudes, exact zeros of both signs, NaN and infinities.
pub fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        12 => -10.0f32..10.0,
        1 => (-1.0f32..1.0, 6i32..=13).prop_map(|(m, e)| m * 10f32.powi(e)),
        1 => (-1.0f32..1.0, -38i32..=-15).prop_map(|(m, e)| m * 10f32.powi(e)),
        1 => prop_oneof![
            Just(0.0f32), Just(-0.0f32), Just(f32::NAN), Just(f32::INFINITY),
            Just(f32::NEG_INFINITY), Just(f32::MIN_POSITIVE / 4.0), Just(f32::MAX)
        ],
    ]
}

/// A vector of [`coord`]s.
pub fn vec3() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A well-behaved vector in [-10, 10]³.
pub fn tame() -> impl Strategy<Value = Vec3> {
    (-10.0f32..10.0, -10.0f32..10.0, -10.0f32..10.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A scale that moves a whole scene to huge or tiny coordinates.
pub fn scale() -> impl Strategy<Value = f32> {
    prop_oneof![6 => Just(1.0f32), 1 => Just(1e-6), 1 => Just(1e6), 1 => Just(1e12), 1 => Just(1e-20)]
}

/// A triangle: random, or degenerate (zero area, repeated vertex), all scaled.
pub fn triangle() -> impl Strategy<Value = [Vec3; 3]> {
    let random = (tame(), tame(), tame()).prop_map(|(a, b, c)| [a, b, c]);
    let wild = (vec3(), vec3(), vec3()).prop_map(|(a, b, c)| [a, b, c]);
    let collinear = (tame(), tame(), -3.0f32..3.0).prop_map(|(a, b, k)| [a, b, a + (b - a) * k]);
    let repeated = (tame(), tame()).prop_map(|(a, b)| [a, a, b]);
    (
        prop_oneof![8 => random, 2 => wild, 1 => collinear, 1 => repeated],
        scale(),
    )
        .prop_map(|(t, s)| t.map(|v| v * s))
}

/// How a ray is aimed at a triangle of the scene.
#[derive(Clone, Debug)]
pub enum Aim {
    /// Any direction.
    Free(Vec3),
    /// Exactly at vertex `k`.
    Vertex(usize),
    /// At a point of edge `k` (parameter `f`).
    Edge(usize, f32),
    /// At the interior point with barycentrics `(u, v)`.
    Inside(f32, f32),
    /// Nearly parallel to the plane, tilted by `eps`.
    Grazing(f32),
}

/// A ray spec: origin, which triangle/sphere to aim at, how, and its t range.
#[derive(Clone, Debug)]
pub struct RaySpec {
    pub origin: Vec3,
    pub target: usize,
    pub aim: Aim,
    pub range: (f32, f32),
}

fn aim() -> impl Strategy<Value = Aim> {
    prop_oneof![
        2 => vec3().prop_map(Aim::Free),
        2 => (0usize..3).prop_map(Aim::Vertex),
        2 => (0usize..3, 0.0f32..=1.0).prop_map(|(k, f)| Aim::Edge(k, f)),
        2 => (0.0f32..1.0, 0.0f32..1.0).prop_map(|(u, v)| Aim::Inside(u, v)),
        1 => prop_oneof![Just(0.0f32), 1e-7f32..1e-3].prop_map(Aim::Grazing),
    ]
}

fn range() -> impl Strategy<Value = (f32, f32)> {
    prop_oneof![
        6 => Just((0.0f32, f32::INFINITY)),
        2 => (-2.0f32..1.0, 0.0f32..3.0).prop_map(|(a, b)| (a, a + b)),
        1 => (coord(), coord()),
    ]
}

/// A ray spec whose origin is random (or a wild coordinate).
pub fn ray_spec() -> impl Strategy<Value = RaySpec> {
    (
        prop_oneof![6 => tame(), 1 => vec3()],
        any::<usize>(),
        aim(),
        range(),
    )
        .prop_map(|(origin, target, aim, range)| RaySpec {
            origin,
            target,
            aim,
            range,
        })
}

/// Builds the ray that `spec` describes against `tris` (the origin is scaled with the scene).
pub fn aim_at_triangle(spec: &RaySpec, tris: &[[Vec3; 3]], s: f32) -> Ray {
    let [a, b, c] = tris[spec.target % tris.len()];
    let o = spec.origin * s;
    let (e1, e2) = (b - a, c - a);
    let dir = match spec.aim {
        Aim::Free(d) => d,
        Aim::Vertex(k) => [a, b, c][k] - o,
        Aim::Edge(k, f) => {
            let (p, q) = [(a, b), (b, c), (c, a)][k];
            p + (q - p) * f - o
        }
        Aim::Inside(u, v) => {
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            a + e1 * u + e2 * v - o
        }
        Aim::Grazing(eps) => {
            let n = e1.cross(e2).normalize_or_zero();
            // Start slightly above the plane, head along it, dipping by eps.
            let start = a - e1 + n * (eps * e1.length());
            return Ray::with_range(
                start,
                e1 + e2 * 0.25 - n * (eps * e1.length()),
                spec.range.0,
                spec.range.1,
            );
        }
    };
    Ray::with_range(o, dir, spec.range.0, spec.range.1)
}

/// Sphere inputs: centre, radius (including bad radii), scaled; and how rays meet them.
pub fn sphere() -> impl Strategy<Value = (Vec3, f32)> {
    let radius = prop_oneof![
        8 => 0.01f32..10.0,
        1 => 1e3f32..1e6,
        1 => prop_oneof![Just(-1.0f32), Just(0.0), Just(f32::NAN), Just(f32::INFINITY), Just(1e-30)],
    ];
    let center = prop_oneof![6 => tame(), 1 => vec3(), 1 => tame().prop_map(|v| v * 1e4)];
    (center, radius)
}

/// How a ray meets a sphere.
#[derive(Clone, Debug)]
pub enum SphereAim {
    /// Any direction.
    Free(Vec3),
    /// From far away towards a point near the centre (small distant spheres).
    Distant(f32, Vec3),
    /// Origin on the surface in direction `u`, heading along `d`.
    OnSurface(Vec3, Vec3),
    /// Tangent-ish: aimed at a point at `k`·radius from the centre, `k` near 1.
    Rim(Vec3, f32),
}

/// A ray spec for spheres.
pub fn sphere_ray_spec() -> impl Strategy<Value = (Vec3, usize, SphereAim, (f32, f32))> {
    let aim = prop_oneof![
        2 => vec3().prop_map(SphereAim::Free),
        2 => (prop_oneof![Just(1e2f32), Just(1e4), Just(1e6)], tame()).prop_map(|(d, j)| SphereAim::Distant(d, j)),
        2 => (tame(), tame()).prop_map(|(u, d)| SphereAim::OnSurface(u, d)),
        2 => (tame(), 0.99f32..1.01).prop_map(|(u, k)| SphereAim::Rim(u, k)),
    ];
    (
        prop_oneof![6 => tame(), 1 => vec3()],
        any::<usize>(),
        aim,
        range(),
    )
}

/// Builds the ray of a sphere spec.
pub fn aim_at_sphere(spec: &(Vec3, usize, SphereAim, (f32, f32)), spheres: &[(Vec3, f32)]) -> Ray {
    let (origin, target, aim, (t0, t1)) = spec;
    let (c, r) = spheres[target % spheres.len()];
    let (o, d) = match *aim {
        SphereAim::Free(d) => (*origin, d),
        SphereAim::Distant(dist, jitter) => {
            let o = c + origin.normalize_or_zero() * (dist * r.abs());
            (o, c + jitter * (r.abs() * 0.05) - o)
        }
        SphereAim::OnSurface(u, d) => (c + u.normalize_or_zero() * r, d),
        SphereAim::Rim(u, k) => {
            let side = u.cross(*origin - c).normalize_or_zero();
            (*origin, c + side * (r * k) - *origin)
        }
    };
    Ray::with_range(o, d, *t0, *t1)
}

/// Packs triangles.
pub fn pack_triangles(tris: &[[Vec3; 3]]) -> Vec<PackedTriangle> {
    tris.iter()
        .map(|t| PackedTriangle::new(t[0], t[1], t[2]))
        .collect()
}

/// The same triangles in the vertex layout (the watertight and exact tiers').
pub fn pack_vertex_triangles(tris: &[[Vec3; 3]]) -> Vec<VertexTriangle> {
    tris.iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect()
}

/// Packs spheres.
pub fn pack_spheres(s: &[(Vec3, f32)]) -> Vec<PackedSphere> {
    s.iter().map(|&(c, r)| PackedSphere::new(c, r)).collect()
}
