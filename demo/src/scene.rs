//! The demo's embedded scene and its packet tracer.

use octoray::glam::{Affine3A, DVec3, Quat, Vec3};
use octoray::hit::{Digest, Hit};
use octoray::ingest;
use octoray::kernels::{Kernel, StableSphere};
use octoray::lanes::Lanes;
use octoray::prim::{PackedSphere, PackedTriangle, Primitive, Ray, Sphere, VertexTriangle};
use octoray::recommend::{recommend, Recommendation, SceneSpec, TierChoice};
use octoray::scene::{Trace, Transform};
use octoray::shading::{Shade, Surface};
use octoray_testkit::camera::Pinhole;
use rayon::prelude::*;
use std::path::Path;

/// Which tier traces the triangles (`auto` asks the recommender).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TierArg {
    /// The recommender picks from the scene's extent and degenerate triangles.
    Auto,
    /// Möller-Trumbore at f32.
    Standard,
    /// The watertight test at f32.
    Watertight,
    /// Möller-Trumbore at f64.
    F64,
    /// The watertight test at f64.
    WatertightF64,
    /// Exact edge signs and range.
    Exact,
}

impl TierArg {
    /// The tier a `--tier` value names.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "auto" => Self::Auto,
            "standard" => Self::Standard,
            "watertight" => Self::Watertight,
            "f64" => Self::F64,
            "watertight-f64" => Self::WatertightF64,
            "exact" => Self::Exact,
            _ => return None,
        })
    }
    /// The `--tier` value naming this tier.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Standard => "standard",
            Self::Watertight => "watertight",
            Self::F64 => "f64",
            Self::WatertightF64 => "watertight-f64",
            Self::Exact => "exact",
        }
    }
}

/// A scene: triangles (a mesh of one or more models plus a ground quad), spheres, each with a
/// colour, and a field of instances of the mesh.
pub struct Scene {
    /// Every triangle's vertices: the mesh's, then the ground's.
    pub tris: Vec<[Vec3; 3]>,
    /// Each triangle's colour.
    pub tri_color: Vec<Vec3>,
    /// Where each model of the mesh starts in `tris` (`[0]`: one model); each is a geometry.
    pub mesh_groups: Vec<usize>,
    /// Object → world placements of more instances of the mesh (all its models).
    pub field: Vec<Affine3A>,
    /// Each sphere's centre and radius.
    pub spheres: Vec<(Vec3, f32)>,
    /// Each sphere's colour.
    pub sphere_color: Vec<Vec3>,
    /// Unit direction towards the sun.
    pub light: Vec3,
    /// Camera position.
    pub eye: Vec3,
    /// The point the camera looks at.
    pub target: Vec3,
    /// Vertical field of view, radians.
    pub fov: f32,
    /// Number of triangles of the mesh (the rest is the ground).
    pub mesh_tris: usize,
    /// Ambient-occlusion rays per shaded pixel (0: a constant ambient term instead).
    pub ao_samples: u32,
}

/// A deterministic jitter.
fn hash(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 15;
    x = x.wrapping_mul(0x2C1B_3C6D);
    x ^= x >> 12;
    (x & 0xFFFF) as f32 / 65535.0 - 0.5
}

use octoray_testkit::icosphere;

/// An icosphere of radius ~1 subdivided `levels` times, with smooth bumps of ±5 % and every
/// radius jittered by a third of an edge: positions and indices, the way a mesh loader hands them
/// over.
pub fn icosphere(levels: u32) -> (Vec<[f32; 3]>, Vec<u32>) {
    let (v, f) = icosphere::icosphere(levels);
    let edge = 1.1 / (1u32 << levels) as f32;
    let positions = v
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let bumps = ((7.0 * p.x).sin() + (7.0 * p.y).sin() + (7.0 * p.z).sin()) / 3.0;
            (*p * (1.0 + 0.05 * bumps + edge / 3.0 * hash(i as u32))).to_array()
        })
        .collect();
    (positions, f.concat())
}

/// A field of `n` small copies of a mesh fitted into the unit ball at (0, 1, 0): scaled 0.07–0.13
/// (so each sits on the ground), turned about the vertical, on a jittered grid over the ground
/// behind the main mesh (z from −5.6 to −1.6, x from −5.6 to 5.6).
pub fn field(n: u32) -> Vec<Affine3A> {
    let cols = (n as f32 * 2.8).sqrt().ceil().max(1.0) as u32;
    (0..n)
        .map(|i| {
            let (c, r) = (i % cols, i / cols);
            let rows = n.div_ceil(cols).max(1);
            let x = -5.6 + 11.2 * (c as f32 + 0.5 + 0.6 * hash(3 * i)) / cols as f32;
            let z = -5.6 + 4.0 * (r as f32 + 0.5 + 0.6 * hash(3 * i + 1)) / rows as f32;
            let s = 0.1 + 0.06 * hash(3 * i + 2);
            Affine3A::from_scale_rotation_translation(
                Vec3::splat(s),
                Quat::from_rotation_y(7.0 * hash(i ^ 0x5555)),
                Vec3::new(x, 0.0, z),
            )
        })
        .collect()
}

impl Scene {
    /// The embedded default scene: a bumpy, jittered icosphere of 1.3 M triangles (8 levels) on a
    /// ground quad with three spheres, and a field of 1 600 small instances of the icosphere
    /// behind it (2.1 billion virtual triangles, one tree).
    pub fn default_scene() -> Self {
        let (positions, indices) = icosphere(8);
        let mut s = Self::with_mesh(&positions, &indices).expect("the embedded mesh is valid");
        s.field = field(1600);
        s
    }

    /// The number of triangles the instances place: the mesh once per placement, plus the
    /// ground.
    pub fn virtual_triangles(&self) -> u64 {
        self.mesh_tris as u64 * (1 + self.field.len() as u64)
            + (self.tris.len() - self.mesh_tris) as u64
    }

    /// A mesh at its own coordinates (no ground quad), the default scene's spheres and sun,
    /// and a camera at the mesh's bounding-box centre (set it with `eye`/`target`).
    pub fn with_mesh_in_place(positions: &[[f32; 3]], indices: &[u32]) -> Result<Self, String> {
        let verts = checked_mesh(positions, indices)?;
        let mut s = Self::default_scene();
        s.tris = verts
            .iter()
            .map(|t| [t.v0.into(), t.v1.into(), t.v2.into()])
            .collect();
        s.mesh_tris = s.tris.len();
        s.tri_color = vec![Vec3::new(0.8, 0.72, 0.6); s.mesh_tris];
        s.field.clear();
        Ok(s)
    }

    /// The default scene with the icosphere replaced by `positions`/`indices`, fitted into the
    /// same unit ball at (0, 1, 0).
    pub fn with_mesh(positions: &[[f32; 3]], indices: &[u32]) -> Result<Self, String> {
        let verts = checked_mesh(positions, indices)?;
        // Bounds, centre and radius in f64: coordinates near f32::MAX or 1e-40 neither overflow
        // nor underflow the fit.
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for t in &verts {
            for p in [t.v0, t.v1, t.v2] {
                let p = Vec3::from(p).as_dvec3();
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let (center, radius) = ((lo + hi) * 0.5, ((hi - lo) * 0.5).length());
        // Finite vertices give a finite radius; 0 means a single point.
        if radius <= 0.0 {
            return Err("the mesh has no extent (every vertex is the same point)".into());
        }
        let place = |p: [f32; 3]| {
            ((Vec3::from(p).as_dvec3() - center) / radius + DVec3::new(0.0, 1.0, 0.0)).as_vec3()
        };
        let mut tris: Vec<[Vec3; 3]> = verts
            .iter()
            .map(|t| [place(t.v0), place(t.v1), place(t.v2)])
            .collect();
        let mesh_tris = tris.len();
        let mut tri_color = vec![Vec3::new(0.85, 0.55, 0.3); mesh_tris];
        let g = 6.0;
        tris.push([
            Vec3::new(-g, 0.0, -g),
            Vec3::new(g, 0.0, g),
            Vec3::new(g, 0.0, -g),
        ]);
        tris.push([
            Vec3::new(-g, 0.0, -g),
            Vec3::new(-g, 0.0, g),
            Vec3::new(g, 0.0, g),
        ]);
        tri_color.extend([Vec3::new(0.6, 0.62, 0.6); 2]);
        Ok(Self {
            tris,
            tri_color,
            mesh_groups: vec![0],
            field: Vec::new(),
            spheres: vec![
                (Vec3::new(-2.1, 0.6, 0.6), 0.6),
                (Vec3::new(2.0, 0.5, -0.4), 0.5),
                (Vec3::new(0.9, 0.3, 1.9), 0.3),
            ],
            sphere_color: vec![
                Vec3::new(0.3, 0.5, 0.85),
                Vec3::new(0.35, 0.75, 0.4),
                Vec3::new(0.85, 0.3, 0.35),
            ],
            light: Vec3::new(-0.45, 1.0, 0.35).normalize(),
            eye: Vec3::new(0.0, 2.4, 6.8),
            target: Vec3::new(0.0, 0.8, 0.0),
            fov: 0.75,
            mesh_tris,
            ao_samples: 0,
        })
    }

    /// The scene's pinhole camera.
    pub fn camera(&self) -> Pinhole {
        Pinhole {
            eye: self.eye,
            target: self.target,
            fov: self.fov,
        }
    }

    /// The camera ray through the centre of pixel (x, y) of a w×h image.
    pub fn camera_ray(&self, x: u32, y: u32, w: u32, h: u32) -> Ray {
        self.camera().ray(x, y, w, h)
    }

    /// The pixel a point projects to (for tests), if on screen.
    pub fn project(&self, p: Vec3, w: u32, h: u32) -> Option<(u32, u32)> {
        self.camera().project(p, w, h)
    }

    /// Makes the mesh's models (starting at `starts` in `tris`) separate geometries, each
    /// coloured its own way (a hue per model; one model keeps the scene's colour).
    pub fn set_models(&mut self, starts: &[usize]) {
        let mut starts: Vec<usize> = starts
            .iter()
            .copied()
            .filter(|&k| k < self.mesh_tris)
            .collect();
        starts.sort_unstable();
        starts.dedup();
        if starts.first() != Some(&0) {
            starts.insert(0, 0);
        }
        if starts.len() > 1 {
            let mut bounds = starts.clone();
            bounds.push(self.mesh_tris);
            for (m, w) in bounds.windows(2).enumerate() {
                let h = m as u32;
                let c = Vec3::new(
                    0.55 + hash(7 * h),
                    0.55 + hash(7 * h + 1),
                    0.55 + hash(7 * h + 2),
                );
                self.tri_color[w[0]..w[1]].fill(c.clamp(Vec3::splat(0.1), Vec3::ONE));
            }
        }
        self.mesh_groups = starts;
    }

    /// Triangles with zero area (a repeated vertex, or collinear): they can never be hit.
    pub fn degenerate_triangles(&self) -> usize {
        self.tris.iter().filter(|t| is_degenerate(t)).count()
    }

    /// The recommender's tier for this scene: bounds over the geometry and the camera, the
    /// smallest edge or radius as the smallest feature (degenerate triangles left out: they are
    /// never hit), a tenth of a pixel's footprint at the target as the budget (at 640 px),
    /// closed meshes (the mesh must not leak light).
    pub fn recommendation(&self) -> Result<Recommendation, String> {
        let (mut lo, mut hi) = (self.eye, self.eye);
        let mut smallest = f32::INFINITY;
        for t in &self.tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            if !is_degenerate(t) {
                for k in 0..3 {
                    smallest = smallest.min((t[(k + 1) % 3] - t[k]).length());
                }
            }
        }
        for &(c, r) in &self.spheres {
            lo = lo.min(c - r);
            hi = hi.max(c + r);
            smallest = smallest.min(r);
        }
        let footprint = (self.target - self.eye).length() * (self.fov * 0.5).tan() * 2.0 / 640.0;
        recommend(&SceneSpec {
            bounds_min: lo,
            bounds_max: hi,
            smallest_feature: smallest,
            error_budget: footprint * 0.1,
            closed_meshes: true,
        })
        .map_err(|e| format!("the recommender cannot judge this scene: {e}"))
    }
}

/// The mesh's triangles through the library's ingest (bad indices are an error, not a panic),
/// with every vertex a triangle uses finite (a NaN or infinite vertex cannot be placed or drawn).
fn checked_mesh(positions: &[[f32; 3]], indices: &[u32]) -> Result<Vec<VertexTriangle>, String> {
    let verts = ingest::pack_vertex_triangles_vec(positions, indices).map_err(|e| e.to_string())?;
    for (i, t) in verts.iter().enumerate() {
        for p in [t.v0, t.v1, t.v2] {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(format!(
                    "triangle {i} has a vertex that is not finite ({p:?}): the mesh cannot be placed"
                ));
            }
        }
    }
    Ok(verts)
}

/// Zero area in f64 (a repeated vertex or three collinear vertices).
fn is_degenerate(t: &[Vec3; 3]) -> bool {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    (b - a).cross(c - a) == DVec3::ZERO
}

/// What a pixel's primary ray found (for tests and the summary).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelKind {
    /// Nothing hit.
    Sky,
    /// The mesh (in place, not the field's copies).
    Mesh {
        /// The sun is hidden from the hit point.
        shadowed: bool,
    },
    /// One of the field's instances of the mesh.
    Field {
        /// The sun is hidden from the hit point.
        shadowed: bool,
    },
    /// The ground quad.
    Ground {
        /// The sun is hidden from the hit point.
        shadowed: bool,
    },
    /// A sphere.
    Sphere {
        /// Which sphere (its index in [`Scene::spheres`]).
        index: u32,
        /// The sun is hidden from the hit point.
        shadowed: bool,
    },
}

/// A rendered image.
pub struct Image {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// 8-bit RGB, row by row from the top.
    pub rgb: Vec<u8>,
    /// What each pixel's primary ray found, row by row from the top.
    pub kinds: Vec<PixelKind>,
    /// Rays traced (primary, shadow and ambient occlusion).
    pub rays: u64,
    /// Seconds to build the scene (its trees and the top level, all threads).
    pub build_secs: f64,
    /// Seconds spent tracing (all threads, wall clock).
    pub trace_secs: f64,
    /// Geometries, trees and instances of the scene as traced.
    pub counts: (usize, usize, usize),
    /// FNV-1a over the primary hits, row by row (`t`, `u`, `v`, primitive, geometry, instance;
    /// a miss as `INFINITY, 0, 0` and three `u32::MAX`): the C ABI's examples print the same.
    pub digest: u64,
}

/// FNV-1a over words ([`Digest`]).
fn fnv(words: impl Iterator<Item = u32>) -> u64 {
    let mut d = Digest::new();
    words.for_each(|w| d.word(w));
    d.value()
}

/// A triangle layout the demo traces, made from a triangle's three vertices.
pub trait Triangles: Primitive + Sync {
    /// The layout of the triangle `v`.
    fn from_vertices(v: &[Vec3; 3]) -> Self;
}

impl Triangles for PackedTriangle {
    fn from_vertices(v: &[Vec3; 3]) -> Self {
        PackedTriangle::new(v[0], v[1], v[2])
    }
}

impl Triangles for VertexTriangle {
    fn from_vertices(v: &[Vec3; 3]) -> Self {
        VertexTriangle::new(v[0], v[1], v[2])
    }
}

/// The scene's triangles in layout `T` and its spheres.
fn primitives<T: Triangles>(scene: &Scene) -> (Vec<T>, Vec<PackedSphere>) {
    (
        scene.tris.iter().map(T::from_vertices).collect(),
        scene
            .spheres
            .iter()
            .map(|&(c, r)| PackedSphere::new(c, r))
            .collect(),
    )
}

fn sky(d: Vec3) -> Vec3 {
    let t = (d.normalize().y * 0.5 + 0.5).clamp(0.0, 1.0);
    Vec3::new(0.9, 0.93, 0.97) * (1.0 - t) + Vec3::new(0.45, 0.62, 0.9) * t
}

/// `n` directions per shading point, cosine-weighted about `normal` (deterministic: hashed from
/// `seed`).
fn cosine_directions(normal: Vec3, seed: u32, n: u32) -> impl Iterator<Item = Vec3> {
    let t = if normal.x.abs() > 0.9 {
        Vec3::Y
    } else {
        Vec3::X
    };
    let b1 = normal.cross(t).normalize();
    let b2 = normal.cross(b1);
    (0..n).map(move |s| {
        let k = seed.wrapping_mul(2 * n).wrapping_add(2 * s);
        let (u1, u2) = (hash(k) + 0.5, hash(k.wrapping_add(1)) + 0.5);
        let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
        b1 * (r * phi.cos()) + b2 * (r * phi.sin()) + normal * (1.0 - u1).max(0.0).sqrt()
    })
}

/// What a hit is, from its geometry and instance in the traced scene.
#[derive(Clone, Copy)]
enum Part {
    /// Model `m` of the mesh (the main one, or field instance `f`).
    Mesh {
        model: usize,
        field: Option<usize>,
    },
    Ground,
    Sphere,
}

/// The scene as octoray traces it: one triangle geometry per model of the mesh, one for the
/// ground and one for the spheres; the mesh's models in one tree placed once at the origin and
/// once per field instance, the ground and the spheres placed once.
struct Traced<T> {
    world: octoray::scene::Scene<T, PackedSphere>,
    models: usize,
    ground: Option<u32>,
    first_field: u32,
}

impl<T: Primitive + Sync> Traced<T> {
    fn new(scene: &Scene, tris: &[T], spheres: &[PackedSphere]) -> Self {
        let mut world = octoray::scene::Scene::new();
        let mut bounds = scene.mesh_groups.clone();
        bounds.push(scene.mesh_tris);
        let mesh: Vec<u32> = bounds
            .windows(2)
            .map(|w| world.add_triangles(&tris[w[0]..w[1]]).expect("build"))
            .collect();
        let ground = (scene.mesh_tris < tris.len()).then(|| {
            world
                .add_triangles(&tris[scene.mesh_tris..])
                .expect("build")
        });
        let balls = world.add_spheres(spheres).expect("build");
        world.add_instance(&mesh, Transform::IDENTITY, !0);
        if let Some(g) = ground {
            world.add_instance(&[g], Transform::IDENTITY, !0);
        }
        let first_field = world.add_instance(&[balls], Transform::IDENTITY, !0) + 1;
        for a in &scene.field {
            // A placement that cannot be inverted (a zero scale) places nothing.
            if let Some(t) = Transform::placing(*a) {
                world.add_instance(&mesh, t, !0);
            }
        }
        world
            .commit_on(&octoray::parallel::Rayon)
            .expect("the scene's indices fit u32");
        Self {
            world,
            models: mesh.len(),
            ground,
            first_field,
        }
    }

    fn part(&self, h: &Hit) -> Part {
        let g = h.geom as usize;
        if g < self.models {
            let field = (h.inst >= self.first_field).then(|| (h.inst - self.first_field) as usize);
            Part::Mesh { model: g, field }
        } else if Some(h.geom) == self.ground {
            Part::Ground
        } else {
            Part::Sphere
        }
    }
}

/// Renders `scene` at `w`×`h` with triangle kernel `K` and the stable sphere kernel at lane
/// width `L` (a [`Tracer`] names the pairs the `render` binary offers). `progress` is called
/// once per finished row.
pub fn render_with<L, K>(scene: &Scene, w: u32, h: u32, progress: &(dyn Fn(u64) + Sync)) -> Image
where
    L: Lanes,
    K: Kernel<L>,
    K::Prim: Triangles,
    StableSphere: Kernel<L, Prim = PackedSphere>,
{
    let (tris, spheres) = primitives::<K::Prim>(scene);
    let start = std::time::Instant::now();
    // The trees' binary SAH builds on rayon's threads (the same trees as one thread's).
    let traced = Traced::new(scene, &tris, &spheres);
    let build_secs = start.elapsed().as_secs_f64();
    let world = traced.world.as_ref();
    let start = std::time::Instant::now();
    let job = RowJob {
        scene,
        traced: &traced,
        w,
        h,
        ao_reach: scene.ao_reach(),
    };
    let rows: Vec<Row> = (0..h)
        .into_par_iter()
        .map(|y| {
            let row = job.row::<L, K>(y);
            progress(1);
            row
        })
        .collect();
    let digest = fnv(rows.iter().flat_map(|r| r.words.iter().flatten().copied()));
    Image {
        width: w,
        height: h,
        rays: rows.iter().map(|r| r.rays).sum(),
        rgb: rows.iter().flat_map(|r| r.rgb.iter().copied()).collect(),
        kinds: rows.into_iter().flat_map(|r| r.kinds).collect(),
        build_secs,
        trace_secs: start.elapsed().as_secs_f64(),
        counts: (
            world.geometries().len(),
            world.trees().len(),
            world.instances().len(),
        ),
        digest,
    }
}

/// One rendered row: its pixels, their kinds, its primary hits as the digest's words and the
/// rays it traced.
struct Row {
    rgb: Vec<u8>,
    kinds: Vec<PixelKind>,
    words: Vec<[u32; 6]>,
    rays: u64,
}

/// What every row of a render shares.
struct RowJob<'a, T> {
    scene: &'a Scene,
    traced: &'a Traced<T>,
    w: u32,
    h: u32,
    /// How far ambient-occlusion rays reach.
    ao_reach: f32,
}

/// A row's shading points: their normals, and the shadow and ambient-occlusion rays from them
/// (`ao_samples` per point, point after point).
struct Shading {
    normals: Vec<Vec3>,
    shadow: Vec<Ray>,
    ao: Vec<Ray>,
}

impl<T: Primitive + Sync> RowJob<'_, T> {
    /// Row `y`: primary rays, then shadow and ambient-occlusion rays from their hits, shaded.
    fn row<L, K>(&self, y: u32) -> Row
    where
        L: Lanes,
        K: Kernel<L, Prim = T>,
        StableSphere: Kernel<L, Prim = PackedSphere>,
    {
        let (scene, world) = (self.scene, self.traced.world.as_ref());
        let primary: Vec<Ray> = (0..self.w)
            .map(|x| scene.camera_ray(x, y, self.w, self.h))
            .collect();
        // Triangles and spheres in one query: the hit names its geometry and instance.
        let mut hits = vec![None; primary.len()];
        world.closest::<L, K, StableSphere>(&primary, !0, &mut hits);
        let sh = self.shading(y, &primary, &hits);
        let mut blocked = vec![false; sh.shadow.len()];
        world.occluded::<L, K, StableSphere>(&sh.shadow, !0, &mut blocked);
        // A shading point's share of ambient-occlusion rays that reach open space.
        let mut ao_open = vec![1.0f32; sh.normals.len()];
        if scene.ao_samples > 0 {
            let mut by_any = vec![false; sh.ao.len()];
            world.occluded::<L, K, StableSphere>(&sh.ao, !0, &mut by_any);
            let n = scene.ao_samples as usize;
            for (open, rays) in ao_open.iter_mut().zip(by_any.chunks(n)) {
                let hit = rays.iter().filter(|&&b| b).count();
                *open = 1.0 - hit as f32 / n as f32;
            }
        }
        let (mut rgb, mut kinds) = (
            Vec::with_capacity(self.w as usize * 3),
            Vec::with_capacity(self.w as usize),
        );
        let mut k = 0;
        for (ray, hit) in primary.iter().zip(&hits) {
            let (color, kind) = match *hit {
                None => (sky(ray.dir), PixelKind::Sky),
                Some(h) => {
                    let lit = self.shade(&h, sh.normals[k], !blocked[k], ao_open[k]);
                    k += 1;
                    lit
                }
            };
            rgb.extend(
                color
                    .to_array()
                    .map(|c| (c.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8),
            );
            kinds.push(kind);
        }
        Row {
            rgb,
            kinds,
            words: hits.into_iter().map(Hit::words).collect(),
            rays: (primary.len() + sh.shadow.len() + sh.ao.len()) as u64,
        }
    }

    /// The shading points of row `y`'s hits, with shadow rays towards the sun and
    /// ambient-occlusion rays into the hemisphere, each from its own conservatively offset
    /// origin.
    fn shading(&self, y: u32, primary: &[Ray], hits: &[Option<Hit>]) -> Shading {
        let scene = self.scene;
        let mut sh = Shading {
            normals: vec![],
            shadow: vec![],
            ao: vec![],
        };
        for (ray, hit) in primary.iter().zip(hits) {
            let Some(h) = *hit else { continue };
            let surface = self.surface(ray, &h);
            sh.normals.push(surface.normal);
            sh.shadow
                .push(Ray::new(surface.spawn(scene.light), scene.light));
            let seed = y.wrapping_mul(self.w).wrapping_add(sh.normals.len() as u32);
            for dir in cosine_directions(surface.normal, seed, scene.ao_samples) {
                sh.ao
                    .push(Ray::with_range(surface.spawn(dir), dir, 0.0, self.ao_reach));
            }
        }
        sh
    }

    /// The surface `ray` meets at hit `h`.
    fn surface(&self, ray: &Ray, h: &Hit) -> Surface {
        let scene = self.scene;
        match self.traced.part(h) {
            Part::Sphere => {
                let (c, r) = scene.spheres[h.prim as usize];
                Sphere::new(c, r).surface(ray, h)
            }
            Part::Ground => {
                let t = scene.tris[scene.mesh_tris + h.prim as usize];
                VertexTriangle::new(t[0], t[1], t[2]).surface(ray, h)
            }
            Part::Mesh { model, field } => {
                let t = scene.tris[scene.mesh_groups[model] + h.prim as usize];
                // A field instance is shaded from its triangle carried into the world
                // (barycentrics and t are the same in both spaces).
                let t = match field {
                    Some(f) => t.map(|v| scene.field[f].transform_point3(v)),
                    None => t,
                };
                VertexTriangle::new(t[0], t[1], t[2]).surface(ray, h)
            }
        }
    }

    /// The colour and kind of a hit's pixel with normal `n`, lit by the sun when `visible` and
    /// by the sky as far as the hemisphere is `open`.
    fn shade(&self, h: &Hit, n: Vec3, visible: bool, open: f32) -> (Vec3, PixelKind) {
        let scene = self.scene;
        let shadowed = !visible;
        let (albedo, kind) = match self.traced.part(h) {
            Part::Sphere => (
                scene.sphere_color[h.prim as usize],
                PixelKind::Sphere {
                    index: h.prim,
                    shadowed,
                },
            ),
            Part::Ground => (
                scene.tri_color[scene.mesh_tris + h.prim as usize],
                PixelKind::Ground { shadowed },
            ),
            Part::Mesh { model, field } => {
                let c = scene.tri_color[scene.mesh_groups[model] + h.prim as usize];
                match field {
                    // Each field instance tinted its own way.
                    Some(f) => {
                        let f = f as u32;
                        let tint = Vec3::new(
                            1.0 + 0.6 * hash(5 * f),
                            1.0 + 0.6 * hash(5 * f + 1),
                            1.0 + 0.6 * hash(5 * f + 2),
                        );
                        (c * tint, PixelKind::Field { shadowed })
                    }
                    None => (c, PixelKind::Mesh { shadowed }),
                }
            }
        };
        let diffuse = if visible {
            n.dot(scene.light).max(0.0)
        } else {
            0.0
        };
        // Without ambient occlusion a constant ambient term; with it, a larger sky term scaled
        // by how open the hemisphere is.
        let light = if scene.ao_samples > 0 {
            0.4 * open + 0.6 * diffuse
        } else {
            0.18 + 0.82 * diffuse
        };
        (albedo * light, kind)
    }
}

impl Scene {
    /// How far ambient-occlusion rays reach: a tenth of the scene's box diagonal.
    fn ao_reach(&self) -> f32 {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in self.tris.iter().flatten() {
            (lo, hi) = (lo.min(*p), hi.max(*p));
        }
        0.1 * (hi - lo).length()
    }
}

/// Writes the scene as `tier` traces it to `dir/scene.bin` (`SceneRef::to_words`,
/// little-endian) and the primary rays of a `w`×`h` image to `dir/rays.bin` (origin,
/// direction, `t_min`, `t_max` as little-endian f32, row by row).
pub fn export(scene: &Scene, tier: TierArg, w: u32, h: u32, dir: &Path) -> Result<(), String> {
    fn words<T: Triangles>(scene: &Scene) -> Vec<u32> {
        let (tris, spheres) = primitives::<T>(scene);
        Traced::new(scene, &tris, &spheres)
            .world
            .as_ref()
            .to_words()
    }
    let words = match tier {
        TierArg::Standard => words::<PackedTriangle>(scene),
        TierArg::Watertight | TierArg::Exact => words::<VertexTriangle>(scene),
        t => return Err(format!("--export: the C ABI has no {} tier", t.name())),
    };
    let rays = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            let r = scene.camera_ray(x, y, w, h);
            [
                r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.t_min, r.t_max,
            ]
            .map(f32::to_bits)
        });
    let bytes =
        |w: &mut dyn Iterator<Item = u32>| w.flat_map(u32::to_le_bytes).collect::<Vec<u8>>();
    std::fs::create_dir_all(dir).map_err(|e| format!("--export: {}: {e}", dir.display()))?;
    for (name, data) in [
        ("scene.bin", bytes(&mut words.into_iter())),
        ("rays.bin", bytes(&mut rays.into_iter())),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, data).map_err(|e| format!("--export: {}: {e}", path.display()))?;
    }
    Ok(())
}

/// The digest of the primary hits (as [`Image::digest`]) of the scene and rays that [`export`]
/// wrote to `dir`, read back as a stored scene (`SceneRef::from_words`, validated) and traced
/// with triangle kernel `K` and the stable sphere kernel at lane width `L`: for the tier the
/// scene was exported for, what the demo's render of it prints, and what the C ABI's examples
/// must print for the same files.
pub fn stored_digest<L, K>(dir: &Path) -> Result<u64, String>
where
    L: Lanes,
    K: Kernel<L>,
    K::Prim: Triangles,
    StableSphere: Kernel<L, Prim = PackedSphere>,
{
    let read = |name: &str| -> Result<Vec<u32>, String> {
        let path = dir.join(name);
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    };
    let words = read("scene.bin")?;
    let world = octoray::scene::SceneRef::<K::Prim, PackedSphere>::from_words(&words)
        .map_err(|e| format!("scene.bin: {e}"))?;
    let rays: Vec<Ray> = read("rays.bin")?
        .chunks_exact(8)
        .map(|r| {
            let f = |i: usize| f32::from_bits(r[i]);
            Ray::with_range(
                Vec3::new(f(0), f(1), f(2)),
                Vec3::new(f(3), f(4), f(5)),
                f(6),
                f(7),
            )
        })
        .collect();
    let mut hits = vec![None; rays.len()];
    world.closest::<L, K, StableSphere>(&rays, !0, &mut hits);
    Ok(fnv(hits.into_iter().flat_map(Hit::words)))
}

/// Packets of 4, 8 or 16 f32 lanes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// `f32x4`.
    X4,
    /// `f32x8`.
    X8,
    /// `f32x16`.
    X16,
}

/// Packets of 4 or 8 f64 lanes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum F64Width {
    /// `f64x4`.
    X4,
    /// `f64x8`.
    X8,
}

/// What a render traces with: a resolved tier at a packet width (`--tier`, `--lanes`). The
/// `render` binary holds one [`render_with`] instantiation per value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tracer {
    /// Möller-Trumbore at f32.
    Standard(Width),
    /// The watertight test at f32.
    Watertight(Width),
    /// Exact edge signs and range.
    Exact(Width),
    /// Möller-Trumbore at f64.
    F64(F64Width),
    /// The watertight test at f64.
    WatertightF64(F64Width),
}

impl Tracer {
    /// `tier` (already resolved, not `Auto`) at `lanes` ∈ {4, 8, 16} (f64: 4 or 8); an error
    /// says which part is not offered.
    pub fn new(tier: TierArg, lanes: u32) -> Result<Self, String> {
        let f64_width = |tier: &str| match lanes {
            4 => Ok(F64Width::X4),
            8 => Ok(F64Width::X8),
            l => Err(format!(
                "the {tier} tier runs 4 or 8 lanes (f64x4, f64x8), not {l}"
            )),
        };
        let width = match lanes {
            4 => Ok(Width::X4),
            8 => Ok(Width::X8),
            16 => Ok(Width::X16),
            l => Err(format!("lanes must be 4, 8 or 16, not {l}")),
        };
        Ok(match tier {
            TierArg::Standard => Self::Standard(width?),
            TierArg::Watertight => Self::Watertight(width?),
            TierArg::Exact => Self::Exact(width?),
            TierArg::F64 => Self::F64(f64_width("f64")?),
            TierArg::WatertightF64 => Self::WatertightF64(f64_width("watertight-f64")?),
            TierArg::Auto => return Err("resolve the auto tier first".into()),
        })
    }
}

/// Resolves `auto` through the recommender; the report says why. With `auto`, an f64 tier's
/// 16 lanes become 8 (f64 runs 4 or 8), and the report says so.
pub fn resolve_tier(
    scene: &Scene,
    tier: TierArg,
    lanes: u32,
) -> Result<(TierArg, u32, String), String> {
    match tier {
        TierArg::Auto => {
            let r = scene.recommendation()?;
            let t = match r.tier {
                TierChoice::Standard => TierArg::Standard,
                TierChoice::Watertight => TierArg::Watertight,
                TierChoice::F64 => TierArg::F64,
                TierChoice::WatertightF64 => TierArg::WatertightF64,
                TierChoice::Exact => TierArg::Exact,
            };
            let f64_tier = matches!(t, TierArg::F64 | TierArg::WatertightF64);
            if f64_tier && lanes == 16 {
                return Ok((
                    t,
                    8,
                    format!("chosen by the recommender: {r}; 8 lanes, the widest f64 packet"),
                ));
            }
            Ok((t, lanes, format!("chosen by the recommender: {r}")))
        }
        t => Ok((t, lanes, "chosen on the command line".into())),
    }
}

/// Writes an 8-bit RGB PNG to `file` (already created at `path`, which messages name).
pub fn write_png(img: &Image, file: std::fs::File, path: &std::path::Path) -> Result<(), String> {
    use std::io::Write;
    let fail = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", path.display());
    let mut out = std::io::BufWriter::new(file);
    let mut enc = png::Encoder::new(&mut out, img.width, img.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(|e| fail(&e))?;
    w.write_image_data(&img.rgb).map_err(|e| fail(&e))?;
    // Finish and flush explicitly: a dropped writer would lose the last write's error (a full
    // disk then looked like success for small images).
    w.finish().map_err(|e| fail(&e))?;
    out.flush().map_err(|e| fail(&e))
}
