//! What a shading step asks of a triangle hit, computed only on request: the hit point, the unit
//! geometric normal facing the ray, and conservatively offset origins for rays that leave the
//! surface on either side (see [`crate::offset`]).

use crate::offset::{offset_ray_origin, triangle_hit_point};
use crate::ray::{Hit, PackedTriangle, Ray, VertexTriangle};
use glam::Vec3;

/// Surface data of a triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// The hit point from the barycentrics.
    pub point: Vec3,
    /// Unit geometric normal, turned to face the incoming ray (`n·d ≤ 0`).
    pub normal: Vec3,
    /// Origin for rays leaving on the side the ray came from (reflection, shadow rays).
    pub spawn_front: Vec3,
    /// Origin for rays continuing through the surface (refraction).
    pub spawn_back: Vec3,
}

fn surface(ray: &Ray, tri: &VertexTriangle, hit: &Hit) -> Surface {
    let (p, err) = triangle_hit_point(tri, hit.u, hit.v);
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let mut n = (v1 - v0).cross(v2 - v0).normalize_or_zero();
    if n.dot(ray.dir) > 0.0 {
        n = -n;
    }
    Surface {
        point: p,
        normal: n,
        spawn_front: offset_ray_origin(p, err, n, n),
        spawn_back: offset_ray_origin(p, err, n, -n),
    }
}

/// Surface data for a hit on a [`VertexTriangle`] (watertight tier).
pub fn vertex_triangle_surface(ray: &Ray, tri: &VertexTriangle, hit: &Hit) -> Surface {
    surface(ray, tri, hit)
}

/// Surface data for a hit on a [`PackedTriangle`] (standard and fast tiers): the triangle
/// `v0, v0 + e1, v0 + e2` it describes.
pub fn packed_triangle_surface(ray: &Ray, tri: &PackedTriangle, hit: &Hit) -> Surface {
    let v0 = Vec3::from(tri.v0);
    let vt = VertexTriangle::new(v0, v0 + Vec3::from(tri.e1), v0 + Vec3::from(tri.e2));
    surface(ray, &vt, hit)
}
