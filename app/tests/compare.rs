//! `vitreous compare`: FLIP and PSNR over the whole view and per region of a scene, the error
//! map, and bad input.

use std::path::{Path, PathBuf};

use vitreous_compare::{Eye, Region, regions};
use vitreous_frames::output::encode_png;
use vitreous_scene::load_scene;

use crate::cli::{assert_clean_failure, vitreous};

fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/glass-sphere.toml")
}

/// Writes an RGB image as a PNG.
fn write_png(path: &Path, rgb: &[u8], w: u32, h: u32) {
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    std::fs::write(path, encode_png(&rgba, w, h).unwrap()).unwrap();
}

pub(crate) fn json(args: &[&str], cwd: &Path) -> serde_json::Value {
    let out = vitreous(args, cwd);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn region<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["regions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["region"] == name)
        .unwrap_or_else(|| panic!("no {name} in {report}"))
}

#[test]
fn the_disc_matches_the_balls_projection_and_the_floor_regions_lie_under_it() {
    let scene = load_scene(&scene_path()).unwrap();
    let (w, h) = (640u32, 480u32);
    let labels = regions(&scene, Eye::Left, w, h);
    let count = |r: Region| labels.iter().filter(|&&l| l == r).count() as f32;
    // The ball's outline from the left eye: the cone of half-angle alpha = asin(r / d) about
    // the centre's direction, theta off the view axis, cuts the image plane (focal length f
    // from the field of view) in an ellipse of semi-axes f sin(alpha) cos(alpha) / k and
    // f sin(alpha) / sqrt(k), k = cos^2(theta) - sin^2(alpha).
    let eye = scene.viewer.head_position_m - glam::Vec3::X * scene.viewer.ipd_m / 2.0;
    let to_centre = scene.object.center_m - eye;
    let d = to_centre.length();
    let cos_theta = -to_centre.z / d;
    let sin_alpha = scene.object.radius_m / d;
    let k = cos_theta * cos_theta - sin_alpha * sin_alpha;
    let f = (w as f32 / 2.0) / scene.output.fov.angle_right_rad.tan();
    let major = f * sin_alpha * (1.0 - sin_alpha * sin_alpha).sqrt() / k;
    let minor = f * sin_alpha / k.sqrt();
    let expected = std::f32::consts::PI * major * minor;
    assert!(
        (count(Region::Disc) - expected).abs() < 0.05 * expected,
        "{} disc pixels, expected {expected}",
        count(Region::Disc)
    );
    // The shadow falls on the floor towards the viewer, ringed by the ramp (D = 140 mm, far
    // wider than the shadow).
    assert!(count(Region::ShadowCaustic) > 50.0);
    assert!(count(Region::InducerRamp) > 4.0 * count(Region::ShadowCaustic));
    let lowest_row = |r: Region| {
        (0..labels.len())
            .filter(|&i| labels[i] == r)
            .map(|i| i as u32 / w)
            .max()
            .unwrap()
    };
    assert!(lowest_row(Region::ShadowCaustic) > lowest_row(Region::Disc));
}

#[test]
fn identical_images_score_zero_and_a_uniform_step_gives_its_psnr() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64u32, 48u32);
    let grey = vec![100u8; (w * h * 3) as usize];
    let brighter = vec![110u8; (w * h * 3) as usize];
    write_png(&dir.path().join("a.png"), &grey, w, h);
    write_png(&dir.path().join("b.png"), &brighter, w, h);
    let same = json(&["compare", "a.png", "a.png", "--json"], dir.path());
    let whole = region(&same, "whole");
    assert_eq!(whole["flip_mean"], 0.0);
    assert!(whole["psnr_db"].is_null());
    assert_eq!(whole["pixels"], u64::from(w * h));
    let step = json(&["compare", "a.png", "b.png", "--json"], dir.path());
    let whole = region(&step, "whole");
    // PSNR = 20 log10(255 / 10) for an error of 10 in every channel of every pixel.
    let psnr = whole["psnr_db"].as_f64().unwrap();
    assert!((psnr - 20.0 * (25.5f64).log10()).abs() < 1e-9, "{psnr}");
    assert!(whole["flip_mean"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_change_inside_the_disc_is_charged_to_the_disc() {
    let scene = load_scene(&scene_path()).unwrap();
    let (w, h) = (320u32, 240u32);
    let labels = regions(&scene, Eye::Left, w, h);
    // A textured reference, and the test with the disc's inner pixels (every neighbour within
    // 3 px also disc) turned bright.
    let reference: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let v = (40 + (i * 7919) % 120) as u8;
            [v, v, v]
        })
        .collect();
    let inner = |i: u32| {
        let (x, y) = ((i % w) as i32, (i / w) as i32);
        (-3..=3).all(|dy| {
            (-3..=3).all(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                nx >= 0
                    && ny >= 0
                    && nx < w as i32
                    && ny < h as i32
                    && labels[(ny as u32 * w + nx as u32) as usize] == Region::Disc
            })
        })
    };
    let mut test = reference.clone();
    let mut changed = 0;
    for i in (0..w * h).filter(|&i| inner(i)) {
        test[(i * 3) as usize..(i * 3 + 3) as usize].copy_from_slice(&[250, 240, 200]);
        changed += 1;
    }
    assert!(changed > 20, "{changed}");
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("ref.png"), &reference, w, h);
    write_png(&dir.path().join("test.png"), &test, w, h);
    let scene = scene_path();
    let report = json(
        &[
            "compare",
            "ref.png",
            "test.png",
            "--scene",
            scene.to_str().unwrap(),
            "--map",
            "map.png",
            "--json",
        ],
        dir.path(),
    );
    let flip = |name: &str| region(&report, name)["flip_mean"].as_f64().unwrap();
    assert!(flip("disc") > 0.2, "{report}");
    for other in ["shadow_caustic", "inducer_ramp", "rest"] {
        assert!(flip(other) < flip("disc") / 20.0, "{other}: {report}");
    }
    // The regions and the whole view count every pixel once.
    let pixels = |name: &str| region(&report, name)["pixels"].as_u64().unwrap();
    assert_eq!(
        ["disc", "shadow_caustic", "inducer_ramp", "rest"]
            .map(pixels)
            .iter()
            .sum::<u64>(),
        pixels("whole")
    );
    // The scene's pixels per degree: 320 px over 40 degrees.
    assert_eq!(report["pixels_per_degree"], 8.0);
    let map = image::open(dir.path().join("map.png")).unwrap();
    assert_eq!((map.width(), map.height()), (w, h));
}

#[test]
fn bad_images_are_named_and_no_map_is_written() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("a.png"), &[0; 16 * 8 * 3], 16, 8);
    write_png(&dir.path().join("b.png"), &[0; 8 * 8 * 3], 8, 8);
    std::fs::write(dir.path().join("text.png"), "not a png").unwrap();
    let out = vitreous(&["compare", "a.png", "b.png", "--map", "m.png"], dir.path());
    assert_clean_failure(&out, &["a.png is 16x8", "b.png is 8x8", "differ in size"]);
    let out = vitreous(
        &["compare", "a.png", "text.png", "--map", "m.png"],
        dir.path(),
    );
    assert_clean_failure(&out, &["text.png", "not a PNG"]);
    let out = vitreous(&["compare", "a.png", "gone.png"], dir.path());
    assert_clean_failure(&out, &["gone.png"]);
    let out = vitreous(&["compare", "a.png", "a.png", "--map", "a.png"], dir.path());
    assert_clean_failure(&out, &["--map", "a.png"]);
    let out = vitreous(&["compare", "a.png", "a.png", "--ppd", "nan"], dir.path());
    assert_clean_failure(&out, &["--ppd", "pixels per degree"]);
    assert!(!dir.path().join("m.png").exists());
}

#[test]
fn with_what_is_seen_the_nothing_drawn_and_additive_limit_rows_follow() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (32u32, 16u32);
    let reference = vec![100u8; (w * h * 3) as usize];
    // What the eye sees with nothing drawn: darker than the reference on the left half (a
    // display can add the difference), brighter on the right (it cannot take light away).
    let seen: Vec<u8> = (0..w * h)
        .flat_map(|i| if i % w < w / 2 { [60u8; 3] } else { [140u8; 3] })
        .collect();
    write_png(&dir.path().join("r.png"), &reference, w, h);
    write_png(&dir.path().join("s.png"), &seen, w, h);
    write_png(&dir.path().join("t.png"), &reference, w, h);
    let report = json(
        &["compare", "r.png", "t.png", "--seen", "s.png", "--json"],
        dir.path(),
    );
    let psnr = |rows: &str| report[rows][0]["psnr_db"].as_f64().unwrap();
    // Nothing drawn: 40 off everywhere. The limit: exact on the left, 40 off on the right,
    // so half the squared error.
    let nothing = 20.0 * (255.0f64 / 40.0).log10();
    assert!((psnr("nothing_drawn") - nothing).abs() < 1e-9, "{report}");
    assert!(
        (psnr("additive_limit") - (nothing + 10.0 * 2f64.log10())).abs() < 1e-9,
        "{report}"
    );
    assert!(report["regions"][0]["psnr_db"].is_null());
    let out = vitreous(
        &["compare", "r.png", "t.png", "--seen", "s.png"],
        dir.path(),
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("limit FLIP"), "{table}");
    // A seen image of another size is refused, naming it.
    write_png(&dir.path().join("small.png"), &[0; 8 * 8 * 3], 8, 8);
    let out = vitreous(
        &["compare", "r.png", "t.png", "--seen", "small.png"],
        dir.path(),
    );
    assert_clean_failure(&out, &["small.png is 8x8", "differ in size"]);
}

/// The arguments of `compare` of the display's light (`t.png`) over the seen image through
/// `scene`'s panel, then `extra`.
fn through(scene: &str, extra: &[&str]) -> Vec<String> {
    let mut args = vec!["compare", "r.png", "t.png", "--seen", "s.png", "--display"];
    args.extend_from_slice(&["--scene", scene]);
    args.extend_from_slice(extra);
    args.iter().map(|a| a.to_string()).collect()
}

#[test]
fn a_dimmer_scenes_display_light_is_seen_through_its_panel_and_the_panels_blur_can_be_varied() {
    let dir = tempfile::tempdir().unwrap();
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/glass-sphere-ml2.toml");
    let (w, h) = (64u32, 48u32);
    let grey = vec![128u8; (w * h * 3) as usize];
    write_png(&dir.path().join("r.png"), &grey, w, h);
    write_png(&dir.path().join("s.png"), &grey, w, h);
    // The display's light: none, and the dimmer taking all of the world away in the middle.
    let rgba: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            let dark = (24..40).contains(&x) && (16..32).contains(&y);
            [0, 0, 0, if dark { 255 } else { 0 }]
        })
        .collect();
    std::fs::write(dir.path().join("t.png"), encode_png(&rgba, w, h).unwrap()).unwrap();
    let scene_arg = scene.to_str().unwrap();
    let whole = |extra: &[&str]| {
        let mut args = through(scene_arg, extra);
        args.push("--json".into());
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        json(&args, dir.path())["regions"][0]["psnr_db"]
            .as_f64()
            .unwrap()
    };
    // Through the panel the middle goes dark: far from the reference. A sharper panel darkens
    // less of the view around it than a blurrier one, so the two differ.
    let scene_blur = whole(&[]);
    let blurrier = whole(&["--panel-blur-deg", "4"]);
    assert!(scene_blur < 30.0, "{scene_blur} dB");
    assert!(
        (scene_blur - blurrier).abs() > 0.1,
        "{scene_blur} vs {blurrier} dB"
    );
    // The display image's alpha is the panel's here; through an additive display it is
    // ignored, and said.
    let plain = scene_path();
    let plain = plain.to_str().unwrap();
    let alpha_warning = |scene: &str| {
        let args = through(scene, &[]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = vitreous(&args, dir.path());
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stderr).contains("t.png: alpha ignored")
    };
    assert!(!alpha_warning(scene_arg));
    assert!(alpha_warning(plain));
    // The option needs a dimmer scene, and a blur in range.
    let refused = |scene: &str, blur: &str| {
        let args = through(scene, &[&format!("--panel-blur-deg={blur}")]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        vitreous(&args, dir.path())
    };
    let out = refused(plain, "2");
    assert_clean_failure(&out, &["--panel-blur-deg", "segmented dimmer"]);
    let out = refused(scene_arg, "-1");
    assert_clean_failure(&out, &["--panel-blur-deg", "0 to 20 degrees"]);
}

/// The glass sphere scene copied into `dir` with its assets, in the repository's layout
/// (`scenes/`, `models/`, ...: the same scene hash), so that a test may aim an output at any of
/// them without risk to the repository's files. Returns the scene file and its assets.
pub(crate) fn sphere_copy(dir: &Path) -> (PathBuf, Vec<PathBuf>) {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config");
    let mut files = Vec::new();
    for rel in [
        "scenes/glass-sphere.toml",
        "models/sphere.glb",
        "textures/gravel.png",
        "textures/brick.png",
        "env/forest_ll_zip.exr",
        "bakes/glass-sphere.exr",
    ] {
        let to = dir.join(rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(config.join(rel), &to).unwrap();
        files.push(to);
    }
    (files.remove(0), files)
}

/// The physical reference of `scene` at 16 x 16 pixels in `dir/ref` (`000000-left.png` and
/// its `reference.json`), quickly.
fn small_reference(scene: &Path, dir: &Path) -> PathBuf {
    let out = dir.join("ref");
    let args = [
        "reference",
        scene.to_str().unwrap(),
        "--size",
        "16x16",
        "--samples",
        "1",
        "--photons-per-texel",
        "1",
        "--eye",
        "left",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    let run = vitreous(&args, dir);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

#[test]
fn a_map_naming_any_file_compare_reads_is_refused_and_the_file_kept() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, assets) = sphere_copy(dir.path());
    let refs = small_reference(&scene, dir.path());
    let reference = refs.join("000000-left.png");
    let test = dir.path().join("test.png");
    let seen = refs.join("000000-left-seen.png");
    std::fs::copy(&reference, &test).unwrap();
    let args = |map: &Path| {
        [
            "compare",
            reference.to_str().unwrap(),
            test.to_str().unwrap(),
            "--seen",
            seen.to_str().unwrap(),
            "--scene",
            scene.to_str().unwrap(),
            "--map",
            map.to_str().unwrap(),
        ]
        .map(String::from)
    };
    let run = |map: &Path| {
        let args = args(map);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        vitreous(&args, dir.path())
    };
    let mut inputs = vec![
        scene.clone(),
        reference.clone(),
        test.clone(),
        seen.clone(),
        refs.join("reference.json"),
    ];
    inputs.extend(assets);
    for input in &inputs {
        let before = std::fs::read(input).unwrap();
        let out = run(input);
        assert_clean_failure(
            &out,
            &["--map", &input.display().to_string(), "is the input file"],
        );
        assert_eq!(std::fs::read(input).unwrap(), before, "{}", input.display());
    }
    // A hard link to the scene is the scene.
    let link = dir.path().join("link.toml");
    std::fs::hard_link(&scene, &link).unwrap();
    assert_clean_failure(&run(&link), &["--map", "link.toml", "is the input file"]);
    // Anywhere else the map is written.
    let map = dir.path().join("map.png");
    let out = run(&map);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(map.is_file());
}

#[test]
fn a_reference_json_cut_short_or_written_for_another_scene_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = sphere_copy(dir.path());
    let refs = small_reference(&scene, dir.path());
    let reference = refs.join("000000-left.png");
    let r = reference.to_str().unwrap();
    let listing = refs.join("reference.json");
    let with_scene = |scene: &Path| {
        let scene = scene.to_str().unwrap().to_owned();
        move |dir: &Path| vitreous(&["compare", r, r, "--scene", &scene, "--json"], dir)
    };
    // As written: the regions are the listed frame's.
    let out = with_scene(&scene)(dir.path());
    assert!(out.status.success(), "{out:?}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let from = report["regions_from"].as_str().unwrap();
    assert!(from.starts_with("frame 0 left eye of"), "{from}");
    // The same scene with a line more has another hash: the frame is another scene's.
    let other = scene.with_file_name("other.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&other, format!("{text}\n# moved\n")).unwrap();
    let out = with_scene(&other)(dir.path());
    assert_clean_failure(
        &out,
        &[
            &listing.display().to_string(),
            "as frame 0 of",
            "not of --scene",
            "other.toml",
            "render the reference again",
        ],
    );
    // Cut short.
    let whole = std::fs::read(&listing).unwrap();
    std::fs::write(&listing, &whole[..whole.len() / 2]).unwrap();
    let out = with_scene(&scene)(dir.path());
    assert_clean_failure(
        &out,
        &[
            &listing.display().to_string(),
            "not a reference.json",
            "000000-left.png",
            "EOF",
        ],
    );
    // Without --scene it is not read: the whole view alone.
    let report = json(&["compare", r, r, "--json"], dir.path());
    assert_eq!(report["regions"].as_array().unwrap().len(), 1, "{report}");
}

#[test]
fn alpha_left_out_of_the_comparison_is_said_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (16u32, 8u32);
    write_png(
        &dir.path().join("opaque.png"),
        &vec![90; (w * h * 3) as usize],
        w,
        h,
    );
    // The same colours, a quarter of the pixels half transparent.
    let rgba: Vec<u8> = (0..w * h)
        .flat_map(|i| [90, 90, 90, if i % 4 == 0 { 128 } else { 255 }])
        .collect();
    std::fs::write(
        dir.path().join("clear.png"),
        encode_png(&rgba, w, h).unwrap(),
    )
    .unwrap();
    let warned = |args: &[&str]| {
        let out = vitreous(args, dir.path());
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    for (reference, test) in [("clear.png", "opaque.png"), ("opaque.png", "clear.png")] {
        let stderr = warned(&["compare", reference, test, "--json"]);
        assert!(
            stderr.contains("clear.png: alpha ignored: 32 of 128 pixels are not opaque"),
            "{stderr}"
        );
        assert!(stderr.contains("--display"), "{stderr}");
        assert!(!stderr.contains("opaque.png: alpha"), "{stderr}");
    }
    // As what the eye sees: alpha ignored, said; its colours are the opaque image's.
    let stderr = warned(&["compare", "opaque.png", "opaque.png", "--seen", "clear.png"]);
    assert!(stderr.contains("clear.png: alpha ignored"), "{stderr}");
    assert!(!warned(&["compare", "opaque.png", "opaque.png"]).contains("alpha"));
}

#[test]
fn an_eye_without_a_scene_or_against_the_reference_json_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("a.png"), &[0; 16 * 8 * 3], 16, 8);
    let out = vitreous(&["compare", "a.png", "a.png", "--eye", "right"], dir.path());
    assert_clean_failure(
        &out,
        &["--eye right", "without --scene", "add --scene SCENE"],
    );
    let (scene, _) = sphere_copy(dir.path());
    let refs = small_reference(&scene, dir.path());
    let r = refs.join("000000-left.png");
    let (r, s) = (r.to_str().unwrap(), scene.to_str().unwrap());
    let out = vitreous(
        &["compare", r, r, "--scene", s, "--eye", "right"],
        dir.path(),
    );
    assert_clean_failure(
        &out,
        &[
            "--eye right",
            "reference.json lists",
            "as the left eye of frame 0",
        ],
    );
    let agreed = json(
        &["compare", r, r, "--scene", s, "--eye", "left", "--json"],
        dir.path(),
    );
    let from = agreed["regions_from"].as_str().unwrap();
    assert!(from.starts_with("frame 0 left eye"), "{from}");
}
