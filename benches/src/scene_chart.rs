//! The scene report's chart (`benches/scenes.svg`): per scene, the speed of each system on the
//! main rows relative to Embree 3 robust in the same run (1 = as fast; above is faster).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::collections::HashMap;

/// One scene's rows: `"rays|query|traversal|tier or peer"` → Mrays/s.
pub type Rates = HashMap<String, f64>;

/// Which of a row's `rays|query|traversal` columns ([`ROWS`]) a system's rows use.
#[derive(Clone, Copy)]
enum Kind {
    Octoray = 0,
    Embree = 1,
    TinyBvh = 2,
    Obvhs = 3,
}

/// The systems drawn: label, colour, the tier-or-peer column of its rows, and its kind of row.
const SERIES: [(&str, RGBColor, &str, Kind); 5] = [
    (
        "octoray watertight",
        RGBColor(31, 119, 180),
        "watertight",
        Kind::Octoray,
    ),
    (
        "octoray watertight, spatial splits",
        RGBColor(23, 190, 207),
        "watertight, spatial splits",
        Kind::Octoray,
    ),
    (
        "Embree 3 fast",
        RGBColor(214, 39, 40),
        "Embree 3 fast",
        Kind::Embree,
    ),
    (
        "tinybvh BVH8_CPU, BuildHQ",
        RGBColor(255, 127, 14),
        "tinybvh 1.6.8 (BVH8_CPU, BuildHQ: spatial splits)",
        Kind::TinyBvh,
    ),
    (
        "obvhs CWBVH",
        RGBColor(44, 160, 44),
        "obvhs 0.4 (CWBVH)",
        Kind::Obvhs,
    ),
];

/// The rows drawn: a label, then per [`Kind`] the `rays|query|traversal` of its row (empty where
/// the system has no such row).
const ROWS: [(&str, [&str; 4]); 5] = [
    (
        "primary packet-8",
        [
            "primary|closest|packet-8 (4×2 tiles)",
            "primary|closest|packet-8 (rtcIntersect8)",
            "",
            "",
        ],
    ),
    (
        "primary single",
        [
            "primary|closest|single ray (leaves ×8)",
            "primary|closest|single ray (rtcIntersect1)",
            "primary|closest|single ray",
            "primary|closest|single ray",
        ],
    ),
    (
        "camera 2 single",
        [
            "primary (camera 2)|closest|single ray",
            "primary (camera 2)|closest|single ray (rtcIntersect1)",
            "primary (camera 2)|closest|single ray",
            "primary (camera 2)|closest|single ray",
        ],
    ),
    (
        "bounce single",
        [
            "diffuse bounce|closest|single ray",
            "diffuse bounce|closest|single ray (rtcIntersect1)",
            "diffuse bounce|closest|single ray",
            "diffuse bounce|closest|single ray",
        ],
    ),
    (
        "shadow single",
        [
            "shadow|any|single ray",
            "shadow|any|single ray (rtcOccluded1)",
            "shadow|closest (no occlusion query)|single ray",
            "shadow|any|single ray",
        ],
    ),
];

/// Speed of `series` (an index into [`SERIES`]) on `row` relative to Embree 3 robust, where both
/// rows were measured.
fn ratio(rates: &Rates, row: &[&str; 4], series: usize) -> Option<f64> {
    let (_, _, column, kind) = SERIES[series];
    let kind = kind as usize;
    if row[kind].is_empty() {
        return None;
    }
    let own = rates.get(&format!("{}|{}", row[kind], column))?;
    let robust = rates.get(&format!("{}|Embree 3 robust", row[1]))?;
    Some(own / robust)
}

/// Draws one panel per scene, side by side in rows of three, to `path` (SVG).
pub fn draw(scenes: &[(String, Rates)], machine: &str, path: &str) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let cols = 3usize;
    let panels = scenes.len().max(1);
    let rows = panels.div_ceil(cols);
    let (pw, ph) = (420u32, 300u32);
    let root = SVGBackend::new(path, (pw * cols as u32, ph * rows as u32 + 90)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (title, rest) = root.split_vertically(40);
    let (body, legend) = rest.split_vertically(ph * rows as u32);
    title
        .draw(&Text::new(
            format!("speed relative to Embree 3 robust, same rays, one thread ({machine})"),
            ((pw * cols as u32 / 2) as i32, 20),
            ("sans-serif", 16)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(|e| err(&e))?;
    let areas = body.split_evenly((rows, cols));
    for ((name, rates), area) in scenes.iter().zip(areas) {
        let top = ROWS
            .iter()
            .flat_map(|(_, row)| (0..SERIES.len()).filter_map(|s| ratio(rates, row, s)))
            .fold(1.5f64, f64::max)
            * 1.1;
        let mut c = ChartBuilder::on(&area)
            .caption(name, ("sans-serif", 14))
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(36)
            .build_cartesian_2d(0f64..ROWS.len() as f64, 0f64..top)
            .map_err(|e| err(&e))?;
        c.configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .y_labels(6)
            .y_label_formatter(&|y| format!("{y:.1}"))
            .light_line_style(WHITE)
            .draw()
            .map_err(|e| err(&e))?;
        // Embree 3 robust itself: the line at 1.
        c.draw_series(LineSeries::new(
            [(0.0, 1.0), (ROWS.len() as f64, 1.0)],
            ShapeStyle::from(&BLACK.mix(0.7)).stroke_width(1),
        ))
        .map_err(|e| err(&e))?;
        let w = 0.8 / SERIES.len() as f64;
        for (k, (label, row)) in ROWS.iter().enumerate() {
            for (s, (_, colour, _, _)) in SERIES.iter().enumerate() {
                if let Some(r) = ratio(rates, row, s) {
                    let x0 = k as f64 + 0.1 + w * s as f64;
                    c.draw_series(std::iter::once(Rectangle::new(
                        [(x0, 0.0), (x0 + w * 0.9, r)],
                        colour.filled(),
                    )))
                    .map_err(|e| err(&e))?;
                }
            }
            // Two lines under the group: the rays, then the traversal.
            let (rays, how) = label.split_once(' ').unwrap_or((label, ""));
            let (x, y) = c.backend_coord(&(k as f64 + 0.5, 0.0));
            for (i, line) in [rays, how].into_iter().enumerate() {
                area.draw(&Text::new(
                    line,
                    (
                        x - area.get_base_pixel().0,
                        y - area.get_base_pixel().1 + 4 + 12 * i as i32,
                    ),
                    ("sans-serif", 11)
                        .into_font()
                        .color(&BLACK)
                        .pos(Pos::new(HPos::Center, VPos::Top)),
                ))
                .map_err(|e| err(&e))?;
            }
        }
    }
    let step = (pw * cols as u32) as i32 / SERIES.len() as i32;
    for (s, (label, colour, _, _)) in SERIES.iter().enumerate() {
        let x = 12 + step * s as i32;
        legend
            .draw(&Rectangle::new([(x, 18), (x + 14, 32)], colour.filled()))
            .map_err(|e| err(&e))?;
        legend
            .draw(&Text::new(
                *label,
                (x + 20, 25),
                ("sans-serif", 12)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
