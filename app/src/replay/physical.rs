//! `replay --compare-reference`: the physical reference of every saved frame, written beside
//! it, and what the eye sees measured against it.

use std::path::Path;

use anyhow::Result;
use vitreous_xr::FrameInput;

use crate::compare::{ReferenceFigures, against_reference, rgb_of};
use crate::output::{self, write_atomic};
use crate::reference_cmd::{ReferenceSettings, render_reference, srgb_rgba};
use crate::scene::{Placement, Scene};

/// `--compare-reference`: the saved frames' placements until they finish, and the figures.
pub(super) struct Physical {
    /// The scene, with its caustic bake read when it has one (the caustic is a region).
    pub(super) scene: Scene,
    /// Saved frames in flight: index and where the object and light were.
    pub(super) pending: Vec<(u64, Placement)>,
    /// Each finished saved frame's figures, per eye.
    pub(super) figures: Vec<ReferenceFigures>,
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
        let frame = render_reference(
            &self.scene,
            &input.views,
            &placement,
            size,
            &[0, 1],
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
            let [regions, nothing_drawn, additive_limit] = against_reference(
                &self.scene,
                &input.views[eye],
                &placement,
                [&rgb_of(&real), &rgb_of(&seen), &readback.eyes[eye]],
                size,
            )?;
            self.figures.push(ReferenceFigures {
                frame: input.index,
                eye: name,
                regions,
                nothing_drawn,
                additive_limit,
            });
        }
        Ok(files)
    }
}
