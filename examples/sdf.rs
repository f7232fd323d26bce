//! A slice of a mesh's signed distance field, written as an image: a torus (an indexed mesh, so
//! its shared vertices are bitwise equal and it is closed), checked as a `Solid`, sampled on
//! the plane z = 0 with `tree::signed_distance` (exact sign from the crossing rule, distance
//! from `tree::closest_point`). Writes `sdf.pgm` (grey: outside bright, inside dark, the surface
//! a black line) to the directory given, or the system's temporary directory.
//!
//! Run: `cargo run --release --example sdf [DIR]`.
use octoray::bvh::{Bvh8, Solid};
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::prim::VertexTriangle;
use octoray::tree::signed_distance;
use std::f32::consts::TAU;

/// A torus of radii `big` and `small` around the z axis: `n × m` quads, two triangles each,
/// counter-clockwise seen from outside.
fn torus(big: f32, small: f32, n: u32, m: u32) -> Vec<VertexTriangle> {
    let vertex = |i: u32, j: u32| {
        let (a, b) = (
            TAU * (i % n) as f32 / n as f32,
            TAU * (j % m) as f32 / m as f32,
        );
        let r = big + small * b.cos();
        Vec3::new(r * a.cos(), r * a.sin(), small * b.sin())
    };
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (p, q, r, s) = (
                vertex(i, j),
                vertex(i + 1, j),
                vertex(i + 1, j + 1),
                vertex(i, j + 1),
            );
            tris.push(VertexTriangle::new(p, q, r));
            tris.push(VertexTriangle::new(p, r, s));
        }
    }
    tris
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tris = torus(1.0, 0.4, 96, 48);
    let bvh = Bvh8::build(&tris);
    let solid = Solid::new(bvh.as_ref(), &tris)?;
    let (w, h) = (320usize, 320usize);
    let mut pixels = Vec::with_capacity(w * h);
    let (mut inside, mut nearest) = (0, f32::INFINITY);
    for y in 0..h {
        for x in 0..w {
            let p = Vec3::new(
                (x as f32 + 0.5) / w as f32 * 3.2 - 1.6,
                (y as f32 + 0.5) / h as f32 * 3.2 - 1.6,
                0.0,
            );
            let d = signed_distance::<f32x8>(solid, p);
            inside += usize::from(d < 0.0);
            nearest = nearest.min(d.abs());
            // Bands every 0.1, darker inside, black within 0.01 of the surface.
            let band = if (d / 0.1).fract().abs() < 0.5 {
                1.0
            } else {
                0.85
            };
            let base = if d < 0.0 { 90.0 } else { 230.0 };
            let v = if d.abs() < 0.01 { 0.0 } else { base * band };
            pixels.push(v as u8);
        }
    }
    // The plane z = 0 cuts the tube in an annulus of radii 0.6 and 1.4: π·(1.4² − 0.6²) ≈ 5.027
    // of the slice's 3.2² = 10.24 (the polygonal torus is a little smaller).
    let share = inside as f64 / (w * h) as f64;
    assert!((share - 5.027 / 10.24).abs() < 0.01, "inside share {share}");
    let dir = std::env::args()
        .nth(1)
        .map_or_else(std::env::temp_dir, std::path::PathBuf::from);
    let path = dir.join("sdf.pgm");
    let mut file = format!("P5\n{w} {h}\n255\n").into_bytes();
    file.extend_from_slice(&pixels);
    std::fs::write(&path, file)?;
    println!(
        "{} triangles, closed; {inside} of {} pixels inside ({:.1} %), nearest sample {nearest:.4} from the surface; wrote {}",
        tris.len(),
        w * h,
        100.0 * share,
        path.display()
    );
    Ok(())
}
