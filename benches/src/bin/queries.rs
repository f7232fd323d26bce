//! The query report: containment, closest point and every hit along a ray against parry3d and
//! Embree 3 on the same meshes, points and rays. Writes `benches/queries.md`.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo run --release -p octoray-benches --bin queries`.

use glam::Vec3;
use octoray_benches::query::{markdown, measure, QueryMesh};
use octoray_benches::scene::sets::sponza;
use octoray_testkit::mesh::Mesh;
use octoray_testkit::Rng;

fn main() {
    let mut rng = Rng(7);
    let mut meshes = vec![
        QueryMesh::closed(
            "jittered icosphere".into(),
            Mesh::icosphere(5, 0.02, 1.0, Vec3::ZERO, &mut rng),
        ),
        QueryMesh::closed(
            "jittered icosphere, fine".into(),
            Mesh::icosphere(7, 0.02, 1.0, Vec3::ZERO, &mut rng),
        ),
    ];
    match sponza() {
        Ok(set) => meshes.push(QueryMesh::soup("Sponza".into(), &set.tris)),
        Err(e) => eprintln!("Sponza skipped: {e}"),
    }
    let mut rows = vec![];
    for m in &meshes {
        eprintln!("{} …", m.name);
        rows.extend(measure(m, 20_000, 5));
    }
    let text = markdown::report(
        &rows,
        &octoray_benches::machine(),
        octoray_benches::build_flags(),
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/queries.md");
    std::fs::write(path, &text).expect("write benches/queries.md");
    print!("{text}");
}
