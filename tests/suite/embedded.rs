//! The Cortex-M firmware's job (`examples/cortex-m`) run on the host: its transcript must be
//! `examples/cortex-m/expected.txt` line for line, the file `.ci/cortex-m.sh` compares the
//! firmware's output with under QEMU (`mps2-an386`, a Cortex-M4F). So the microcontroller, and
//! every ISA this test runs on, give the same answers and digest as this machine. The tree is
//! the one the firmware's build script stores (the same function builds it here).
#![cfg(all(feature = "triangle", feature = "sphere", feature = "alloc"))]
use octoray_testkit as testkit;

#[path = "../../examples/cortex-m/src/job.rs"]
#[allow(dead_code)]
mod job;
#[path = "../../examples/cortex-m/src/tree.rs"]
mod tree;

const EXPECTED: &str = include_str!("../../examples/cortex-m/expected.txt");

#[test]
fn host_transcript_is_the_firmwares() {
    let words = tree::words(&job::torus());
    let mut out = String::new();
    let s = job::run(&words, &mut out).expect("the job runs");
    assert_eq!(s.tree_mismatches, 0, "{out}");
    assert_eq!(s.packet_mismatches, 0, "{out}");
    // Some rays hit the torus, some miss it, some hits are shadowed.
    assert!(s.hits > 100 && s.hits < 500, "{out}");
    assert!(out.contains(" of them in shadow") && !out.contains(" 0 of them in shadow"));
    assert_eq!(
        out, EXPECTED,
        "the job's transcript changed; if deliberate, store it in examples/cortex-m/expected.txt \
         and rerun .ci/cortex-m.sh"
    );
}

#[test]
fn the_firmwares_seed_is_the_sheets() {
    let (ray, tris, spheres) = job::seed();
    assert_eq!(ray, testkit::seed_ray());
    assert_eq!(tris, testkit::seed_triangles());
    assert_eq!(spheres, testkit::seed_spheres());
}

#[test]
fn stored_tree_words_are_parsed_totally() {
    use octoray::prim::VertexTriangle;
    let words = tree::words(&job::torus());
    assert!(job::parse::<VertexTriangle>(&words).is_ok());
    // Every truncation, a wrong magic, every header count off by one or made huge, and a
    // word appended: an error, never a panic.
    for n in 0..words.len() {
        assert!(job::parse::<VertexTriangle>(&words[..n]).is_err(), "{n}");
    }
    let mut bad = words.clone();
    bad[0] ^= 1;
    assert!(job::parse::<VertexTriangle>(&bad).is_err());
    for i in 1..job::HEADER {
        // One more primitive than the slots name is a valid tree (the caller's slice may be
        // longer than what the tree holds); the job itself checks the count.
        let more = (i != job::HEADER - 1).then(|| words[i].wrapping_add(1));
        for v in [more, Some(words[i].wrapping_sub(1)), Some(u32::MAX)] {
            let Some(v) = v else { continue };
            let mut bad = words.clone();
            bad[i] = v;
            assert!(
                job::parse::<VertexTriangle>(&bad).is_err(),
                "word {i} = {v}"
            );
        }
    }
    let mut long = words.clone();
    long.push(0);
    assert!(job::parse::<VertexTriangle>(&long).is_err());
}
