//! Links both octoray crates into a `#![no_std]` staticlib with its own panic handler.
#![no_std]

use octoray_core::glam::Vec3;
use octoray_core::bvh::{Bvh8Node, Bvh8Ref};
use octoray_core::kernels::{MollerTrumbore, StableSphere, Watertight};
use octoray_core::lanes::LaneMask;
use octoray_core::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, VertexTriangle, BLOCK};
use octoray_packet::{f32x8, scene, tree};

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}

/// Seed problem 1 through the packet kernel; returns the hit mask so nothing is optimised away.
#[no_mangle]
pub extern "C" fn octoray_nostd_probe(x: f32) -> u32 {
    let ray = Ray::new(Vec3::new(x, -2.0, -1.0), Vec3::new(1.0, 2.0, 3.0));
    let tri = PackedTriangle::new(Vec3::new(0.0, 6.0, 7.0), Vec3::new(-3.0, 1.0, 5.0), Vec3::new(-2.0, 1.0, 4.0));
    let sph = PackedSphere::new(Vec3::ZERO, 10.0);
    let p = RayLanes::<f32x8>::load(&[ray; 5]);
    let t = octoray_core::query::closest::<_, MollerTrumbore>(&p, &[tri]).mask.bitmask();
    let s = octoray_core::query::occluded::<_, StableSphere>(&p, &[sph]).bitmask();
    let scalar = octoray_core::intersect_triangle(&ray, &tri).is_some() as u32;
    t ^ (s << 8) ^ (scalar << 16)
}

/// BVH traversal from borrowed slices with neither `std` nor `alloc`: a tree built on a host and
/// handed over as bytes (here a one-leaf tree of one triangle made by hand) is validated and traversed, single
/// ray and packet. Returns the hit index, or u32::MAX for a miss or an invalid tree.
#[no_mangle]
pub extern "C" fn octoray_nostd_bvh_probe(
    nodes: &[Bvh8Node; 1],
    blocks: &[[f32; BLOCK]; 9],
    ids: &[u32; BLOCK],
    x: f32,
) -> u32 {
    let Ok(bvh) = Bvh8Ref::<VertexTriangle>::new(nodes, blocks, ids, 1) else {
        return u32::MAX;
    };
    let ray = Ray::new(Vec3::new(x, 0.25, -1.0), Vec3::new(0.0, 0.0, 1.0));
    let packet = RayLanes::<f32x8>::load(&[ray; 3]);
    let p = tree::closest_packet::<f32x8, Watertight>(bvh, &packet);
    match tree::closest_ray::<f32x8, Watertight>(bvh, &ray) {
        Some(h) => h.prim ^ (p.mask.bitmask() << 8),
        None => u32::MAX,
    }
}

/// A whole scene (top level and bottom trees) from borrowed slices with neither `std` nor
/// `alloc`: validated, then traced by one ray and one packet. Returns the hit's instance, or
/// u32::MAX for a miss or an invalid scene.
pub fn octoray_nostd_scene_probe(parts: scene::SceneParts<'_>, x: f32) -> u32 {
    use scene::Trace;
    let Ok(s) = scene::SceneRef::<VertexTriangle, PackedSphere>::new(parts) else {
        return u32::MAX;
    };
    let ray = Ray::new(Vec3::new(x, 0.25, -1.0), Vec3::new(0.0, 0.0, 1.0));
    let packet = RayLanes::<f32x8>::load(&[ray; 3]);
    let p = s.occluded_packet::<f32x8, Watertight, StableSphere>(&packet, !0);
    match s.closest_ray::<f32x8, Watertight, StableSphere>(&ray, !0) {
        Some(h) => h.inst ^ (p.bitmask() << 8),
        None => u32::MAX,
    }
}
