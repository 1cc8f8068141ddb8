//! `vitreous study analyze --plot`: the scale values in the paper's style (its Fig. 6 and
//! Fig. 13): one horizontal psychological-scale axis per stimulus, each condition marked on it
//! and labelled, and for ratings the yardsticks Y(0.05) and Y(0.01) drawn to the same scale.

use std::fmt;

use anyhow::{Result, anyhow};
use plotters::prelude::*;

use vitreous_study::report::{Analysis, StudyReport};

/// Width of the figure, pixels.
const WIDTH_PX: u32 = 1200;
/// Height of one stimulus's axis row, pixels.
const ROW_PX: u32 = 170;
/// Left and right margins of every axis, pixels.
const MARGIN_PX: i32 = 80;
/// Colour of the condition marks.
const MARK: RGBColor = RGBColor(200, 30, 30);

/// Where a condition was marked, for checks of the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// The stimulus row (0 from the top).
    pub row: usize,
    /// The condition.
    pub condition: String,
    /// Its scale value.
    pub value: f64,
    /// Column of the mark, pixels.
    pub x_px: i32,
    /// Row of the axis line, pixels.
    pub y_px: i32,
}

/// The figure as PNG bytes.
pub fn plot(report: &StudyReport) -> Result<Vec<u8>> {
    let (rgba, w, h, _) = draw(report)?;
    vitreous_frames::output::encode_png(&rgba, w, h)
}

/// The figure as RGBA pixels (width, height) and where each condition was marked.
pub fn draw(report: &StudyReport) -> Result<(Vec<u8>, u32, u32, Vec<Mark>)> {
    crate::font::register_plot_font()?;
    let (w, h) = (WIDTH_PX, ROW_PX * report.groups.len().max(1) as u32);
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    let mut marks = Vec::new();
    {
        let draw_err = |e: &dyn fmt::Display| anyhow!("drawing the study plot: {e}");
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&e))?;
        let font = |size: i32| ("sans-serif", size).into_font().color(&BLACK);
        for (row, (name, analysis)) in report.groups.iter().enumerate() {
            let (conditions, scale, yardsticks, method) = match analysis {
                Analysis::CaseV(r) => (&r.conditions, &r.scale, None, "Thurstone Case V"),
                Analysis::Scheffe(r) => (&r.conditions, &r.scale, r.yardsticks, "Scheffe (Nakaya)"),
            };
            let top = row as i32 * ROW_PX as i32;
            let axis_y = top + 95;
            let low = scale.iter().copied().fold(f64::INFINITY, f64::min);
            let high = scale.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            // A span of at least 0.5 units, with a tenth of margin on each side.
            let centre = (low + high) / 2.0;
            let half = ((high - low) / 2.0).max(0.25) * 1.1;
            let (from, to) = (centre - half, centre + half);
            let x_of = |v: f64| {
                MARGIN_PX
                    + ((v - from) / (to - from) * f64::from(w as i32 - 2 * MARGIN_PX)).round()
                        as i32
            };
            let title = if name.is_empty() {
                format!("psychological scale ({method})")
            } else {
                format!("{name}: psychological scale ({method})")
            };
            root.draw(&Text::new(title, (MARGIN_PX, top + 12), font(16)))
                .map_err(|e| draw_err(&e))?;
            root.draw(&PathElement::new(
                vec![(MARGIN_PX, axis_y), (w as i32 - MARGIN_PX, axis_y)],
                BLACK,
            ))
            .map_err(|e| draw_err(&e))?;
            // Ticks every 0.1 or 0.5 units, labelled at whole halves.
            let step = if to - from > 3.0 { 0.5 } else { 0.1 };
            let mut tick = (from / step).ceil() * step;
            while tick <= to {
                let x = x_of(tick);
                let major = (tick / 0.5).round() * 0.5 - tick;
                let len = if major.abs() < 1e-9 { 8 } else { 4 };
                root.draw(&PathElement::new(
                    vec![(x, axis_y), (x, axis_y + len)],
                    BLACK,
                ))
                .map_err(|e| draw_err(&e))?;
                if major.abs() < 1e-9 {
                    // No "-0.0" where rounding leaves a negative zero.
                    let shown = if tick.abs() < 1e-9 { 0.0 } else { tick };
                    root.draw(&Text::new(
                        format!("{shown:.1}"),
                        (x - 10, axis_y + 12),
                        font(12),
                    ))
                    .map_err(|e| draw_err(&e))?;
                }
                tick += step;
            }
            // Marks, with labels staggered up so that close conditions stay readable.
            let mut order: Vec<usize> = (0..scale.len()).collect();
            order.sort_by(|&a, &b| scale[a].total_cmp(&scale[b]));
            let mut last_x: Option<i32> = None;
            let mut level = 0;
            for i in order {
                let x = x_of(scale[i]);
                level = match last_x {
                    Some(last) if x - last < 70 => (level + 1) % 3,
                    _ => 0,
                };
                last_x = Some(x);
                root.draw(&Rectangle::new(
                    [(x - 1, axis_y - 14), (x + 1, axis_y)],
                    MARK.filled(),
                ))
                .map_err(|e| draw_err(&e))?;
                root.draw(&Circle::new((x, axis_y - 14), 4, MARK.filled()))
                    .map_err(|e| draw_err(&e))?;
                root.draw(&Text::new(
                    format!("{} ({:.3})", conditions[i], scale[i]),
                    (x - 20, axis_y - 36 - 16 * level),
                    font(13),
                ))
                .map_err(|e| draw_err(&e))?;
                marks.push(Mark {
                    row,
                    condition: conditions[i].clone(),
                    value: scale[i],
                    x_px: x,
                    y_px: axis_y,
                });
            }
            if let Some([y05, y01]) = yardsticks {
                for (k, (label, y)) in [("Y(0.05)", y05), ("Y(0.01)", y01)].iter().enumerate() {
                    let y_px = axis_y + 34 + 14 * k as i32;
                    let x0 = MARGIN_PX;
                    let x1 = x0 + (x_of(from + y) - MARGIN_PX).max(1);
                    root.draw(&PathElement::new(vec![(x0, y_px), (x1, y_px)], BLACK))
                        .map_err(|e| draw_err(&e))?;
                    root.draw(&Text::new(
                        format!("{label} = {y:.4}"),
                        (x1 + 8, y_px - 6),
                        font(12),
                    ))
                    .map_err(|e| draw_err(&e))?;
                }
            }
        }
        root.present().map_err(|e| draw_err(&e))?;
    }
    let rgba = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    Ok((rgba, w, h, marks))
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_study::thurstone::case_v;

    #[test]
    fn each_condition_is_marked_in_scale_order_at_its_place() {
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let counts = vec![vec![0, 3, 1], vec![7, 0, 4], vec![9, 6, 0]];
        let report = StudyReport {
            groups: vec![("sphere".into(), Analysis::CaseV(case_v(names, counts)))],
        };
        let (rgba, w, _, marks) = draw(&report).unwrap();
        assert_eq!(marks.len(), 3);
        // Marks are left to right in scale order, proportionally spaced.
        let (a, b, c) = (&marks[0], &marks[1], &marks[2]);
        assert!(a.x_px < b.x_px && b.x_px < c.x_px, "{marks:?}");
        let ratio = f64::from(c.x_px - b.x_px) / f64::from(b.x_px - a.x_px);
        let want = (c.value - b.value) / (b.value - a.value);
        assert!(
            (ratio - want).abs() < 0.05 * want.max(1.0),
            "{ratio} vs {want}"
        );
        // Each mark is drawn in its colour just above the axis.
        for m in &marks {
            let at = ((m.y_px - 8) as u32 * w + m.x_px as u32) as usize * 4;
            assert_eq!(&rgba[at..at + 3], &[MARK.0, MARK.1, MARK.2], "{m:?}");
        }
        assert!(plot(&report).unwrap().starts_with(b"\x89PNG"));
    }
}
