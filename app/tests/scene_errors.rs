//! Every class of bad scene file and every broken asset gives an error that names the file,
//! line, column and field (and the asset), never a panic.

use std::path::{Path, PathBuf};

use vitreous_scene::{SceneError, load_scene};

pub(crate) fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub(crate) fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(rel)
}

/// A valid scene with absolute asset paths (TOML literal strings), model and env map
/// replaceable.
pub(crate) fn scene_text(model: &Path, env: &Path) -> String {
    let tex = repo().join("config/textures");
    format!(
        r#"[object]
model = '{model}'
diameter_m = 0.08
position_m = [0.0, -0.26, -1.5]

[light]
frame = "object"
position_m = [0.0, 1.0, -1.0]

[floor]
photo = '{floor}'
size_m = [1.0, 1.0]
position_m = [0.0, -0.30, -1.5]
rotation_deg = [-90.0, 0.0, 0.0]

[background]
photo = '{brick}'
size_m = [1.5, 1.5]
position_m = [0.0, 0.45, -2.0]

[environment]
map = '{env}'

[viewer]
ipd_mm = 63.0

[output]
width_px = 1280

[effects]
set = "none"
"#,
        model = model.display(),
        env = env.display(),
        floor = tex.join("gravel.png").display(),
        brick = tex.join("brick.png").display(),
    )
}

pub(crate) fn good_model() -> PathBuf {
    data("models/TransmissionTest.glb")
}

pub(crate) fn good_env() -> PathBuf {
    repo().join("config/env/forest_ll_zip.exr")
}

pub(crate) fn good_text() -> String {
    scene_text(&good_model(), &good_env())
}

/// Writes `text` to a fresh `scene.toml` and loads it.
pub(crate) fn load_text(
    text: &str,
) -> (
    tempfile::TempDir,
    PathBuf,
    Result<vitreous_scene::Scene, SceneError>,
) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let result = load_scene(&path);
    (dir, path, result)
}

/// The 1-based line of the first line containing `needle` outside single-quoted strings (the
/// scenes' paths are written so, and a checkout's folder names may hold any needle: "nan",
/// "-1"), else of the first containing it anywhere (a needle in a path).
pub(crate) fn line_of(text: &str, needle: &str) -> usize {
    let unquoted = |l: &str| l.split('\'').step_by(2).collect::<String>();
    let first = |hit: &dyn Fn(&str) -> bool| text.lines().position(hit);
    first(&|l| unquoted(l).contains(needle))
        .or_else(|| first(&|l| l.contains(needle)))
        .unwrap_or_else(|| panic!("{needle} not in text"))
        + 1
}

/// Loads `text`, expects an error at `line` about `field`, and returns its message.
pub(crate) fn expect_error(text: &str, line: usize, field: &str) -> String {
    let (_dir, path, result) = load_text(text);
    let err = result.expect_err("the scene should be refused");
    let msg = err.to_string();
    let at = err
        .location()
        .unwrap_or_else(|| panic!("no location in {msg}"));
    assert_eq!(at.line, line, "wrong line in: {msg}");
    assert!(at.column >= 1);
    let prefix = format!("{}:{}:{}", path.display(), at.line, at.column);
    assert!(
        msg.starts_with(&prefix),
        "{msg} does not start with {prefix}"
    );
    assert_eq!(err.field(), Some(field), "wrong field in: {msg}");
    assert!(msg.contains(field), "{msg} does not name {field}");
    msg
}

#[test]
fn valid_base_scene_loads() {
    let (_dir, _path, result) = load_text(&good_text());
    result.unwrap();
}

#[test]
fn missing_scene_file_names_it() {
    let err = load_scene(Path::new("/nonexistent/dir/scene.toml")).unwrap_err();
    assert!(matches!(err, SceneError::Read { .. }));
    assert!(err.to_string().contains("/nonexistent/dir/scene.toml"));
}

#[test]
fn syntax_error_points_at_line_and_key() {
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = 0.08 m");
    let msg = expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
    assert!(msg.contains("syntax"), "{msg}");
}

#[test]
fn unknown_field_is_named() {
    let text = good_text().replace("diameter_m = 0.08", "diamter_m = 0.08");
    let msg = expect_error(&text, line_of(&text, "diamter_m"), "object.diamter_m");
    assert!(msg.contains("unknown field"), "{msg}");
}

#[test]
fn unknown_table_is_named() {
    let text = format!("{}\n[lights]\nposition_m = [0, 0, 0]\n", good_text());
    expect_error(&text, line_of(&text, "[lights]"), "lights");
}

#[test]
fn wrong_type_is_named() {
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = \"big\"");
    let msg = expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
    assert!(
        msg.contains("expected a number, found string \"big\""),
        "{msg}"
    );
}

#[test]
fn wrong_array_length_is_named() {
    let text = good_text().replace("size_m = [1.0, 1.0]", "size_m = [1.0, 1.0, 1.0]");
    expect_error(
        &text,
        line_of(&text, "size_m = [1.0, 1.0, 1.0]"),
        "floor.size_m",
    );
}

#[test]
fn missing_required_field_is_named_at_its_table() {
    let floor = repo().join("config/textures/gravel.png");
    let text = good_text().replace(&format!("photo = '{}'\n", floor.display()), "");
    let (_dir, _path, result) = load_text(&text);
    let err = result.unwrap_err();
    let msg = err.to_string();
    assert_eq!(err.field(), Some("floor.photo"), "{msg}");
    assert!(msg.contains("missing field"), "{msg}");
    let line = err.location().unwrap().line;
    let floor_line = line_of(&text, "[floor]");
    assert!(
        (floor_line..floor_line + 4).contains(&line),
        "line {line} is not in the [floor] table: {msg}"
    );
}

#[test]
fn missing_required_table_is_named() {
    let text = good_text().replace("[environment]\n", "[environment_]\n");
    let (_dir, _path, result) = load_text(&text);
    let err = result.unwrap_err();
    assert!(err.location().is_some());
    assert!(err.to_string().contains("environment"), "{err}");
}

#[test]
fn out_of_range_value_is_named() {
    let text = good_text().replace("ipd_mm = 63.0", "ipd_mm = 120");
    let msg = expect_error(&text, line_of(&text, "ipd_mm"), "viewer.ipd_mm");
    assert!(msg.contains("120"), "{msg}");
    let text = good_text().replace("width_px = 1280", "width_px = 10");
    expect_error(&text, line_of(&text, "width_px"), "output.width_px");
    for samples in ["0", "9", "2.5"] {
        let text = good_text().replace(
            "width_px = 1280",
            &format!("width_px = 1280\nglass_samples = {samples}"),
        );
        let msg = expect_error(
            &text,
            line_of(&text, "glass_samples"),
            "output.glass_samples",
        );
        // A fraction is refused as a number out of range is, with the range in words.
        assert!(
            msg.contains(
                "expected a whole number of positions along each side of a pixel from 1 to 8"
            ),
            "{msg}"
        );
        assert!(msg.contains(samples), "{msg}");
    }
    for yaw in ["400", "-361", "\"east\""] {
        let text = good_text().replace("map = '", &format!("yaw_deg = {yaw}\nmap = '"));
        let msg = expect_error(&text, line_of(&text, "yaw_deg"), "environment.yaw_deg");
        assert!(msg.contains(yaw.trim_matches('"')), "{msg}");
    }
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = 12.0");
    expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = -0.1");
    expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
}

#[test]
fn unknown_refraction_model_is_named() {
    let text = good_text().replace(
        "diameter_m = 0.08",
        "diameter_m = 0.08\nrefraction = \"thick\"",
    );
    let msg = expect_error(&text, line_of(&text, "refraction"), "object.refraction");
    assert!(
        msg.contains("two-surface") && msg.contains("thick"),
        "{msg}"
    );
}

#[test]
fn non_finite_numbers_are_refused() {
    let text = good_text().replace(
        "position_m = [0.0, -0.26, -1.5]",
        "position_m = [nan, -0.26, -1.5]",
    );
    expect_error(&text, line_of(&text, "[nan"), "object.position_m");
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = inf");
    expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
}

#[test]
fn diameter_and_scale_together_are_refused() {
    let text = good_text().replace("diameter_m = 0.08", "diameter_m = 0.08\nscale = 2.0");
    let msg = expect_error(&text, line_of(&text, "diameter_m"), "object.diameter_m");
    assert!(msg.contains("scale"), "{msg}");
}

#[test]
fn missing_photo_file_names_field_and_file() {
    let floor = repo().join("config/textures/gravel.png");
    let text = good_text().replace(
        &floor.display().to_string(),
        &floor
            .with_file_name("no-such-photo.png")
            .display()
            .to_string(),
    );
    let msg = expect_error(&text, line_of(&text, "no-such-photo"), "floor.photo");
    assert!(msg.contains("no-such-photo.png: file not found"), "{msg}");
}

#[test]
fn photo_that_is_not_a_png_is_refused() {
    let text = good_text().replace(
        &repo()
            .join("config/textures/brick.png")
            .display()
            .to_string(),
        &good_env().display().to_string(),
    );
    let msg = expect_error(
        &text,
        line_of(&text, "forest_ll_zip.exr'"),
        "background.photo",
    );
    assert!(msg.contains("forest_ll_zip.exr"), "{msg}");
}

#[test]
fn unknown_effect_is_named_with_valid_list() {
    let text = good_text().replace("set = \"none\"", "set = \"disparity,sparkle\"");
    let msg = expect_error(&text, line_of(&text, "sparkle"), "effects.set");
    assert!(
        msg.contains("'sparkle'") && msg.contains("defocus"),
        "{msg}"
    );
}

#[test]
fn unimplemented_effects_still_parse() {
    let text = good_text().replace("set = \"none\"", "set = \"O5\"");
    let (_dir, _path, result) = load_text(&text);
    let scene = result.unwrap();
    assert!(scene.effects.disparity && scene.effects.defocus);
}

#[test]
fn transmittance_needs_a_texture_and_a_range() {
    let text = good_text().replace(
        "diameter_m = 0.08",
        "diameter_m = 0.08\nsurface_transmittance = 0.5",
    );
    expect_error(
        &text,
        line_of(&text, "surface_transmittance"),
        "object.surface_transmittance",
    );
    let tex = repo().join("config/textures/surface-dots.png");
    let text = good_text().replace(
        "diameter_m = 0.08",
        &format!(
            "diameter_m = 0.08\nsurface_texture = '{}'\nsurface_transmittance = 1.5",
            tex.display()
        ),
    );
    expect_error(
        &text,
        line_of(&text, "surface_transmittance"),
        "object.surface_transmittance",
    );
}

#[test]
fn gaze_pupil_source_is_read_and_a_bad_one_named() {
    use vitreous_gaze::PupilSource;
    let (_dir, _path, result) = load_text(&good_text());
    assert_eq!(result.unwrap().gaze.pupil, PupilSource::Paper);
    let text = format!("{}\n[gaze]\npupil = \"measured\"\n", good_text());
    let (_dir, _path, result) = load_text(&text);
    assert_eq!(result.unwrap().gaze.pupil, PupilSource::Measured);
    let text = format!("{}\n[gaze]\npupil = \"tracker\"\n", good_text());
    let msg = expect_error(&text, line_of(&text, "pupil ="), "gaze.pupil");
    assert!(msg.contains("paper or measured"), "{msg}");
}

/// The base scene with `[motion]` light keyframes at `times` (seconds), `position` as written
/// for the second one.
fn motion_text(times: [&str; 3], second_position: &str) -> String {
    format!(
        "{}\n[motion]\n\n[[motion.light]]\ntime_s = {}\nposition_m = [0.0, 1.0, -1.0]\n\n\
         [[motion.light]]\ntime_s = {}\nposition_m = {second_position}\n\n\
         [[motion.light]]\ntime_s = {}\nposition_m = [1.0, 1.0, 0.0]\n",
        good_text(),
        times[0],
        times[1],
        times[2]
    )
}

#[test]
fn keyframes_out_of_order_are_refused_at_their_time() {
    let text = motion_text(["0.0", "2.0", "1.0"], "[1.0, 1.0, 0.0]");
    let msg = expect_error(
        &text,
        line_of(&text, "time_s = 1.0"),
        "motion.light[2].time_s",
    );
    assert!(msg.contains("increase strictly"), "{msg}");
    // Equal times too.
    let text = motion_text(["0.0", "1.0", "1.0"], "[1.0, 1.0, 0.0]");
    let lines: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("time_s = 1.0"))
        .map(|(i, _)| i + 1)
        .collect();
    expect_error(&text, lines[1], "motion.light[2].time_s");
}

#[test]
fn keyframe_nan_and_negative_times_and_wrong_lengths_are_refused() {
    let text = motion_text(["0.0", "nan", "3.0"], "[1.0, 1.0, 0.0]");
    let msg = expect_error(&text, line_of(&text, "nan"), "motion.light[1].time_s");
    assert!(msg.contains("NaN"), "{msg}");
    let text = motion_text(["-1.0", "1.0", "3.0"], "[1.0, 1.0, 0.0]");
    expect_error(
        &text,
        line_of(&text, "time_s = -1.0"),
        "motion.light[0].time_s",
    );
    let text = motion_text(["0.0", "1.0", "3.0"], "[1.0, 1.0]");
    let msg = expect_error(
        &text,
        line_of(&text, "position_m = [1.0, 1.0]"),
        "motion.light[1].position_m",
    );
    assert!(msg.contains("3 numbers"), "{msg}");
    let text = motion_text(["0.0", "1.0", "3.0"], "[nan, 1.0, 0.0]");
    expect_error(&text, line_of(&text, "[nan"), "motion.light[1].position_m");
}

#[test]
fn object_keyframe_rotation_and_repeat_are_checked() {
    let text = format!(
        "{}\n[motion]\nrepeat_s = 0.5\n\n[[motion.object]]\ntime_s = 0.0\n\
         position_m = [0.0, -0.26, -1.5]\nrotation_deg = [0.0, 400.0, 0.0]\n\n\
         [[motion.object]]\ntime_s = 1.0\nposition_m = [0.1, -0.26, -1.5]\n",
        good_text()
    );
    expect_error(
        &text,
        line_of(&text, "400.0"),
        "motion.object[0].rotation_deg",
    );
    let text = text.replace("rotation_deg = [0.0, 400.0", "rotation_deg = [0.0, 40.0");
    // The period ends before the last keyframe.
    let msg = expect_error(&text, line_of(&text, "repeat_s"), "motion.repeat_s");
    assert!(msg.contains("last keyframe"), "{msg}");
    let text = text.replace("repeat_s = 0.5", "repeat_s = 2.0");
    let (_dir, _path, result) = load_text(&text);
    assert!(result.unwrap().motion.is_animated());
}

#[test]
fn caustics_mode_and_live_sizes_are_checked() {
    let text = format!("{}\n[caustics]\nmode = \"realtime\"\n", good_text());
    let msg = expect_error(&text, line_of(&text, "realtime"), "caustics.mode");
    assert!(msg.contains("baked or live"), "{msg}");
    let text = format!(
        "{}\n[caustics]\nmode = \"live\"\nphotons_per_side = 0\n",
        good_text()
    );
    expect_error(
        &text,
        line_of(&text, "photons_per_side"),
        "caustics.photons_per_side",
    );
    let text = format!(
        "{}\n[caustics]\nmode = \"live\"\nsmoothing_px = -1\n",
        good_text()
    );
    expect_error(
        &text,
        line_of(&text, "smoothing_px"),
        "caustics.smoothing_px",
    );
    // The field alone: the scene's paths may hold "-1" (a checkout's folder name).
    let text = text.replace("smoothing_px = -1", "smoothing_px = 3");
    let (_dir, _path, result) = load_text(&text);
    assert_eq!(result.unwrap().caustics.smoothing_px, 3);
    for weight in ["0.0", "1.0", "-0.5", "nan"] {
        let text = format!(
            "{}\n[caustics]\nmode = \"live\"\nmin_path_weight = {weight}\n",
            good_text()
        );
        let msg = expect_error(
            &text,
            line_of(&text, "min_path_weight"),
            "caustics.min_path_weight",
        );
        assert!(msg.contains("> 0 and < 1"), "{msg}");
    }
    let text = format!(
        "{}\n[caustics]\nmode = \"live\"\nmin_path_weight = 0.05\n",
        good_text()
    );
    let (_dir, _path, result) = load_text(&text);
    assert_eq!(result.unwrap().caustics.min_path_weight, 0.05);
    let text = format!(
        "{}\n[caustics]\nmode = \"live\"\nresolution_px = 8\n",
        good_text()
    );
    expect_error(
        &text,
        line_of(&text, "resolution_px"),
        "caustics.resolution_px",
    );
    // A live scene needs no bake: its map is zeros of the given size until the renderer
    // fills it.
    let text = format!(
        "{}\n[caustics]\nmode = \"live\"\nresolution_px = 64\n",
        good_text()
    );
    let (_dir, _path, result) = load_text(&text);
    let mut scene = result.unwrap();
    scene.load_caustics().unwrap();
    let map = scene.caustics.gain.as_ref().unwrap();
    assert_eq!(
        (map.width_px, map.height_px, map.gain.len()),
        (64, 64, 64 * 64)
    );
}

/// A value of the wrong type says what the field takes in words (the range of a whole number),
/// never a Rust type such as `i64` or `i128`.
#[test]
fn wrong_types_and_huge_numbers_are_named_in_words() {
    for (value, says) in [
        (
            "1.5",
            "expected a whole number of pixels from 16 to 8192, found 1.5",
        ),
        (
            "99999999999999999999",
            "expected a whole number of pixels from 16 to 8192, found 99999999999999999999",
        ),
        (
            "-3",
            "expected a whole number of pixels from 16 to 8192, found -3",
        ),
        ("\"wide\"", "expected a whole number, found string \"wide\""),
    ] {
        let text = good_text().replace("width_px = 1280", &format!("width_px = {value}"));
        let msg = expect_error(&text, line_of(&text, "width_px"), "output.width_px");
        assert!(msg.contains(says), "{value}: {msg}");
        assert!(!msg.contains("i64") && !msg.contains("i128"), "{msg}");
    }
    let text = good_text().replace("ipd_mm = 63.0", "ipd_mm = 99999999999999999999");
    let msg = expect_error(&text, line_of(&text, "ipd_mm"), "viewer.ipd_mm");
    assert!(!msg.contains("i128"), "{msg}");
    let text = good_text().replace("[output]", "[inducer]\nresolution_px = 0.5\n\n[output]");
    let msg = expect_error(
        &text,
        line_of(&text, "resolution_px"),
        "inducer.resolution_px",
    );
    assert!(
        msg.contains("a whole number of texels from 16 to 4096"),
        "{msg}"
    );
}
