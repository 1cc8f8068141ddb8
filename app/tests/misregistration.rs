//! `vitreous compare --shift-deg / --roll-deg`: the display's light and panel landing away from
//! the real world, the ring around the object, and bad values.

use std::path::{Path, PathBuf};

use vitreous_frames::output::encode_png;

use crate::cli::{assert_clean_failure, vitreous};
use crate::compare::json;

fn ml2() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/glass-sphere-ml2.toml")
}

/// Writes RGBA pixels as a PNG.
fn write_rgba(path: &Path, rgba: &[u8], w: u32, h: u32) {
    std::fs::write(path, encode_png(rgba, w, h).unwrap()).unwrap();
}

/// A 160 x 120 view (4 pixels per degree over the scene's 40 degrees): the real scene with a
/// lit square that the display's light (`t.png`, no dimming) draws exactly, over a grey world.
fn lit_square(dir: &Path) {
    let (w, h) = (160u32, 120u32);
    let lit = |i: u32| (60..84).contains(&(i % w)) && (40..64).contains(&(i / w));
    let grey: Vec<u8> = (0..w * h).flat_map(|_| [90u8, 90, 90, 255]).collect();
    // 90 in sRGB is 0.102 linear; 0.102 + 0.5 is 0.602, 203 in sRGB.
    let real: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            if lit(i) {
                [203u8, 203, 203, 255]
            } else {
                [90, 90, 90, 255]
            }
        })
        .collect();
    let light: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            if lit(i) {
                [188u8, 188, 188, 0]
            } else {
                [0, 0, 0, 0]
            }
        })
        .collect();
    write_rgba(&dir.join("r.png"), &real, w, h);
    write_rgba(&dir.join("s.png"), &grey, w, h);
    write_rgba(&dir.join("t.png"), &light, w, h);
}

/// `compare r.png t.png --seen s.png --display` and then `extra`.
fn over_seen<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["compare", "r.png", "t.png", "--seen", "s.png", "--display"];
    args.extend_from_slice(extra);
    args
}

fn shifted(dir: &Path, extra: &[&str]) -> serde_json::Value {
    let scene = ml2();
    let mut args = over_seen(&["--scene", scene.to_str().unwrap(), "--json"]);
    args.extend_from_slice(extra);
    json(&args, dir)
}

fn whole_flip(report: &serde_json::Value) -> f64 {
    report["regions"][0]["flip_mean"].as_f64().unwrap()
}

#[test]
fn a_misregistered_display_lands_its_light_away_and_the_error_grows_with_the_angle() {
    let dir = tempfile::tempdir().unwrap();
    lit_square(dir.path());
    let registered = shifted(dir.path(), &[]);
    let zero = shifted(dir.path(), &["--shift-deg", "0,0"]);
    let one = shifted(dir.path(), &["--shift-deg", "1,0"]);
    let two = shifted(dir.path(), &["--shift-deg", "0,-2"]);
    let turned = shifted(dir.path(), &["--roll-deg", "10"]);
    // Registered, the light lands on the lit square: within rounding of the reference.
    assert!(whole_flip(&registered) < 0.001, "{registered}");
    assert_eq!(whole_flip(&zero), whole_flip(&registered));
    assert!(zero["misregistration_deg"].is_null());
    // A degree (4 px) and two (8 px) away, the square's edges are wrong on two sides.
    let (f1, f2) = (whole_flip(&one), whole_flip(&two));
    let r = whole_flip(&registered);
    assert!(f1 > 0.005 && f1 > 10.0 * r && f2 > f1, "{r} {f1} {f2}");
    assert_eq!(
        two["misregistration_deg"],
        serde_json::json!([0.0, -2.0, 0.0])
    );
    assert!(whole_flip(&turned) > 0.005, "{turned}");
    // The ring around the ball is reported after the regions, with its pixels.
    let rows = one["regions"].as_array().unwrap();
    let ring = rows.last().unwrap();
    assert_eq!(ring["region"], "around");
    assert!(ring["pixels"].as_u64().unwrap() > 100, "{ring}");
    assert_eq!(one["nothing_drawn"].as_array().unwrap().len(), rows.len());
}

#[test]
fn bad_shifts_and_rolls_are_refused_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    lit_square(dir.path());
    let scene = ml2();
    let scene = scene.to_str().unwrap();
    let base = [
        "compare",
        "r.png",
        "t.png",
        "--seen",
        "s.png",
        "--display",
        "--scene",
        scene,
    ];
    for (extra, says) in [
        (vec!["--shift-deg", "NaN,0"], "--shift-deg"),
        (vec!["--shift-deg", "11,0"], "from -10 to 10"),
        (vec!["--shift-deg", "1"], "X,Y"),
        (vec!["--shift-deg", "1,2,3"], "X,Y"),
        (vec!["--roll-deg", "90"], "--roll-deg"),
        (vec!["--roll-deg", "inf"], "from -45 to 45"),
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(&extra);
        let out = vitreous(&args, dir.path());
        assert_clean_failure(&out, &[says]);
    }
    // A shift needs the display's light (--display) and, to turn degrees into pixels, the
    // scene or --ppd.
    let out = vitreous(
        &["compare", "r.png", "t.png", "--shift-deg", "1,0"],
        dir.path(),
    );
    assert_clean_failure(&out, &["--display"]);
    let without_scene = |extra: &[&str]| {
        let mut args = over_seen(&["--shift-deg", "1,0"]);
        args.extend_from_slice(extra);
        vitreous(&args, dir.path())
    };
    assert_clean_failure(&without_scene(&[]), &["--scene", "--ppd"]);
    let out = without_scene(&["--ppd", "4"]);
    assert!(out.status.success(), "{out:?}");
}

#[test]
fn replay_refuses_bad_shift_angles_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ml2();
    let scene = scene.to_str().unwrap();
    for (extra, says) in [
        (
            vec!["--compare-reference", "--compare-shift-deg", "0"],
            "above 0",
        ),
        (
            vec!["--compare-reference", "--compare-shift-deg", "0.1,nan"],
            "--compare-shift-deg",
        ),
        (
            vec!["--compare-reference", "--compare-shift-deg", "12"],
            "at most 10",
        ),
        (vec!["--compare-shift-deg", "0.125"], "--compare-reference"),
    ] {
        let mut args = vec!["replay", scene, "--frames", "1", "--out", "out"];
        args.extend_from_slice(&extra);
        let out = vitreous(&args, dir.path());
        assert_clean_failure(&out, &[says]);
        assert!(
            !dir.path().join("out").exists(),
            "nothing written: {extra:?}"
        );
    }
}

/// The RGB pixels of a PNG.
fn read_rgb(path: &Path) -> Vec<u8> {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
        .into_raw()
}

#[test]
fn the_image_measured_is_written_with_the_light_where_the_error_puts_it() {
    let dir = tempfile::tempdir().unwrap();
    lit_square(dir.path());
    let (w, h) = (160usize, 120usize);
    let view = dir.path().join("v.png");
    let view_arg = view.to_str().unwrap();
    // Registered, what the eye sees is the real scene within rounding.
    shifted(dir.path(), &["--wearer-view", view_arg]);
    let real = read_rgb(&dir.path().join("r.png"));
    let seen = read_rgb(&view);
    assert!(
        real.iter().zip(&seen).all(|(a, b)| a.abs_diff(*b) <= 1),
        "registered view differs from the real scene"
    );
    // A degree right (4 px at 4 pixels per degree): the square lit over columns 64..88.
    shifted(
        dir.path(),
        &["--shift-deg", "1,0", "--wearer-view", view_arg],
    );
    let seen = read_rgb(&view);
    let at = |x: usize, y: usize| seen[(y * w + x) * 3];
    for y in 40..64 {
        for x in 56..92 {
            let lit = (64..88).contains(&x);
            assert_eq!(at(x, y) > 150, lit, "pixel ({x}, {y}): {}", at(x, y));
        }
    }
    assert_eq!(seen.len(), w * h * 3);
    // Without --display the image measured is TEST itself.
    std::fs::copy(dir.path().join("r.png"), dir.path().join("copy.png")).unwrap();
    json(
        &[
            "compare",
            "s.png",
            "copy.png",
            "--json",
            "--wearer-view",
            "v2.png",
        ],
        dir.path(),
    );
    assert_eq!(read_rgb(&dir.path().join("v2.png")), real);
}

#[test]
fn the_image_measured_is_never_written_over_an_input_or_the_map() {
    let dir = tempfile::tempdir().unwrap();
    lit_square(dir.path());
    let before = std::fs::read(dir.path().join("s.png")).unwrap();
    let run = |extra: &[&str]| {
        let mut args = over_seen(&["--ppd", "4"]);
        args.extend_from_slice(extra);
        vitreous(&args, dir.path())
    };
    assert_clean_failure(
        &run(&["--wearer-view", "s.png"]),
        &["--wearer-view", "s.png", "is the input file"],
    );
    assert_eq!(std::fs::read(dir.path().join("s.png")).unwrap(), before);
    assert_clean_failure(
        &run(&["--wearer-view", "m.png", "--map", "m.png"]),
        &["--map", "--wearer-view", "m.png"],
    );
    assert!(!dir.path().join("m.png").exists());
}
