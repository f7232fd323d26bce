//! Closed, jittered test meshes (every vertex stored once and shared) and the crack test.

use crate::Rng;
use glam::Vec3;
use octoray::f32x8;
use octoray::kernels::{Exact, MollerTrumbore, Watertight};
use octoray::lanes::LaneMask;
use octoray::prim::{PackedTriangle, Ray, RayLanes, VertexTriangle};
use octoray::query::occluded;
use std::collections::HashMap;

use crate::icosphere;

/// An indexed triangle mesh.
pub struct Mesh {
    pub verts: Vec<Vec3>,
    pub tris: Vec<[u32; 3]>,
}

impl Mesh {
    /// An icosphere (subdivided `levels` times) of radius ~1 with each vertex's radius jittered
    /// by ±`jitter`, then scaled by `radius` and moved to `center` (rounded once, shared).
    pub fn icosphere(levels: u32, jitter: f32, radius: f32, center: Vec3, rng: &mut Rng) -> Self {
        let (verts, tris) = icosphere::icosphere(levels);
        let verts = verts
            .iter()
            .map(|v| center + *v * (radius * (1.0 + rng.range(-jitter, jitter))))
            .collect();
        Self { verts, tris }
    }

    /// The surface of a cube of half-size `half` split into an n×n grid per face, each vertex
    /// jittered by up to `jitter` grid cells along every axis, moved to `center`.
    pub fn cube_grid(n: i32, jitter: f32, half: f32, center: Vec3, rng: &mut Rng) -> Self {
        let mut index: HashMap<(i32, i32, i32), u32> = HashMap::new();
        let mut verts = vec![];
        let mut tris = vec![];
        let cell = 2.0 * half / n as f32;
        let mut vid = |p: (i32, i32, i32), verts: &mut Vec<Vec3>, rng: &mut Rng| {
            *index.entry(p).or_insert_with(|| {
                let base = Vec3::new(p.0 as f32, p.1 as f32, p.2 as f32) * cell - Vec3::splat(half);
                verts.push(center + base + rng.vec3(jitter * cell));
                verts.len() as u32 - 1
            })
        };
        // Each face: fix one axis at 0 or n, walk the other two.
        for axis in 0..3 {
            for side in [0, n] {
                for i in 0..n {
                    for j in 0..n {
                        let at = |a: i32, b: i32| match axis {
                            0 => (side, a, b),
                            1 => (a, side, b),
                            _ => (a, b, side),
                        };
                        let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                            .map(|p| vid(p, &mut verts, rng));
                        tris.push([q[0], q[1], q[2]]);
                        tris.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
        Self { verts, tris }
    }

    pub fn packed(&self) -> Vec<PackedTriangle> {
        self.tris
            .iter()
            .map(|t| PackedTriangle::new(self.v(t[0]), self.v(t[1]), self.v(t[2])))
            .collect()
    }
    pub fn vertex_tris(&self) -> Vec<VertexTriangle> {
        self.tris
            .iter()
            .map(|t| VertexTriangle::new(self.v(t[0]), self.v(t[1]), self.v(t[2])))
            .collect()
    }
    fn v(&self, i: u32) -> Vec3 {
        self.verts[i as usize]
    }

    /// Rays from random origins within `spread` of `center`, aimed exactly at vertices, at points
    /// of edges, at interior points, and in random directions (a quarter each).
    pub fn rays_from_inside(&self, center: Vec3, spread: f32, n: usize, rng: &mut Rng) -> Vec<Ray> {
        (0..n)
            .map(|i| {
                let o = center + rng.vec3(spread);
                let t = self.tris[(rng.next_u64() % self.tris.len() as u64) as usize]
                    .map(|k| self.v(k));
                let target = match i % 4 {
                    0 => t[(rng.next_u64() % 3) as usize],
                    1 => t[0] + (t[1] - t[0]) * rng.range(0.0, 1.0),
                    2 => {
                        let (u, v) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
                        let (u, v) = if u + v > 1.0 {
                            (1.0 - u, 1.0 - v)
                        } else {
                            (u, v)
                        };
                        t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v
                    }
                    _ => o + rng.vec3(1.0),
                };
                Ray::new(o, target - o)
            })
            .collect()
    }
}

impl Mesh {
    /// The triangles as vertex triples.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.tris
            .iter()
            .map(|t| t.map(|k| self.verts[k as usize]))
            .collect()
    }
}

/// Rays that hit no triangle under any single ray-triangle test `hit` (brute force, stopping at
/// the first hit): the crack test for code that is not one of our kernels.
pub fn escapes_by(
    rays: &[Ray],
    tris: &[[Vec3; 3]],
    hit: impl Fn(&Ray, [Vec3; 3]) -> bool,
) -> usize {
    rays.iter()
        .filter(|r| !tris.iter().any(|&t| hit(r, t)))
        .count()
}

/// Rays that hit no triangle of the mesh (8 lanes, any-hit), per tier.
pub struct Escapes {
    pub standard: usize,
    pub watertight: usize,
    pub exact: usize,
}

fn escapes_with<K: octoray::kernels::Kernel<f32x8>>(rays: &[Ray], prims: &[K::Prim]) -> usize {
    rays.chunks(8)
        .map(|c| {
            let p = RayLanes::<f32x8>::load(c);
            let hit = occluded::<f32x8, K>(&p, prims).bitmask();
            c.len() - hit.count_ones() as usize
        })
        .sum()
}

/// Counts escapes of each tier on the same rays.
pub fn escapes(mesh: &Mesh, rays: &[Ray]) -> Escapes {
    let (packed, verts) = (mesh.packed(), mesh.vertex_tris());
    Escapes {
        standard: escapes_with::<MollerTrumbore>(rays, &packed),
        watertight: escapes_with::<Watertight>(rays, &verts),
        exact: escapes_with::<Exact>(rays, &verts),
    }
}

/// One row of the crack suite.
pub struct CrackRow {
    pub mesh: &'static str,
    pub center: f32,
    pub triangles: usize,
    pub rays: usize,
    pub escapes: Escapes,
}

/// The crack suite of `tests/suite/watertight.rs` and the accuracy report: an icosphere (1280
/// triangles) and a cube grid (768) centred at 0, 1e2, 1e4 and 1e6, `rays_per_mesh` rays from
/// inside each.
pub fn crack_suite(rays_per_mesh: usize) -> Vec<CrackRow> {
    crack_meshes(rays_per_mesh, |name, c, mesh, rays| CrackRow {
        mesh: name,
        center: c,
        triangles: mesh.tris.len(),
        rays: rays.len(),
        escapes: escapes(mesh, rays),
    })
}

/// The same meshes and rays, with the escapes counted by `escapes_of(watertight triangles,
/// rays)`: `(mesh name and centre, rays, escapes)` per mesh.
pub fn crack_suite_with(
    rays_per_mesh: usize,
    escapes_of: impl Fn(&[VertexTriangle], &[Ray]) -> usize,
) -> Vec<(String, usize, usize)> {
    crack_meshes(rays_per_mesh, |name, c, mesh, rays| {
        (
            format!("{name} at {c:e}"),
            rays.len(),
            escapes_of(&mesh.vertex_tris(), rays),
        )
    })
}

/// Runs `row` on each mesh of the crack suite with its rays.
fn crack_meshes<R>(
    rays_per_mesh: usize,
    mut row: impl FnMut(&'static str, f32, &Mesh, &[Ray]) -> R,
) -> Vec<R> {
    let mut rows = vec![];
    for (i, c) in [0.0f32, 1e2, 1e4, 1e6].into_iter().enumerate() {
        let center = Vec3::new(c, -0.5 * c, 0.25 * c);
        let mut rng = Rng(1000 + i as u64);
        let meshes = [
            ("icosphere", Mesh::icosphere(3, 0.1, 1.0, center, &mut rng)),
            ("cube grid", Mesh::cube_grid(8, 0.2, 1.0, center, &mut rng)),
        ];
        for (name, mesh) in meshes {
            let rays = mesh.rays_from_inside(center, 0.1, rays_per_mesh, &mut rng);
            rows.push(row(name, c, &mesh, &rays));
        }
    }
    rows
}

impl Mesh {
    /// Every vertex `p` moved to `offset + p·scale` (componentwise; each vertex rounded once and
    /// still shared, so the mesh stays closed).
    pub fn stretched(mut self, scale: Vec3, offset: Vec3) -> Self {
        for v in &mut self.verts {
            *v = offset + *v * scale;
        }
        self
    }

    /// A closed tube: `n` long sides around the x axis of radius `r` from `x = 0` to `len`, each
    /// side one pair of long thin triangles (aspect ≈ `len·n/(2π·r)`), capped by fans around
    /// a centre vertex at each end; then moved to `offset`.
    pub fn tube(n: u32, r: f32, len: f32, offset: Vec3) -> Self {
        let mut verts = vec![offset, offset + Vec3::new(len, 0.0, 0.0)];
        for end in [0.0, len] {
            for k in 0..n {
                let a = core::f32::consts::TAU * k as f32 / n as f32;
                verts.push(offset + Vec3::new(end, r * libm::cosf(a), r * libm::sinf(a)));
            }
        }
        let ring = |end: u32, k: u32| 2 + end * n + k % n;
        let mut tris = vec![];
        for k in 0..n {
            let (a0, a1, b0, b1) = (ring(0, k), ring(0, k + 1), ring(1, k), ring(1, k + 1));
            tris.push([a0, b0, b1]);
            tris.push([a0, b1, a1]);
            tris.push([0, a1, a0]);
            tris.push([1, b0, b1]);
        }
        Self { verts, tris }
    }

    /// The largest ratio of longest edge to smallest height over the mesh's triangles.
    pub fn max_aspect(&self) -> f32 {
        self.triangles()
            .iter()
            .map(|t| {
                let e = [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
                let longest = e.iter().map(|x| x.length()).fold(0.0, f32::max);
                let area2 = e[0].cross(-e[2]).length();
                longest * longest / area2
            })
            .fold(0.0, f32::max)
    }
}

/// Closed meshes of long, thin triangles: an icosphere stretched 1000:1
/// along x, at the origin and offset to about 1e3 (like the reproducer's mesh); one stretched
/// 300:1 along z; a cube grid stretched 1000:1 along y and offset; a 48-sided tube 2000 long
/// of radius 1 (aspect ≈ 2·10⁴), offset. `rays_per_mesh` rays from inside each (origins within
/// a tenth of the smallest dimension of the centre), a quarter each aimed at vertices, at edge
/// points, at interior points and anywhere. Each row: (name, mesh, rays).
pub fn thin_crack_meshes(rays_per_mesh: usize) -> Vec<(String, Mesh, Vec<Ray>)> {
    let mut out = vec![];
    let mut rng = Rng(4242);
    let reproducer = Vec3::new(1108.6238, 699.8606, 1299.9575);
    let families: Vec<(&str, Mesh, Vec3, f32)> = vec![
        (
            "icosphere 1000:1 (x)",
            Mesh::icosphere(3, 0.05, 1.0, Vec3::ZERO, &mut rng)
                .stretched(Vec3::new(1000.0, 1.0, 1.0), Vec3::ZERO),
            Vec3::ZERO,
            0.1,
        ),
        (
            "icosphere 1000:1 (x) at ~1e3",
            Mesh::icosphere(3, 0.05, 1.0, Vec3::ZERO, &mut rng)
                .stretched(Vec3::new(1000.0, 1.0, 1.0), reproducer),
            reproducer,
            0.1,
        ),
        (
            "icosphere 300:1 (z) at ~1e3",
            Mesh::icosphere(3, 0.05, 1.0, Vec3::ZERO, &mut rng)
                .stretched(Vec3::new(1.0, 1.0, 300.0), Vec3::new(-700.0, 1000.0, 20.0)),
            Vec3::new(-700.0, 1000.0, 20.0),
            0.1,
        ),
        (
            "cube grid 1000:1 (y) at ~1e3",
            Mesh::cube_grid(6, 0.15, 1.0, Vec3::ZERO, &mut rng).stretched(
                Vec3::new(1.0, 1000.0, 1.0),
                Vec3::new(1000.0, -500.0, 250.0),
            ),
            Vec3::new(1000.0, -500.0, 250.0),
            0.1,
        ),
        (
            "tube 48 sides, 2000 long",
            Mesh::tube(48, 1.0, 2000.0, Vec3::new(-300.0, 700.0, 1300.0)),
            Vec3::new(700.0, 700.0, 1300.0),
            0.1,
        ),
    ];
    for (name, mesh, center, spread) in families {
        let rays = mesh.rays_from_inside(center, spread, rays_per_mesh, &mut rng);
        out.push((name.to_string(), mesh, rays));
    }
    out
}
