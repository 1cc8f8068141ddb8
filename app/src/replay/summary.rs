//! What a replay's `summary.json` holds: the finished run's figures, or, while it runs or
//! after it failed, a short summary that says so.

use serde::Serialize;

use vitreous_frames::frame_log::PupilSummary;
use vitreous_frames::frame_loop::FrameRecord;
use vitreous_frames::motion_clock::FinalPlacement;
use vitreous_frames::spread::Spread;
use vitreous_frames::validation::ValidationSummary;
use vitreous_gaze::separability::SeparabilitySummary;

/// How a replay ended, as `summary.json` says it. Anything but `complete` means the output
/// folder holds only part of the run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunStatus {
    /// Written when the replay starts; still there after a crash, kill -9 or a full disk.
    Running,
    /// Every frame was rendered and every file written.
    Complete,
    /// Ended early by Ctrl-C or SIGTERM; the frames listed were finished.
    Interrupted,
    /// Ended by an error (named in `error`).
    Failed,
}

/// The `summary.json` of a replay that has not finished (yet): it replaces any earlier run's
/// summary before the first frame, so a folder never claims a success it does not hold.
#[derive(Clone, Debug, Serialize)]
pub(super) struct UnfinishedSummary<'a> {
    /// vitreous version.
    pub(super) vitreous_version: &'static str,
    /// `running` or `failed`.
    pub(super) status: RunStatus,
    /// Always false here.
    pub(super) complete: bool,
    /// The scene file.
    pub(super) scene: &'a str,
    /// The replayed trace file, or "synthetic".
    pub(super) trace: &'a str,
    /// Why the replay failed (`failed` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) error: Option<String>,
}

/// What `summary.json` holds.
#[derive(Clone, Debug, Serialize)]
pub struct ReplaySummary {
    /// vitreous version.
    pub vitreous_version: String,
    /// `complete`, or `interrupted` when Ctrl-C/SIGTERM ended the replay early.
    pub status: RunStatus,
    /// True only when every frame asked for was rendered and saved.
    pub complete: bool,
    /// The scene file.
    pub scene: String,
    /// Hex SHA-256 of the scene and its assets.
    pub scene_hash: String,
    /// The replayed trace file, or "synthetic".
    pub trace: String,
    /// Effect set rendered.
    pub effects: String,
    /// Vulkan device name.
    pub device: String,
    /// Vulkan driver name and version.
    pub driver: String,
    /// Validation results.
    pub validation: ValidationSummary,
    /// Eye image width, pixels.
    pub width_px: u32,
    /// Eye image height, pixels.
    pub height_px: u32,
    /// The field of view the eyes were drawn with (`--fields`): the scene's, or the headset's
    /// from the recording.
    pub fields: super::Fields,
    /// The scene's field (left, right, up, down edges, degrees): with `recorded` fields the
    /// recording's first (left eye), each eye drawn with the line in force.
    pub fov_deg: [f32; 4],
    /// Display frame rate replayed, hertz.
    pub frame_rate_hz: f64,
    /// Frames rendered.
    pub frames: u64,
    /// Frames rendered per second of wall-clock time, saving included.
    pub frames_per_second: f64,
    /// Wall-clock time of the frame loop, seconds.
    pub wall_s: f64,
    /// CPU milliseconds per stereo frame.
    pub cpu_ms: Option<Spread>,
    /// GPU milliseconds per stereo frame.
    pub gpu_ms: Option<Spread>,
    /// Files written, relative to the output folder.
    pub saved: Vec<String>,
    /// Changes of the gaze-image decision between surface and refracted (see `frames.csv`).
    pub gaze_image_switches: u64,
    /// How far apart the two images are in the tracker's vergence noise, the noise estimated
    /// over the trace (`null` without defocus or without a sample with a depth).
    pub separability: Option<SeparabilitySummary>,
    /// Where A_p came from and the values used (`null` without defocus).
    pub pupil: Option<PupilSummary>,
    /// Frames whose object or light pose differed from the previous frame's (`[motion]`).
    pub moved_frames: u64,
    /// Computations of the shadow inducer's fields (mask, distance, gain) on the GPU: one
    /// for the first frame drawing them, then one per moved frame, none otherwise.
    pub inducer_computations: u64,
    /// Scene edits of the trace (version 1.2 edit lines) applied.
    pub scene_edits: u64,
    /// The recording's session events (version 1.4 event lines: frames not rendered, the
    /// headset taken off, a loss, ...), by kind, as the live session had them.
    pub session_events: std::collections::BTreeMap<String, u64>,
    /// Where the object and light were in the last frame (`null` when nothing moved).
    pub final_placement: Option<FinalPlacement>,
    /// With `--compare-reference`: each saved frame's eyes measured against the physical
    /// reference (`null` without).
    pub compare_reference: Option<Vec<vitreous_compare::ReferenceFigures>>,
    /// Every frame's timing.
    pub per_frame: Vec<FrameRecord>,
}

impl ReplaySummary {
    /// Frames, size, device and timings in one line.
    pub fn summary_line(&self) -> String {
        let median =
            |s: Option<Spread>| s.map_or("n/a".to_string(), |s| format!("{:.2}", s.median_ms));
        format!(
            "rendered {} frames of {}x{} per eye on {} in {:.1} s ({:.1} frames/s; median GPU {} \
             ms, CPU {} ms per stereo frame)",
            self.frames,
            self.width_px,
            self.height_px,
            self.device,
            self.wall_s,
            self.frames_per_second,
            median(self.gpu_ms),
            median(self.cpu_ms),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_fails_on_any_message_and_names_the_first() {
        let mut v = ValidationSummary {
            enabled: true,
            warnings: 0,
            errors: 0,
            messages: Vec::new(),
        };
        assert!(v.check(None).is_ok());
        v.warnings = 1;
        v.messages = vec!["VUID-x: first".into(), "second".into()];
        let err = v.check(None).unwrap_err().to_string();
        assert_eq!(
            err,
            "the Vulkan validation layers reported 0 errors and 1 warnings, first: VUID-x: first"
        );
        v.errors = 2;
        let err = v
            .check(Some(std::path::Path::new("out/summary.json")))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("2 errors and 1 warnings (see out/summary.json), first: VUID-x"),
            "{err}"
        );
    }
}
