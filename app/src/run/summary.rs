//! What `vitreous run` reports: [`RunSummary`] (written to summary.json) and its one-paragraph
//! text.

use serde::Serialize;

use vitreous_frames::frame_log::PupilSummary;
use vitreous_frames::resident::ResidentMemory;
use vitreous_frames::spread::Spread;
use vitreous_frames::validation::ValidationSummary;
use vitreous_gaze::separability::SeparabilitySummary;

use super::ReplayCheck;
use vitreous_frames::readback_check::ReadbackCheck;

/// What `vitreous run` reports (and writes to summary.json).
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    /// vitreous version.
    pub vitreous_version: String,
    /// The scene file.
    pub scene: String,
    /// OpenXR runtime name and version.
    pub runtime: String,
    /// The headset's name.
    pub system: String,
    /// Enabled OpenXR extensions.
    pub extensions: Vec<String>,
    /// Blend modes offered.
    pub blend_modes_offered: Vec<String>,
    /// The blend mode used: `additive`, `alpha-blend` or `opaque`.
    pub blend: String,
    /// Whether the real world was drawn behind the glass (opaque displays).
    pub world_behind: bool,
    /// The reference space.
    pub space: String,
    /// The gaze source, named by its extension (`XR_ML_eye_tracker (...)`,
    /// `XR_FB_eye_tracking_social (...)`, `XR_EXT_eye_gaze_interaction (...)`), or
    /// `recorded trace (--gaze-trace)`, or `manual (no eye tracker)`.
    pub gaze_source: String,
    /// The gaze source's samples.
    pub gaze_samples: GazeSamples,
    /// XrEventDataReferenceSpaceChangePending events for the scene's space (each re-anchored
    /// the scene at the next head pose).
    pub space_changes: u64,
    /// Frames begun but left unshown after an error (ended with no layers).
    pub frames_abandoned: u64,
    /// Swapchain format and whether it encodes sRGB.
    pub swapchain_format: String,
    /// Session states reached, in order.
    pub states: Vec<String>,
    /// Whether FOCUSED was reached.
    pub reached_focused: bool,
    /// Why the session ended.
    pub end_reason: String,
    /// Frames submitted with a projection layer.
    pub frames_submitted: u64,
    /// Frames the runtime said not to render.
    pub frames_skipped: u64,
    /// Frames whose head pose was not fully tracked.
    pub frames_untracked: u64,
    /// Vulkan device and driver.
    pub device: String,
    /// Eye image size, pixels.
    pub width_px: u32,
    /// Eye image size, pixels.
    pub height_px: u32,
    /// Vulkan validation results.
    pub validation: ValidationSummary,
    /// Wall-clock time of the session's frame loop, seconds.
    pub wall_s: f64,
    /// Frames per second.
    pub frames_per_second: f64,
    /// CPU milliseconds per frame.
    pub cpu_ms: Option<Spread>,
    /// GPU milliseconds per frame.
    pub gpu_ms: Option<Spread>,
    /// The readback check, when asked for.
    pub readback: Option<ReadbackCheck>,
    /// The recording, when asked for.
    pub recorded: Option<String>,
    /// Samples recorded.
    pub recorded_samples: u64,
    /// Replay of the recording against the session's views, when recorded.
    pub replay_check: Option<ReplayCheck>,
    /// The headset's eye views against the scene's (`None`: no frame was drawn).
    pub headset_views: Option<super::views::HeadsetViews>,
    /// The controller action set was created and attached.
    pub actions_attached: bool,
    /// Interaction profiles whose bindings the runtime accepted.
    pub action_profiles: Vec<String>,
    /// xrSyncActions calls (one per FOCUSED frame).
    pub action_syncs: u64,
    /// Commands the live actions gave.
    pub commands: u64,
    /// The effect conditions the live actions cycle through, the first one the start.
    pub conditions: Vec<String>,
    /// The effect condition at the end.
    pub final_condition: String,
    /// The forced gaze image at the end (`auto`: the tracker decides).
    pub final_gaze_image: String,
    /// Whether depth was submitted (XR_KHR_composition_layer_depth).
    pub depth_submitted: bool,
    /// The depth swapchain's format, when depth was submitted.
    pub depth_format: Option<String>,
    /// Frames submitted with depth.
    pub frames_with_depth: u64,
    /// Frames submitted with `XrFrameEndInfoML` (XR_ML_frame_end_info): the focus plane at the
    /// wearer's filtered fixation depth.
    pub frames_with_focus_distance: u64,
    /// The last focus distance submitted, metres (`null`: none).
    pub last_focus_distance_m: Option<f32>,
    /// Frames submitted with `XrGlobalDimmerFrameEndInfoML` (XR_ML_global_dimmer, the scene's
    /// `[display] global_dimmer`).
    pub frames_with_global_dimmer: u64,
    /// Plane detections the runtime finished (XR_EXT_plane_detection; 0 without it).
    pub plane_detections: u64,
    /// Light estimates read from the runtime (XR_ML_light_estimation; 0 without it).
    pub light_estimates: u64,
    /// What the room's light estimates did to the scene's light (`null`: none came).
    pub room_light: Option<super::room_light::RoomLight>,
    /// With `--readback-check`: where the shadow and the caustic lay on the floor at the end
    /// (`null` otherwise).
    pub floor_centroids: Option<vitreous_frames::readback_check::FloorCentroids>,
    /// Changes of the gaze-image decision between surface and refracted (see `frames.csv`).
    pub gaze_image_switches: u64,
    /// How far apart the two images are in the tracker's vergence noise, the noise estimated
    /// over the session (`null` when no condition has defocus, or without a sample with a
    /// depth).
    pub separability: Option<SeparabilitySummary>,
    /// Where A_p came from and the values used (`null` when no condition has defocus).
    pub pupil: Option<PupilSummary>,
    /// Live-control edits made (keyboard, controllers), re-registrations included.
    pub scene_edits: u64,
    /// Frames whose object or light pose differed from the previous frame's (`[motion]` and
    /// edits).
    pub moved_frames: u64,
    /// Computations of the shadow inducer's fields on the GPU (one, then one per moved
    /// frame that draws them).
    pub inducer_computations: u64,
    /// Where the object and light were in the last frame (`null` when nothing moved).
    pub final_placement: Option<vitreous_frames::motion_clock::FinalPlacement>,
    /// What a misbehaving headset did to the run and what the run did about it.
    pub interruptions: super::InterruptionSummary,
    /// The process's resident memory over the frames after a warm-up (`null` when the session
    /// ended in its warm-up).
    pub resident_memory: Option<ResidentMemory>,
}

impl RunSummary {
    /// The summary as `vitreous run` prints it: one line per topic.
    pub fn report(&self) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "session on {} ({}): states {}; {} frames submitted ({} skipped) at {}x{} per \
             eye, {:.1} frames/s; blend {}; gaze {} ({} of {} frames with a fresh sample); \
             ended: {}",
            self.runtime,
            self.system,
            self.states.join(" > "),
            self.frames_submitted,
            self.frames_skipped,
            self.width_px,
            self.height_px,
            self.frames_per_second,
            self.blend,
            self.gaze_source,
            self.gaze_samples.fresh_frames,
            self.gaze_samples.frames,
            self.end_reason
        );
        if self.space_changes + self.frames_abandoned > 0 {
            let _ = writeln!(
                out,
                "reference space changes: {} (scene re-anchored each time); frames left \
                 unshown after an error: {}",
                self.space_changes, self.frames_abandoned
            );
        }
        if let Some(line) = self.interruptions.line() {
            let _ = writeln!(out, "{line}");
        }
        let _ = writeln!(
            out,
            "vulkan validation: {} errors, {} warnings (enabled: {})",
            self.validation.errors, self.validation.warnings, self.validation.enabled
        );
        let _ = writeln!(
            out,
            "actions attached: {}, syncs: {}, commands: {} (profiles: {}; conditions: {}; \
             final condition {}, gaze image {})",
            self.actions_attached,
            self.action_syncs,
            self.commands,
            self.action_profiles.join(", "),
            self.conditions.join(" > "),
            self.final_condition,
            self.final_gaze_image
        );
        let _ = writeln!(
            out,
            "depth submitted: {} ({}), {} of {} frames with depth",
            self.depth_submitted,
            self.depth_format.as_deref().unwrap_or("no depth swapchain"),
            self.frames_with_depth,
            self.frames_submitted
        );
        if let Some(c) = &self.readback {
            let _ = writeln!(
                out,
                "readback of frame {} ({}): object in {:.1} % of its region ({} of {} px), mean \
                 {:.1}; {:.1} % of the {} px away from it as the blend mode needs; {} px with \
                 alpha above 0",
                c.frame,
                c.blend,
                c.object_fraction * 100.0,
                c.object_px,
                c.region_px,
                c.mean_value,
                c.away_fraction * 100.0,
                c.away_px,
                c.alpha_nonzero_px
            );
        }
        if let Some(s) = &self.separability {
            let _ = writeln!(
                out,
                "gaze-image switches: {}; {}",
                self.gaze_image_switches,
                s.line()
            );
        }
        if let Some(m) = &self.resident_memory {
            let _ = writeln!(
                out,
                "resident memory: {} KiB at frame {} (after {} warm-up frames), {} KiB at frame \
                 {} ({:+.2} %), at most {} KiB",
                m.first_kib,
                m.first_frame,
                m.warm_up_frames,
                m.last_kib,
                m.last_frame,
                m.growth_percent,
                m.max_kib
            );
        }
        if let Some(v) = &self.headset_views {
            let _ = writeln!(
                out,
                "headset's eyes: {:.1} mm apart, turned {:.2}/{:.2} deg outwards; {}",
                v.ipd_mm[1],
                v.toe_out_deg[0],
                v.toe_out_deg[1],
                match (&v.replay_eye_mm, v.differences.is_empty()) {
                    (None, _) => "not recorded",
                    (Some(_), true) => "the recording replays from them",
                    (Some(_), false) => "the recording's replay draws from other eyes",
                }
            );
        }
        if let Some(r) = &self.replay_check {
            let _ = writeln!(
                out,
                "recording replayed: {} samples, {} frames; max head difference {:.2e} m, \
                 {:.2e} deg; max eye position difference {:.4} m",
                r.samples,
                r.frames,
                r.max_head_position_m,
                r.max_head_angle_deg,
                r.max_eye_position_m
            );
        }
        out
    }
}

/// The gaze source's samples over the session.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct GazeSamples {
    /// Frames the source was asked for a sample.
    pub frames: u64,
    /// Frames it gave a sample (for `ext`: the runtime's combined ray, also when the trace
    /// decides the gaze image).
    pub received: u64,
    /// Frames whose sample was newer than any before: a fresh sample.
    pub fresh_frames: u64,
    /// Frames whose sample was stamped before one already used: they got the newest one
    /// again (the recording's gaze times never go back).
    pub out_of_order: u64,
    /// Frames whose new sample was stamped after the frame's display time (an eye tracker's
    /// clock ahead of the runtime's): the frame used it, stamped at its display time.
    pub after_display: u64,
    /// The most a sample was stamped after its frame's display time, milliseconds.
    pub max_ahead_ms: f64,
}
