//! Scene files whose assets are broken: glTF models (indices out of range, missing buffers,
//! non-finite values, schema failures, bad attenuation) and EXR environment maps. Each error
//! names the file and, where there is one, the field.

use std::path::Path;

use vitreous_scene::SceneError;

use super::scene_errors::{
    data, expect_error, good_env, good_model, good_text, line_of, load_text, repo, scene_text,
};

/// Loads a scene whose model is `model` and checks the error names the model file.
fn expect_model_error(model: &Path) -> String {
    let text = scene_text(model, &good_env());
    let (_dir, _path, result) = load_text(&text);
    let err = match result {
        Ok(_) => panic!("{} should be refused", model.display()),
        Err(e) => e,
    };
    let msg = err.to_string();
    assert!(
        matches!(err, SceneError::Asset { .. }),
        "not an asset error: {msg}"
    );
    assert_eq!(err.field(), Some("object.model"), "{msg}");
    let name = model.file_name().unwrap().to_str().unwrap();
    assert!(msg.contains(name), "{msg} does not name {name}");
    assert_eq!(err.location().unwrap().line, 2, "{msg}");
    msg
}

#[test]
fn gltf_with_indices_out_of_range_is_refused() {
    let msg = expect_model_error(&data(
        "bad-inputs/gltf/IndexOutOfRange/IndexOutOfRange.gltf",
    ));
    assert!(msg.contains("out of range"), "{msg}");
    expect_model_error(&data(
        "bad-inputs/gltf/IndexOutOfRange/AllIndicesOutOfRange.gltf",
    ));
}

#[test]
fn gltf_with_missing_bin_names_the_buffer() {
    let msg = expect_model_error(&data("bad-inputs/gltf/MissingBin/BoxTextured.gltf"));
    assert!(
        msg.contains("buffer 0") && msg.contains("not found"),
        "{msg}"
    );
}

#[test]
fn gltf_with_recursive_nodes_is_refused() {
    let msg = expect_model_error(&data("bad-inputs/gltf/RecursiveNodes/RecursiveNodes.gltf"));
    assert!(
        msg.contains("recursive") || msg.contains("invalid glTF"),
        "{msg}"
    );
}

#[test]
fn gltf_with_infinite_values_is_refused() {
    expect_model_error(&data(
        "bad-inputs/gltf/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
    ));
}

#[test]
fn gltf_with_bad_vertex_arrays_is_refused() {
    expect_model_error(&data("bad-inputs/gltf/IncorrectVertexArrays/Cube.gltf"));
}

#[test]
fn gltf_schema_failures_and_wrong_types_are_refused() {
    expect_model_error(&data("bad-inputs/gltf/SchemaFailures/sceneWrongType.gltf"));
    for name in ["badArray", "badNumber", "badObject", "badString", "badUint"] {
        expect_model_error(&data(&format!("bad-inputs/gltf/wrongTypes/{name}.gltf")));
    }
}

#[test]
fn bad_value_in_an_unused_extension_is_ignored() {
    // KHR_texture_transform holds a string instead of an object; the loader reads no
    // texture transforms (the gltf crate is built without that extension), so the model loads.
    let text = scene_text(
        &data("bad-inputs/gltf/wrongTypes/badExtension.gltf"),
        &good_env(),
    );
    let (_dir, _path, result) = load_text(&text);
    assert!(result.unwrap().object.mesh.triangle_count() > 0);
}

#[test]
fn bad_gltf_volume_attenuation_names_the_file_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    for (volume, field) in [
        (r#"{"attenuationDistance":0}"#, "attenuationDistance"),
        (r#"{"attenuationDistance":-2}"#, "attenuationDistance"),
        (
            r#"{"attenuationDistance":1,"attenuationColor":[0.5,1.25,0]}"#,
            "attenuationColor",
        ),
        (r#"{"attenuationColor":[-0.5,1,1]}"#, "attenuationColor"),
    ] {
        let model = crate::scene_load::tetrahedron_with_volume(dir.path(), volume);
        let msg = expect_model_error(&model);
        assert!(
            msg.contains(&format!(
                "materials[0].extensions.KHR_materials_volume.{field}"
            )),
            "{volume}: {msg}"
        );
    }
}

#[test]
fn bad_scene_attenuation_is_named() {
    let text = good_text().replace(
        "diameter_m = 0.08",
        "diameter_m = 0.08\nattenuation_distance_m = 0",
    );
    expect_error(
        &text,
        line_of(&text, "attenuation_distance_m"),
        "object.attenuation_distance_m",
    );
    let text = good_text().replace(
        "diameter_m = 0.08",
        "diameter_m = 0.08\nattenuation_distance_m = 0.1\nattenuation_color = [0.5, 2, 0]",
    );
    expect_error(
        &text,
        line_of(&text, "attenuation_color"),
        "object.attenuation_color",
    );
    // A colour needs a distance: the model gives none.
    let text = good_text().replace(
        "diameter_m = 0.08",
        "diameter_m = 0.08\nattenuation_color = [0.5, 0.5, 0.5]",
    );
    let msg = expect_error(
        &text,
        line_of(&text, "attenuation_color"),
        "object.attenuation_color",
    );
    assert!(msg.contains("attenuation_distance_m"), "{msg}");
}

#[test]
fn model_that_is_not_gltf_is_refused() {
    let msg = expect_model_error(&repo().join("config/textures/brick.png"));
    assert!(msg.contains("invalid glTF"), "{msg}");
}

/// Loads a scene whose environment map is `env` and checks the error names the file.
fn expect_env_error(env: &Path) -> String {
    let text = scene_text(&good_model(), env);
    let (_dir, _path, result) = load_text(&text);
    let err = match result {
        Ok(_) => panic!("{} should be refused", env.display()),
        Err(e) => e,
    };
    let msg = err.to_string();
    assert!(
        matches!(err, SceneError::Asset { .. }),
        "not an asset error: {msg}"
    );
    assert_eq!(err.field(), Some("environment.map"), "{msg}");
    let name = env.file_name().unwrap().to_str().unwrap();
    assert!(msg.contains(name), "{msg} does not name {name}");
    assert_eq!(
        err.location().unwrap().line,
        line_of(&text, "map = "),
        "{msg}"
    );
    msg
}

#[test]
fn broken_exr_files_are_refused() {
    for name in [
        "comp_bad_bounds_piz.exr",
        "comp_early_eof_piz.exr",
        "comp_invalid_unknown.exr",
        "comp_short_decode_piz.exr",
    ] {
        expect_env_error(&data(&format!("bad-inputs/exr/{name}")));
    }
}

#[test]
fn exr_with_bad_magic_is_refused() {
    let msg = expect_env_error(&data("bad-inputs/exr/invalid.exr"));
    assert!(msg.contains("magic"), "{msg}");
}

#[test]
fn dwab_exr_loads_or_is_refused_without_panic() {
    // exr 1.74 decodes DWAA/DWAB; older versions refuse it with a reason.
    let text = scene_text(&good_model(), &data("bad-inputs/exr/comp_dwab_v2.exr"));
    let (_dir, _path, result) = load_text(&text);
    if let Err(err) = result {
        assert!(err.to_string().contains("comp_dwab_v2.exr"), "{err}");
    }
}

#[test]
fn tiny_tiled_exr_loads_or_is_refused_without_panic() {
    let text = scene_text(&good_model(), &data("bad-inputs/exr/tiled.exr"));
    let (_dir, _path, result) = load_text(&text);
    if let Err(err) = result {
        assert!(err.to_string().contains("tiled.exr"), "{err}");
    }
}

#[test]
fn missing_env_map_is_named() {
    let msg = expect_env_error(&data("bad-inputs/exr/no-such-map.exr"));
    assert!(msg.contains("file not found"), "{msg}");
}
