//! Scenes that could not exist as a real room are named (a plane between the light and the
//! object, an object sunk into the floor), at rest and along `[motion]`, and `[light] share` is
//! read and checked.

use crate::scene_errors::{expect_error, good_text, line_of, load_text};

/// The base scene with `from` replaced by `to` (which must be there).
fn with(from: &str, to: &str) -> String {
    let text = good_text();
    assert!(text.contains(from), "{from} not in the base scene");
    text.replace(from, to)
}

fn warnings(text: &str) -> Vec<String> {
    let (_dir, _path, result) = load_text(text);
    result.expect("the scene loads").warnings
}

#[test]
fn a_wall_between_the_light_and_the_object_is_named_with_its_fields() {
    // The base scene keeps the paper's light 1 m beyond the object, 0.5 m behind the wall.
    let w = warnings(&good_text());
    assert_eq!(w.len(), 1, "{w:?}");
    for field in [
        "background.position_m",
        "background.size_m",
        "light.position_m",
        "object.position_m",
    ] {
        assert!(w[0].contains(field), "{} does not name {field}", w[0]);
    }
    assert!(w[0].contains("[0.00, 0.24, -2.00]"), "{}", w[0]);
}

#[test]
fn a_wall_behind_the_light_or_beside_its_path_is_no_warning() {
    for wall in [
        "position_m = [0.0, 0.45, -2.6]",
        // Moved aside: the light's path passes it by.
        "position_m = [1.5, 0.45, -2.0]",
    ] {
        let text = with("position_m = [0.0, 0.45, -2.0]", wall);
        assert_eq!(warnings(&text), Vec::<String>::new(), "{wall}");
    }
}

#[test]
fn a_light_under_the_floor_is_named() {
    let text = with(
        "position_m = [0.0, 1.0, -1.0]",
        "position_m = [0.0, -1.0, 0.2]",
    );
    let w = warnings(&text);
    assert!(
        w.iter().any(|w| w.contains("the floor (floor.position_m")),
        "{w:?}"
    );
}

#[test]
fn an_object_sunk_into_the_floor_is_named_and_one_resting_on_it_is_not() {
    let rests = with(
        "position_m = [0.0, 1.0, -1.0]",
        "position_m = [0.0, 1.0, 1.0]",
    );
    assert_eq!(warnings(&rests), Vec::<String>::new());
    let sunk = rests.replace(
        "position_m = [0.0, -0.26, -1.5]",
        "position_m = [0.0, -0.32, -1.5]",
    );
    let w = warnings(&sunk);
    let sunk = w
        .iter()
        .find(|w| w.contains("into the floor"))
        .unwrap_or_else(|| panic!("{w:?}"));
    for field in ["object.position_m", "object.diameter_m", "floor.position_m"] {
        assert!(sunk.contains(field), "{sunk} does not name {field}");
    }
}

#[test]
fn light_share_defaults_to_the_papers_one_and_is_read() {
    let (_dir, _path, scene) = load_text(&good_text());
    assert_eq!(scene.unwrap().light.share, 1.0);
    let text = with("frame = \"object\"\n", "frame = \"object\"\nshare = 0.5\n");
    let (_dir, _path, scene) = load_text(&text);
    assert_eq!(scene.unwrap().light.share, 0.5);
}

#[test]
fn a_light_share_outside_zero_to_one_names_the_field() {
    for bad in ["1.5", "-0.1", "nan"] {
        let text = with(
            "frame = \"object\"\n",
            &format!("frame = \"object\"\nshare = {bad}\n"),
        );
        let msg = expect_error(&text, line_of(&text, "share ="), "light.share");
        assert!(msg.contains(">= 0 and <= 1"), "{msg}");
    }
}

#[test]
fn display_compensation_is_read_and_an_unknown_one_names_the_field() {
    let (_dir, _path, scene) = load_text(&good_text());
    assert_eq!(
        scene.unwrap().compensation,
        vitreous_optics::display::Compensation::None
    );
    let text = format!(
        "{}\n[display]\ncompensation = \"background\"\n",
        good_text()
    );
    let (_dir, _path, scene) = load_text(&text);
    assert_eq!(
        scene.unwrap().compensation,
        vitreous_optics::display::Compensation::Background
    );
    let text = format!("{}\n[display]\ncompensation = \"half\"\n", good_text());
    let msg = expect_error(
        &text,
        line_of(&text, "compensation ="),
        "display.compensation",
    );
    assert!(msg.contains("\"none\" or \"background\""), "{msg}");
}

#[test]
fn the_global_dimmer_is_a_level_from_0_to_1_or_not_asked_for() {
    let (_dir, _path, scene) = load_text(&good_text());
    assert_eq!(scene.unwrap().global_dimmer, None);
    let text = format!("{}\n[display]\nglobal_dimmer = 0.25\n", good_text());
    let (_dir, _path, scene) = load_text(&text);
    assert_eq!(scene.unwrap().global_dimmer, Some(0.25));
    for bad in ["1.5", "-0.1", "nan"] {
        let text = format!("{}\n[display]\nglobal_dimmer = {bad}\n", good_text());
        expect_error(
            &text,
            line_of(&text, "global_dimmer ="),
            "display.global_dimmer",
        );
    }
}

#[test]
fn a_dimmer_display_takes_magic_leap_2s_defaults_and_refuses_what_it_cannot_be() {
    let (_dir, _path, scene) = load_text(&good_text());
    assert_eq!(scene.unwrap().dimmer, None);
    let text = format!("{}\n[display]\nmodel = \"dimmer\"\n", good_text());
    let (_dir, _path, scene) = load_text(&text);
    let dimmer = scene.unwrap().dimmer.expect("a dimmer");
    assert_eq!(dimmer.cells, [64, 48]);
    assert_eq!(dimmer.blur_deg, 1.5);
    assert!((dimmer.max - (1.0 - 0.3 / 22.0)).abs() < 1e-6);
    let text = format!(
        "{}\n[display]\nmodel = \"dimmer\"\ndimmer_cells = [32, 24]\ndimmer_blur_deg = 2\ndimmer_max = 0.5\n",
        good_text()
    );
    let (_dir, _path, scene) = load_text(&text);
    let scene = scene.unwrap();
    let dimmer = scene.dimmer.expect("a dimmer");
    assert_eq!(
        (dimmer.cells, dimmer.blur_deg, dimmer.max),
        ([32, 24], 2.0, 0.5)
    );
    // The registration error the display is planned for: the default, or the scene's, also
    // handed to the dimmer.
    assert_eq!(scene.registration_error_deg, 0.125);
    assert_eq!(dimmer.registration_error_deg, 0.125);
    let text = format!(
        "{}\n[display]\nmodel = \"dimmer\"\nregistration_error_deg = 0.5\n",
        good_text()
    );
    let (_dir, _path, scene) = load_text(&text);
    let scene = scene.unwrap();
    assert_eq!(scene.registration_error_deg, 0.5);
    assert_eq!(scene.dimmer.unwrap().registration_error_deg, 0.5);
    let cases = [
        (
            "registration_error_deg = -0.1",
            "registration_error_deg =",
            "display.registration_error_deg",
            ">= 0",
        ),
        (
            "registration_error_deg = nan",
            "registration_error_deg =",
            "display.registration_error_deg",
            "found NaN",
        ),
        (
            "model = \"dimmer\"\nregistration_error_deg = 6",
            "registration_error_deg =",
            "display.registration_error_deg",
            "<= 5",
        ),
        (
            "model = \"lcd\"",
            "model = \"lcd\"",
            "display.model",
            "\"additive\" or \"dimmer\"",
        ),
        (
            "dimmer_blur_deg = 1",
            "dimmer_blur_deg =",
            "display.dimmer_blur_deg",
            "model = \"dimmer\"",
        ),
        (
            "model = \"dimmer\"\ndimmer_cells = [64.5, 48]",
            "dimmer_cells =",
            "display.dimmer_cells",
            "whole numbers",
        ),
        (
            "model = \"dimmer\"\ndimmer_cells = [64]",
            "dimmer_cells =",
            "display.dimmer_cells",
            "2 numbers",
        ),
        (
            "model = \"dimmer\"\ndimmer_max = 1.5",
            "dimmer_max =",
            "display.dimmer_max",
            "<= 1",
        ),
        (
            "model = \"dimmer\"\ndimmer_blur_deg = 10",
            "dimmer_blur_deg =",
            "display.dimmer_blur_deg",
            "fewer cells or less blur",
        ),
    ];
    for (fields, at, field, says) in cases {
        let text = format!("{}\n[display]\n{fields}\n", good_text());
        let msg = expect_error(&text, line_of(&text, at), field);
        assert!(msg.contains(says), "{fields}: {msg}");
    }
}

/// The base scene with its light in front of the object (no warning at rest) and `motion`
/// appended.
fn resting_with_motion(motion: &str) -> String {
    let rests = with(
        "position_m = [0.0, 1.0, -1.0]",
        "position_m = [0.0, 1.0, 1.0]",
    );
    assert_eq!(warnings(&rests), Vec::<String>::new());
    format!("{rests}\n{motion}")
}

#[test]
fn an_object_keyframe_sunk_into_the_floor_is_named_with_its_time() {
    // The model's lowest point rests 18 mm over the floor; down 35 mm over 2 s, it is more
    // than the 2 mm tolerance into the floor from 1.14 s, first seen at the check 1.2 s in
    // (four checks between two keyframes), its centre still above the floor.
    let text = resting_with_motion(
        "[[motion.object]]\ntime_s = 0.0\nposition_m = [0.0, -0.26, -1.5]\n\
         [[motion.object]]\ntime_s = 2.0\nposition_m = [0.0, -0.295, -1.5]\n",
    );
    let w = warnings(&text);
    assert_eq!(w.len(), 1, "{w:?}");
    for part in [
        "1.20 s into its motion (motion.object)",
        "mm into the floor",
        "raise the keyframes",
    ] {
        assert!(w[0].contains(part), "{} does not say {part}", w[0]);
    }
}

#[test]
fn a_light_keyframe_path_behind_the_wall_is_named_with_its_time() {
    // The light (following the object) swings from in front of it to 1 m behind it, past the
    // wall 0.5 m behind the object.
    let text = resting_with_motion(
        "[[motion.light]]\ntime_s = 0.0\nposition_m = [0.0, 1.0, 1.0]\n\
         [[motion.light]]\ntime_s = 4.0\nposition_m = [0.0, 1.0, -1.0]\n",
    );
    let w = warnings(&text);
    assert_eq!(w.len(), 1, "{w:?}");
    for part in [
        "s into its motion (motion.light)",
        "the background (background.position_m, background.size_m)",
        "change the keyframes",
    ] {
        assert!(w[0].contains(part), "{} does not say {part}", w[0]);
    }
}

#[test]
fn a_motion_a_real_room_allows_and_a_warning_already_given_at_rest_add_nothing() {
    // The ball rolls 0.2 m along the floor, its light following.
    let rolls = "[[motion.object]]\ntime_s = 0.0\nposition_m = [0.0, -0.26, -1.5]\n\
                 [[motion.object]]\ntime_s = 3.0\nposition_m = [0.2, -0.26, -1.5]\n";
    assert_eq!(warnings(&resting_with_motion(rolls)), Vec::<String>::new());
    // The base scene's light stands behind the wall at rest and all along the roll: one
    // warning, the resting one.
    let w = warnings(&format!("{}\n{rolls}", good_text()));
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("(light.position_m)"), "{}", w[0]);
}

#[test]
fn an_object_behind_the_wall_out_of_the_viewers_sight_is_named_with_its_fields() {
    // Half a metre behind the wall, its light (following it) behind it too: only the wall
    // between the viewer's head (at the origin) and the object.
    let behind = with(
        "position_m = [0.0, -0.26, -1.5]",
        "position_m = [0.0, -0.26, -2.5]",
    );
    let w = warnings(&behind);
    assert_eq!(w.len(), 1, "{w:?}");
    for part in [
        "the background (background.position_m, background.size_m)",
        "the viewer (viewer.head_position_m)",
        "the object (object.position_m)",
        "at [0.00, -0.21, -2.00] m",
        "could not see a real object there",
    ] {
        assert!(w[0].contains(part), "{} does not say {part}", w[0]);
    }
    // The viewer's head from the scene: behind the wall as well, the object is in sight.
    let beside = behind.replace(
        "ipd_mm = 63.0",
        "ipd_mm = 63.0\nhead_position_m = [0.0, 0.0, -2.3]",
    );
    assert_eq!(warnings(&beside), Vec::<String>::new());
}

#[test]
fn an_object_keyframe_behind_the_wall_is_named_with_its_time() {
    // From its place on the table to 1 m further over 2 s: behind the wall (0.5 m behind
    // its place) from 1 s on, first seen at the check 1.2 s in.
    let text = resting_with_motion(
        "[[motion.object]]\ntime_s = 0.0\nposition_m = [0.0, -0.26, -1.5]\n\
         [[motion.object]]\ntime_s = 2.0\nposition_m = [0.0, -0.26, -2.5]\n",
    );
    let w = warnings(&text);
    let hidden = w
        .iter()
        .find(|w| w.contains("the viewer"))
        .unwrap_or_else(|| panic!("{w:?}"));
    for part in [
        "1.20 s into its motion (motion.object)",
        "the background (background.position_m, background.size_m)",
        "the viewer (viewer.head_position_m)",
        "change the keyframes",
    ] {
        assert!(hidden.contains(part), "{hidden} does not say {part}");
    }
}
