//! The bench's text report: the timings' table, the counted work's, and the floor stages.

use std::fmt::Write as _;

use super::{BenchReport, VariantResult};
use vitreous_frames::spread::Spread;
use vitreous_render::work::counts::WorkCounts;

/// A column: its header, and its cell for a variant.
type Column<'a> = (&'a str, Box<dyn Fn(&VariantResult) -> String + 'a>);

impl BenchReport {
    /// The report as text: the timings, the counted work per frame, then the floor stages of
    /// the variants that recomputed them. The columns of moving variants appear only with
    /// `--moving`, the two-surface ratio only with `--two-surface`, the ratio to the proof off
    /// only with `--unproved`.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "{} at {}x{} per eye on {} ({}), {} frames per variant, alternated",
            self.scene, self.width_px, self.height_px, self.device, self.driver, self.frames
        );
        out.push_str(&grid(&self.variants, &self.timing_columns()));
        let _ = writeln!(
            out,
            "\ncounted work per frame (mean; the same run after run){}:",
            if self.invocations_counted {
                ""
            } else {
                ", without shader invocations (the device has no pipeline-statistics queries)"
            }
        );
        out.push_str(&grid(&self.variants, &self.work_columns()));
        // The variants whose frames have floor work (a still frame's stamps alone take a few
        // hundredths of a millisecond each on lavapipe).
        let stages: Vec<_> = self
            .variants
            .iter()
            .filter(|v| v.prepare_gpu_ms.is_some_and(|p| p.median_ms > 0.5))
            .filter_map(|v| v.field_passes_gpu_ms.map(|f| (v, f)))
            .collect();
        if !stages.is_empty() {
            let _ = writeln!(out, "\nfields GPU ms per stage (medians):");
        }
        for (v, f) in stages {
            let _ = write!(
                out,
                "  {}: mask {:.2}, nearest {:.2}, ramp {:.2}, \
                 live caustics {:.2} (photons {:.2}, smoothing {:.2})",
                v.effects,
                f.mask_ms,
                f.nearest_ms,
                f.ramp_ms,
                f.caustic_photons_ms + f.caustic_smoothing_ms,
                f.caustic_photons_ms,
                f.caustic_smoothing_ms
            );
            // What the live map's computations did, counted, mean per frame.
            let count = |name: &str| v.work.get(name).copied().unwrap_or(0.0);
            if count("caustic_photons.traced") > 0.0 {
                let _ = write!(
                    out,
                    "; photons traced {}, splatted {}, texels smoothed {}",
                    compact(count("caustic_photons.traced")),
                    compact(count("caustic_photons.splatted")),
                    compact(count("caustic_smoothing.texels"))
                );
            }
            out.push('\n');
        }
        out
    }

    /// The timings' columns.
    fn timing_columns(&self) -> Vec<Column<'_>> {
        let spread = |s: Option<Spread>| {
            s.map_or("n/a".to_string(), |s| {
                format!("{:.2} ({:.2}-{:.2})", s.median_ms, s.p10_ms, s.p90_ms)
            })
        };
        let ratio = |x: Option<f64>| x.map_or("n/a".to_string(), |x| format!("{x:.3}"));
        let mut columns: Vec<Column<'_>> = vec![
            ("effects", Box::new(|v| v.effects.clone())),
            ("fetch", Box::new(|v| v.fetches_per_pixel.to_string())),
            ("GPU ms (p10-p90)", Box::new(move |v| spread(v.gpu_ms))),
            ("GPU ratio", Box::new(move |v| ratio(v.gpu_ratio))),
            ("CPU ms (p10-p90)", Box::new(move |v| spread(v.cpu_ms))),
            ("CPU ratio", Box::new(move |v| ratio(v.cpu_ratio))),
            ("wall ms (p10-p90)", Box::new(move |v| spread(v.wall_ms))),
            ("wall ratio", Box::new(move |v| ratio(v.wall_ratio))),
        ];
        if self.moving {
            columns.push((
                "fields GPU ms (p10-p90)",
                Box::new(move |v| spread(v.prepare_gpu_ms)),
            ));
            columns.push(("GPU/still", Box::new(move |v| ratio(v.gpu_over_static))));
            columns.push(("wall/still", Box::new(move |v| ratio(v.wall_over_static))));
        }
        if self.two_surface {
            columns.push(("GPU/paper", Box::new(move |v| ratio(v.gpu_over_paper))));
        }
        if self.unproved {
            columns.push((
                "GPU/unproved",
                Box::new(move |v| ratio(v.gpu_over_unproved)),
            ));
        }
        columns
    }

    /// The counted work's columns.
    fn work_columns(&self) -> Vec<Column<'_>> {
        let count = |name: &'static str| {
            move |v: &VariantResult| v.work.get(name).map_or("n/a".into(), |x| compact(*x))
        };
        let sum = |suffix: &'static str| move |v: &VariantResult| compact(sum_of(&v.work, suffix));
        let mut columns: Vec<Column<'_>> = vec![
            ("effects", Box::new(|v| v.effects.clone())),
            ("passes", Box::new(count("render_passes"))),
            ("draws", Box::new(count("draws"))),
            ("dispatches", Box::new(count("dispatches"))),
            ("workgroups", Box::new(count("workgroups"))),
            ("uploaded B", Box::new(count("uploaded_bytes"))),
        ];
        if self.invocations_counted {
            columns.extend([
                (
                    "floor frags",
                    Box::new(count("eye_floor.fragment_invocations")) as Box<dyn Fn(&_) -> _>,
                ),
                (
                    "glass frags",
                    Box::new(|v: &VariantResult| {
                        let frags = |name| v.work.get(name).copied().unwrap_or(0.0);
                        compact(
                            frags("eye_glass.fragment_invocations")
                                + frags("eye_glass_covered.fragment_invocations"),
                        )
                    }),
                ),
                (
                    "covered",
                    Box::new(count("eye_glass_covered.fragment_invocations")),
                ),
                ("glass texels", Box::new(count("glass_texels"))),
                ("glass instr", Box::new(count("glass_instructions"))),
                // Where the glass shades a ball's light in parts over the positions each needs.
                (
                    "first image pos",
                    Box::new(count("glass_positions.first_images")),
                ),
                ("rest pos", Box::new(count("glass_positions"))),
                // Where the glass searches a mesh's triangles for the exit.
                ("mesh nodes", Box::new(count("glass_mesh.nodes"))),
                ("mesh tris", Box::new(count("glass_mesh.triangles"))),
                ("mesh pos", Box::new(count("glass_mesh.positions"))),
                ("field frags", Box::new(count("mask.fragment_invocations"))),
                ("compute inv", Box::new(sum(".compute_invocations"))),
            ]);
        }
        columns
    }
}

/// The sum of the counts whose names end with `suffix`.
fn sum_of(work: &WorkCounts, suffix: &str) -> f64 {
    work.iter()
        .filter(|(name, _)| name.ends_with(suffix))
        .map(|(_, value)| value)
        .sum()
}

/// A count in at most about six characters: 1234, 12.3k, 4.56M.
fn compact(x: f64) -> String {
    match x.abs() {
        a if a >= 1e9 => format!("{:.2}G", x / 1e9),
        a if a >= 1e6 => format!("{:.2}M", x / 1e6),
        a if a >= 1e4 => format!("{:.1}k", x / 1e3),
        a if a == a.trunc() => format!("{x:.0}"),
        _ => format!("{x:.1}"),
    }
}

/// `variants` as a table with `columns`, each as wide as its widest cell or header: the
/// first left-aligned, the others right-aligned.
fn grid(variants: &[VariantResult], columns: &[Column<'_>]) -> String {
    let cells: Vec<Vec<String>> = variants
        .iter()
        .map(|v| columns.iter().map(|(_, cell)| cell(v)).collect())
        .collect();
    let widths: Vec<usize> = columns
        .iter()
        .enumerate()
        .map(|(i, (header, _))| {
            cells
                .iter()
                .map(|row| row[i].chars().count())
                .chain([header.chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |row: Vec<&str>| {
        let mut text = String::new();
        for (i, (cell, width)) in row.iter().zip(&widths).enumerate() {
            if i == 0 {
                let _ = write!(text, "{cell:<width$}");
            } else {
                let _ = write!(text, "  {cell:>width$}");
            }
        }
        text.trim_end().to_owned() + "\n"
    };
    let mut out = line(columns.iter().map(|(header, _)| *header).collect());
    for row in &cells {
        out.push_str(&line(row.iter().map(String::as_str).collect()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(moving: bool, two_surface: bool, unproved: bool) -> BenchReport {
        let spread = Some(Spread {
            median_ms: 12.5,
            p10_ms: 11.0,
            p90_ms: 14.25,
        });
        let variant = |effects: &str| VariantResult {
            effects: effects.to_owned(),
            fetches_per_pixel: 3,
            moving: false,
            gpu_ms: spread,
            prepare_gpu_ms: spread,
            field_passes_gpu_ms: None,
            cpu_ms: spread,
            wall_ms: spread,
            gpu_ratio: Some(1.0),
            cpu_ratio: Some(1.0),
            wall_ratio: Some(1.0),
            gpu_over_static: None,
            gpu_over_paper: None,
            gpu_over_unproved: None,
            wall_over_static: None,
            work: WorkCounts::from([("draws".to_owned(), 4.0)]),
        };
        BenchReport {
            scene: "s.toml".into(),
            device: "d".into(),
            driver: "v".into(),
            width_px: 64,
            height_px: 48,
            frames: 2,
            moving,
            two_surface,
            unproved,
            invocations_counted: false,
            variants: vec![
                variant("none"),
                variant("disparity,defocus A_p=6mm two-surface moving"),
            ],
        }
    }

    #[test]
    fn every_row_is_as_wide_as_its_header_whatever_the_label() {
        let text = report(true, true, true).table();
        // Every column is right-aligned to its widest cell or header (the first left-aligned
        // and as wide as the longest label), so a table's lines are all equally long.
        for table in text.split("\n\n") {
            let lines: Vec<usize> = table
                .lines()
                .filter(|l| {
                    l.starts_with("effects") || l.starts_with("none") || l.starts_with("disp")
                })
                .map(|l| l.chars().count())
                .collect();
            assert_eq!(lines.len(), 3, "{text}");
            assert!(lines.iter().all(|&n| n == lines[0]), "{text}");
        }
    }

    #[test]
    fn moving_two_surface_and_unproved_columns_appear_only_when_asked_for() {
        let plain = report(false, false, false).table();
        for header in [
            "fields GPU ms",
            "GPU/still",
            "wall/still",
            "GPU/paper",
            "GPU/unproved",
        ] {
            assert!(!plain.contains(header), "{plain}");
        }
        let moving = report(true, false, false).table();
        assert!(moving.contains("GPU/still") && !moving.contains("GPU/paper"));
        let two = report(false, true, false).table();
        assert!(two.contains("GPU/paper") && !two.contains("GPU/still"));
        let unproved = report(false, false, true).table();
        assert!(unproved.contains("GPU/unproved") && !unproved.contains("GPU/paper"));
        assert!(plain.contains("without shader invocations"), "{plain}");
    }

    #[test]
    fn a_variant_that_computed_the_live_map_shows_its_counted_photons() {
        let mut r = report(true, false, false);
        let stages = super::super::FieldPassesMedians {
            mask_ms: 0.3,
            nearest_ms: 1.9,
            ramp_ms: 0.1,
            caustic_photons_ms: 6.5,
            caustic_smoothing_ms: 3.0,
        };
        for (v, traced) in r.variants.iter_mut().zip([0.0, 4096.0]) {
            v.field_passes_gpu_ms = Some(stages);
            v.work.insert("caustic_photons.traced".into(), traced);
            v.work
                .insert("caustic_photons.splatted".into(), 2.5 * traced);
            v.work.insert("caustic_smoothing.texels".into(), 75_382.6);
        }
        let text = r.table();
        let lines: Vec<&str> = text.lines().filter(|l| l.contains("mask 0.30")).collect();
        assert_eq!(lines.len(), 2, "{text}");
        assert!(!lines[0].contains("photons traced"), "{text}");
        assert!(
            lines[1].ends_with("; photons traced 4096, splatted 10.2k, texels smoothed 75.4k"),
            "{text}"
        );
    }

    #[test]
    fn compact_counts_keep_their_magnitude() {
        assert_eq!(compact(12.0), "12");
        assert_eq!(compact(2.5), "2.5");
        assert_eq!(compact(12_345.0), "12.3k");
        assert_eq!(compact(4_560_000.0), "4.56M");
        assert_eq!(compact(7.2e9), "7.20G");
    }
}
