//! The bake file's round trip, its errors and its limits.

use super::*;

fn sample() -> Bake {
    Bake {
        width_px: 5,
        height_px: 3,
        gain: (0..15).map(|i| i as f32 * 0.5).collect(),
        // Ratios half floats hold exactly.
        light: Some((0..15).map(|i| i as f32 * 0.25).collect()),
        inputs_hash: Some("abc123".into()),
        params: "method=test".into(),
    }
}

#[test]
fn bake_round_trips_with_hash_and_orientation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.exr");
    write_bake(&path, &sample()).unwrap();
    let back = read_bake(&path, "abc123").unwrap();
    assert_eq!(back, sample());
    // Written through a temporary file, renamed into place: nothing else is left.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["b.exr"]);
    assert_eq!(back.gain_at(4, 0), 2.0);
    assert!((back.sample(0.1, 1.0 / 6.0) - 0.0).abs() < 1e-6);
}

#[test]
fn a_bake_without_the_light_ratio_reads_as_before_and_a_bad_ratio_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.exr");
    // A bake made before the floor's light was stored: the gain alone.
    let old = Bake {
        light: None,
        ..sample()
    };
    write_bake(&path, &old).unwrap();
    assert_eq!(read_bake(&path, "abc123").unwrap(), old);
    // A negative or non-finite ratio is no light.
    for bad in [-0.5, f32::NAN, f32::INFINITY] {
        let mut light = vec![1.0; 15];
        light[7] = bad;
        let corrupt = Bake {
            light: Some(light),
            ..sample()
        };
        write_bake(&path, &corrupt).unwrap();
        let err = read_bake(&path, "abc123").unwrap_err().to_string();
        assert!(
            err.contains("light ratio") && err.contains("b.exr"),
            "{bad}: {err}"
        );
    }
    // As many ratios as texels, or nothing is written.
    let short = Bake {
        light: Some(vec![1.0; 14]),
        ..sample()
    };
    let err = write_bake(&dir.path().join("c.exr"), &short).unwrap_err();
    assert!(err.to_string().contains("14 light ratios"), "{err}");
    assert!(!dir.path().join("c.exr").exists());
}

#[test]
fn missing_corrupt_and_foreign_bakes_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.exr");
    let err = read_bake(&path, "x").unwrap_err();
    assert!(matches!(err, BakeError::Missing { .. }), "{err}");
    assert!(err.to_string().contains("vitreous bake"));

    std::fs::write(&path, b"not an exr").unwrap();
    let err = read_bake(&path, "x").unwrap_err();
    assert!(matches!(err, BakeError::Corrupt { .. }), "{err}");

    write_bake(&path, &sample()).unwrap();
    let err = read_bake(&path, "other").unwrap_err();
    assert!(matches!(err, BakeError::WrongScene { .. }), "{err}");
    assert!(err.to_string().contains("abc123") && err.to_string().contains("other"));
}

#[test]
fn a_bake_made_before_inputs_were_hashed_is_refused_as_outdated() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.exr");
    write_with_hash(&path, &sample(), (SCENE_HASH_ATTRIBUTE, "abc123")).unwrap();
    let old = read_bake_unchecked(&path).unwrap();
    assert_eq!(old.inputs_hash, None);
    assert_eq!(old.gain, sample().gain);
    let err = read_bake(&path, "abc123")
        .unwrap_err()
        .in_scene(Path::new("s.toml"));
    assert!(matches!(err, BakeError::Outdated { .. }), "{err}");
    let text = err.to_string();
    assert!(
        text.contains("earlier vitreous") && text.contains("vitreous bake s.toml -o"),
        "{text}"
    );
    // Neither hash: not a bake.
    write_with_hash(&path, &sample(), ("something_else", "abc123")).unwrap();
    let err = read_bake(&path, "abc123").unwrap_err();
    assert!(matches!(err, BakeError::Corrupt { .. }), "{err}");
    // A bake without a hash is not written.
    let unhashed = Bake {
        inputs_hash: None,
        ..sample()
    };
    let err = write_bake(&dir.path().join("n.exr"), &unhashed).unwrap_err();
    assert!(err.to_string().contains("no inputs hash"), "{err}");
    assert!(!dir.path().join("n.exr").exists());
}

#[test]
fn errors_in_a_scene_name_it_and_give_the_exact_command() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.exr");
    let scene = Path::new("config/scenes/s.toml");
    let command = format!("`vitreous bake config/scenes/s.toml -o {}`", path.display());
    let missing = read_bake(&path, "x").unwrap_err().in_scene(scene);
    std::fs::write(&path, b"not an exr").unwrap();
    let corrupt = read_bake(&path, "x").unwrap_err().in_scene(scene);
    write_bake(&path, &sample()).unwrap();
    let stale = read_bake(&path, "other").unwrap_err().in_scene(scene);
    for err in [missing, corrupt, stale] {
        let text = err.to_string();
        assert!(text.contains("(named by config/scenes/s.toml)"), "{text}");
        assert!(text.contains(&command), "{text}");
        assert!(!text.contains("<scene.toml>"), "{text}");
    }
}

/// A header claiming an absurd layer is refused before any sample is read, and so is a
/// file larger than the largest bake, without reading it.
#[test]
fn absurd_sizes_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.exr");
    write_bake(&path, &sample()).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    for (max_x, max_y, refused_for_size) in [(99_999, 2, true), (4, 16_384, true), (-1, 2, false)] {
        let mut patched = bytes.clone();
        let window = [0i32, 0, max_x, max_y].map(i32::to_le_bytes).concat();
        patched[at..at + 16].copy_from_slice(&window);
        let err = decode_bake(&patched).unwrap_err();
        let size = format!(
            "{} x {} texels; a bake has 1..=16384 per side",
            max_x + 1,
            max_y + 1
        );
        assert!(
            !refused_for_size || err.contains(&size),
            "{max_x} {max_y}: {err}"
        );
        std::fs::write(&path, &patched).unwrap();
        let err = read_bake(&path, "abc123").unwrap_err();
        assert!(matches!(err, BakeError::Corrupt { .. }), "{err}");
    }
    bytes.truncate(bytes.len() - 8);
    assert!(decode_bake(&bytes).is_err());

    let file = std::fs::File::create(&path).unwrap();
    file.set_len(MAX_BAKE_BYTES + 1).unwrap();
    let err = read_bake(&path, "abc123").unwrap_err();
    assert!(matches!(err, BakeError::Corrupt { .. }), "{err}");
    assert!(
        err.to_string().contains("the largest bake is smaller"),
        "{err}"
    );
}
