//! Builds the torus' trees on the host (one per triangle layout: `vertex.bin` for the
//! watertight and exact tiers, `packed.bin` for the standard tier) and stores them as
//! little-endian words in `OUT_DIR`, which the firmware includes as `&'static` data; puts
//! `memory.x` on the linker's path.
use std::path::{Path, PathBuf};

#[path = "src/job.rs"]
#[allow(dead_code)]
mod job;
#[path = "src/tree.rs"]
mod tree;

fn store(dir: &Path, name: &str, words: &[u32]) {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(dir.join(name), bytes).expect("OUT_DIR is writable");
}

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let mesh = job::torus();
    store(&out, "vertex.bin", &tree::words(&mesh));
    store(
        &out,
        "packed.bin",
        &tree::words(&mesh.map(|t| job::packed(&t))),
    );
    std::fs::copy("memory.x", out.join("memory.x")).expect("memory.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    for f in ["memory.x", "src/job.rs", "src/tree.rs"] {
        println!("cargo:rerun-if-changed={f}");
    }
}
