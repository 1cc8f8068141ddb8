//! A minimal scene resolves with the documented defaults; glTF IOR and transforms are honoured.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{IorSource, load_scene};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(rel)
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

#[test]
fn minimal_scene_takes_the_documented_defaults() {
    let scene = load_scene(&data("scenes/minimal.toml")).unwrap();
    assert_eq!(scene.viewer.ipd_m, 0.063);
    assert_eq!(scene.viewer.pupil_diameter_m, 0.006);
    assert_eq!(scene.viewer.head_position_m, Vec3::ZERO);
    assert_eq!((scene.output.width_px, scene.output.height_px), (1280, 960));
    assert_eq!(scene.output.glass_samples, 1);
    let fov = scene.output.fov;
    assert!((fov.angle_right_rad - 20f32.to_radians()).abs() < 1e-6);
    assert!((fov.angle_up_rad - 15f32.to_radians()).abs() < 1e-6);
    assert_eq!(fov.angle_left_rad, -fov.angle_right_rad);
    assert_eq!(scene.effects, EffectSet::NONE);
    // Light frame defaults to world.
    assert_eq!(scene.light.position_m, Vec3::new(0.0, 1.0, 1.0));
    assert_eq!(scene.light.intensity, 1.0);
    assert_eq!(scene.light.color, Vec3::ONE);
    assert_eq!(scene.object.surface_texture, None);
    assert_eq!(scene.object.surface_transmittance, 1.0);
    assert_eq!(scene.background.size_m, Vec2::new(2.0, 1.0));
    assert!(scene.environment.cube_map_path.is_none());
    // Paths are resolved against the scene file's folder, `..` folded.
    assert!(
        scene
            .object
            .model_path
            .ends_with("tests/data/models/TransmissionTest.glb")
    );
    assert!(!scene.environment.path.to_string_lossy().contains(".."));
}

#[test]
fn diameter_scales_the_largest_extent_and_position_is_the_box_centre() {
    let scene = load_scene(&data("scenes/minimal.toml")).unwrap();
    let object = &scene.object;
    let (lo, hi) = object.mesh.bounds();
    let a = object.world_from_model.transform_point3(lo);
    let b = object.world_from_model.transform_point3(hi);
    assert!(((b - a).abs().max_element() - 0.5).abs() < 1e-4);
    assert!(((a + b) / 2.0).abs_diff_eq(Vec3::new(0.0, 0.0, -2.0), 1e-4));
    assert_eq!(object.center_m, Vec3::new(0.0, 0.0, -2.0));
    assert!(object.radius_m >= 0.25 && object.radius_m <= 0.25 * 3f32.sqrt() + 1e-4);
    // Every vertex lies inside the bounding sphere.
    for p in &object.mesh.positions {
        let w = object.world_from_model.transform_point3(*p);
        assert!(w.distance(object.center_m) <= object.radius_m + 1e-4);
    }
    assert_eq!(object.mesh.normals.len(), object.mesh.positions.len());
    assert_eq!(object.mesh.uvs.len(), object.mesh.positions.len());
}

#[test]
fn gltf_ior_is_used_when_the_scene_gives_none() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("scenes/minimal.toml"))
        .unwrap()
        .replace(
            "\"../models/TransmissionTest.glb\"",
            &format!("'{}'", repo("config/models/sphere.glb").display()),
        )
        .replace(
            "\"../../../../config/",
            &format!("\"{}/", repo("config").display()),
        );
    let path = dir.path().join("s.toml");
    std::fs::write(&path, &text).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.object.ior_source, IorSource::Gltf);
    assert!((scene.object.ior - 1.51).abs() < 1e-6);

    let with_ior = text.replace("diameter_m = 0.5", "diameter_m = 0.5\nior = 1.33");
    std::fs::write(&path, &with_ior).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.object.ior_source, IorSource::Scene);
    assert_eq!(scene.object.ior, 1.33);
}

#[test]
fn refraction_defaults_to_the_paper_and_reads_two_surface() {
    let text = std::fs::read_to_string(data("scenes/minimal.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", data("scenes/..").display()));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, &text).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(
        scene.object.refraction,
        vitreous_optics::refraction::Refraction::Paper
    );
    let two = text.replace(
        "diameter_m = 0.5",
        "diameter_m = 0.5\nrefraction = \"two-surface\"",
    );
    // The sample's planes enclose no volume, which two-surface refraction needs.
    std::fs::write(&path, &two).unwrap();
    let err = load_scene(&path).unwrap_err();
    assert_eq!(err.field(), Some("object.model"), "{err}");
    assert!(
        err.to_string().contains("does not enclose a volume"),
        "{err}"
    );
    let sphere = repo("config/models/sphere.glb");
    let two = two
        .lines()
        .map(|line| match line.starts_with("model =") {
            true => format!("model = '{}'", sphere.display()),
            false => line.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(two.contains("sphere.glb"), "{two}");
    std::fs::write(&path, &two).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(
        scene.object.refraction,
        vitreous_optics::refraction::Refraction::TwoSurface
    );
}

#[test]
fn rotation_and_object_frame_light_are_applied() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("scenes/minimal.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", data("scenes/..").display()))
        .replace(
            "position_m = [0, 1, 1]",
            "position_m = [0, 1, 1]\nframe = \"object\"\nintensity = 2.5\ncolor = [1, 0.5, 0.25]",
        )
        .replace("diameter_m = 0.5", "scale = 0.1\nrotation_deg = [0, 90, 0]");
    let path = dir.path().join("s.toml");
    std::fs::write(&path, &text).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.light.position_m, Vec3::new(0.0, 1.0, -1.0));
    assert_eq!(scene.light.intensity, 2.5);
    assert_eq!(scene.light.color, Vec3::new(1.0, 0.5, 0.25));
    // A model-space +x direction turns to -z under +90 degrees about y, scaled by 0.1.
    let m = scene.object.world_from_model;
    let d = m.transform_vector3(Vec3::X);
    assert!(d.abs_diff_eq(Vec3::new(0.0, 0.0, -0.1), 1e-6), "{d}");
    // The hash covers the scene text: a different file, a different hash.
    let first = scene.hash.clone();
    std::fs::write(&path, format!("{text}\n# comment\n")).unwrap();
    assert_ne!(load_scene(&path).unwrap().hash, first);
}

#[test]
fn moving_light_circles_the_sphere_then_holds() {
    let scene = load_scene(&repo("config/scenes/moving-light.toml")).unwrap();
    assert!(scene.motion.is_animated());
    let center = scene.object.center_m;
    // Starts where [light] puts it: the paper's offset.
    let start = scene.placement_at(0.0);
    assert!(
        start
            .light_position_m
            .abs_diff_eq(center + Vec3::new(0.0, 1.0, -1.0), 1e-6)
    );
    assert_eq!(start.light_position_m, scene.light.position_m);
    // A quarter of the circle later (1.5 s) the light is 1 m to the left, 1 m up.
    let quarter = scene.placement_at(1.5).light_position_m - center;
    assert!(
        quarter.abs_diff_eq(Vec3::new(-1.0, 1.0, 0.0), 1e-4),
        "{quarter}"
    );
    // Held from 6 s to 8 s, then it starts again.
    assert_eq!(scene.placement_at(6.5), scene.placement_at(7.9));
    assert!(
        scene
            .placement_at(8.0 + 1.5)
            .light_position_m
            .abs_diff_eq(quarter + center, 1e-4)
    );
    // Between keyframes the light stays 1 m above the sphere, about 1 m out.
    let between = scene.placement_at(0.25).light_position_m - center;
    assert!((between.y - 1.0).abs() < 1e-6);
    assert!((between.x.hypot(between.z) - 1.0).abs() < 0.04, "{between}");
    // The object stays put.
    assert_eq!(scene.placement_at(3.0).object_position_m, center);
}

#[test]
fn rolling_diamond_moves_and_turns_on_the_table() {
    let scene = load_scene(&repo("config/scenes/rolling-diamond.toml")).unwrap();
    assert!(scene.motion.is_animated());
    let half = scene.placement_at(0.5);
    assert!(
        half.object_position_m
            .abs_diff_eq(Vec3::new(-0.15, -0.26, -1.5), 1e-5)
    );
    let angle = half.object_rotation.to_axis_angle();
    assert!((angle.1.to_degrees() - 45.0).abs() < 1e-3, "{angle:?}");
    // The placement's transform puts the box centre where the keyframe says.
    let m = scene
        .object
        .world_from_model_at(half.object_position_m, half.object_rotation);
    let centre = m.transform_point3(scene.object.model_center);
    assert!(centre.abs_diff_eq(half.object_position_m, 1e-5));
    // At rest on the same spot from 8 s to 10 s; the light stands still throughout.
    assert_eq!(scene.placement_at(8.5), scene.placement_at(9.5));
    assert_eq!(
        scene.placement_at(2.3).light_position_m,
        scene.light.position_m
    );
    // Its caustics are computed live; a caustic bake is refused: it holds one pose.
    let mut scene = scene;
    assert_eq!(scene.caustics.mode, vitreous_scene::CausticsMode::Live);
    scene.load_caustics().expect("live caustics read no file");
    scene.caustics.mode = vitreous_scene::CausticsMode::Baked;
    let err = scene.load_caustics().unwrap_err();
    assert!(err.to_string().contains("[motion]"), "{err}");
}

#[test]
fn static_scenes_keep_their_transform() {
    let scene = load_scene(&repo("config/scenes/diamond.toml")).unwrap();
    assert!(!scene.motion.is_animated());
    let rest = scene.placement_at(3.0);
    let m = scene
        .object
        .world_from_model_at(rest.object_position_m, rest.object_rotation);
    assert!(m.abs_diff_eq(scene.object.world_from_model, 1e-6));
}

/// Writes `tetrahedron.gltf` (one unit across, closed, its buffer in `tetrahedron.bin` beside
/// it) into `dir`, its material carrying `KHR_materials_volume` = `volume` (JSON), and returns
/// its path.
pub(crate) fn tetrahedron_with_volume(dir: &Path, volume: &str) -> PathBuf {
    let mut bytes = Vec::new();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        bytes.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    // Counter-clockwise seen from outside.
    for i in [0u16, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3] {
        bytes.extend(i.to_le_bytes());
    }
    std::fs::write(dir.join("tetrahedron.bin"), &bytes).unwrap();
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
        "extensionsUsed":["KHR_materials_volume"],
        "materials":[{{"extensions":{{"KHR_materials_volume":{volume}}}}}],
        "buffers":[{{"byteLength":72,"uri":"tetrahedron.bin"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},
                       {{"buffer":0,"byteOffset":48,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",
                       "min":[0,0,0],"max":[1,1,1]}},
                     {{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}}]}}"#
    );
    let path = dir.join("tetrahedron.gltf");
    std::fs::write(&path, gltf).unwrap();
    path
}

#[test]
fn gltf_volume_attenuation_scales_with_the_object_and_the_scene_overrides_it() {
    use vitreous_optics::absorption::Attenuation;

    let dir = tempfile::tempdir().unwrap();
    let model = tetrahedron_with_volume(
        dir.path(),
        r#"{"thicknessFactor":0.5,"attenuationDistance":0.2,"attenuationColor":[0.9,0.5,0.25]}"#,
    );
    let minimal = std::fs::read_to_string(data("scenes/minimal.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", data("scenes/..").display()));
    let text = minimal.replace(
        &format!(
            "\"{}/models/TransmissionTest.glb\"",
            data("scenes/..").display()
        ),
        &format!("'{}'", model.display()),
    );
    assert_ne!(text, minimal);
    let path = dir.path().join("s.toml");
    std::fs::write(&path, &text).unwrap();
    // One unit across at diameter 0.5 m: 0.2 units inside are 0.1 m.
    let scene = load_scene(&path).unwrap();
    let attenuation = scene.object.attenuation;
    assert_eq!(attenuation.color, Vec3::new(0.9, 0.5, 0.25));
    assert!(
        (attenuation.distance_m - 0.1).abs() < 1e-7,
        "{attenuation:?}"
    );

    // Each part of the scene's own attenuation replaces the model's.
    let overridden = text.replace(
        "diameter_m = 0.5",
        "diameter_m = 0.5\nattenuation_distance_m = 0.3",
    );
    std::fs::write(&path, &overridden).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(
        scene.object.attenuation,
        Attenuation {
            color: Vec3::new(0.9, 0.5, 0.25),
            distance_m: 0.3,
        }
    );
    let overridden = overridden.replace(
        "attenuation_distance_m = 0.3",
        "attenuation_distance_m = 0.3\nattenuation_color = [1, 0.75, 0.5]",
    );
    std::fs::write(&path, &overridden).unwrap();
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.object.attenuation.color, Vec3::new(1.0, 0.75, 0.5));

    // A model without the extension is clear glass.
    let scene = load_scene(&data("scenes/minimal.toml")).unwrap();
    assert_eq!(scene.object.attenuation, Attenuation::NONE);
    assert!(scene.object.attenuation.is_clear());
}

#[test]
fn the_environment_map_turns_about_the_vertical() {
    // The shipped room scene with its map turned a quarter (counter-clockwise from above):
    // what the file holds ahead (-z, the middle column) is then seen to the left (-x, a quarter
    // of the width), and a full turn is the file's map.
    let path = repo("config/scenes/glass-sphere-real.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let turned_by = |yaw: &str| {
        let dir = tempfile::tempdir().unwrap();
        let copy = dir.path().join("turned.toml");
        let text = text
            .replace("room = true", &format!("room = true\nyaw_deg = {yaw}"))
            .replace("\"../", &format!("\"{}/", repo("config").display()));
        std::fs::write(&copy, text).unwrap();
        load_scene(&copy).unwrap()
    };
    let file_scene = load_scene(&path).unwrap();
    let file = &file_scene.environment;
    assert_eq!(file.yaw_deg, 0.0);
    let column = |env: &vitreous_scene::Environment, x: u32| -> Vec<f32> {
        let vitreous_scene::PixelData::LinearF32(v) = &env.latlong.data else {
            panic!("a float map");
        };
        let w = env.latlong.width;
        (0..env.latlong.height)
            .flat_map(|y| v[((y * w + x) * 4) as usize..][..3].to_vec())
            .collect()
    };
    let w = file.latlong.width;
    assert_eq!(w % 4, 0, "a width the test can turn by whole columns");
    let quarter_scene = turned_by("90");
    let quarter = &quarter_scene.environment;
    assert_eq!(quarter.yaw_deg, 90.0);
    assert_eq!(column(quarter, w / 4), column(file, w / 2));
    assert_ne!(column(quarter, w / 2), column(file, w / 2));
    let full = turned_by("-360");
    assert_eq!(column(&full.environment, 7), column(file, 7));
    // The physical reference sees the turned map: to the left what the file has ahead.
    let world = |scene: &vitreous_scene::Scene| {
        vitreous_reference::World::of(scene, &scene.rest_placement()).unwrap()
    };
    let ahead = Vec3::new(0.0, 0.3, -1.0).normalize();
    let left = Vec3::new(-1.0, 0.3, 0.0).normalize();
    assert_eq!(
        world(&quarter_scene).environment_radiance(left),
        world(&file_scene).environment_radiance(ahead)
    );
}
