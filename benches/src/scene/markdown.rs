//! The scene report's markdown (`benches/scenes.md`): a measured [`Section`] written as its
//! heading, build line, table of rows, builds line and targets table.

use super::chart::Rates;
use super::row::{Query, Row, System, Tier};
use super::section::Section;
use super::targets::TARGETS;
use std::fmt::Write as _;

/// Writes one scene's section.
pub fn section(md: &mut String, s: &Section) {
    heading(md, s);
    rows(md, s);
    for line in &s.skipped {
        writeln!(md, "{line}").unwrap();
    }
    builds(md, s);
    targets(md, &s.rates());
}

/// The heading and the watertight tree's build line.
fn heading(md: &mut String, s: &Section) {
    let [primary, bounce, shadow] = s.rays;
    writeln!(
        md,
        "\n### {} ({} triangles; {primary} primary rays at 1024×768 from each of two cameras, {bounce} diffuse-bounce rays and {shadow} shadow rays from the first camera's hits)\n",
        s.name, s.triangles
    )
    .unwrap();
    let (st, t) = (&s.stats, &s.times);
    writeln!(
        md,
        "Build (1 thread): **{:.3} s** ({} threads, rayon: {:.3} s); {} nodes, {} leaves, depth {}, SAH cost {:.1}, {:.0} bytes per triangle (watertight layout, SoA blocks of 8, {:.0} % of block slots filled). Validating the stored tree as untrusted slices (`Bvh8Ref::new`): {:.2} ms.\n",
        t.one,
        rayon::current_num_threads(),
        t.all,
        st.nodes,
        st.leaves,
        st.depth,
        st.sah_cost,
        st.bytes_per_prim,
        100.0 * st.block_fill,
        t.validate * 1e3
    )
    .unwrap();
}

/// The table: every row measured, then the rows on all threads.
fn rows(md: &mut String, s: &Section) {
    md.push_str("| rays | query | traversal | tier or peer | Mrays/s, 1 thread | hits |\n");
    md.push_str("|---|---|---|---|---|---|\n");
    for m in &s.rows {
        let [rays, q, how, tier] = m.row.cells();
        writeln!(
            md,
            "| {rays} | {q} | {how} | {tier} | {:.2} | {} |",
            m.mrays, m.hits
        )
        .unwrap();
    }
    for t in &s.threaded {
        let row = Row::new(
            t.rays,
            Query::Closest,
            t.traversal,
            System::Octoray(Tier::Watertight),
        );
        let [rays, q, how, tier] = row.cells();
        let n = t.threads;
        writeln!(
            md,
            "| {rays} | {q} | {how}, {n} threads (rayon) | {tier} | {:.2} ({n} threads) | |",
            t.mrays
        )
        .unwrap();
    }
}

/// The builds line: spatial splits' and the peers' build times beside octoray's binned build.
fn builds(md: &mut String, s: &Section) {
    let line: Vec<String> = s
        .builds
        .iter()
        .map(|(n, t)| format!("{n} {t:.3} s"))
        .collect();
    let (node, leaf, blocks) = s.sah;
    writeln!(
        md,
        "\nPeers' builds (1 thread, but tinybvh's `BuildHQ`, which runs subtrees as jobs on every core): {}; octoray {:.3} s (SAH cost {:.1} = {node:.1} node + {leaf:.1} leaf; in blocks of 8: {:.1}). SAH costs: 1 per node visit and 1 per primitive test (\"in blocks of 8\": 1 per leaf block of up to 8, what one octoray leaf test costs), relative to the scene's box.",
        line.join(", "),
        s.times.one,
        s.stats.sah_cost,
        node + blocks
    )
    .unwrap();
}

/// Every target's ratio in this scene ("n/a" where a row was not measured).
fn targets(md: &mut String, rates: &Rates) {
    md.push_str("\n| target (1 thread) | octoray row | peer row | ratio |\n|---|---|---|---|\n");
    for t in TARGETS {
        let ratio = match (rates.get(&t.octoray), rates.get(&t.peer)) {
            (Some(x), Some(y)) => format!("{:.2}×", x / y),
            _ => "n/a".into(),
        };
        writeln!(md, "| {} | {} | {} | {ratio} |", t.what, t.octoray, t.peer).unwrap();
    }
}
