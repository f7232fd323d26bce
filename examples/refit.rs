//! An animated mesh: a wavy sheet refitted in place every frame (the topology kept), against a
//! rebuild, and a moving instance of it, with only the top level rebuilt.
use octoray::bvh::Bvh8;
use octoray::f32x8;
use octoray::glam::{Affine3A, Vec3};
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{PackedSphere, Ray, VertexTriangle};
use octoray::scene::{Scene, Trace, Transform};
use octoray::tree::closest_ray;
use std::time::Instant;

/// A 200×200 sheet in the xz plane at frame `f`: heights move with a travelling wave.
fn sheet(f: u32) -> Vec<VertexTriangle> {
    let n = 200;
    let p = |i: u32, j: u32| {
        let (x, z) = (
            i as f32 / n as f32 * 10.0 - 5.0,
            j as f32 / n as f32 * 10.0 - 5.0,
        );
        Vec3::new(x, 0.3 * (x + 0.2 * f as f32).sin() * z.cos(), z)
    };
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            tris.push(VertexTriangle::new(a, b, c));
            tris.push(VertexTriangle::new(a, c, d));
        }
    }
    tris
}

fn main() {
    let mut tree = Bvh8::build(&sheet(0));
    let ray = Ray::new(Vec3::new(0.5, 2.0, 0.5), -Vec3::Y);
    let (mut refit_s, mut build_s) = (0.0, 0.0);
    for f in 1..=30 {
        let tris = sheet(f);
        let t = Instant::now();
        tree.refit(&tris).expect("same slice");
        refit_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let rebuilt = Bvh8::build(&tris);
        build_s += t.elapsed().as_secs_f64();
        // The refitted tree answers as a rebuilt one: both equal brute force.
        let (a, b) = (
            closest_ray::<f32x8, Watertight>(tree.as_ref(), &ray),
            closest_ray::<f32x8, Watertight>(rebuilt.as_ref(), &ray),
        );
        assert_eq!(a, b);
        if f % 10 == 0 {
            println!(
                "frame {f}: height under the ray {:.4}",
                2.0 - a.expect("the sheet").t
            );
        }
    }
    println!(
        "80 000 triangles, 30 frames: refit {:.2} ms per frame, rebuild {:.2} ms",
        refit_s / 30.0 * 1e3,
        build_s / 30.0 * 1e3
    );

    // In a scene: the sheet refitted, and an instance of it moving (only the top level rebuilt).
    let mut scene = Scene::<VertexTriangle, PackedSphere>::new();
    let g = scene.add_triangles(&sheet(0)).expect("build");
    let fixed = scene.add_instance(&[g], Transform::IDENTITY, !0);
    let moving = scene.add_instance(&[g], Transform::IDENTITY, !0);
    for f in 1..=3 {
        scene.refit_triangles(g, &sheet(f)).expect("same slice");
        let up = Affine3A::from_translation(Vec3::new(0.0, f as f32, 0.0));
        scene.set_transform(moving, Transform::placing(up).expect("invertible"));
        scene.commit().expect("commit");
        let h = scene
            .as_ref()
            .closest_ray::<f32x8, Watertight, StableSphere>(
                &Ray::new(Vec3::new(0.5, 9.0, 0.5), -Vec3::Y),
                !0,
            )
            .expect("a sheet");
        assert_eq!(h.inst, moving);
        println!(
            "frame {f}: the moving sheet (instance {}, not {fixed}) at t = {:.4}",
            h.inst, h.t
        );
    }
}
