//! `replay --compare-reference`: the physical reference of every saved frame, written beside
//! it, and what the eye sees measured against it; a `reference.json` beside them says which
//! frame and eye each reference image is, so `vitreous compare` finds their regions. With
//! `--compare-shift-deg`, the same figures with the display misregistered by each angle.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use vitreous_compare::{Against, ReferenceFigures, ShiftedFigures, additive_limit, rgb_of};
use vitreous_optics::display::registration::Misregistration;
use vitreous_reference::{FrameReport, ReferenceSettings, Report, render_reference, srgb_rgba};
use vitreous_trace::FrameInput;

use crate::reference_cmd::eye_record;
use vitreous_frames::output::{self, write_atomic};
use vitreous_frames::render_desc::eye_params;
use vitreous_frames::wearer::WearerView;
use vitreous_scene::{Placement, Scene};

/// `--compare-reference`: the saved frames' placements until they finish, and the figures.
pub(super) struct Physical {
    /// The scene, with its caustic bake read when it has one (the caustic is a region).
    pub(super) scene: Scene,
    /// The registration errors to measure beside the registered display, degrees.
    pub(super) shifts_deg: Vec<f32>,
    /// Saved frames in flight: index and where the object and light were.
    pub(super) pending: Vec<(u64, Placement)>,
    /// Each finished saved frame's figures, per eye.
    pub(super) figures: Vec<ReferenceFigures>,
    /// Each finished saved frame's record, for `reference.json`.
    pub(super) reports: Vec<FrameReport>,
    /// The scene file and the trace's name, for `reference.json`.
    pub(super) source: (PathBuf, String),
}

impl Physical {
    /// Renders the reference of saved frame `input`, writes it and what the eye sees with
    /// nothing drawn into `dir`, and measures the frame's display light over that against it;
    /// returns the files written.
    pub(super) fn measure(
        &mut self,
        dir: &Path,
        input: &FrameInput,
        readback: &vitreous_render::Readback,
    ) -> Result<Vec<String>> {
        let Some(k) = self.pending.iter().position(|p| p.0 == input.index) else {
            return Ok(Vec::new());
        };
        let (_, placement) = self.pending.swap_remove(k);
        let size = (readback.width, readback.height);
        let started = Instant::now();
        let cameras = input.views.each_ref().map(eye_params);
        let frame = render_reference(
            &self.scene,
            &cameras,
            &placement,
            size,
            &ReferenceSettings::default(),
        )?;
        let mut files = Vec::new();
        for (eye, name) in output::EYE_NAMES.iter().enumerate() {
            let real = srgb_rgba(&frame.real[eye]);
            let seen = srgb_rgba(&frame.seen[eye]);
            for (suffix, image) in [("-real", &real), ("-seen", &seen)] {
                let file = format!("{:06}-{name}{suffix}.png", input.index);
                write_atomic(
                    &dir.join(&file),
                    &output::encode_png(image, size.0, size.1)?,
                )?;
                files.push(format!("frames/{file}"));
            }
            // The display's light over the seen image, as the scene's display shows it.
            let display = WearerView::of_scene(&self.scene);
            let real = rgb_of(&real);
            let against = Against::new(&self.scene, &cameras[eye], &placement, &real, size);
            let shown = |error: &Misregistration| {
                rgb_of(&display.see_misregistered(
                    &readback.eyes[eye],
                    &seen,
                    [size.0, size.1],
                    error,
                    against.pixels_per_degree(),
                ))
            };
            let seen_rgb = rgb_of(&seen);
            let mut misregistered = Vec::new();
            for &angle in &self.shifts_deg {
                for shift_deg in [[angle, 0.0], [-angle, 0.0], [0.0, angle], [0.0, -angle]] {
                    let error = Misregistration::new(shift_deg, 0.0)?;
                    misregistered.push(ShiftedFigures {
                        shift_deg,
                        roll_deg: 0.0,
                        regions: against.rows(&shown(&error))?,
                    });
                }
            }
            self.figures.push(ReferenceFigures {
                frame: input.index,
                eye: name,
                regions: against.rows(&shown(&Misregistration::default()))?,
                nothing_drawn: against.rows(&seen_rgb)?,
                additive_limit: against.rows(&additive_limit(&seen_rgb, &real))?,
                misregistered,
            });
        }
        self.reports.push(FrameReport {
            frame: input.index,
            time_ns: input.time_ns,
            eyes: input.views.each_ref().map(eye_record),
            object_position_m: placement.object_position_m.to_array(),
            object_rotation_xyzw: placement.object_rotation.to_array(),
            light_position_m: placement.light_position_m.to_array(),
            photons: frame.photons,
            floor_light_noise: frame.noise,
            files: files
                .iter()
                .map(|f| f.trim_start_matches("frames/").to_owned())
                .collect(),
            seconds: started.elapsed().as_secs_f64(),
        });
        Ok(files)
    }

    /// Writes `reference.json` into `dir` (the frames' folder), listing every measured frame;
    /// returns its name as the summary lists files.
    pub(super) fn write_report(&mut self, dir: &Path, size: (u32, u32)) -> Result<String> {
        let (scene_path, trace) = self.source.clone();
        let report = Report::new(
            &self.scene,
            &scene_path,
            trace,
            size,
            &ReferenceSettings::default(),
            std::mem::take(&mut self.reports),
        );
        let json = serde_json::to_vec_pretty(&report).context("encoding reference.json")?;
        write_atomic(&dir.join("reference.json"), &json)?;
        Ok("frames/reference.json".into())
    }
}
