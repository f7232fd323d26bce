//! The tree is the architecture: `octoray-core`'s modules are layers, and each imports only from
//! the layers below it (docs/architecture.md). This test reads the sources and fails on an
//! import that goes up or sideways, so a cycle cannot creep back in.

use octoray_testkit::rust_files;
use std::path::Path;

/// `octoray-core`'s top-level modules, lowest layer first; modules on one line share a layer
/// and may not import each other.
const LAYERS: &[&[&str]] = &[
    &["lanes"],
    &["prim"],
    &["hit"],
    &["kernels"],
    &["query"],
    &["bvh"],
    &["scene"],
    &["shading", "ingest", "recommend", "textbook"],
];

fn layer(module: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&module))
        .unwrap_or_else(|| panic!("module `{module}` is in no layer: add it to LAYERS"))
}

/// Every `crate::<module>` named in code (not in comments) of `src`.
fn crate_refs(src: &str) -> Vec<String> {
    let mut out = vec![];
    for line in src.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            let after = &rest[i + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            // `use crate::{a, b}` names several modules.
            if let Some(group) = after.strip_prefix('{') {
                let group = group.split('}').next().unwrap_or("");
                for item in group.split(',') {
                    let m: String = item
                        .trim()
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    if !m.is_empty() {
                        out.push(m);
                    }
                }
            } else if !name.is_empty() {
                out.push(name);
            }
            rest = after;
        }
    }
    out
}

#[test]
fn core_modules_import_only_from_layers_below() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("core/src");
    let files = rust_files(&src);
    let mut checked = 0;
    let mut bad = vec![];
    for f in &files {
        let rel = f.strip_prefix(&src).expect("under core/src");
        let first = rel.components().next().expect("component");
        let module = first
            .as_os_str()
            .to_str()
            .expect("utf-8")
            .trim_end_matches(".rs");
        if module == "lib" {
            continue; // the crate root re-exports every layer
        }
        let from = layer(module);
        let text = std::fs::read_to_string(f).expect("read");
        for target in crate_refs(&text) {
            if target == module {
                continue;
            }
            checked += 1;
            // Items re-exported at the crate root (`crate::Hit`) name no module: look up where
            // they live is not needed, since the root only re-exports; forbid them instead.
            let Some(to) = LAYERS.iter().position(|l| l.contains(&target.as_str())) else {
                bad.push(format!("{}: `crate::{target}` is not a layer module (import from the module, not the root)", rel.display()));
                continue;
            };
            if to >= from {
                bad.push(format!(
                    "{}: `{module}` (layer {from}) imports `{target}` (layer {to})",
                    rel.display()
                ));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "imports against the layering:\n{}",
        bad.join("\n")
    );
    assert!(checked > 50, "only {checked} imports seen");
}

/// `octoray-packet`'s layers on top of the core: ray slices against primitive slices
/// (`slices.rs`) beside the walks of one tree (`tree/`), and the scene's walks (`scene/`) on the
/// tree's. Each imports only itself and the layers it builds on (`PACKET_LAYERS`); the crate
/// root only declares them.
const PACKET_LAYERS: &[(&str, &[&str])] = &[("slices", &[]), ("tree", &[]), ("scene", &["tree"])];

#[test]
fn packet_layers_import_only_downwards() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("packet/src");
    for f in rust_files(&src) {
        let rel = f.strip_prefix(&src).expect("under packet/src");
        let module = rel
            .components()
            .next()
            .expect("component")
            .as_os_str()
            .to_str()
            .expect("utf-8")
            .trim_end_matches(".rs")
            .to_string();
        let text = std::fs::read_to_string(&f).expect("read");
        let below = PACKET_LAYERS
            .iter()
            .find(|(m, _)| *m == module)
            .map(|(_, below)| *below);
        assert!(
            module == "lib" || below.is_some(),
            "packet/src/{}: `{module}` is in no layer: add it to PACKET_LAYERS",
            rel.display()
        );
        for target in crate_refs(&text) {
            assert!(
                module == "lib"
                    || target == module
                    || below.unwrap_or(&[]).contains(&target.as_str()),
                "{}: `{module}` imports `crate::{target}`",
                rel.display()
            );
        }
        if module != "lib" {
            assert!(
                text.contains("octoray_core::"),
                "{}: builds on octoray-core",
                rel.display()
            );
        }
    }
    assert!(rust_files(&src).len() >= 4, "packet/src has its layers");
}

/// The files of `packet/src/tree/`, each with the files it may import (`super::…`): from the slab
/// test and the best-hit record up through the leaf, the single-ray walk, the packet walk and the
/// slice loops to the calls. A cycle between them cannot return.
const TREE_LAYERS: &[(&str, &[&str])] = &[
    ("slab", &[]),
    ("epilog", &[]),
    ("leaf", &["epilog"]),
    ("single", &["epilog", "leaf", "slab"]),
    ("packet", &["epilog", "leaf", "slab", "single"]),
    ("batch", &["epilog", "packet", "single"]),
    ("queries", &["epilog", "leaf", "packet", "single", "batch"]),
    ("all_hits", &["queries"]),
    ("point", &["all_hits"]),
    ("region", &["all_hits"]),
    ("solid", &["all_hits", "point"]),
    ("winding", &[]),
    ("box_test", &["slab"]),
];

/// The modules `super::` names in `src` (outside comments).
fn super_refs(src: &str) -> Vec<String> {
    crate_refs(&src.replace("super::", "crate::"))
}

#[test]
fn tree_files_import_only_files_below() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("packet/src/tree");
    let mut seen = 0;
    for f in rust_files(&dir) {
        let name = f.file_stem().and_then(|s| s.to_str()).expect("utf-8");
        let text = std::fs::read_to_string(&f).expect("read");
        if name == "mod" {
            assert!(
                super_refs(&text).is_empty(),
                "packet/src/tree/mod.rs only declares the files"
            );
            continue;
        }
        let below = TREE_LAYERS
            .iter()
            .find(|(m, _)| *m == name)
            .map(|(_, b)| *b)
            .unwrap_or_else(|| {
                panic!("packet/src/tree/{name}.rs is in no layer: add it to TREE_LAYERS")
            });
        for target in super_refs(&text) {
            assert!(
                below.contains(&target.as_str()),
                "packet/src/tree/{name}.rs imports `super::{target}`"
            );
        }
        seen += 1;
    }
    assert_eq!(seen, TREE_LAYERS.len(), "every layer is a file");
}

/// The parser sees through groups and skips comments.
#[test]
fn crate_refs_reads_groups_and_skips_comments() {
    let refs = crate_refs(
        "use crate::{lanes::V3, prim::Ray};\n// crate::bvh\nlet x = crate::hit::Hit; // crate::query",
    );
    assert_eq!(refs, ["lanes", "prim", "hit"]);
}
