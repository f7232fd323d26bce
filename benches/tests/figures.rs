//! Measured per-test figures live in one place, `benches/tradeoff.md` (written by the report
//! binary). This test fails when a copy or a quote of it drifts: the README's table must be the
//! report's text, every `` <value> (report: `<row>`, <column>) `` quote in the README, the crate
//! READMEs and the library's rustdoc must equal the report's cell, and the chart must carry every
//! row of the report.

use octoray_benches::kernel::report::{self, prose, quotes, Report};
use octoray_testkit::rust_files;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The text of `file` between `<!-- {name}:begin -->` and `<!-- {name}:end -->`.
fn marked(file: &str, name: &str) -> String {
    let text = std::fs::read_to_string(root().join(file)).expect("read");
    let (start, end) = (
        format!("<!-- {name}:begin -->\n"),
        format!("<!-- {name}:end -->"),
    );
    let a = text
        .find(&start)
        .unwrap_or_else(|| panic!("{file} has the {name} start marker"))
        + start.len();
    let b = text[a..]
        .find(&end)
        .unwrap_or_else(|| panic!("{file} has the {name} end marker"))
        + a;
    text[a..b].to_string()
}

#[test]
fn readme_table_is_the_report() {
    let md = std::fs::read_to_string(report::path()).expect("tradeoff.md");
    let doc = std::fs::read_to_string(root().join("docs/speed.md")).expect("docs/speed.md");
    let (start, end) = ("<!-- tradeoff:start -->\n", "<!-- tradeoff:end -->");
    let a = doc.find(start).expect("docs/speed.md has the start marker") + start.len();
    let b = doc.find(end).expect("docs/speed.md has the end marker");
    assert_eq!(
        &doc[a..b],
        md,
        "docs/speed.md's table differs from benches/tradeoff.md: rerun the report"
    );
}

#[test]
fn readme_scene_rows_are_the_scene_report() {
    // The README's scene table is a selection of Sponza's rows in `benches/scenes.md`, copied
    // verbatim: every row must be one of the report's Sponza rows.
    let md = std::fs::read_to_string(root().join("benches/scenes.md")).expect("scenes.md");
    let sponza = &md[md.find("### Sponza").expect("Sponza section")..];
    let sponza = &sponza[..sponza.find("\n### ").unwrap_or(sponza.len())];
    for file in ["README.md", "docs/scenes.md"] {
        let block = marked(file, "scenes");
        let rows: Vec<&str> = block.lines().skip(2).collect();
        assert!(
            rows.len() >= 8,
            "{file}'s scene table has {} rows",
            rows.len()
        );
        for row in rows {
            assert!(
                sponza.lines().any(|l| l == row),
                "{file}: scene row not in benches/scenes.md's Sponza section (rerun and copy): {row}"
            );
        }
    }
}

#[test]
fn scene_chart_covers_every_scene_of_the_report() {
    // `benches/scenes.svg` is drawn by the same run as `benches/scenes.md`: a panel per scene
    // section ("### <name> (<n> triangles; ..."), each named by its caption.
    let md = std::fs::read_to_string(root().join("benches/scenes.md")).expect("scenes.md");
    let svg = std::fs::read_to_string(root().join("benches/scenes.svg")).expect("scenes.svg");
    let scenes: Vec<&str> = md
        .lines()
        .filter_map(|l| l.strip_prefix("### "))
        .filter(|l| l.contains(" triangles; "))
        .filter_map(|l| l.split(" (").next())
        .collect();
    assert!(scenes.len() >= 6, "scene sections: {scenes:?}");
    for name in scenes {
        assert!(
            svg.lines().any(|l| l.trim() == name),
            "benches/scenes.svg has no panel for {name}: rerun the scene report"
        );
    }
    assert!(
        marked("README.md", "scenes-chart").contains("benches/scenes.svg"),
        "the README shows the scene chart"
    );
}

#[test]
fn readme_microcontroller_figures_are_the_report() {
    // The README's Cortex-M table is the block `bash .ci/cortex-m.sh --report` writes.
    let report = marked("benches/cortex-m.md", "cortex-m");
    assert!(report.lines().count() >= 6, "{report}");
    assert_eq!(
        marked("README.md", "cortex-m"),
        report,
        "README.md's Cortex-M table differs from benches/cortex-m.md: copy the report's block"
    );
}

#[test]
fn quoted_figures_equal_the_report() {
    let r = Report::load().expect("benches/tradeoff.md parses");
    let mut files = vec![
        root().join("README.md"),
        root().join("core/README.md"),
        root().join("packet/README.md"),
    ];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    assert!(docs.len() >= 5, "{docs:?}");
    files.extend(docs);
    for dir in ["core/src", "packet/src", "src"] {
        files.extend(rust_files(&root().join(dir)));
    }
    let mut checked = 0;
    let mut bad = vec![];
    for f in &files {
        let text = std::fs::read_to_string(f).expect("read");
        for q in quotes(&prose(&text)) {
            match r.cell(&q.row, &q.column) {
                Some(cell) if cell == q.value => checked += 1,
                Some(cell) => bad.push(format!(
                    "{}: quotes {} for `{}`, {}; the report says {cell}",
                    f.display(),
                    q.value,
                    q.row,
                    q.column
                )),
                None => bad.push(format!(
                    "{}: quotes `{}`, {}, which the report does not have",
                    f.display(),
                    q.row,
                    q.column
                )),
            }
        }
    }
    assert!(
        bad.is_empty(),
        "figures drifted from the report:\n{}",
        bad.join("\n")
    );
    // The README's accuracy table and the kernels' contracts quote the report's crack rates.
    assert!(checked >= 6, "only {checked} quotes found");
}

#[test]
fn chart_shows_every_row_of_the_report() {
    let r = Report::load().expect("benches/tradeoff.md parses");
    let svg = std::fs::read_to_string(root().join("benches/tradeoff.svg")).expect("svg");
    for row in &r.rows {
        let name = row[0].trim_start_matches("peer: ");
        assert!(
            svg.contains(name),
            "the chart has no `{name}`: redraw it (`--chart`)"
        );
    }
}

#[test]
fn every_missed_target_is_counted() {
    // `benches/counts.md` (`profile --report`) bounds every target `benches/scenes.md` shows
    // missed with both rows' counts per ray: a missed target without counts means the counts
    // report is older than the scene report.
    use octoray_benches::scene::counts::{reported_ratio, SCENES};
    use octoray_benches::scene::targets::TARGETS;
    let scenes = std::fs::read_to_string(root().join("benches/scenes.md")).expect("scenes.md");
    let counts = std::fs::read_to_string(root().join("benches/counts.md")).expect("counts.md");
    let mut missed = 0;
    for (key, name) in SCENES {
        for t in TARGETS {
            let ratio = reported_ratio(&scenes, name, t)
                .unwrap_or_else(|| panic!("scenes.md has no ratio for {name}: {}", t.what));
            if ratio >= t.ratio {
                continue;
            }
            missed += 1;
            let head = format!("| {name} | {} | {ratio:.2}× | ", t.what);
            let line = counts
                .lines()
                .find(|l| l.starts_with(&head))
                .unwrap_or_else(|| {
                    panic!("counts.md does not bound `{head}`: rerun `profile --report`")
                });
            // A row left uncounted names why in the report's header.
            assert!(
                !line.contains("not counted") || counts.contains(&format!("Not counted: {key} ")),
                "counts.md has no counts for `{head}` and says not why"
            );
        }
    }
    assert!(missed > 0, "no missed target found");
}

#[test]
fn quoted_counts_are_the_counts_report() {
    // docs/scenes.md's per-ray counts are lines of `benches/counts.md`, copied verbatim.
    let counts = std::fs::read_to_string(root().join("benches/counts.md")).expect("counts.md");
    let block = marked("docs/scenes.md", "counts");
    let rows: Vec<&str> = block
        .lines()
        .filter(|l| l.starts_with("| "))
        .skip(1)
        .collect();
    assert!(
        rows.len() >= 8,
        "docs/scenes.md quotes {} count rows",
        rows.len()
    );
    for line in block
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("|---"))
    {
        if line.starts_with("| scene |") || line.starts_with("| rays |") {
            continue;
        }
        assert!(
            counts.lines().any(|l| l == line),
            "docs/scenes.md: not a line of benches/counts.md (rerun and copy): {line}"
        );
    }
}
