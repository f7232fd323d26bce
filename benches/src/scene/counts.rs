//! The counts report: instructions, branches, mispredicted branches and cache misses per ray of
//! the scene report's rows, counted by callgrind over the traversal alone, and for every speed
//! target the scene report shows missed, both rows' counts side by side (`benches/counts.md`,
//! written by `profile --report`).

use crate::scene::row::{Query, RaySet, Row, System, Tier, Traversal};
use crate::scene::targets::{Target, TARGETS};
use std::fmt::Write as _;

/// The scenes, as `profile` names them, with their section names in `benches/scenes.md`.
pub const SCENES: [(&str, &str); 6] = [
    ("sponza", "Sponza"),
    ("sphere", "jittered sphere"),
    ("city", "city"),
    ("terrain", "terrain"),
    ("scanned", "scanned mesh in a room"),
    ("open", "open field"),
];

/// The systems `profile` runs, by the name `profile` takes.
pub const SYSTEMS: [(&str, System); 6] = [
    ("watertight", System::Octoray(Tier::Watertight)),
    ("spatial", System::Octoray(Tier::Spatial)),
    ("standard", System::Octoray(Tier::Standard)),
    ("embree-robust", System::Embree { robust: true }),
    ("tinybvh", System::TinyBvh { hq: true }),
    ("obvhs", System::Obvhs),
];

/// The rows `profile <scene> all <system>` runs, in order: ray set and packets of 8.
pub fn rows(system: &str) -> Vec<(&'static str, bool)> {
    let single = |r: &[&'static str]| r.iter().map(|&r| (r, false)).collect();
    match system {
        "tinybvh" => single(&["primary", "camera2", "bounce", "shadow"]),
        "obvhs" => single(&["primary", "camera2", "bounce", "primary-any", "shadow"]),
        _ => {
            let mut v: Vec<_> = single(&["primary", "camera2", "bounce", "primary-any", "shadow"]);
            v.extend([("primary", true), ("camera2", true)]);
            v
        }
    }
}

/// `profile`'s arguments for a scene report row: ray set, system and packets of 8; `None` for a
/// row `profile` does not run.
pub fn profile_args(row: Row) -> Option<(&'static str, &'static str, bool)> {
    let rays = match (row.rays, row.query) {
        (RaySet::Primary, Query::Closest) => "primary",
        (RaySet::Primary, Query::Any) => "primary-any",
        (RaySet::Camera2, Query::Closest) => "camera2",
        (RaySet::Bounce, Query::Closest) => "bounce",
        (RaySet::Shadow, Query::Any) => "shadow",
        _ => return None,
    };
    let packets = match row.traversal {
        Traversal::Packet8 => true,
        Traversal::Single => false,
        Traversal::Packet16 | Traversal::Batch => return None,
    };
    let system = SYSTEMS.iter().find(|(_, s)| *s == row.system)?.0;
    Some((rays, system, packets))
}

/// Event totals of one callgrind profile, for the rays it traced.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counts {
    /// Instructions executed.
    pub instructions: u64,
    /// Conditional branches executed.
    pub branches: u64,
    /// Mispredicted branches, conditional and indirect (callgrind's simulated predictor).
    pub mispredicted: u64,
    /// First-level data cache misses, reads and writes (callgrind's simulated D1).
    pub d1_misses: u64,
    /// Last-level data cache misses, reads and writes.
    pub ll_misses: u64,
}

impl Counts {
    /// The totals of a callgrind output file (its `events:` and `totals:` lines; events it does
    /// not list count 0). `None` when either line is missing.
    pub fn parse(text: &str) -> Option<Self> {
        let events: Vec<&str> = text
            .lines()
            .find_map(|l| l.strip_prefix("events:"))?
            .split_whitespace()
            .collect();
        let totals: Vec<u64> = text
            .lines()
            .find_map(|l| l.strip_prefix("totals:"))?
            .split_whitespace()
            .map(|x| x.parse().ok())
            .collect::<Option<_>>()?;
        let get = |name: &str| {
            events
                .iter()
                .position(|e| *e == name)
                .and_then(|i| totals.get(i))
                .copied()
                .unwrap_or(0)
        };
        Some(Self {
            instructions: get("Ir"),
            branches: get("Bc"),
            mispredicted: get("Bcm") + get("Bim"),
            d1_misses: get("D1mr") + get("D1mw"),
            ll_misses: get("DLmr") + get("DLmw"),
        })
    }
}

/// One counted row: scene, `profile`'s ray set, system and packets, the rays traced and their
/// counts.
#[derive(Clone, Debug)]
pub struct Counted {
    /// The scene, as `profile` names it.
    pub scene: &'static str,
    /// The ray set, as `profile` names it.
    pub rays: &'static str,
    /// The system, as `profile` names it.
    pub system: &'static str,
    /// Packets of 8 (else single rays).
    pub packets: bool,
    /// Rays traced.
    pub n: u64,
    /// Their counts.
    pub counts: Counts,
}

impl Counted {
    /// `x` per ray.
    fn per_ray(&self, x: u64) -> f64 {
        x as f64 / self.n.max(1) as f64
    }
}

/// How the counts report names a ray set.
fn rays_label(rays: &str) -> &str {
    match rays {
        "primary" => "primary, closest",
        "primary-any" => "primary, any",
        "camera2" => "primary (camera 2), closest",
        "bounce" => "diffuse bounce, closest",
        "shadow" => "shadow, any",
        other => other,
    }
}

/// The ratio the scene report printed for `target` in the section of `scene` (`benches/scenes.md`).
pub fn reported_ratio(scenes_md: &str, scene: &str, target: &Target) -> Option<f64> {
    let head = format!("### {scene} (");
    let at = scenes_md.find(&head)?;
    let section = &scenes_md[at + head.len()..];
    let section = &section[..section.find("\n### ").unwrap_or(section.len())];
    let row = format!("| {} |", target.what);
    let line = section.lines().find(|l| l.starts_with(&row))?;
    let cell = line.trim_end_matches('|').rsplit('|').next()?.trim();
    cell.trim_end_matches('×').parse().ok()
}

/// What would move each kind of bound: the design steps the counts point at.
const NEXT_STEPS: &str = "\nWhat the next design step is, by the count that is over the target's share (the breakdown per ray is in `docs/scenes.md`, \"What bounds it\"):\n\n- **Instructions**: about 365 per ray of setup (the box ray and the sheared ray, prepared whole before the first node), the leaf's exact range decision (7-12 % of a ray) and the ordering and pushing of children hit. Next: a single-ray walk whose per-ray state fits in registers (the shear prepared at the first leaf, the reciprocals shared with the box ray), and a leaf layout per tier that hoists the shear-independent work out of the test.\n- **Mispredicted branches**: the near-first order of three or more children hit, node visits that find no child hit and entries popped beyond the hit. Next: fewer, wider decisions per visit (tinybvh's one-child and all-children paths without a per-child branch).\n- **D1 misses**: 256-byte nodes, four cache lines a visit. Next: compressed or quantised nodes, measured on the CPU before adopting them.\n- **None**: the counts would allow the target; the time goes to latency (the node test's dependent chain: child index, node load, slab distances, compare, branch; divisions in the setup), not to these counts. Next: more independent work per visit (two rays or two subtrees at once).\n";

/// The report: per scene, every counted row; then every target the scene report shows missed,
/// with both rows' counts per ray and which of them octoray's row exceeds.
pub fn markdown(header: &str, counted: &[Counted], scenes_md: &str) -> String {
    let mut md = String::new();
    md.push_str(header);
    counted_tables(&mut md, counted);
    md.push_str("\n### Missed targets: octoray's row against the peer's, per ray\n\n");
    md.push_str("Every target of `benches/scenes.md` whose ratio there is below the target, with both rows' counts per ray (octoray / peer) and, largest first, the counts where octoray's row has more than the target allows (more than 5 % over the peer's count divided by the target ratio: for \"≥ 1.2× Embree\", above 0.83× Embree's count), each as a multiple of the peer's count.\n\n");
    md.push_str("| scene | target | ratio (scenes.md) | instructions | mispredicted | D1 misses | over the target's share |\n");
    md.push_str("|---|---|---|---|---|---|---|\n");
    let mut tally = Tally::default();
    for (scene, name) in SCENES {
        for t in TARGETS {
            match reported_ratio(scenes_md, name, t) {
                Some(ratio) if ratio < t.ratio => {
                    missed_row(&mut md, &mut tally, counted, (scene, name), t, ratio)
                }
                _ => {}
            }
        }
    }
    md.push_str(NEXT_STEPS);
    let Tally {
        missed,
        by_instr,
        by_branch,
        by_d1,
        by_none,
        uncounted,
    } = tally;
    writeln!(
        md,
        "\n{missed} targets missed; octoray's row is over the target's share of the peer's instructions in {by_instr}, of its mispredicted branches in {by_branch}, of its D1 misses in {by_d1}, and within it on all three in {by_none}; {uncounted} not counted."
    )
    .unwrap();
    md
}

/// Per scene, a table of every counted row.
fn counted_tables(md: &mut String, counted: &[Counted]) {
    for (scene, name) in SCENES {
        let rows: Vec<&Counted> = counted.iter().filter(|c| c.scene == scene).collect();
        if rows.is_empty() {
            continue;
        }
        writeln!(md, "\n### {name}\n").unwrap();
        md.push_str("| rays | traversal | system | instructions | branches | mispredicted | D1 misses | LL misses | rays traced |\n");
        md.push_str("|---|---|---|---|---|---|---|---|---|\n");
        for c in rows {
            let system = SYSTEMS
                .iter()
                .find(|s| s.0 == c.system)
                .map_or(c.system, |s| s.1.label());
            writeln!(
                md,
                "| {} | {} | {system} | {:.0} | {:.0} | {:.2} | {:.2} | {:.3} | {} |",
                if c.system == "tinybvh" && c.rays == "shadow" {
                    "shadow, closest (no occlusion query)"
                } else {
                    rays_label(c.rays)
                },
                if c.packets { "packet-8" } else { "single ray" },
                c.per_ray(c.counts.instructions),
                c.per_ray(c.counts.branches),
                c.per_ray(c.counts.mispredicted),
                c.per_ray(c.counts.d1_misses),
                c.per_ray(c.counts.ll_misses),
                c.n
            )
            .unwrap();
        }
    }
}

/// The missed targets: how many, by which count octoray's row is over the target's share, and
/// how many had no counts.
#[derive(Default)]
struct Tally {
    missed: usize,
    by_instr: usize,
    by_branch: usize,
    by_d1: usize,
    by_none: usize,
    uncounted: usize,
}

/// One missed target's row: both rows' counts per ray and which of octoray's exceed the
/// target's share of the peer's.
fn missed_row(
    md: &mut String,
    tally: &mut Tally,
    counted: &[Counted],
    (scene, name): (&str, &str),
    t: &Target,
    ratio: f64,
) {
    tally.missed += 1;
    let find = |(rays, system, packets): (&str, &str, bool)| {
        counted.iter().find(|c| {
            c.scene == scene && c.rays == rays && c.system == system && c.packets == packets
        })
    };
    let pair = profile_args(t.octoray)
        .and_then(find)
        .zip(profile_args(t.peer).and_then(find));
    let Some((a, b)) = pair else {
        tally.uncounted += 1;
        writeln!(
            md,
            "| {name} | {} | {ratio:.2}× | | | | not counted |",
            t.what
        )
        .unwrap();
        return;
    };
    let per_ray = |f: fn(&Counts) -> u64| (a.per_ray(f(&a.counts)), b.per_ray(f(&b.counts)));
    let cols = [
        ("instructions", per_ray(|c| c.instructions)),
        ("mispredicted branches", per_ray(|c| c.mispredicted)),
        ("D1 misses", per_ray(|c| c.d1_misses)),
    ];
    let mut over: Vec<(&str, f64)> = cols
        .iter()
        .filter(|(_, (own, peer))| *own > 1.05 * peer / t.ratio)
        .map(|&(n, (own, peer))| (n, own / peer.max(1e-9)))
        .collect();
    over.sort_by(|x, y| y.1.total_cmp(&x.1));
    let has = |n: &str| usize::from(over.iter().any(|o| o.0 == n));
    tally.by_instr += has("instructions");
    tally.by_branch += has("mispredicted branches");
    tally.by_d1 += has("D1 misses");
    tally.by_none += usize::from(over.is_empty());
    let more = if over.is_empty() {
        "none: each is within the target's share".to_string()
    } else {
        over.iter()
            .map(|(n, r)| format!("{n} {r:.2}×"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let [(_, i), (_, m), (_, d)] = cols;
    writeln!(
        md,
        "| {name} | {} | {ratio:.2}× | {:.0} / {:.0} | {:.2} / {:.2} | {:.2} / {:.2} | {more} |",
        t.what, i.0, i.1, m.0, m.1, d.0, d.1
    )
    .unwrap();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_callgrind_totals_with_missing_trailing_events() {
        let text = "events: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw Bc Bcm Bi Bim\nsummary: 9\ntotals: 15007 1 0 1 3 2 1 4 5 1001 10\n";
        let c = Counts::parse(text).expect("parses");
        assert_eq!(
            c,
            Counts {
                instructions: 15007,
                branches: 1001,
                mispredicted: 10,
                d1_misses: 5,
                ll_misses: 9,
            }
        );
        assert_eq!(Counts::parse("events: Ir\n"), None);
    }

    #[test]
    fn every_target_row_maps_to_a_profile_row() {
        for t in TARGETS {
            for key in [t.octoray, t.peer] {
                let (rays, system, packets) =
                    profile_args(key).unwrap_or_else(|| panic!("{key} has no profile row"));
                assert!(
                    rows(system).contains(&(rays, packets)),
                    "{key}: profile's all-rows mode of {system} does not run {rays}"
                );
            }
        }
        assert_eq!(
            profile_args(Row::new(
                RaySet::Shadow,
                Query::Any,
                Traversal::Single,
                System::Embree { robust: true }
            )),
            Some(("shadow", "embree-robust", false))
        );
        assert_eq!(
            profile_args(Row::new(
                RaySet::Primary,
                Query::Closest,
                Traversal::Packet16,
                System::Octoray(Tier::Watertight)
            )),
            None
        );
    }

    #[test]
    fn reads_the_ratio_of_a_scene_section() {
        let md = "### A (1 triangles; x)\n| t | o | p | ratio |\n| shadow single ray ≥ 2× obvhs | a | b | 0.80× |\n### B (2 triangles; y)\n| shadow single ray ≥ 2× obvhs | a | b | 2.50× |\n";
        let t = TARGETS
            .iter()
            .find(|t| t.what == "shadow single ray ≥ 2× obvhs")
            .expect("target");
        assert_eq!(reported_ratio(md, "A", t), Some(0.80));
        assert_eq!(reported_ratio(md, "B", t), Some(2.50));
        assert_eq!(reported_ratio(md, "C", t), None);
    }
}
