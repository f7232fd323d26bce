//! The firmware's job, shared word for word by the firmware (`main.rs`), its build script (the
//! mesh the host builds the tree from) and the host's check (`tests/suite/embedded.rs`): the seed
//! sheet's seven problems, then rays through a tree read from untrusted words, checked against
//! brute force and packets on the device itself, and a digest of every answer. `no_std`, no
//! allocator.
use core::fmt::{self, Write};

use octoray::bvh::{Bvh8Node, Bvh8Ref};
use octoray::f32x4;
use octoray::glam::Vec3;
use octoray::hit::Digest;
use octoray::kernels::{StableSphere, Watertight};
use octoray::prim::{
    PackedSphere, PackedTriangle, Primitive, Ray, RayLanes, Sphere, VertexTriangle, BLOCK,
};
use octoray::query;
use octoray::textbook::{self, InsideTest, SphereOutcome, TriangleOutcome};
use octoray::tree::{closest_packet, closest_ray, occluded_ray};

/// The first word of a stored tree ("o8t1").
pub const MAGIC: u32 = u32::from_le_bytes(*b"o8t1");
/// Words before the sections: magic, node count, block rows, slots, primitives.
pub const HEADER: usize = 5;

/// Rings around the torus' axis and sides around its tube: a closed mesh of `2·RINGS·SIDES`
/// triangles.
const RINGS: usize = 24;
const SIDES: usize = 12;
/// The torus' triangle count.
pub const TRIANGLES: usize = 2 * RINGS * SIDES;
/// The camera's rays per side: `GRID²` primary rays.
const GRID: usize = 24;

/// Vertex `(i, j)` of the torus (major radius 1, minor 0.4, axis z), from libm's `sinf`/`cosf`
/// so that the host and the device make the same mesh.
fn torus_vertex(i: usize, j: usize) -> Vec3 {
    let tau = core::f32::consts::TAU;
    let (a, b) = (
        tau * (i % RINGS) as f32 / RINGS as f32,
        tau * (j % SIDES) as f32 / SIDES as f32,
    );
    let r = 1.0 + 0.4 * libm::cosf(b);
    Vec3::new(r * libm::cosf(a), r * libm::sinf(a), 0.4 * libm::sinf(b))
}

/// The torus' triangles: quad `(i, j)` split along its diagonal, vertices shared exactly.
pub fn torus() -> [VertexTriangle; TRIANGLES] {
    core::array::from_fn(|k| {
        let (q, second) = (k / 2, k % 2 == 1);
        let (i, j) = (q / SIDES, q % SIDES);
        let (a, b, c, d) = (
            torus_vertex(i, j),
            torus_vertex(i + 1, j),
            torus_vertex(i + 1, j + 1),
            torus_vertex(i, j + 1),
        );
        if second {
            VertexTriangle::new(a, c, d)
        } else {
            VertexTriangle::new(a, b, c)
        }
    })
}

/// The camera's rays.
pub fn primaries() -> [Ray; GRID * GRID] {
    core::array::from_fn(primary)
}

/// A triangle in the standard tier's layout.
pub fn packed(t: &VertexTriangle) -> PackedTriangle {
    let v = |p: [f32; 3]| Vec3::from(p);
    PackedTriangle::new(v(t.v0), v(t.v1), v(t.v2))
}

/// Primary ray `k` of the camera: from above the torus' rim, a `GRID × GRID` fan whose corners
/// miss it.
fn primary(k: usize) -> Ray {
    let (x, y) = ((k % GRID) as f32, (k / GRID) as f32);
    let s = 3.4 / GRID as f32;
    let dir = Vec3::new(-1.7 + s * (x + 0.5), 3.0, 1.7 - s * (y + 0.5) - 1.2);
    Ray::new(Vec3::new(0.0, -3.0, 1.2), dir)
}

/// The light the shadow rays aim at.
const LIGHT: Vec3 = Vec3::new(-2.0, -1.0, 3.0);

/// A stored tree's words read as a validated [`Bvh8Ref`]: every length is checked before a
/// slice is cut and the slices are validated as any untrusted tree, so bad words give an error,
/// never a panic.
pub fn parse<P: Primitive>(words: &[u32]) -> Result<Bvh8Ref<'_, P>, &'static str> {
    let node_words = core::mem::size_of::<Bvh8Node>() / 4;
    let header = words.get(..HEADER).ok_or("shorter than its header")?;
    if header[0] != MAGIC {
        return Err("not a stored tree");
    }
    let [nodes, rows, slots, prims] = [1, 2, 3, 4].map(|i| header[i] as usize);
    let cut = |at: usize, n: Option<usize>| -> Result<(&[u32], usize), &'static str> {
        let end = n
            .and_then(|n| at.checked_add(n))
            .filter(|&e| e <= words.len())
            .ok_or("a section runs past the end")?;
        Ok((&words[at..end], end))
    };
    let (n, at) = cut(HEADER, nodes.checked_mul(node_words))?;
    let (b, at) = cut(at, rows.checked_mul(BLOCK))?;
    let (ids, at) = cut(at, Some(slots))?;
    if at != words.len() {
        return Err("words past the last section");
    }
    let nodes: &[Bvh8Node] = bytemuck::try_cast_slice(n).map_err(|_| "misaligned nodes")?;
    let blocks: &[[f32; BLOCK]] = bytemuck::try_cast_slice(b).map_err(|_| "misaligned blocks")?;
    Bvh8Ref::new(nodes, blocks, ids, prims).map_err(|_| "the tree does not validate")
}

/// The seed ray and primitives of `shared/seed/problems.md`.
pub fn seed() -> (Ray, [VertexTriangle; 3], [Sphere; 4]) {
    let v = Vec3::new;
    (
        Ray::new(v(-4.0, -2.0, -1.0), v(1.0, 2.0, 3.0)),
        [
            VertexTriangle::new(v(0.0, 6.0, 7.0), v(-3.0, 1.0, 5.0), v(-2.0, 1.0, 4.0)),
            VertexTriangle::new(v(-2.0, 1.0, 2.0), v(-1.0, 1.0, 1.0), v(1.0, 6.0, 4.0)),
            VertexTriangle::new(v(0.0, 0.0, 0.0), v(2.0, 4.0, 6.0), v(1.0, 0.0, 0.0)),
        ],
        [
            Sphere::new(v(0.0, 0.0, 0.0), 10.0),
            Sphere::new(v(-3.0, 0.0, 2.0), 1.0),
            Sphere::new(v(-5.0, -6.0, -7.0), 2.0),
            Sphere::new(v(0.0, 0.0, -1.0), 3.0),
        ],
    )
}

/// What the job found: the transcript's last figures, for the host's assertions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Primary rays that hit the torus.
    pub hits: usize,
    /// Rays whose tree answer differed from brute force over the triangles (closest or shadow).
    pub tree_mismatches: usize,
    /// Rays whose 4-lane packet answer differed from the single ray's.
    pub packet_mismatches: usize,
    /// The digest of every answer.
    pub digest: u64,
}

/// Runs the job on a stored tree's words, writing the transcript to `out`.
pub fn run(words: &[u32], out: &mut impl Write) -> Result<Summary, fmt::Error> {
    let mut f = Digest::new();
    let (ray, tris, spheres) = seed();
    for (i, tri) in tris.iter().enumerate() {
        let s = textbook::triangle_steps(&ray, tri, InsideTest::Full);
        match s.outcome {
            TriangleOutcome::Hit(h) => writeln!(
                out,
                "seed triangle {}: hit t={:?} p={:?}",
                i + 1,
                h.t,
                h.point
            )?,
            o => writeln!(out, "seed triangle {}: {o:?}", i + 1)?,
        }
        let h = octoray::intersect::<f32, Watertight>(&ray, tri);
        writeln!(out, "  watertight: {:?}", h.map(|h| (h.t, h.u, h.v)))?;
        f.hit(h);
    }
    for (i, sphere) in spheres.iter().enumerate() {
        match textbook::sphere_steps(&ray, sphere).outcome {
            SphereOutcome::Hit { hit, inside } => writeln!(
                out,
                "seed sphere {}: hit t={:?} p={:?} inside={inside}",
                i + 1,
                hit.t,
                hit.point
            )?,
            o => writeln!(out, "seed sphere {}: {o:?}", i + 1)?,
        }
        let p = PackedSphere::new(sphere.center, sphere.radius);
        let h = octoray::intersect::<f32, StableSphere>(&ray, &p);
        writeln!(out, "  stable: {:?}", h.map(|h| h.t))?;
        f.hit(h);
    }

    let mesh = torus();
    let tree = match parse::<VertexTriangle>(words) {
        Ok(t) if t.prims() == TRIANGLES => t,
        Ok(t) => {
            writeln!(out, "tree: {} primitives, expected {TRIANGLES}", t.prims())?;
            return Err(fmt::Error);
        }
        Err(e) => {
            writeln!(out, "tree: {e}")?;
            return Err(fmt::Error);
        }
    };
    writeln!(
        out,
        "tree: {} triangles, {} nodes, validated",
        tree.prims(),
        tree.nodes().len()
    )?;
    let (mut hits, mut shadowed, mut tree_mismatches, mut packet_mismatches) = (0, 0, 0, 0);
    let rays = primaries();
    for (g, group) in rays.chunks(4).enumerate() {
        let packet = closest_packet::<f32x4, Watertight>(tree, &RayLanes::load(group));
        for (i, r) in group.iter().enumerate() {
            let h = closest_ray::<f32, Watertight>(tree, r);
            let brute = query::closest::<f32, Watertight>(&RayLanes::single(r), &mesh).lane(0);
            tree_mismatches += usize::from(h != brute);
            packet_mismatches += usize::from(packet.lane(i) != h);
            f.hit(h);
            let Some(h) = h else { continue };
            hits += 1;
            // A shadow ray from the hit point toward the light, started past the surface by
            // a relative margin (the spawn helpers' job in a renderer; here the figure is only
            // compared, tree against brute force).
            let p = r.origin + r.dir * h.t;
            let mut s = Ray::new(p, LIGHT - p);
            s.t_min = 1e-3;
            s.t_max = 1.0;
            let blocked = occluded_ray::<f32, Watertight>(tree, &s);
            let brute = query::occluded::<f32, Watertight>(&RayLanes::single(&s), &mesh);
            tree_mismatches += usize::from(blocked != brute);
            shadowed += usize::from(blocked);
            f.word(u32::from(blocked) | (g as u32) << 1);
        }
    }
    writeln!(
        out,
        "rays: {} primary, {hits} hit, {shadowed} of them in shadow",
        rays.len()
    )?;
    writeln!(
        out,
        "tree == brute force on {} of {} answers, packet-4 == single ray on {} of {}",
        rays.len() + hits - tree_mismatches,
        rays.len() + hits,
        rays.len() - packet_mismatches,
        rays.len()
    )?;
    writeln!(out, "digest 0x{:016x}", f.value())?;
    Ok(Summary {
        hits,
        tree_mismatches,
        packet_mismatches,
        digest: f.value(),
    })
}
