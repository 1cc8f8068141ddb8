//! Version 1.2's scene-edit lines: what a live control changed during a recorded session, so
//! that a replay reproduces the session's scene as well as its views.
//!
//! An edit line starts with the word `edit` and holds [`EDIT_FIELDS`] fields:
//!
//! ```text
//! edit,time_ns,action,object_dx_m,object_dy_m,object_dz_m,object_qx,object_qy,object_qz,object_qw,light_dx_m,light_dy_m,light_dz_m,world_dx_m,world_dy_m,world_dz_m
//! ```
//!
//! and one more, [`EDIT_SHARE_FIELD`] (0 to 1), once the room's light estimate set the light's
//! share of the floor's light (`light-estimate` edits); without it the share is the scene's.
//!
//! The numbers are the edit state *after* the edit (not the step), so a replay sets them
//! instead of repeating the arithmetic, and a lost line cannot shift every later pose.

use glam::{Quat, Vec3};

use super::{QUAT_NORM_TOLERANCE, TraceError};
use crate::records::Record;

/// The first field of an edit line.
pub const EDIT_TAG: &str = "edit";

/// The names of an edit line's fields, in file order (the first is the tag itself).
pub const EDIT_FIELDS: [&str; 16] = [
    "edit",
    "time_ns",
    "action",
    "object_dx_m",
    "object_dy_m",
    "object_dz_m",
    "object_qx",
    "object_qy",
    "object_qz",
    "object_qw",
    "light_dx_m",
    "light_dy_m",
    "light_dz_m",
    "world_dx_m",
    "world_dy_m",
    "world_dz_m",
];

/// The optional last field of an edit line: the light's share of the floor's light.
pub const EDIT_SHARE_FIELD: &str = "light_share";

/// Longest action name accepted, bytes.
pub const MAX_ACTION_BYTES: usize = 40;

/// One scene edit of a recorded session: when it was made, what it was, and the edit state
/// it left (offsets from the scene's own, keyframed or resting, placement).
#[derive(Clone, Debug, PartialEq)]
pub struct EditRecord {
    /// Time of the frame the edit was applied to, nanoseconds on the trace clock: at or after
    /// the sample before it, and the frame of that sample shows it.
    pub time_ns: i64,
    /// What was done, one word of `a-z 0-9 + - _ .` (`object+x`, `turn-10`, `place`,
    /// `light+y`, `register-z`), for the logs.
    pub action: String,
    /// Added to the object's position (bounding-box centre), world axes, metres.
    pub object_offset_m: Vec3,
    /// Turn applied to the object about its centre after its own rotation (world axes).
    pub object_turn: Quat,
    /// Added to the light's position, world axes, metres.
    pub light_offset_m: Vec3,
    /// The re-registration so far: how far the whole world (floor, background, object,
    /// light) was moved against the tracking, metres. The head poses of the samples already
    /// include it (they are in the re-registered frame), so a replay only reports it.
    pub world_offset_m: Vec3,
    /// The light's share of the floor's light as the room's light estimate set it (`None`:
    /// the scene's `[light] share`).
    pub light_share: Option<f32>,
}

impl EditRecord {
    /// No edit: zero offsets, no turn.
    pub fn none(time_ns: i64, action: impl Into<String>) -> EditRecord {
        EditRecord {
            time_ns,
            action: action.into(),
            object_offset_m: Vec3::ZERO,
            object_turn: Quat::IDENTITY,
            light_offset_m: Vec3::ZERO,
            world_offset_m: Vec3::ZERO,
            light_share: None,
        }
    }
}

/// Whether `action` is a name an edit line may hold.
pub fn valid_action(action: &str) -> bool {
    !action.is_empty()
        && action.len() <= MAX_ACTION_BYTES
        && action
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b"+-_.".contains(&b))
}

/// Checks an edit made at `time_ns` after a sample at `previous_ns` (if any) and the edit
/// before it (`previous_edit_ns`): a known action, finite numbers, a unit turn (normalised
/// within [`QUAT_NORM_TOLERANCE`]), no time before the sample or edit it follows.
pub(super) fn check_edit(
    file: &str,
    line: usize,
    edit: &EditRecord,
    previous_ns: Option<i64>,
    previous_edit_ns: Option<i64>,
) -> Result<EditRecord, TraceError> {
    let bad = |reason: String| TraceError::BadEdit {
        file: file.to_owned(),
        line,
        reason,
    };
    if !valid_action(&edit.action) {
        return Err(bad(format!(
            "action `{}` is not one word of a-z 0-9 + - _ . (at most {MAX_ACTION_BYTES} bytes)",
            crate::records::printable(&edit.action)
        )));
    }
    if let Some(p) = previous_ns.into_iter().chain(previous_edit_ns).max()
        && edit.time_ns < p
    {
        return Err(bad(format!(
            "time_ns {} is before the line it follows ({p})",
            edit.time_ns
        )));
    }
    let numbers = [
        edit.object_offset_m,
        edit.light_offset_m,
        edit.world_offset_m,
    ];
    if !numbers.iter().all(|v| v.is_finite()) || !edit.object_turn.is_finite() {
        return Err(bad("offsets and turn must be finite numbers".into()));
    }
    if let Some(share) = edit.light_share
        && !(0.0..=1.0).contains(&share)
    {
        return Err(bad(format!(
            "{EDIT_SHARE_FIELD} {share} is not a share from 0 to 1"
        )));
    }
    let norm = edit.object_turn.length();
    if (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
        return Err(bad(format!(
            "object turn quaternion has norm {norm}, expected 1 (within {QUAT_NORM_TOLERANCE})"
        )));
    }
    Ok(EditRecord {
        object_turn: edit.object_turn.normalize(),
        ..edit.clone()
    })
}

/// Parses an edit line (its first field is [`EDIT_TAG`]) without the order checks.
pub(super) fn parse_edit(record: &Record<'_>) -> Result<EditRecord, TraceError> {
    let light_share = if record.len() == EDIT_FIELDS.len() + 1 {
        Some(record.f32(EDIT_FIELDS.len(), EDIT_SHARE_FIELD)?)
    } else {
        record.expect_len(EDIT_FIELDS.len())?;
        None
    };
    let f = &EDIT_FIELDS;
    let vec = |at: usize| record.vec3([at, at + 1, at + 2], [f[at], f[at + 1], f[at + 2]]);
    Ok(EditRecord {
        time_ns: record.i64(1, f[1], "an integer number of nanoseconds")?,
        action: record.field(2).to_owned(),
        object_offset_m: vec(3)?,
        object_turn: Quat::from_xyzw(
            record.f32(6, f[6])?,
            record.f32(7, f[7])?,
            record.f32(8, f[8])?,
            record.f32(9, f[9])?,
        ),
        light_offset_m: vec(10)?,
        world_offset_m: vec(13)?,
        light_share,
    })
}

/// The line of an edit (with its line ending).
pub(super) fn format_edit(edit: &EditRecord) -> String {
    let (o, q, l, w) = (
        edit.object_offset_m,
        edit.object_turn,
        edit.light_offset_m,
        edit.world_offset_m,
    );
    let share = edit.light_share.map_or(String::new(), |s| format!(",{s}"));
    format!(
        "{EDIT_TAG},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}{share}\n",
        edit.time_ns, edit.action, o.x, o.y, o.z, q.x, q.y, q.z, q.w, l.x, l.y, l.z, w.x, w.y, w.z
    )
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::super::test_traces::sample;
    use super::super::*;

    fn edit(time_ns: i64, action: &str) -> EditRecord {
        EditRecord {
            time_ns,
            action: action.into(),
            object_offset_m: Vec3::new(0.01, 0.0, -0.001),
            object_turn: Quat::from_rotation_y(10f32.to_radians()),
            light_offset_m: Vec3::new(0.0, 0.1, 0.0),
            world_offset_m: Vec3::new(0.0, 0.0, 0.01),
            light_share: None,
        }
    }

    #[test]
    fn a_light_share_rides_on_its_edit_line_and_must_be_a_share() {
        let shared = EditRecord {
            light_share: Some(0.62),
            ..edit(2500, "light-estimate")
        };
        let text = written(&[(0, edit(1000, "object+x")), (1, shared.clone())], 3);
        let (_, read_edits) = read(&text).unwrap();
        assert_eq!(read_edits[0].light_share, None);
        assert_eq!(read_edits[1], shared);
        for bad in ["1.5", "-0.1", "NaN"] {
            let e = read(&text.replacen(",0.62\n", &format!(",{bad}\n"), 1)).unwrap_err();
            assert!(e.to_string().contains(EDIT_SHARE_FIELD), "{bad}: {e}");
        }
        // Not 18 fields.
        let e = read(&text.replacen(",0.62\n", ",0.62,0\n", 1)).unwrap_err();
        assert!(matches!(e, TraceError::FieldCount { .. }), "{e}");
    }

    fn written(edits_at: &[(usize, EditRecord)], samples: usize) -> String {
        let mut w =
            TraceWriter::with_version(Vec::new(), "edits.trace", TraceVersion::V1_2).unwrap();
        for i in 0..samples {
            w.write(&sample(1000 * (i as i64 + 1))).unwrap();
            for (_, e) in edits_at.iter().filter(|(after, _)| *after == i) {
                w.write_edit(e).unwrap();
            }
        }
        String::from_utf8(w.finish().unwrap()).unwrap()
    }

    fn read(text: &str) -> Result<(Vec<TraceSample>, Vec<EditRecord>), TraceError> {
        let mut r = TraceReader::new(text.as_bytes(), "edits.trace")?;
        let samples = r.by_ref().collect::<Result<Vec<_>, _>>()?;
        Ok((samples, r.take_edits()))
    }

    #[test]
    fn edits_round_trip_between_the_samples_of_a_v1_2_trace() {
        let edits = [(0, edit(1000, "object+x")), (1, edit(2500, "turn-10"))];
        let text = written(&edits, 3);
        assert!(text.starts_with("# vitreous-trace v1.2\n"), "{text}");
        let (samples, read_edits) = read(&text).unwrap();
        assert_eq!(samples.len(), 3);
        assert_eq!(read_edits.len(), 2);
        assert_eq!(read_edits[0], edits[0].1);
        assert_eq!(read_edits[1].action, "turn-10");
        assert!(
            read_edits[1]
                .object_turn
                .abs_diff_eq(edits[1].1.object_turn, 1e-7)
        );
        // An edit after the last sample is kept too.
        let (_, tail) = read(&written(&[(1, edit(2000, "place"))], 2)).unwrap();
        assert_eq!(tail.len(), 1);
    }

    #[test]
    fn edit_lines_are_refused_before_version_1_2_and_when_bad() {
        let text = written(&[(0, edit(1000, "light+y"))], 2);
        let v1_1 = text.replacen("v1.2", "v1.1", 1);
        let e = read(&v1_1).unwrap_err();
        assert!(matches!(e, TraceError::FieldCount { line: 4, .. }), "{e}");
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        let e = w.write_edit(&edit(0, "place")).unwrap_err();
        assert!(matches!(e, TraceError::EditsNotInVersion { .. }), "{e}");

        // Before the sample it follows.
        let early = text.replacen("edit,1000,", "edit,999,", 1);
        let e = read(&early).unwrap_err();
        assert!(
            matches!(e, TraceError::BadEdit { line: 4, .. }) && e.to_string().contains("999"),
            "{e}"
        );
        // An action with a space, a short line, a non-unit turn.
        let e = read(&text.replacen("light+y", "light y", 1)).unwrap_err();
        assert!(matches!(e, TraceError::BadEdit { line: 4, .. }), "{e}");
        let short = text.replacen(",light+y,", ",light+y,1,1,", 1);
        assert!(matches!(
            read(&short).unwrap_err(),
            TraceError::FieldCount { line: 4, .. }
        ));
        let mut bad = edit(1000, "turn+1");
        bad.object_turn = Quat::from_xyzw(0.0, 0.5, 0.0, 0.5);
        let mut w =
            TraceWriter::with_version(Vec::new(), "edits.trace", TraceVersion::V1_2).unwrap();
        w.write(&sample(1000)).unwrap();
        assert!(matches!(
            w.write_edit(&bad).unwrap_err(),
            TraceError::BadEdit { line: 4, .. }
        ));
    }

    #[test]
    fn version_1_2_example_in_the_format_doc_reads_with_its_edits() {
        let doc = include_str!("../../../docs/trace-format.md");
        let at = doc.find("```text\n# vitreous-trace v1.2").unwrap() + "```text\n".len();
        let end = at + doc[at..].find("```").unwrap();
        let (samples, edits) = read(&doc[at..end]).unwrap();
        assert_eq!(samples.len(), 2);
        assert_eq!(edits.len(), 2);
        assert_eq!(edits[1].action, "turn+10");
        let angle = edits[1]
            .object_turn
            .angle_between(Quat::IDENTITY)
            .to_degrees();
        assert!((angle - 10.0).abs() < 1e-3, "{angle}");
    }

    #[test]
    fn action_names_are_single_lower_case_words() {
        assert!(valid_action("object+x"));
        assert!(valid_action("register-z"));
        assert!(!valid_action(""));
        assert!(!valid_action("Object"));
        assert!(!valid_action("a,b"));
        assert!(!valid_action(&"x".repeat(MAX_ACTION_BYTES + 1)));
    }
}
