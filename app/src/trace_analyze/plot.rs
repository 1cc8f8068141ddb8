//! `vitreous trace plot`: raw and filtered fixation depth over time with each filter's
//! gaze-image decisions, drawn as a PNG (like the paper's Fig. 11).
//!
//! Depth is drawn as vergence in dioptres (1 / depth), where the tracker's angular noise is
//! about even and a far fixation stays in view (10 m is 0.1 D); samples whose rays diverge are
//! drawn in a band below 0 D. Fixations (as the `fixation` filter's classifier finds them,
//! at least 60 ms long) are shaded. plotters does not clip to the plotting area, so every
//! value is clamped to the axis range less the marker size and lines are one pixel wide: nothing
//! is drawn outside the chart.

use std::fmt;
use std::path::Path;

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use vitreous_trace::TraceSample;

use super::{Truth, load_inputs, timeline_from_phases};
use vitreous_gaze::analysis::{
    AnalyzeConfig, RawSample, ReplayedFrame, raw_samples, replay, timeline_from_raw_depth,
};
use vitreous_gaze::fixation::{DEFAULT_MIN_FIXATION_MS, DEFAULT_VELOCITY_DEG_S, fixation_spans};
use vitreous_gaze::{FilterKind, GazeImage};

/// `vitreous trace plot TRACE --scene SCENE -o OUT`: see [`plot`].
pub fn plot_trace_file(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
    out_png: &Path,
) -> Result<()> {
    let (samples, config, inputs) = load_inputs(trace, scene, filters)?;
    inputs.check_file("--out", out_png)?;
    plot(&samples, Truth::FromRawDepth, &config, out_png).map(|_| ())
}

/// Where `plot` drew its depth chart, pixels of the PNG.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlotLayout {
    /// Columns of the depth chart's plotting area (half-open).
    pub chart_x_px: std::ops::Range<i32>,
    /// Rows of the depth chart's plotting area (half-open).
    pub chart_y_px: std::ops::Range<i32>,
}

/// Plot size, pixels.
const PLOT_SIZE_PX: (u32, u32) = (1400, 800);

/// Colour of a gaze image in plots.
fn image_colour(image: GazeImage) -> RGBColor {
    match image {
        GazeImage::Surface => RGBColor(31, 119, 180),
        GazeImage::Refracted => RGBColor(230, 120, 20),
        GazeImage::Unknown => RGBColor(200, 200, 200),
    }
}

/// Line colours of the filters, in order (none of them grey, so text never has them).
pub const FILTER_COLOURS: [RGBColor; 5] = [
    RGBColor(110, 40, 150),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(0, 150, 170),
    RGBColor(140, 86, 75),
];

/// Colour of the fixation shading.
const FIXATION_SHADE: RGBColor = RGBColor(236, 236, 228);

/// Where diverging samples are drawn: a band this share of the axis's height below 0 D.
const DIVERGING_SHARE: f64 = 0.1;

/// Radius of the raw-sample markers, pixels.
const MARKER_PX: i32 = 2;

/// Colour of the markers of samples beyond the vergence axis.
const BEYOND: RGBColor = RGBColor(128, 60, 160);

/// Most vergence the axis reaches, dioptres (5 cm): nearer samples are marked on its top edge.
const MOST_D: f64 = 20.0;

/// Share of the finite samples the axis holds at least, unless that takes it past [`MOST_D`]
/// (a tracker's near spikes would otherwise squeeze the images' range into a few pixels).
const HELD_SHARE: f64 = 0.9;

/// The top of the vergence axis, dioptres: 1.6 times the nearer image's vergence and 1 D at
/// least, raised to hold [`HELD_SHARE`] of `vergences` (up to [`MOST_D`]).
fn axis_top_d(nearer_image_d: f64, vergences: &[f64]) -> f64 {
    let mut sorted: Vec<f64> = vergences
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    sorted.sort_by(f64::total_cmp);
    let held = sorted
        .get(((sorted.len() as f64 * HELD_SHARE).ceil() as usize).saturating_sub(1))
        .map_or(0.0, |v| (v * 1.05).min(MOST_D));
    (nearer_image_d * 1.6).max(1.0).max(held)
}

/// A tick label of the vergence axis: dioptres with the distance, `0 (far)`, and nothing
/// below 0 D (the diverging band is labelled once, beside it).
fn y_label(v: f64) -> String {
    if v < -1e-9 {
        String::new()
    } else if v < 1e-9 {
        "0 (far)".to_owned()
    } else {
        format!("{v:.1} ({:.2} m)", 1.0 / v)
    }
}

/// The times of the samples (not diverging) whose vergence lies above `top_d`.
fn vergences_beyond(
    raw: &[RawSample],
    top_d: f64,
    dioptres: impl Fn(f32) -> f64,
) -> impl Iterator<Item = i64> {
    raw.iter()
        .filter(|r| !r.divergent && r.depth_m.is_some_and(|d| dioptres(d) > top_d))
        .map(|r| r.time_ns)
        .collect::<Vec<_>>()
        .into_iter()
}

/// Draws raw and filtered fixation depth over time with the gaze-image decisions (like the
/// paper's Fig. 11) as a PNG at `out_png`, written to `out_png.partial` then renamed; returns
/// where the depth chart lies in the image.
///
/// Top: vergence (dioptres) of each tracker sample (grey dots; diverging rays as red dots
/// below 0 D), each filter's depth (lines), the two images and the threshold, over shaded
/// fixations. Bottom: one strip per filter (and the truth) coloured by the gaze image over
/// time (blue surface, orange refracted, grey unknown).
pub fn plot(
    samples: &[TraceSample],
    truth: Truth<'_>,
    config: &AnalyzeConfig,
    out_png: &Path,
) -> Result<PlotLayout> {
    crate::font::register_plot_font()?;
    let raw: Vec<RawSample> = raw_samples(samples, config.vergence, DEFAULT_VELOCITY_DEG_S);
    let raw_depths: Vec<(i64, Option<f32>)> = raw.iter().map(|r| (r.time_ns, r.depth_m)).collect();
    let timeline = match truth {
        Truth::Phases(phases) => timeline_from_phases(phases),
        Truth::FromRawDepth => {
            timeline_from_raw_depth(&raw_depths, &config.distances, config.persist_ns)
        }
    };
    let t0 = samples.first().map_or(0, |s| s.time_ns);
    let secs = |t: i64| (t - t0) as f64 * 1e-9;
    let t_max = samples.last().map_or(1.0, |s| secs(s.time_ns)).max(1e-3);
    let replays: Vec<(FilterKind, Vec<ReplayedFrame>)> = config
        .filters
        .iter()
        .map(|&f| (f, replay(samples, config.gaze_config(f), config.object)))
        .collect();
    let d = config.distances;
    let dioptres = |depth_m: f32| 1.0 / f64::from(depth_m.max(1e-3));
    let vergences: Vec<f64> = raw
        .iter()
        .filter(|r| !r.divergent)
        .filter_map(|r| r.depth_m.map(dioptres))
        .collect();
    let y_top = axis_top_d(dioptres(d.surface_m.min(d.refracted_m)), &vergences);
    let beyond = vergences.iter().filter(|&&v| v > y_top).count();
    let diverging_d = -DIVERGING_SHARE * y_top;
    let y_bottom = diverging_d * 2.0;
    let layout;

    let (w, h) = PLOT_SIZE_PX;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let draw_err = |e: &dyn fmt::Display| anyhow!("drawing the plot: {e}");
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&e))?;
        let rows = replays.len() + 1;
        let strip_px = 28 * rows as u32 + 70;
        let (upper, lower) = root.split_vertically(h - strip_px);
        let truth_label = if matches!(truth, Truth::Phases(_)) {
            "ground truth"
        } else {
            "raw-depth changes"
        };
        let mut chart = ChartBuilder::on(&upper)
            .caption(
                format!(
                    "Vergence: raw and filtered (surface {:.2} m, refracted {:.2} m)",
                    d.surface_m, d.refracted_m
                ),
                ("sans-serif", 22),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(118)
            .build_cartesian_2d(0.0..t_max, y_bottom..y_top)
            .map_err(|e| draw_err(&e))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("vergence (dioptres = 1 / depth in m)")
            .y_label_formatter(&|v: &f64| y_label(*v))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw_err(&e))?;
        // The diverging band's one label, beside it (a tick label would repeat it for every
        // tick below 0 D).
        let (x_axis_px, band_px) = chart.backend_coord(&(0.0, diverging_d));
        root.draw(&Text::new(
            "diverging",
            (x_axis_px - 10, band_px),
            TextStyle::from(("sans-serif", 14).into_font())
                .pos(Pos::new(HPos::Right, VPos::Center)),
        ))
        .map_err(|e| draw_err(&e))?;
        let (x_px, y_px) = chart.plotting_area().get_pixel_range();
        layout = PlotLayout {
            chart_x_px: x_px.clone(),
            chart_y_px: y_px.clone(),
        };
        // Keep markers of radius MARKER_PX (and one-pixel lines) inside the plotting area.
        let pad_y =
            (y_top - y_bottom) * f64::from(MARKER_PX + 1) / f64::from(y_px.len().max(1) as i32);
        let pad_x = t_max * f64::from(MARKER_PX + 1) / f64::from(x_px.len().max(1) as i32);
        let clamp_y = |v: f64| v.clamp(y_bottom + pad_y, y_top - pad_y);
        let clamp_t = |t: f64| t.clamp(pad_x, t_max - pad_x);

        // Fixations, shaded behind everything.
        let times: Vec<i64> = raw.iter().map(|r| r.time_ns).collect();
        let steps: Vec<_> = raw.iter().map(|r| r.step).collect();
        let min_ns = (f64::from(DEFAULT_MIN_FIXATION_MS) * 1e6) as i64;
        chart
            .draw_series(
                fixation_spans(&times, &steps, min_ns)
                    .into_iter()
                    .map(|(a, b)| {
                        Rectangle::new(
                            [
                                (secs(a).clamp(0.0, t_max), y_top),
                                (secs(b).clamp(0.0, t_max), y_bottom),
                            ],
                            FIXATION_SHADE.filled(),
                        )
                    }),
            )
            .map_err(|e| draw_err(&e))?
            .label("fixation (I-VT)")
            .legend(|(x, y)| {
                Rectangle::new([(x, y - 5), (x + 20, y + 5)], FIXATION_SHADE.filled())
            });
        let grey = RGBColor(150, 150, 150);
        let red = RGBColor(200, 60, 60);
        for (divergent, colour, label) in
            [(false, grey, "raw vergence"), (true, red, "diverging rays")]
        {
            chart
                .draw_series(
                    raw.iter()
                        .filter(|r| r.divergent == divergent)
                        .filter_map(|r| {
                            let v = if divergent {
                                diverging_d
                            } else {
                                dioptres(r.depth_m?)
                            };
                            // Beyond the axis: marked on its edge below.
                            (v <= y_top).then_some(())?;
                            Some(Circle::new(
                                (clamp_t(secs(r.time_ns)), clamp_y(v)),
                                MARKER_PX,
                                colour.filled(),
                            ))
                        }),
                )
                .map_err(|e| draw_err(&e))?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()));
        }
        if beyond > 0 {
            // Samples nearer than the axis reaches: a triangle on its top edge each.
            let largest = vergences.iter().copied().fold(y_top, f64::max);
            let triangle = |(x, y): (i32, i32)| {
                Polygon::new(
                    vec![(x, y - 4), (x - 4, y + 3), (x + 4, y + 3)],
                    BEYOND.filled(),
                )
            };
            chart
                .draw_series(vergences_beyond(&raw, y_top, dioptres).map(|t| {
                    EmptyElement::at((clamp_t(secs(t)), y_top - pad_y)) + triangle((0, 0))
                }))
                .map_err(|e| draw_err(&e))?
                .label(format!(
                    "{beyond} samples beyond the axis (up to {largest:.1} D)"
                ))
                .legend(move |(x, y)| triangle((x + 10, y)));
        }
        for (image, dist) in [
            (GazeImage::Surface, d.surface_m),
            (GazeImage::Refracted, d.refracted_m),
        ] {
            let c = image_colour(image);
            let v = clamp_y(dioptres(dist));
            chart
                .draw_series(LineSeries::new([(0.0, v), (t_max, v)], c.stroke_width(1)))
                .map_err(|e| draw_err(&e))?
                .label(format!("{image} image"))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c));
        }
        let threshold = clamp_y(dioptres(d.threshold_m()));
        chart
            .draw_series(DashedLineSeries::new(
                [(0.0, threshold), (t_max, threshold)],
                6,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(|e| draw_err(&e))?
            .label("threshold")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
        for (i, (kind, frames)) in replays.iter().enumerate() {
            let c = FILTER_COLOURS[i % FILTER_COLOURS.len()];
            // One line per stretch with a known depth.
            let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for &(t, state) in frames {
                match state.filtered_depth.depth_m() {
                    Some(dm) => segments
                        .last_mut()
                        .into_iter()
                        .for_each(|s| s.push((clamp_t(secs(t)), clamp_y(dioptres(dm))))),
                    None if segments.last().is_some_and(|s| !s.is_empty()) => {
                        segments.push(Vec::new())
                    }
                    None => {}
                }
            }
            for (k, seg) in segments.into_iter().filter(|s| !s.is_empty()).enumerate() {
                let series = chart
                    .draw_series(LineSeries::new(seg, c.stroke_width(1)))
                    .map_err(|e| draw_err(&e))?;
                if k == 0 {
                    series.label(kind.to_string()).legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], c.stroke_width(1))
                    });
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| draw_err(&e))?;

        // Decision strips: truth first, then one per filter.
        let mut strips = ChartBuilder::on(&lower)
            .margin_left(12)
            .margin_right(12)
            .margin_bottom(8)
            .x_label_area_size(30)
            .y_label_area_size(118)
            .build_cartesian_2d(0.0..t_max, 0.0..rows as f64)
            .map_err(|e| draw_err(&e))?;
        strips
            .configure_mesh()
            .disable_mesh()
            .disable_y_axis()
            .x_desc("time (s)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw_err(&e))?;
        let row_top = |row: usize| (rows - row) as f64;
        let mut bars: Vec<Rectangle<(f64, f64)>> = Vec::new();
        let mut label_rows: Vec<(usize, String)> = vec![(0, truth_label.to_owned())];
        // Truth row.
        let mut truth_points: Vec<(f64, GazeImage)> = Vec::new();
        if let Some((start, first)) = timeline.initial {
            truth_points.push((secs(start).max(0.0), first));
        }
        truth_points.extend(timeline.changes.iter().map(|c| (secs(c.time_ns), c.to)));
        let mut push_row = |row: usize, points: &[(f64, GazeImage)]| {
            for (k, &(t, image)) in points.iter().enumerate() {
                let end = points.get(k + 1).map_or(t_max, |p| p.0);
                if end > t {
                    bars.push(Rectangle::new(
                        [(t, row_top(row) - 0.85), (end, row_top(row) - 0.15)],
                        image_colour(image).filled(),
                    ));
                }
            }
        };
        push_row(0, &truth_points);
        for (i, (kind, frames)) in replays.iter().enumerate() {
            let mut points: Vec<(f64, GazeImage)> = Vec::new();
            for &(t, state) in frames {
                if points.last().is_none_or(|p| p.1 != state.image) {
                    points.push((secs(t), state.image));
                }
            }
            push_row(i + 1, &points);
            label_rows.push((i + 1, kind.to_string()));
        }
        strips.draw_series(bars).map_err(|e| draw_err(&e))?;
        strips
            .draw_series(label_rows.into_iter().map(|(row, text)| {
                Text::new(
                    text,
                    (0.005 * t_max, row_top(row) - 0.4),
                    ("sans-serif", 13).into_font().color(&BLACK),
                )
            }))
            .map_err(|e| draw_err(&e))?;
        root.present().map_err(|e| draw_err(&e))?;
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let png = vitreous_frames::output::encode_png(&rgba, w, h)?;
    vitreous_frames::output::write_atomic(out_png, &png)?;
    Ok(layout)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_holds_nine_tenths_of_the_samples_up_to_5_cm() {
        // The images alone: 1.6 times the nearer one's vergence, 1 D at least.
        assert_eq!(axis_top_d(0.675, &[]), 1.08);
        assert_eq!(axis_top_d(0.2, &[0.1, 0.3]), 1.0);
        // 900 samples from 0.5 to 2.5 D and a hundred at 100 D: the axis holds the 900, with
        // room, and no more.
        let mut v: Vec<f64> = (0..900).map(|i| 0.5 + 2.0 * f64::from(i) / 899.0).collect();
        v.extend([100.0; 100]);
        let top = axis_top_d(0.675, &v);
        let held = v.iter().filter(|&&x| x <= top).count();
        assert_eq!(held, 900, "{top}");
        assert!((2.5..3.0).contains(&top), "{top}");
        // Never past 20 D, whatever the samples.
        assert_eq!(axis_top_d(0.675, &[50.0; 100]), MOST_D);
        assert!(axis_top_d(0.675, &[f64::NAN, f64::INFINITY]) >= 1.0);
    }

    #[test]
    fn no_tick_below_0_d_says_diverging() {
        assert_eq!(y_label(-0.2), "");
        assert_eq!(y_label(-0.4), "");
        assert_eq!(y_label(0.0), "0 (far)");
        assert_eq!(y_label(0.5), "0.5 (2.00 m)");
    }
}
