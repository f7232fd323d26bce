//! A renderer's code on its own glam: its `Vec3` goes into octoray's rays and triangles and its
//! hits come back as its own `Vec3`.
use glam::Vec3;
use octoray::bvh::Bvh8;
use octoray::kernels::Watertight;
use octoray::prim::{Ray, VertexTriangle};
use octoray::shading::Shade;
use octoray::{f32x8, tree::closest_ray};

/// The hit point and normal of a ray down −z onto the unit square, through a BVH.
pub fn trace(x: f32, y: f32) -> Option<(Vec3, Vec3)> {
    let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
    let tris = [VertexTriangle::new(a, b, c), VertexTriangle::new(a, c, d)];
    let bvh = Bvh8::build(&tris);
    let ray = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
    let hit = closest_ray::<f32x8, Watertight>(bvh.as_ref(), &ray)?;
    let s = tris[hit.prim as usize].surface(&ray, &hit);
    Some((s.point, s.normal))
}
