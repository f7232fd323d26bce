//! The C examples' job (`examples/job.h`) through the Rust API: the same scene, rays and shadow
//! rays, and the same printed line. `.ci/capi.sh` checks that the C and C++ programs print what
//! this prints, so the C ABI answers what the Rust API answers, bit for bit. Takes the tier as
//! its argument (0 standard, 1 watertight, 2 exact; default 1).
//!
//! `digest demo DIR TIER WIDTH HEIGHT` exports the demo's embedded scene as that tier traces it,
//! and the primary rays of a WIDTH×HEIGHT image, to `DIR` (what `render --export DIR` writes),
//! and prints the digest of their primary hits through the Rust API on the stored scene (the
//! demo's tests check that it is the digest the demo's render prints); `trace.c demo` must
//! print the same.
use octoray::f32x8;
use octoray::glam::{Affine3A, Mat3A, Vec3, Vec3A};
use octoray::hit::{Digest, Hit};
use octoray::kernels::{Exact, Kernel, MollerTrumbore, NearestPoint, StableSphere, Watertight};
use octoray::prim::{PackedSphere, PackedTriangle, Primitive, Ray, VertexTriangle};
use octoray::scene::{Scene, Trace, Transform};
use octoray::tree::PointHit;
use octoray_demo::scene::{stored_digest, TierArg, Triangles};

const GRID: u32 = 24;
const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;

fn camera(k: u32) -> Ray {
    let dx = ((k % WIDTH) as f32 + 0.5) / 32.0 - 1.0;
    let dy = ((k / WIDTH) as f32 + 0.5) / 24.0 - 1.0;
    Ray::new(
        Vec3::new(0.0, 25.0, -60.0),
        Vec3::new(dx, -0.35 - 0.3 * dy, 1.0),
    )
}

fn run<T, KT>(tier: u32, tri: impl Fn(Vec3, Vec3, Vec3) -> T)
where
    T: Primitive + Sync + NearestPoint,
    KT: Kernel<f32x8, Prim = T>,
{
    let vertex =
        |x: u32, z: u32| Vec3::new(x as f32, ((x * 7 + z * 13) % 5) as f32 * 0.25, z as f32);
    let mut tris = Vec::new();
    for z in 0..GRID {
        for x in 0..GRID {
            let (a, b) = (vertex(x, z), vertex(x + 1, z));
            let (c, d) = (vertex(x + 1, z + 1), vertex(x, z + 1));
            tris.push(tri(a, b, c));
            tris.push(tri(a, c, d));
        }
    }
    let balls: Vec<PackedSphere> = (0..4)
        .map(|k| {
            PackedSphere::new(
                Vec3::new((k * 9 - 12) as f32, 6.0, 10.0),
                2.0 + 0.5 * k as f32,
            )
        })
        .collect();
    let mut scene = Scene::<T, PackedSphere>::new();
    let terrain = scene.add_triangles(&tris).expect("build");
    let balls = scene.add_spheres(&balls).expect("build");
    for i in 0..9 {
        let s = if i % 2 == 0 { 1.0 } else { 0.5 };
        let mirror = if i == 4 { -1.0 } else { 1.0 };
        let place = Affine3A {
            matrix3: Mat3A::from_cols(
                Vec3A::new(mirror * s, 0.0, 0.0),
                Vec3A::new(0.0, s, 0.0),
                Vec3A::new(0.0, 0.0, s),
            ),
            translation: Vec3A::new(((i % 3) * 30 - 45) as f32, -2.0, ((i / 3) * 30 - 20) as f32),
        };
        scene.add_instance(
            &[terrain],
            Transform::placing(place).expect("invertible"),
            1,
        );
    }
    scene.add_instance(&[balls], Transform::IDENTITY, 2);
    scene.commit().expect("commit");
    let s = scene.as_ref();

    let rays: Vec<Ray> = (0..WIDTH * HEIGHT).map(camera).collect();
    let mut hits = vec![None; rays.len()];
    s.closest::<f32x8, KT, StableSphere>(&rays, !0, &mut hits);
    let light = Vec3::new(20.0, 60.0, -10.0);
    let shadow: Vec<Ray> = rays
        .iter()
        .zip(&hits)
        .filter_map(|(r, h)| {
            let h: Hit = (*h)?;
            let p = r.origin + r.dir * h.t;
            Some(Ray::with_range(p, light - p, 1e-3, 1.0))
        })
        .collect();
    let mut blocked = vec![false; shadow.len()];
    s.occluded::<f32x8, KT, StableSphere>(&shadow, !0, &mut blocked);

    // Every hit along each camera ray (as many as the C job keeps: eight per ray on average).
    let mut along = vec![];
    for r in &rays {
        let mut page = [Hit::default(); 64];
        let mut after = None;
        loop {
            let found = s.all_hits_ray::<f32x8, KT, StableSphere>(r, !0, after, &mut page);
            along.extend_from_slice(&page[..found.stored]);
            if found.complete {
                break;
            }
            after = Some(page[found.stored - 1]);
        }
    }

    // The closest point to each shadow ray's origin lifted by 1.5.
    let near: Vec<PointHit> = shadow
        .iter()
        .map(|r| {
            let p = r.origin + Vec3::new(0.0, 1.5, 0.0);
            s.closest_point(p, f32::INFINITY, !0)
                .expect("a point near the scene")
        })
        .collect();

    let mut digest = Digest::new();
    hits.iter().for_each(|&h| digest.placed_hit(h));
    blocked.iter().for_each(|&b| digest.word(u32::from(b)));
    along
        .iter()
        .take(rays.len() * 8)
        .for_each(|&h| digest.placed_hit(Some(h)));
    for h in &near {
        let floats = [h.point.x, h.point.y, h.point.z, h.dist, h.u, h.v];
        floats.iter().for_each(|x| digest.word(x.to_bits()));
        [h.prim, h.geom, h.inst]
            .iter()
            .for_each(|&w| digest.word(w));
    }
    let digest = digest.value();
    println!(
        "tier {tier}: {} rays, {} hit, {} in shadow, {} hits along them, {} closest points, \
         digest 0x{digest:016x}",
        rays.len(),
        shadow.len(),
        blocked.iter().filter(|&&b| b).count(),
        along.len(),
        near.len()
    );
}

/// The `demo` mode (module doc).
fn demo(args: &[String]) {
    let [dir, tier, w, h] = args else {
        panic!("digest demo DIR TIER WIDTH HEIGHT");
    };
    let dir = std::path::Path::new(dir);
    let size = |s: &str| s.parse::<u32>().expect("a size in pixels");
    let at = (dir, size(w), size(h));
    let digest = match tier.as_str() {
        "0" => demo_tier::<MollerTrumbore>(TierArg::Standard, at),
        "1" => demo_tier::<Watertight>(TierArg::Watertight, at),
        "2" => demo_tier::<Exact>(TierArg::Exact, at),
        _ => panic!("a tier: 0, 1 or 2"),
    };
    println!("0x{digest:016x}");
}

/// The demo's default scene stored for `tier` in `dir` as `render --export` stores it, and the
/// digest of kernel `K`'s primary hits on the stored scene.
fn demo_tier<K>(tier: TierArg, (dir, w, h): (&std::path::Path, u32, u32)) -> u64
where
    K: Kernel<f32x8>,
    K::Prim: Triangles,
{
    let scene = octoray_demo::scene::Scene::default_scene();
    octoray_demo::scene::export(&scene, tier, w, h, dir).expect("export");
    stored_digest::<f32x8, K>(dir).expect("the stored scene")
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("demo") {
        return demo(&args[1..]);
    }
    let tier = args
        .first()
        .map_or(1, |a| a.parse().expect("a tier: 0, 1 or 2"));
    match tier {
        0 => run::<_, MollerTrumbore>(0, PackedTriangle::new),
        1 => run::<_, Watertight>(1, VertexTriangle::new),
        2 => run::<_, Exact>(2, VertexTriangle::new),
        _ => panic!("a tier: 0, 1 or 2"),
    }
}
