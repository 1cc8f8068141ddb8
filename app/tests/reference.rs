//! `vitreous reference`: the physical reference's files, what it changes against the seen
//! image (the ball's disc, its shadow), `compare` reading its frames, its light unclipped in
//! OpenEXR, and bad input.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec2};
use vitreous_frames::render_desc::render_fov;
use vitreous_optics::camera::EyeParams;
use vitreous_scene::load_scene;

use crate::cli::{assert_clean_failure, vitreous};
use crate::compare::json;

fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/glass-sphere-real.toml")
}

/// Linear RGB of pixel `(x, y)` of an sRGB PNG.
fn pixel(path: &Path, x: u32, y: u32) -> glam::Vec3 {
    let image = image::open(path).unwrap().to_rgb8();
    let p = image.get_pixel(x, y);
    glam::Vec3::new(
        vitreous_optics::srgb::to_linear(p[0]),
        vitreous_optics::srgb::to_linear(p[1]),
        vitreous_optics::srgb::to_linear(p[2]),
    )
}

/// Runs `vitreous reference` of the scene at 320 x 240 with few photons and `args` into `out`,
/// which must succeed.
fn reference(cwd: &Path, out: &Path, args: &[&str]) {
    let scene = scene_path();
    let mut all = vec!["reference", scene.to_str().unwrap(), "--size", "320x240"];
    all.extend([
        "--photons-per-texel",
        "8",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    all.extend(args);
    let run = vitreous(&all, cwd);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn the_reference_shows_the_ball_and_half_its_lights_shadow_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ref");
    reference(dir.path(), &out, &["--samples", "2"]);
    for eye in ["left", "right"] {
        for suffix in ["", "-seen"] {
            assert!(out.join(format!("000000-{eye}{suffix}.png")).is_file());
        }
    }
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("reference.json")).unwrap()).unwrap();
    assert_eq!(report["object"], "analytic ball");
    assert_eq!(report["light_share"], 0.5);
    let frame = &report["frames"][0];
    assert!(frame["photons"].as_u64().unwrap() > 10_000, "{frame}");
    assert!(
        frame["floor_light_noise"].as_f64().unwrap() < 0.05,
        "{frame}"
    );

    // Where the light's ray through the ball's centre meets the floor: the middle of the shadow,
    // whose darkest part is lit by the room's half of the floor's light only.
    let scene = load_scene(&scene_path()).unwrap();
    let light = scene.light.position_m;
    let centre = scene.object.center_m;
    let floor_y = scene.floor.pose.position.y;
    let towards = (centre - light).normalize();
    let umbra = light + towards * ((floor_y - light.y) / towards.y);
    let head = vitreous_trace::Pose {
        position: scene.viewer.head_position_m,
        orientation: Quat::IDENTITY,
    };
    let left = scene.viewer.eye_positions_m(&head)[0];
    let camera = EyeParams::new(left, Quat::IDENTITY, render_fov(scene.output.fov));
    let size = Vec2::new(320.0, 240.0);
    let at = |p: glam::Vec3| {
        let px = camera.project_to_pixel(p, size).unwrap();
        (px.x as u32, px.y as u32)
    };
    let (ux, uy) = at(umbra);
    let real = out.join("000000-left.png");
    let seen = out.join("000000-left-seen.png");
    let ratios: Vec<f32> = (ux - 12..=ux + 12)
        .map(|x| pixel(&real, x, uy).element_sum() / pixel(&seen, x, uy).element_sum())
        .collect();
    let darkest = ratios.iter().copied().fold(f32::MAX, f32::min);
    let brightest = ratios.iter().copied().fold(0.0, f32::max);
    assert!(
        (0.4..0.62).contains(&darkest),
        "the shadow keeps {darkest} of the floor's light at its darkest, expected about 0.5 \
         (the room's half): {ratios:?}"
    );
    // The ball focuses the light it lets through into the middle of its shadow.
    assert!(brightest > 1.2, "no caustic: {ratios:?}");
    // The ball's centre shows something else than the floor behind it; far from the ball and
    // its shadow the two images are the same.
    let (cx, cy) = at(centre);
    assert_ne!(pixel(&real, cx, cy), pixel(&seen, cx, cy));
    for (x, y) in [(5, 120), (300, 230), (160, 100)] {
        assert_eq!(pixel(&real, x, y), pixel(&seen, x, y), "at {x},{y}");
    }

    // `compare` takes its regions from the frame in reference.json beside the reference.
    let cmp = json(
        &[
            "compare",
            real.to_str().unwrap(),
            real.to_str().unwrap(),
            "--scene",
            scene_path().to_str().unwrap(),
            "--json",
        ],
        dir.path(),
    );
    assert!(
        cmp["regions_from"]
            .as_str()
            .unwrap()
            .starts_with("frame 0 left eye of"),
        "{cmp}"
    );
    // A display that adds nothing, over the seen image, is the seen image.
    let black = dir.path().join("black.png");
    let rgba = vec![0u8; 320 * 240 * 4];
    std::fs::write(
        &black,
        vitreous_frames::output::encode_png(&rgba, 320, 240).unwrap(),
    )
    .unwrap();
    let cmp = json(
        &[
            "compare",
            real.to_str().unwrap(),
            black.to_str().unwrap(),
            "--display",
            "--seen",
            seen.to_str().unwrap(),
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(
        cmp["regions"][0]["flip_mean"],
        cmp["nothing_drawn"][0]["flip_mean"]
    );
    assert!(cmp["regions"][0]["flip_mean"].as_f64().unwrap() > 0.0);
}

#[test]
fn exr_keeps_the_light_the_png_clips() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ref");
    let args = [
        "--eye",
        "left",
        "--samples",
        "1",
        "--object-samples",
        "4",
        "--exr",
    ];
    reference(dir.path(), &out, &args);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("reference.json")).unwrap()).unwrap();
    assert_eq!(
        report["frames"][0]["files"],
        serde_json::json!([
            "000000-left.png",
            "000000-left.exr",
            "000000-left-seen.png",
            "000000-left-seen.exr"
        ])
    );
    let mut above_one = 0;
    for stem in ["000000-left", "000000-left-seen"] {
        let exr = exr::prelude::read_first_rgba_layer_from_file(
            out.join(format!("{stem}.exr")),
            |size, _| vec![[0f32; 3]; size.width() * size.height()],
            |pixels, at, (r, g, b, _): (f32, f32, f32, f32)| {
                pixels[at.y() * 320 + at.x()] = [r, g, b];
            },
        )
        .unwrap();
        let size = exr.layer_data.size;
        assert_eq!((size.width(), size.height()), (320, 240), "{stem}");
        let light = &exr.layer_data.channel_data.pixels;
        let png = image::open(out.join(format!("{stem}.png")))
            .unwrap()
            .to_rgb8();
        // The PNG is the same light encoded to 8-bit sRGB, pixel for pixel.
        for (p, l) in png.pixels().zip(light) {
            let encoded = l.map(vitreous_optics::srgb::from_linear);
            assert_eq!(p.0, encoded, "{stem}: {l:?}");
        }
        above_one += light.iter().flatten().filter(|&&v| v > 1.0).count();
    }
    // The grazing reflections at the ball's outline carry the sky's light above 1: the PNG
    // clips it at 255, the OpenEXR keeps it.
    assert!(above_one > 0, "no light above 1");
}

#[test]
fn bad_reference_input_fails_cleanly_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ref");
    let scene = scene_path();
    let scene = scene.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["reference", "missing.toml", "--out", o],
            &["missing.toml"],
        ),
        (
            &["reference", scene, "--samples", "0", "--out", o],
            &["--samples", "between 1 and 16"],
        ),
        (
            &["reference", scene, "--photons-per-texel", "nan", "--out", o],
            &["--photons-per-texel"],
        ),
        (
            &["reference", scene, "--frames", "2", "--out", o],
            &["--frames needs --trace"],
        ),
        (
            &["reference", scene, "--trace", "nope.csv", "--out", o],
            &["nope.csv"],
        ),
        (
            &["reference", scene, "--size", "0x10", "--out", o],
            &["0x10", "16..=8192"],
        ),
    ];
    for (args, needles) in cases {
        assert_clean_failure(&vitreous(args, dir.path()), needles);
        assert!(
            !out.join("reference.json").exists(),
            "{args:?} wrote reference.json"
        );
    }
}

#[test]
fn a_recording_with_the_headsets_eyes_is_drawn_from_them() {
    use vitreous_trace::format::{HeadView, TraceSample, TraceVersion, TraceWriter, ViewsRecord};
    use vitreous_trace::{Fov, GazeSample, Pose};
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&scene_path()).unwrap();
    // The head where the scene puts it, still, for three samples; the headset's eyes 58 mm
    // apart and each turned 2 degrees outwards (the scene's are 63 mm apart, parallel).
    let head = Pose {
        position: scene.viewer.head_position_m,
        orientation: Quat::IDENTITY,
    };
    let write = |path: &Path, views: bool| {
        let mut w = TraceWriter::create_version(path, TraceVersion::V1_5).unwrap();
        if views {
            let eye = |side: f32| HeadView {
                pose: Pose {
                    position: glam::Vec3::X * 0.029 * side,
                    orientation: Quat::from_rotation_y(-side * 2f32.to_radians()),
                },
                fov: Fov::symmetric(0.7, 0.5),
            };
            w.write_views(&ViewsRecord {
                time_ns: 0,
                eyes: [eye(-1.0), eye(1.0)],
            })
            .unwrap();
        }
        for k in 0..3 {
            let t = k * 50_000_000;
            w.write(&TraceSample {
                time_ns: t,
                head,
                gaze: GazeSample::none(t),
            })
            .unwrap();
        }
        w.finish().unwrap();
    };
    let mut apart = Vec::new();
    for views in [true, false] {
        let trace = dir.path().join(format!("views-{views}.trace"));
        write(&trace, views);
        let out = dir.path().join(format!("ref-{views}"));
        let scene = scene_path();
        let run = vitreous(
            &[
                "reference",
                scene.to_str().unwrap(),
                "--trace",
                trace.to_str().unwrap(),
                "--frames",
                "1",
                "--size",
                "64x48",
                "--samples",
                "1",
                "--photons-per-texel",
                "1",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ],
            dir.path(),
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("reference.json")).unwrap()).unwrap();
        let eyes = &report["frames"][0]["eyes"];
        let at = |e: usize, k: &str| -> Vec<f32> {
            eyes[e][k]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap() as f32)
                .collect()
        };
        let (l, r) = (at(0, "position_m"), at(1, "position_m"));
        let (lq, rq) = (at(0, "orientation_xyzw"), at(1, "orientation_xyzw"));
        let turn = |q: &[f32]| 2.0 * q[1].atan2(q[3]).to_degrees();
        apart.push((
            glam::Vec3::from_slice(&l).distance(glam::Vec3::from_slice(&r)) * 1000.0,
            turn(&lq),
            turn(&rq),
        ));
    }
    let (with, without) = (apart[0], apart[1]);
    assert!((with.0 - 58.0).abs() < 0.01, "{with:?}");
    assert!(
        (with.1 - 2.0).abs() < 0.01 && (with.2 + 2.0).abs() < 0.01,
        "{with:?}"
    );
    assert!((without.0 - 63.0).abs() < 0.01, "{without:?}");
    assert!(
        without.1.abs() < 0.01 && without.2.abs() < 0.01,
        "{without:?}"
    );
}
