//! The hash a bake stores (`Scene::caustic_inputs_hash`) changes exactly when what the baker
//! reads (`CausticScene::from_scene`) changes: an edit that moves the object, the light or the
//! floor, or changes the model or its index of refraction, asks for a re-bake; an edit to
//! anything else (a comment, the viewer, the display, the photos, the effects) keeps the bake.

use std::path::{Path, PathBuf};

use vitreous_caustics::CausticScene;
use vitreous_scene::{DiskFiles, Scene, SceneFiles, load_scene, load_scene_from};

fn shipped() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenes/glass-sphere.toml")
}

/// The disk, with the scene file's text replaced.
struct Edited {
    scene: PathBuf,
    text: String,
}

impl SceneFiles for Edited {
    fn read_bounded(&self, path: &Path, limit: u64, what: &str) -> std::io::Result<Vec<u8>> {
        if path == self.scene {
            Ok(self.text.clone().into_bytes())
        } else {
            DiskFiles.read_bounded(path, limit, what)
        }
    }
}

/// The shipped scene with `from` replaced by `to` in its file.
fn edited(from: &str, to: &str) -> Scene {
    let scene = shipped();
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains(from), "{from:?} is not in the shipped scene");
    let files = Edited {
        scene: scene.clone(),
        text: text.replacen(from, to, 1),
    };
    load_scene_from(&scene, &files).unwrap_or_else(|e| panic!("{from:?} -> {to:?}: {e}"))
}

/// Whether the baker reads the same from both scenes.
fn same_inputs(a: &Scene, b: &Scene) -> bool {
    let (a, b) = (CausticScene::from_scene(a), CausticScene::from_scene(b));
    a.positions_m == b.positions_m
        && a.normals == b.normals
        && a.indices == b.indices
        && a.ior == b.ior
        && a.light_position_m == b.light_position_m
        && a.world_from_floor == b.world_from_floor
}

#[test]
fn the_inputs_hash_follows_what_the_baker_reads_and_nothing_else() {
    let base = load_scene(&shipped()).unwrap();
    // The shipped bake holds the shipped scene's inputs hash.
    let mut loaded = base.clone();
    loaded.load_caustics().unwrap();
    assert_eq!(
        loaded.caustics.gain.unwrap().inputs_hash,
        Some(base.caustic_inputs_hash())
    );
    let keep = [
        ("[object]", "# a comment\n[object]"),
        ("ipd_mm = 63.0", "ipd_mm = 58.0"),
        ("width_px = 1280", "width_px = 640"),
        ("set = \"none\"", "set = \"c\""),
        ("gravel.png", "brick.png"),
        ("size_m = [1.5, 0.5]", "size_m = [1.5, 0.4]"),
        (
            "[environment]",
            "[display]\ncompensation = \"background\"\n\n[environment]",
        ),
        ("frame = \"object\"", "frame = \"object\"\nshare = 0.5"),
    ];
    let change = [
        ("diameter_m = 0.08", "diameter_m = 0.081"),
        ("ior = 1.51", "ior = 1.5"),
        (
            "position_m = [0.0, -0.26, -1.5]",
            "position_m = [0.001, -0.26, -1.5]",
        ),
        (
            "position_m = [0.0, 1.0, -1.0]",
            "position_m = [0.0, 1.0, -1.001]",
        ),
        ("size_m = [1.0, 1.0]", "size_m = [1.0, 1.01]"),
        (
            "position_m = [0.0, -0.30, -1.5]",
            "position_m = [0.0, -0.30, -1.49]",
        ),
        (
            "rotation_deg = [-90.0, 0.0, 0.0]",
            "rotation_deg = [-90.0, 0.0, 1.0]",
        ),
        ("sphere.glb", "torus.glb"),
        ("[light]", "rotation_deg = [0.0, 10.0, 0.0]\n\n[light]"),
    ];
    for (from, to) in keep {
        let scene = edited(from, to);
        assert!(
            same_inputs(&base, &scene),
            "{from:?} -> {to:?} changed the baker's inputs"
        );
        assert_eq!(
            scene.caustic_inputs_hash(),
            base.caustic_inputs_hash(),
            "{from:?} -> {to:?}"
        );
        // The whole scene's hash, which outputs record, still tells the files apart.
        assert_ne!(scene.hash, base.hash, "{from:?} -> {to:?}");
    }
    for (from, to) in change {
        let scene = edited(from, to);
        assert!(
            !same_inputs(&base, &scene),
            "{from:?} -> {to:?} left the baker's inputs"
        );
        assert_ne!(
            scene.caustic_inputs_hash(),
            base.caustic_inputs_hash(),
            "{from:?} -> {to:?}"
        );
        let err = {
            let mut s = scene;
            s.load_caustics().unwrap_err().to_string()
        };
        assert!(err.contains("re-bake with"), "{from:?} -> {to:?}: {err}");
    }
}
