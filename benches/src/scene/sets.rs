//! Scene-scale workloads: Sponza (the OBJ shipped in the `bvh` crate's package, found through
//! `cargo metadata`) and generated scenes of other kinds (a sphere of ≥ 1 M triangles, a city of
//! boxes, beams and needles, a terrain at grazing angles, a scanned-like mesh in a closed room,
//! an open field of rocks where most rays miss), each with two cameras and a point light: pinhole
//! primary rays, one diffuse bounce per primary hit and one shadow ray per primary hit.

use glam::Vec3;
use octoray::bvh::{Bvh8, Bvh8Ref};
use octoray::kernels::{Kernel, Watertight};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{Ray, RayLanes, VertexTriangle};
use octoray::tree::{closest, closest_packet, closest_ray, occluded_packet, occluded_ray};
use octoray_testkit::camera::Pinhole;
use std::path::PathBuf;
use std::process::Command;
use wide::f32x8;

/// A triangle scene with two cameras and a point light.
pub struct SceneSet {
    /// Its name in the reports.
    pub name: &'static str,
    /// Its triangles, as vertices.
    pub tris: Vec<[Vec3; 3]>,
    /// Where each mesh of the file starts in `tris` (one mesh: `[0]`).
    pub meshes: Vec<usize>,
    /// The main camera and a second one that sees the scene from elsewhere.
    pub cameras: [Pinhole; 2],
    /// Where shadow rays go.
    pub light: Vec3,
}

/// Where cargo unpacked the `bvh` crate's `media/sponza.obj`.
pub fn sponza_path() -> Result<PathBuf, String> {
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(["metadata", "--format-version", "1"])
        .output()
        .map_err(|e| format!("cannot run cargo metadata: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    // Each package's "manifest_path":"…/bvh-0.13.x/Cargo.toml".
    for part in text.split("\"manifest_path\":\"").skip(1) {
        let path = &part[..part.find('"').unwrap_or(0)];
        let dir = std::path::Path::new(path).parent().map(PathBuf::from);
        if let Some(dir) = dir {
            let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if name.starts_with("bvh-0.") && dir.join("media/sponza.obj").is_file() {
                return Ok(dir.join("media/sponza.obj"));
            }
        }
    }
    Err("the bvh crate's media/sponza.obj was not found through cargo metadata".into())
}

/// Sponza, triangulated (66 450 triangles), camera inside the atrium.
pub fn sponza() -> Result<SceneSet, String> {
    let path = sponza_path()?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) =
        tobj::load_obj(&path, &opts).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut tris = vec![];
    let mut meshes = vec![];
    for m in &models {
        meshes.push(tris.len());
        let p = &m.mesh.positions;
        let v = |i: u32| {
            Vec3::new(
                p[3 * i as usize],
                p[3 * i as usize + 1],
                p[3 * i as usize + 2],
            )
        };
        for f in m.mesh.indices.chunks_exact(3) {
            tris.push([v(f[0]), v(f[1]), v(f[2])]);
        }
    }
    Ok(SceneSet {
        name: "Sponza",
        tris,
        meshes,
        cameras: [
            Pinhole {
                eye: Vec3::new(-10.0, 3.0, 0.0),
                target: Vec3::new(10.0, 5.0, 0.0),
                fov: 70f32.to_radians(),
            },
            // From the far end, up into the arcades.
            Pinhole {
                eye: Vec3::new(11.0, 1.5, 2.5),
                target: Vec3::new(-6.0, 7.0, -3.0),
                fov: 60f32.to_radians(),
            },
        ],
        light: Vec3::new(0.5, 13.0, 0.3),
    })
}

/// Two triangles per cell of an `n × rows` grid of points `p(i, j)` (`i ≤ n`, `j ≤ rows`).
fn grid(n: u32, rows: u32, p: impl Fn(u32, u32) -> Vec3) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::with_capacity((2 * n * rows) as usize);
    for j in 0..rows {
        for i in 0..n {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    tris
}

/// A latitude-longitude sphere of `2·n·(n/2)` triangles, radius 1 jittered by ±2 %, seen from
/// outside.
pub fn jittered_sphere(n: u32) -> SceneSet {
    let h = |i: u32| {
        let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
        x ^= x >> 15;
        x = x.wrapping_mul(0x2C1B_3C6D);
        x ^= x >> 12;
        (x & 0xFFFF) as f32 / 65535.0 - 0.5
    };
    let rows = n / 2;
    let p = |i: u32, j: u32| {
        let (th, ph) = (
            std::f32::consts::PI * j as f32 / rows as f32,
            std::f32::consts::TAU * (i % n) as f32 / n as f32,
        );
        let r = 1.0 + 0.04 * h(j * n + (i % n));
        Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()) * r
    };
    let tris = grid(n, rows, p);
    SceneSet {
        name: "jittered sphere",
        tris,
        meshes: vec![0],
        cameras: [
            Pinhole {
                eye: Vec3::new(0.0, 0.3, 3.2),
                target: Vec3::ZERO,
                fov: 45f32.to_radians(),
            },
            // Close, along the surface toward the horizon.
            Pinhole {
                eye: Vec3::new(1.3, 0.9, 0.4),
                target: Vec3::new(-1.0, -0.6, -0.6),
                fov: 70f32.to_radians(),
            },
        ],
        light: Vec3::new(3.0, 4.0, 2.0),
    }
}

/// A deterministic xorshift stream in `[0, 1)` (the generated scenes' only randomness).
fn stream(mut seed: u64) -> impl FnMut() -> f32 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The twelve triangles of a box with corner `o` and edges `a`, `b`, `c`.
fn box_tris(o: Vec3, a: Vec3, b: Vec3, c: Vec3, out: &mut Vec<[Vec3; 3]>) {
    for (u, v, w) in [(a, b, c), (b, c, a), (c, a, b)] {
        let far = o + w;
        out.push([o, o + u, o + u + v]);
        out.push([o, o + u + v, o + v]);
        out.push([far, far + v, far + u + v]);
        out.push([far, far + u + v, far + u]);
    }
}

/// A city of boxes, long thin beams and needle triangles on a 400 × 400 ground of two
/// triangles (the case spatial splits exist for: long primitives across many small ones), seen
/// from street level: about 80 000 triangles.
pub fn city() -> SceneSet {
    let mut r = stream(0x9E37_79B9_7F4A_7C15);
    let mut tris = vec![
        [
            Vec3::new(-200.0, 0.0, -200.0),
            Vec3::new(200.0, 0.0, 200.0),
            Vec3::new(200.0, 0.0, -200.0),
        ],
        [
            Vec3::new(-200.0, 0.0, -200.0),
            Vec3::new(-200.0, 0.0, 200.0),
            Vec3::new(200.0, 0.0, 200.0),
        ],
    ];
    // Buildings on a jittered 60 × 60 grid of 6-unit lots, some rotated about y.
    for i in 0..60 {
        for j in 0..60 {
            if r() < 0.15 {
                continue;
            }
            let (w, d, h) = (1.0 + 3.5 * r(), 1.0 + 3.5 * r(), 2.0 + 38.0 * r() * r());
            let base = Vec3::new(-180.0 + 6.0 * i as f32, 0.0, -180.0 + 6.0 * j as f32);
            let angle = if r() < 0.3 { r() * 1.5 } else { 0.0 };
            let (s, c) = angle.sin_cos();
            let (a, b) = (Vec3::new(c, 0.0, s) * w, Vec3::new(-s, 0.0, c) * d);
            box_tris(base, a, Vec3::Y * h, b, &mut tris);
        }
    }
    // Beams: 2 000 long thin boxes at random heights and headings, 20 to 120 long.
    for _ in 0..2_000 {
        let o = Vec3::new(360.0 * r() - 180.0, 1.0 + 40.0 * r(), 360.0 * r() - 180.0);
        let heading = r() * std::f32::consts::TAU;
        let len = 20.0 + 100.0 * r();
        let along = Vec3::new(heading.cos(), 0.05 * (r() - 0.5), heading.sin()) * len;
        let side = along.cross(Vec3::Y).normalize_or_zero() * (0.1 + 0.2 * r());
        box_tris(o, along, Vec3::Y * (0.1 + 0.3 * r()), side, &mut tris);
    }
    // Needles: 10 000 triangles 5 to 60 long and about 0.02 wide (cables, antennas, trim).
    for _ in 0..10_000 {
        let o = Vec3::new(380.0 * r() - 190.0, 50.0 * r(), 380.0 * r() - 190.0);
        let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::X);
        let len = 5.0 + 55.0 * r();
        let w = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y) * 0.02;
        tris.push([o, o + dir * len, o + w]);
    }
    SceneSet {
        name: "city",
        tris,
        meshes: vec![0],
        cameras: [
            Pinhole {
                eye: Vec3::new(-170.0, 6.0, -160.0),
                target: Vec3::new(0.0, 10.0, 0.0),
                fov: 70f32.to_radians(),
            },
            // From above a corner, down across the roofs.
            Pinhole {
                eye: Vec3::new(160.0, 90.0, 170.0),
                target: Vec3::new(-20.0, 0.0, -10.0),
                fov: 60f32.to_radians(),
            },
        ],
        light: Vec3::new(120.0, 300.0, -80.0),
    }
}

/// A fractal heightfield of `2·n²` triangles over 1000 × 1000, seen at grazing angles from just
/// above it (`n = 708`: a million triangles).
pub fn terrain(n: u32) -> SceneSet {
    let height = |x: f32, z: f32| {
        let mut h = 0.0;
        let (mut f, mut a) = (0.004f32, 60.0f32);
        for k in 0..6 {
            let k = k as f32;
            h += a * ((x * f + 1.3 * k).sin() * (z * f * 1.1 + 0.7 * k).cos());
            f *= 2.03;
            a *= 0.45;
        }
        h
    };
    let step = 1000.0 / n as f32;
    let p = |i: u32, j: u32| {
        let (x, z) = (-500.0 + step * i as f32, -500.0 + step * j as f32);
        Vec3::new(x, height(x, z), z)
    };
    let tris = grid(n, n, p);
    let eye = Vec3::new(-480.0, 0.0, -480.0);
    let high = Vec3::new(300.0, 0.0, -350.0);
    SceneSet {
        name: "terrain",
        tris,
        meshes: vec![0],
        cameras: [
            Pinhole {
                eye: eye + Vec3::Y * (height(eye.x, eye.z) + 8.0),
                target: Vec3::new(200.0, 0.0, 250.0),
                fov: 60f32.to_radians(),
            },
            // From a height, down over the valleys.
            Pinhole {
                eye: high + Vec3::Y * (height(high.x, high.z) + 120.0),
                target: Vec3::new(-100.0, 0.0, 100.0),
                fov: 60f32.to_radians(),
            },
        ],
        // A low sun: long shadows across the valleys.
        light: Vec3::new(2000.0, 350.0, -1500.0),
    }
}

/// A scanned-like object: a lumpy blob of `2·n·(n/2)` small triangles, its vertices jittered like
/// a scanner's noise, standing in a closed room of twelve triangles (`n = 640`: about 410 000).
pub fn scanned(n: u32) -> SceneSet {
    let mut jitter = stream(0x51_7CC1_B727_220A);
    let rows = n / 2;
    let mut noise = vec![0.0f32; ((n + 1) * (rows + 1)) as usize];
    for x in &mut noise {
        *x = jitter() - 0.5;
    }
    let p = |i: u32, j: u32| {
        let (th, ph) = (
            std::f32::consts::PI * j as f32 / rows as f32,
            std::f32::consts::TAU * (i % n) as f32 / n as f32,
        );
        let dir = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
        // Lobes, ridges and fine grain, then the scanner's noise (seam and poles shared).
        let k = if j == 0 || j == rows {
            0
        } else {
            j * n + (i % n)
        };
        let r = 1.0
            + 0.25 * (3.0 * th).sin() * (2.0 * ph).cos()
            + 0.08 * (11.0 * th + 1.0).sin() * (9.0 * ph).sin()
            + 0.02 * (37.0 * th).cos() * (41.0 * ph + 0.5).sin()
            + 0.002 * noise[k as usize];
        Vec3::new(0.0, 1.3, 0.0) + dir * Vec3::new(1.0, 1.3, 0.8) * r
    };
    let mut tris = grid(n, rows, p);
    // The room, faces inward: 8 × 4 × 8.
    let (lo, hi) = (Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 4.0, 4.0));
    box_tris(
        lo,
        Vec3::X * (hi.x - lo.x),
        Vec3::Y * (hi.y - lo.y),
        Vec3::Z * (hi.z - lo.z),
        &mut tris,
    );
    SceneSet {
        name: "scanned mesh in a room",
        tris,
        meshes: vec![0],
        cameras: [
            Pinhole {
                eye: Vec3::new(-3.2, 1.8, 3.0),
                target: Vec3::new(0.0, 1.3, 0.0),
                fov: 55f32.to_radians(),
            },
            // Close up, grazing along the surface.
            Pinhole {
                eye: Vec3::new(1.9, 0.4, -1.2),
                target: Vec3::new(-0.5, 2.2, 0.6),
                fov: 70f32.to_radians(),
            },
        ],
        light: Vec3::new(1.5, 3.8, 2.0),
    }
}

/// An open scene where most rays miss: 700 rocks (lumpy spheres of 576 triangles, 1 to 12
/// across) scattered through a 240 × 240 field with no ground and nothing behind them (about
/// 400 000 triangles).
pub fn open_field() -> SceneSet {
    let mut r = stream(0x2F4A_7C15_9E37_79B9);
    let mut tris = vec![];
    for _ in 0..700 {
        let c = Vec3::new(240.0 * r() - 120.0, 30.0 * r() * r(), 240.0 * r() - 120.0);
        let size = 0.5 + 5.5 * r() * r();
        let (a, b) = (r() * 6.0, r() * 6.0);
        let (n, rows) = (24, 12);
        tris.extend(grid(n, rows, |i, j| {
            let (th, ph) = (
                std::f32::consts::PI * j as f32 / rows as f32,
                std::f32::consts::TAU * (i % n) as f32 / n as f32,
            );
            let lump = 1.0 + 0.2 * (3.0 * th + a).sin() * (2.0 * ph + b).cos();
            c + Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()) * size * lump
        }));
    }
    SceneSet {
        name: "open field",
        tris,
        meshes: vec![0],
        cameras: [
            Pinhole {
                eye: Vec3::new(-150.0, 12.0, -30.0),
                target: Vec3::new(0.0, 5.0, 0.0),
                fov: 60f32.to_radians(),
            },
            // From above the field, down at a slant.
            Pinhole {
                eye: Vec3::new(40.0, 110.0, 180.0),
                target: Vec3::new(0.0, 0.0, 0.0),
                fov: 50f32.to_radians(),
            },
        ],
        light: Vec3::new(500.0, 800.0, 300.0),
    }
}

impl SceneSet {
    /// Primary rays of camera `cam` (0 or 1) in tiles of `tw`×`th` pixels (consecutive rays share
    /// a tile: coherent packets of `tw·th`).
    pub fn primary_tiled(&self, cam: usize, w: u32, h: u32, tw: u32, th: u32) -> Vec<Ray> {
        let camera = &self.cameras[cam];
        let mut out = Vec::with_capacity((w * h) as usize);
        for ty in (0..h).step_by(th as usize) {
            for tx in (0..w).step_by(tw as usize) {
                for y in ty..(ty + th).min(h) {
                    for x in tx..(tx + tw).min(w) {
                        out.push(camera.ray(x, y, w, h));
                    }
                }
            }
        }
        out
    }

    /// The triangles in the watertight layout.
    pub fn vertex_tris(&self) -> Vec<VertexTriangle> {
        self.tris
            .iter()
            .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
            .collect()
    }

    /// Where `r` first hits (watertight tier through `bvh`): the hit point, its error bound and
    /// the unit normal on the side `r` came from.
    fn surface(&self, r: &Ray, bvh: &Bvh8<VertexTriangle>) -> Option<(Vec3, Vec3, Vec3)> {
        let h = closest_ray::<f32x8, Watertight>(bvh.as_ref(), r)?;
        let t = self.tris[h.prim as usize];
        let (p, err) = octoray::shading::offset::triangle_hit_point(
            &VertexTriangle::new(t[0], t[1], t[2]),
            h.u,
            h.v,
        );
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        Some((p, err, if n.dot(r.dir) > 0.0 { -n } else { n }))
    }

    /// One shadow ray per primary hit: from the hit point (offset off the surface, on the side
    /// the ray came from) to the light, `t` in `[0, 1)` (the light itself not included); for the
    /// occlusion rows.
    pub fn shadow_rays(&self, primary: &[Ray], bvh: &Bvh8<VertexTriangle>) -> Vec<Ray> {
        let mut out = Vec::with_capacity(primary.len());
        for r in primary {
            let Some((p, err, n)) = self.surface(r, bvh) else {
                continue;
            };
            let o = octoray::shading::offset::offset_ray_origin(p, err, n, self.light - p);
            let mut ray = Ray::new(o, self.light - o);
            ray.t_max = 1.0 - f32::EPSILON;
            out.push(ray);
        }
        out
    }

    /// One diffuse bounce per primary hit: from the hit point (offset off the surface) in a
    /// cosine-weighted direction about the normal facing the ray (incoherent rays).
    pub fn diffuse_bounces(&self, primary: &[Ray], bvh: &Bvh8<VertexTriangle>) -> Vec<Ray> {
        let mut rnd = stream(0x2545_F491_4F6C_DD1D);
        let mut out = Vec::with_capacity(primary.len());
        for r in primary {
            let Some((p, err, n)) = self.surface(r, bvh) else {
                continue;
            };
            // Cosine-weighted: n plus a uniform point on the unit sphere.
            let z = rnd() * 2.0 - 1.0;
            let a = rnd() * std::f32::consts::TAU;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let d = n + Vec3::new(s * a.cos(), s * a.sin(), z);
            if d.length_squared() < 1e-8 {
                continue;
            }
            let o = octoray::shading::offset::offset_ray_origin(p, err, n, d);
            out.push(Ray::new(o, d));
        }
        out
    }
}

// Traversal of a whole ray slice, each returning its hit count (what the scene report and the
// criterion group time).

/// Closest hit of `rays` in packets of `L::LANES`; returns the number of hits.
pub fn packets_closest<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray]) -> u64 {
    rays.chunks(L::LANES)
        .map(|c| {
            let h = closest_packet::<L, K>(bvh, &RayLanes::load(c));
            u64::from(h.mask.bitmask().count_ones())
        })
        .sum()
}

/// Occlusion of `rays` in packets of `L::LANES`; returns the number occluded.
pub fn packets_any<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray]) -> u64 {
    rays.chunks(L::LANES)
        .map(|c| {
            u64::from(
                occluded_packet::<L, K>(bvh, &RayLanes::load(c))
                    .bitmask()
                    .count_ones(),
            )
        })
        .sum()
}

/// Closest hit of each ray alone; returns the number of hits.
pub fn singles_closest<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray]) -> u64 {
    rays.iter()
        .filter(|r| closest_ray::<L, K>(bvh, r).is_some())
        .count() as u64
}

/// Occlusion of each ray alone; returns the number occluded.
pub fn singles_any<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray]) -> u64 {
    rays.iter().filter(|r| occluded_ray::<L, K>(bvh, r)).count() as u64
}

/// Closest hit through the batch call (packets or single rays per chunk); returns the number of
/// hits.
pub fn batch_closest<L: Lanes, K: Kernel<L>>(bvh: Bvh8Ref<'_, K::Prim>, rays: &[Ray]) -> u64 {
    let mut out = vec![None; rays.len()];
    closest::<L, K>(bvh, rays, &mut out);
    out.iter().filter(|h| h.is_some()).count() as u64
}
