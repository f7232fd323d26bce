//! Links both octoray crates into a `#![no_std]` staticlib with its own panic handler.
#![no_std]

use octoray_core::glam::Vec3;
use octoray_core::{PackedSphere, PackedTriangle, Ray};
use octoray_packet::{f32x8, LaneMask, RayPacket};

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
    let p = RayPacket::<f32x8>::load(&[ray; 5]);
    let t = octoray_packet::closest_triangle(&p, &[tri]).mask.bitmask();
    let s = octoray_packet::any_sphere(&p, &[sph]).bitmask();
    let scalar = octoray_core::intersect_triangle(&ray, &tri).is_some() as u32;
    t ^ (s << 8) ^ (scalar << 16)
}
