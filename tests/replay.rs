//! End to end on the machine's Vulkan device with validation on: shipped scenes and traces
//! through the real frame loop, checked against a CPU projection of the object.

use std::path::Path;

use glam::{Vec2, Vec3};
use vitreous::replay::{ReplayOptions, replay};
use vitreous_compare::frame_of_image;
use vitreous_frames::render_desc::eye_params;
use vitreous_scene::load_scene;
use vitreous_tests::{lit_centroid, workspace};
use vitreous_trace::format::read_trace;
use vitreous_xr::Backend;
use vitreous_xr::null::{NullBackend, NullConfig};

pub(crate) fn options(scene: &str, trace: Option<&str>, out: &Path) -> ReplayOptions {
    ReplayOptions {
        scene: workspace().join("config/scenes").join(scene),
        trace: trace.map(|t| workspace().join("config/traces").join(t)),
        out: out.to_path_buf(),
        frames: Some(31),
        save_every: 15,
        size: Some((640, 480)),
        validate: true,
        effects: None,
        device: None,
        frame_rate_hz: 60.0,
        at_samples: false,
        progress: false,
        reflection: vitreous_render::Reflection::Phong,
        sphere_check: false,
        compare_reference: false,
        compare_shifts_deg: Vec::new(),
        gaze: Default::default(),
        fields: Default::default(),
    }
}

fn decode(path: &Path) -> (Vec<u8>, u32) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8();
    let w = img.width();
    (img.into_raw(), w)
}

/// Replays, then checks every saved frame: the object's pixels centre where the CPU
/// projection of the object's centre lands, in each eye, and the eyes differ by the predicted
/// disparity (as far as `check` allows).
/// What a scene's images can be checked for.
#[derive(Clone, Copy, PartialEq)]
enum Check {
    /// The silhouette is centred on the object's centre: centroid and disparity.
    Centred,
    /// Only the disparity between the eyes (the silhouette is not centred on the centre).
    Disparity,
    /// The object fills more than the view: only that it is there.
    Visible,
}

fn check_geometry(scene_name: &str, trace: Option<&str>, check: Check) {
    let dir = tempfile::tempdir().unwrap();
    let opts = options(scene_name, trace, dir.path());
    let summary = replay(&opts).expect("replay succeeds with validation on");
    assert_eq!(summary.frames, 31);
    assert_eq!(summary.validation.errors + summary.validation.warnings, 0);
    assert!(summary.validation.enabled);
    assert_eq!(summary.saved.len(), 3 * 4, "{:?}", summary.saved);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["frames"], 31);
    assert_eq!(json["per_frame"].as_array().unwrap().len(), 31);
    assert!(json["device"].as_str().is_some_and(|d| !d.is_empty()));
    assert_eq!(json["scene_hash"].as_str().unwrap().len(), 64);

    // The same views, from an independent run of the null backend over the same trace.
    let scene = load_scene(&opts.scene).unwrap();
    let samples = match &opts.trace {
        Some(t) => read_trace(t).unwrap(),
        None => {
            vitreous_trace::synth::synthesize_with_truth(&vitreous_scene::synth_params_for(&scene))
                .unwrap()
                .samples
        }
    };
    let mut backend = NullBackend::new(
        samples,
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: Some(31),
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )
    .unwrap();
    let size = Vec2::new(640.0, 480.0);
    while let Some(frame) = backend.wait_frame().unwrap() {
        backend.end_frame(&frame).unwrap();
        if frame.index % 15 != 0 {
            continue;
        }
        let mut xs = [0.0f32; 2];
        let mut expected_xs = [0.0f32; 2];
        for (eye, name) in ["left", "right"].iter().enumerate() {
            let camera = eye_params(&frame.views[eye]);
            let expected = camera
                .project_to_pixel(scene.object.center_m, size)
                .expect("object in front of the eye");
            let png = dir
                .path()
                .join("frames")
                .join(format!("{:06}-{name}.png", frame.index));
            let (rgba, w) = decode(&png);
            let (centroid, count) = lit_centroid(&rgba, w, 8)
                .unwrap_or_else(|| panic!("{}: object not visible", png.display()));
            assert!(count > 50, "{}: only {count} lit pixels", png.display());
            assert!(
                check != Check::Centred || (centroid - expected).length() < 2.0,
                "{} frame {}: centroid {centroid} vs projected centre {expected}",
                scene_name,
                frame.index
            );
            xs[eye] = centroid.x;
            expected_xs[eye] = expected.x;
            // The preview adds the real world: never darker than the eye image alone.
            let preview = png.with_file_name(format!("{:06}-{name}-preview.png", frame.index));
            let (world, _) = decode(&preview);
            let darker = rgba
                .iter()
                .zip(&world)
                .filter(|(e, p)| p < e && (**e - **p) > 1)
                .count();
            assert_eq!(
                darker,
                0,
                "{}: preview darker than the eye image",
                preview.display()
            );
        }
        let disparity = xs[0] - xs[1];
        let predicted = expected_xs[0] - expected_xs[1];
        assert!(
            check == Check::Visible || (disparity - predicted).abs() < 1.0,
            "{scene_name}: disparity {disparity} px vs predicted {predicted} px"
        );
    }
}

#[test]
fn glass_sphere_with_the_real_trace_lands_where_projected() {
    check_geometry(
        "glass-sphere.toml",
        Some("sranipal-TESTNA01-2D-Fist3.csv"),
        Check::Centred,
    );
}

/// The brilliant's silhouette is not centred on its bounding box (the pavilion is deeper than
/// the crown), so only visibility and disparity are checked.
#[test]
fn diamond_with_a_synthetic_trace_shows_the_predicted_disparity() {
    check_geometry("diamond.toml", None, Check::Disparity);
}

/// The paper's 150 mm sphere 0.2 m away overfills the Magic Leap One's field of view.
#[test]
fn visual_effects_scene_replays_its_shipped_synthetic_trace() {
    check_geometry(
        "visual-effects.toml",
        Some("synthetic-visual-effects.csv"),
        Check::Visible,
    );
}

/// The shipped synthetic trace alternates the gaze between the sphere's surface and the
/// background seen through it every 3 s: `frames.csv` follows it frame by frame, the summary
/// counts the switches, and with `[gaze] pupil = "measured"` A_p follows the trace's pupils.
#[test]
fn frames_csv_follows_the_synthetic_traces_alternating_fixation() {
    use vitreous_frames::frame_log::{FRAME_LOG_HEADER, FRAME_LOG_NAME};
    use vitreous_scene::gaze_image_of_target;

    let dir = tempfile::tempdir().unwrap();
    // The shipped scene with a measured pupil, its assets named from the workspace.
    let config = workspace().join("config");
    let text = std::fs::read_to_string(config.join("scenes/visual-effects.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", config.display()));
    // The scene has a `[gaze]` table already (its filter): the pupil goes into it.
    assert_eq!(text.matches("\n[gaze]\n").count(), 1);
    let text = text.replace("\n[gaze]\n", "\n[gaze]\npupil = \"measured\"\n");
    let scene_path = dir.path().join("measured-pupil.toml");
    std::fs::write(&scene_path, text).unwrap();
    let out = dir.path().join("out");
    let mut opts = options(
        "visual-effects.toml",
        Some("synthetic-visual-effects.csv"),
        &out,
    );
    opts.scene = scene_path;
    opts.frames = None;
    opts.frame_rate_hz = 10.0;
    opts.save_every = 0;
    opts.size = Some((64, 48));
    opts.effects = Some(vitreous_scene::effects::EffectSet::parse("defocus").unwrap());
    let summary = replay(&opts).expect("replay succeeds with validation on");
    assert_eq!(summary.frames, 121, "12 s at 10 Hz");

    let log = std::fs::read_to_string(out.join(FRAME_LOG_NAME)).unwrap();
    let mut lines = log.lines();
    assert_eq!(lines.next(), Some(FRAME_LOG_HEADER));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 121);
    let images: Vec<&str> = rows.iter().map(|r| r[4]).collect();
    // The trace's truth: the synthesiser's phases for the scene (12 s, as shipped).
    let scene = load_scene(&workspace().join("config/scenes/visual-effects.toml")).unwrap();
    let params = vitreous_trace::synth::SynthParams {
        duration_s: 12.0,
        ..vitreous_scene::synth_params_for(&scene)
    };
    let truth = vitreous_trace::synth::synthesize_with_truth(&params).unwrap();
    assert!(truth.phases.len() >= 4);
    for phase in &truth.phases {
        // 2.5 s into each phase the eq. 15 mean has settled on the new depth.
        let frame = ((phase.start_ns as f64 * 1e-9 + 2.5) * 10.0) as usize;
        if frame < rows.len() {
            assert_eq!(
                images[frame],
                gaze_image_of_target(phase.target).to_string(),
                "frame {frame}: {:?}",
                rows[frame]
            );
        }
    }
    let known: Vec<&str> = images.iter().copied().filter(|i| *i != "unknown").collect();
    let changes = known.windows(2).filter(|w| w[0] != w[1]).count() as u64;
    assert!(changes >= 3, "{images:?}");
    assert_eq!(summary.gaze_image_switches, changes);
    // The image not looked at is blurred, the one looked at is not.
    for r in &rows {
        let (k_surface, k_refracted) = (r[5], r[6]);
        match r[4] {
            "surface" => assert!(k_surface == "0" && k_refracted.parse::<f32>().unwrap() > 1.0),
            "refracted" => {
                assert!(k_refracted == "0" && k_surface.parse::<f32>().unwrap() > 0.1)
            }
            _ => assert!(k_surface.is_empty() && k_refracted.is_empty()),
        }
    }
    let pupil = summary.pupil.expect("defocus reports the pupil");
    assert_eq!(pupil.source, "measured");
    assert!(pupil.measured_samples > 100, "{pupil:?}");
    let (min, max) = (pupil.min_mm.unwrap(), pupil.max_mm.unwrap());
    assert!(3.4 < min && min < max && max < 5.1, "{pupil:?}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["gaze_image_switches"], changes);
    assert_eq!(json["pupil"]["source"], "measured");
    // The images 0.125 m and 0.4 m away, 19-20 degree apart in vergence; the shipped trace's
    // noise (0.5 degree per eye and axis) is about 0.7 degree of vergence, shrunk toward the
    // 1 degree prior over its 12 s.
    let s = &json["separability"];
    assert_eq!(s["noise_estimated"], true, "{json}");
    let noise = s["vergence_noise_deg"].as_f64().unwrap();
    assert!((0.75..0.99).contains(&noise), "{s}");
    let gap = s["vergence_gap_deg"].as_f64().unwrap();
    assert!((18.0..21.0).contains(&gap), "{s}");
    assert!(
        (s["d_prime"].as_f64().unwrap() - gap / noise).abs() < 1e-3,
        "{s}"
    );
}

#[test]
fn compare_reference_measures_every_saved_eye_against_the_physical_reference() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReplayOptions {
        frames: Some(16),
        compare_reference: true,
        ..options("glass-sphere-real.toml", None, dir.path())
    };
    let summary = replay(&opts).expect("replay succeeds with validation on");
    // Two saved frames (0 and 15), each eye: its image, preview, reference and seen image;
    // and the reference.json that says which frame and eye each reference is.
    assert_eq!(summary.saved.len(), 2 * 2 * 4 + 1, "{:?}", summary.saved);
    for name in ["000015-left-real.png", "000015-right-seen.png"] {
        assert!(dir.path().join("frames").join(name).is_file(), "{name}");
    }
    // `vitreous compare` finds a reference's frame there (its regions follow that frame's eye,
    // not the neutral head's).
    let frames = dir.path().join("frames");
    let listed = |name: &str| {
        let listed = frame_of_image(&frames.join(name)).unwrap().expect("listed");
        (listed.frame, listed.eye)
    };
    let (left, eye) = listed("000015-left-real.png");
    assert_eq!((left.frame, eye), (15, 0));
    let (right, eye) = listed("000015-right-real.png");
    assert_eq!((right.frame, eye), (15, 1));
    let ipd =
        Vec3::from_array(right.eyes[1].position_m) - Vec3::from_array(right.eyes[0].position_m);
    assert!((ipd.length() - 0.063).abs() < 0.002, "{ipd}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    let figures = json["compare_reference"].as_array().unwrap();
    assert_eq!(figures.len(), 4);
    let flip = |rows: &serde_json::Value, region: &str| {
        rows.as_array()
            .unwrap()
            .iter()
            .find(|r| r["region"] == region)
            .unwrap()["flip_mean"]
            .as_f64()
            .unwrap()
    };
    for f in figures {
        // Away from the ball and its shadow the display adds nothing to the real scene.
        assert!(flip(&f["regions"], "rest") < 1e-3, "{f}");
        // In the ball's disc what the display adds brings the eye closer to the real ball than
        // showing nothing, and no closer than any additive display could.
        let disc = flip(&f["regions"], "disc");
        assert!(disc < flip(&f["nothing_drawn"], "disc"), "{f}");
        assert!(disc >= flip(&f["additive_limit"], "disc"), "{f}");
    }
}

#[test]
fn recorded_fields_draw_each_eye_with_the_headsets_field() {
    use vitreous::replay::Fields;
    use vitreous_trace::format::{HeadView, TraceVersion, TraceWriter, ViewsRecord};
    use vitreous_trace::{EyeView, Fov, GazeSample, Pose};
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&workspace().join("config/scenes/glass-sphere.toml")).unwrap();
    // A headset whose fields are narrower than the scene's 40 x 30 degrees and lean outwards
    // and down, mirrored between the eyes.
    let field = |side: f32| Fov {
        angle_left_rad: if side < 0.0 { -0.30 } else { -0.20 },
        angle_right_rad: if side < 0.0 { 0.20 } else { 0.30 },
        angle_up_rad: 0.10,
        angle_down_rad: -0.25,
    };
    let eye = |side: f32| HeadView {
        pose: Pose {
            position: Vec3::X * 0.0315 * side,
            orientation: glam::Quat::IDENTITY,
        },
        fov: field(side),
    };
    let head = Pose {
        position: scene.viewer.head_position_m,
        orientation: glam::Quat::IDENTITY,
    };
    let trace = dir.path().join("headset.trace");
    let mut w = TraceWriter::create_version(&trace, TraceVersion::V1_5).unwrap();
    w.write_views(&ViewsRecord {
        time_ns: 0,
        eyes: [eye(-1.0), eye(1.0)],
    })
    .unwrap();
    for k in 0..3i64 {
        let t = k * 20_000_000;
        w.write(&vitreous_trace::format::TraceSample {
            time_ns: t,
            head,
            gaze: GazeSample::none(t),
        })
        .unwrap();
    }
    w.finish().unwrap();
    let out = dir.path().join("out");
    let summary = replay(&ReplayOptions {
        trace: Some(trace),
        frames: Some(1),
        save_every: 1,
        size: None,
        fields: Fields::Recorded,
        ..options("glass-sphere.toml", None, &out)
    })
    .expect("replay succeeds with validation on");
    // The scene's width, as high as makes the left field's pixels square.
    let f = field(-1.0);
    let aspect = (f.angle_up_rad.tan() - f.angle_down_rad.tan())
        / (f.angle_right_rad.tan() - f.angle_left_rad.tan());
    assert_eq!(summary.width_px, scene.output.width_px);
    assert_eq!(summary.height_px, (1280.0 * aspect).round() as u32);
    let size = Vec2::new(summary.width_px as f32, summary.height_px as f32);
    for (k, name) in ["left", "right"].iter().enumerate() {
        let side = [-1.0, 1.0][k];
        let png = out.join("frames").join(format!("000000-{name}.png"));
        let (rgba, width) = decode(&png);
        let (centroid, count) = lit_centroid(&rgba, width, 8).expect("the ball is drawn");
        assert!(count > 50, "{name}: {count} lit pixels");
        let projected = |fov: Fov| {
            eye_params(&EyeView {
                pose: eye(side).in_world(&head),
                fov,
            })
            .project_to_pixel(scene.object.center_m, size)
            .unwrap()
        };
        let (recorded, scene_field) = (projected(field(side)), projected(scene.output.fov));
        assert!(
            (centroid - recorded).length() < 2.0,
            "{name}: the ball at {centroid}, projected through the headset's field at {recorded}"
        );
        assert!(
            (recorded - scene_field).length() > 50.0,
            "{name}: the two fields put the ball at {recorded} and {scene_field}"
        );
    }
}
