//! The scene report's chart (`benches/scenes.svg`): per scene, the speed of each system on the
//! main rows relative to Embree 3 robust in the same run (1 = as fast; above is faster).

use crate::scene::row::{Query, RaySet, Row, System, Tier, Traversal};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::collections::HashMap;

/// One scene's rows: Mrays/s per row measured.
pub type Rates = HashMap<Row, f64>;

/// The systems drawn: label, colour, system.
const SERIES: [(&str, RGBColor, System); 5] = [
    (
        "octoray watertight",
        RGBColor(31, 119, 180),
        System::Octoray(Tier::Watertight),
    ),
    (
        "octoray watertight, spatial splits",
        RGBColor(23, 190, 207),
        System::Octoray(Tier::Spatial),
    ),
    (
        "Embree 3 fast",
        RGBColor(214, 39, 40),
        System::Embree { robust: false },
    ),
    (
        "tinybvh BVH8_CPU, BuildHQ",
        RGBColor(255, 127, 14),
        System::TinyBvh { hq: true },
    ),
    ("obvhs CWBVH", RGBColor(44, 160, 44), System::Obvhs),
];

/// The rows drawn: a label, the rays, the query and the traversal (a system without that row
/// has no bar).
const ROWS: [(&str, RaySet, Query, Traversal); 5] = [
    (
        "primary packet-8",
        RaySet::Primary,
        Query::Closest,
        Traversal::Packet8,
    ),
    (
        "primary single",
        RaySet::Primary,
        Query::Closest,
        Traversal::Single,
    ),
    (
        "camera 2 single",
        RaySet::Camera2,
        Query::Closest,
        Traversal::Single,
    ),
    (
        "bounce single",
        RaySet::Bounce,
        Query::Closest,
        Traversal::Single,
    ),
    (
        "shadow single",
        RaySet::Shadow,
        Query::Any,
        Traversal::Single,
    ),
];

/// Speed of `system` on the row `(rays, query, traversal)` relative to Embree 3 robust, where
/// both rows were measured.
fn ratio(
    rates: &Rates,
    (_, rays, query, traversal): (&str, RaySet, Query, Traversal),
    system: System,
) -> Option<f64> {
    let own = rates.get(&Row::new(rays, query, traversal, system))?;
    let robust = rates.get(&Row::new(
        rays,
        query,
        traversal,
        System::Embree { robust: true },
    ))?;
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
            .flat_map(|&row| SERIES.iter().filter_map(move |s| ratio(rates, row, s.2)))
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
        for (k, &row) in ROWS.iter().enumerate() {
            for (s, &(_, colour, system)) in SERIES.iter().enumerate() {
                if let Some(r) = ratio(rates, row, system) {
                    let x0 = k as f64 + 0.1 + w * s as f64;
                    c.draw_series(std::iter::once(Rectangle::new(
                        [(x0, 0.0), (x0 + w * 0.9, r)],
                        colour.filled(),
                    )))
                    .map_err(|e| err(&e))?;
                }
            }
            // Two lines under the group: the rays, then the traversal.
            let (rays, how) = row.0.split_once(' ').unwrap_or((row.0, ""));
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
    for (s, (label, colour, _)) in SERIES.iter().enumerate() {
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
