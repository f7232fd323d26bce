//! Queries beyond the first hit against the peers that have them, on the same meshes, points and
//! rays: containment (parry3d's `contains_point`), closest point (parry3d's `project_point`,
//! Embree 3's `rtcPointQuery` with its tutorial's callback) and every hit along a ray (Embree's
//! filter loop). One thread; columns timed in alternation.

pub mod markdown;

use crate::scene::embree::EmbreeScene;
use crate::scene::timing::alternating;
use glam::Vec3;
use octoray::bvh::{Bvh8, Solid};
use octoray::hit::Hit;
use octoray::kernels::Watertight;
use octoray::prim::{Ray, VertexTriangle};
use octoray::tree::{all_hits_ray, closest_point, contains};
use octoray_testkit::Rng;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};
use wide::f32x8;

/// A mesh of the query report: its triangles and, for parry3d, the same as an indexed mesh.
pub struct QueryMesh {
    /// Its name in the report.
    pub name: String,
    /// Vertices (shared by the faces of a closed mesh).
    pub verts: Vec<Vec3>,
    /// Faces, counter-clockwise from outside.
    pub faces: Vec<[u32; 3]>,
    /// Closed and outward-oriented: containment is measured.
    pub closed: bool,
}

impl QueryMesh {
    /// A closed indexed mesh.
    pub fn closed(name: String, mesh: octoray_testkit::mesh::Mesh) -> Self {
        Self {
            name,
            verts: mesh.verts,
            faces: mesh.tris,
            closed: true,
        }
    }

    /// A triangle soup (each triangle its own three vertices).
    pub fn soup(name: String, tris: &[[Vec3; 3]]) -> Self {
        Self {
            name,
            verts: tris.iter().flatten().copied().collect(),
            faces: (0..tris.len() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect(),
            closed: false,
        }
    }

    /// The faces as vertex triples.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.faces
            .iter()
            .map(|f| f.map(|i| self.verts[i as usize]))
            .collect()
    }

    /// `n` points uniform in the mesh's bounding box grown by a tenth, and `n` rays from points
    /// outside the box through points inside it.
    pub fn workload(&self, n: usize, seed: u64) -> (Vec<Vec3>, Vec<Ray>) {
        let (lo, hi) = self.verts.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        );
        let (c, half) = ((lo + hi) * 0.5, (hi - lo) * 0.55);
        let mut rng = Rng(seed);
        let mut inside = || {
            c + half
                * Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                )
        };
        let points: Vec<Vec3> = (0..n).map(|_| inside()).collect();
        let rays = (0..n)
            .map(|_| {
                let (a, b) = (inside(), inside());
                let o = a + (a - b).normalize_or(Vec3::X) * half.length() * 2.0;
                Ray::new(o, b - o)
            })
            .collect();
        (points, rays)
    }
}

/// What a row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QueryKind {
    /// Is the point inside the closed mesh?
    Contains,
    /// The nearest triangle, the point on it and the distance.
    ClosestPoint,
    /// Every hit along the ray, sorted.
    AllHits,
}

/// The systems of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum System {
    /// octoray (`tree::contains`, `tree::closest_point`, `tree::all_hits_ray` at the watertight
    /// tier with a buffer of 64).
    Octoray,
    /// parry3d 0.31 on a `TriMesh` (`ORIENTED` for containment).
    Parry3d,
    /// Embree 3, robust mode.
    Embree,
}

/// One measured cell: ns per query and a digest of the answers (to check the systems did the
/// same work).
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    /// The system.
    pub system: System,
    /// Nanoseconds per query, best round.
    pub ns: f64,
    /// Answers: points inside, the sum of the distances (rounded to 1e-3), or hits in total.
    pub answer: u64,
}

/// One row: a query on a mesh, each system that has it.
#[derive(Clone, Debug)]
pub struct QueryRow {
    /// The mesh's name.
    pub mesh: String,
    /// Its triangles.
    pub tris: usize,
    /// The query.
    pub kind: QueryKind,
    /// Queries per round.
    pub n: usize,
    /// The systems, octoray first.
    pub cells: Vec<Cell>,
}

/// Sums distances as an answer digest (millionths).
fn digest(d: impl Iterator<Item = f32>) -> u64 {
    (d.map(f64::from).sum::<f64>() * 1e6).round() as u64
}

/// Measures every query the mesh supports: `n` queries each, best of `runs` alternating rounds.
pub fn measure(mesh: &QueryMesh, n: usize, runs: usize) -> Vec<QueryRow> {
    let tris = mesh.triangles();
    let vt: Vec<VertexTriangle> = tris
        .iter()
        .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
        .collect();
    let bvh = Bvh8::build(&vt);
    let (points, rays) = mesh.workload(n, 0x5EED);
    let pv = |v: Vec3| parry3d::math::Vector::new(v.x, v.y, v.z);
    let flags = if mesh.closed {
        TriMeshFlags::ORIENTED
    } else {
        TriMeshFlags::empty()
    };
    let parry = TriMesh::with_flags(
        mesh.verts.iter().map(|&v| pv(v)).collect(),
        mesh.faces.clone(),
        flags,
    )
    .expect("parry3d accepts the mesh");
    let id = parry3d::math::Pose::IDENTITY;
    let embree = EmbreeScene::build_collecting(&tris).ok();
    let row = |kind, cells: Vec<(System, (f64, u64))>| QueryRow {
        mesh: mesh.name.clone(),
        tris: tris.len(),
        kind,
        n,
        cells: cells
            .into_iter()
            .map(|(system, (mrays, answer))| Cell {
                system,
                ns: 1e3 / mrays,
                answer,
            })
            .collect(),
    };
    let mut rows = vec![];
    if mesh.closed {
        let solid = Solid::new(bvh.as_ref(), &vt).expect("a closed mesh");
        let mut ours = || {
            points
                .iter()
                .filter(|&&p| contains::<f32x8>(solid, p))
                .count() as u64
        };
        let mut theirs = || {
            points
                .iter()
                .filter(|&&p| parry.contains_point(&id, pv(p)))
                .count() as u64
        };
        let r = alternating(runs, n, &mut [&mut ours, &mut theirs]);
        rows.push(row(
            QueryKind::Contains,
            vec![(System::Octoray, r[0]), (System::Parry3d, r[1])],
        ));
    }
    let mut ours =
        || {
            digest(points.iter().map(|&p| {
                closest_point(bvh.as_ref(), p, f32::INFINITY).map_or(f32::NAN, |h| h.dist)
            }))
        };
    let mut theirs = || {
        digest(points.iter().map(|&p| {
            let q = pv(p);
            (parry.project_point(&id, q, false).point - q).length()
        }))
    };
    let mut out = Vec::with_capacity(n);
    let mut embree_cp = || {
        let e = embree.as_ref().expect("checked");
        e.closest_points(&tris, &points, &mut out);
        digest(out.iter().map(|x| x.1))
    };
    let mut fs: Vec<&mut dyn FnMut() -> u64> = vec![&mut ours, &mut theirs];
    if embree.is_some() {
        fs.push(&mut embree_cp);
    }
    let r = alternating(runs, n, &mut fs);
    let mut cells = vec![(System::Octoray, r[0]), (System::Parry3d, r[1])];
    cells.extend(r.get(2).map(|&c| (System::Embree, c)));
    rows.push(row(QueryKind::ClosestPoint, cells));
    if let Some(e) = &embree {
        let mut page = [Hit::default(); 64];
        let mut ours = || {
            let mut total = 0u64;
            for r in &rays {
                let mut after = None;
                loop {
                    let found =
                        all_hits_ray::<f32x8, Watertight>(bvh.as_ref(), r, after, &mut page);
                    total += found.stored as u64;
                    if found.complete {
                        break;
                    }
                    after = Some(page[found.stored - 1]);
                }
            }
            total
        };
        let mut theirs = || e.all_hits1(&rays);
        let r = alternating(runs, n, &mut [&mut ours, &mut theirs]);
        rows.push(row(
            QueryKind::AllHits,
            vec![(System::Octoray, r[0]), (System::Embree, r[1])],
        ));
    }
    rows
}
