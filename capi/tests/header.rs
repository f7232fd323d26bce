//! The committed C header is the one cbindgen generates from `src/lib.rs` now: a change to the
//! ABI that forgets the header fails here. `OCTORAY_BLESS=1 cargo test -p octoray-capi --test
//! header` rewrites it.
use std::path::Path;

#[test]
fn committed_header_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen reads src/lib.rs")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8");
    let path = dir.join("include/octoray.h");
    if std::env::var_os("OCTORAY_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/octoray.h is stale: rerun with OCTORAY_BLESS=1"
    );
    // The header declares every entry point.
    for f in [
        "octoray_scene_new",
        "octoray_closest16",
        "octoray_scene_load",
        "octoray_last_error",
    ] {
        assert!(generated.contains(&format!("{f}(")), "{f} missing");
    }
}
