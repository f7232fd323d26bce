//! Scene-model workloads: a file's meshes as geometries of one scene, a field of instances (and
//! the same triangles flattened into one tree), alpha-tested leaves, and an animation refitted
//! frame by frame.

use crate::scene::sets::SceneSet;
use glam::{Affine3A, Quat, Vec3};
use octoray::bvh::Bvh8Ref;
use octoray::hit::{Candidate, Hit};
use octoray::kernels::{StableSphere, Watertight};
use octoray::lanes::LaneMask;
use octoray::prim::{PackedSphere, Ray, RayLanes, VertexTriangle};
use octoray::scene::{Scene, SceneRef, Trace, Transform};
use octoray::tree::closest_ray;
use octoray_testkit::camera::Pinhole;
use wide::f32x8;

/// The alpha mask of the alpha rows: every other primitive cut out in a checkerboard of its
/// barycentrics.
pub fn alpha(c: &Candidate) -> bool {
    c.prim % 2 == 1 || ((c.u * 6.0) as i32 + (c.v * 6.0) as i32) % 2 == 0
}

/// The closest hit `keep` accepts, without a filter: the restart loop a renderer writes when its
/// library has none (trace, and on a rejected hit trace again from just past it).
pub fn restart_closest(
    tree: Bvh8Ref<'_, VertexTriangle>,
    ray: &Ray,
    keep: impl Fn(&Candidate) -> bool,
) -> Option<Hit> {
    let mut ray = *ray;
    loop {
        let h = closest_ray::<f32x8, Watertight>(tree, &ray)?;
        if keep(&Candidate::from_hit(&h, 0)) {
            return Some(h);
        }
        ray.t_min = h.t.next_up();
    }
}

/// How a file's meshes go into a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// All triangles as one geometry.
    OneGeometry,
    /// Each mesh a geometry, all in one tree (one instance of the set).
    MeshesOneTree,
    /// Each mesh a geometry with its own tree and instance (a two-level scene).
    MeshesInstanced,
}

/// The scene of `s` in `layout`.
pub fn scene_of(s: &SceneSet, layout: Layout) -> Scene<VertexTriangle, PackedSphere> {
    let verts = s.vertex_tris();
    let mut bounds: Vec<usize> = if layout == Layout::OneGeometry {
        vec![0]
    } else {
        s.meshes.clone()
    };
    bounds.push(verts.len());
    let mut scene = Scene::new();
    let mut geoms = Vec::new();
    for w in bounds.windows(2) {
        if w[0] == w[1] {
            continue;
        }
        geoms.push(scene.add_triangles(&verts[w[0]..w[1]]).expect("build"));
    }
    if layout == Layout::MeshesInstanced {
        for g in geoms {
            scene.add_instance(&[g], Transform::IDENTITY, u32::MAX);
        }
    } else {
        scene.add_instance(&geoms, Transform::IDENTITY, u32::MAX);
    }
    scene.commit().expect("commit");
    scene
}

/// A field of `side × side` instances of one mesh (random rotations about the vertical and
/// scales 0.6–1.4, on a grid of spacing 3), the camera looking across it.
pub fn field(side: u32) -> (Vec<Affine3A>, Pinhole) {
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut places = Vec::new();
    for i in 0..side {
        for j in 0..side {
            let s = 0.6 + 0.8 * rnd();
            let rot = Quat::from_rotation_y(rnd() * std::f32::consts::TAU);
            let at = Vec3::new(3.0 * i as f32, 0.0, 3.0 * j as f32);
            places.push(Affine3A::from_scale_rotation_translation(
                Vec3::splat(s),
                rot,
                at,
            ));
        }
    }
    let mid = 1.5 * side as f32;
    let camera = Pinhole {
        eye: Vec3::new(-4.0, 4.0, -4.0),
        target: Vec3::new(mid, 0.0, mid),
        fov: 50f32.to_radians(),
    };
    (places, camera)
}

/// The instances' triangles in world space (each vertex mapped in f32), for one flat tree.
pub fn flatten(mesh: &[[Vec3; 3]], places: &[Affine3A]) -> Vec<[Vec3; 3]> {
    places
        .iter()
        .flat_map(|a| mesh.iter().map(|t| t.map(|v| a.transform_point3(v))))
        .collect()
}

/// `mesh` placed at `places` as a two-level scene.
pub fn instanced(mesh: &[[Vec3; 3]], places: &[Affine3A]) -> Scene<VertexTriangle, PackedSphere> {
    let verts: Vec<VertexTriangle> = mesh
        .iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect();
    let mut scene = Scene::new();
    let g = scene.add_triangles(&verts).expect("build");
    for a in places {
        let t = Transform::placing(*a).expect("invertible");
        scene.add_instance(&[g], t, u32::MAX);
    }
    scene.commit().expect("commit");
    scene
}

type Wt<'a> = SceneRef<'a, VertexTriangle, PackedSphere>;

/// Closest hit of `rays` in packets of 8 through a scene (watertight); returns the hits.
pub fn scene_packets_closest(scene: Wt<'_>, rays: &[Ray]) -> u64 {
    rays.chunks(8)
        .map(|c| {
            let h = scene
                .closest_packet::<f32x8, Watertight, StableSphere>(&RayLanes::load(c), u32::MAX);
            u64::from(h.mask.bitmask().count_ones())
        })
        .sum()
}

/// Closest hit of each ray alone through a scene; returns the hits.
pub fn scene_singles_closest(scene: Wt<'_>, rays: &[Ray]) -> u64 {
    rays.iter()
        .filter(|r| {
            scene
                .closest_ray::<f32x8, Watertight, StableSphere>(r, u32::MAX)
                .is_some()
        })
        .count() as u64
}

/// Occlusion of each ray alone through a scene; returns the number occluded.
pub fn scene_singles_any(scene: Wt<'_>, rays: &[Ray]) -> u64 {
    rays.iter()
        .filter(|r| scene.occluded_ray::<f32x8, Watertight, StableSphere>(r, u32::MAX))
        .count() as u64
}

/// Sponza-style animation: every vertex moved by a wave whose amplitude grows with `frame`
/// (0.02 of the scene's extent per frame), the mesh's topology kept.
pub fn wave(tris: &[[Vec3; 3]], frame: u32) -> Vec<VertexTriangle> {
    let a = 0.02 * frame as f32;
    let move_v =
        |v: Vec3| v + Vec3::new((v.y * 0.7).sin(), (v.z * 0.5).cos(), (v.x * 0.3).sin()) * a;
    tris.iter()
        .map(|t| VertexTriangle::new(move_v(t[0]), move_v(t[1]), move_v(t[2])))
        .collect()
}
