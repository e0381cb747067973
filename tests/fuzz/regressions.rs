//! Every mutant that once broke a parser, written out as the edit that
//! makes it, with the error it must now give.

use serde_json::{json, Value};

use crate::{load_scene, scene_with_shape, seed, without_panic, PERSPECTIVE};
use lumis_tests::scenes_dir;

/// Loads `doc` as a glTF shape (and, with `as_camera`, as the camera too)
/// and returns the error, which must exist and name the asset.
fn gltf_error(doc: &Value, as_camera: bool) -> String {
    let err = gltf_outcome(doc, as_camera).expect_err("the mutant loaded");
    assert!(
        err.contains("mutant.gltf"),
        "the error names no file: {err}"
    );
    err
}

/// Loads `doc` as [`gltf_error`] does; `Err` holds the error's text.
fn gltf_outcome(doc: &Value, as_camera: bool) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("mutant.gltf"),
        serde_json::to_vec(doc).unwrap(),
    )
    .unwrap();
    let camera = if as_camera {
        "[camera]\ntype = \"gltf\"\nfile = \"mutant.gltf\"".to_string()
    } else {
        PERSPECTIVE.to_string()
    };
    let scene = scene_with_shape("gltf", "mutant.gltf", &camera);
    without_panic(|| load_scene(&scene, dir.path()).map(|_| ()))
        .unwrap_or_else(|panic| panic!("panicked: {panic}"))
        .map_err(|e| e.to_string())
}

fn boxes() -> Value {
    serde_json::from_slice(&seed(scenes_dir().join("gltf/boxes.gltf")).bytes).unwrap()
}

fn sparse_ortho() -> Value {
    serde_json::from_slice(&seed(crate::corpus_dir().join("sparse-ortho.gltf")).bytes).unwrap()
}

#[test]
fn position_naming_a_missing_accessor() {
    let mut doc = boxes();
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(999);
    let err = gltf_error(&doc, false);
    assert!(
        err.contains("POSITION: accessor 999 does not exist"),
        "{err}"
    );
}

/// A texture that cannot be read is left out with a warning (the asset
/// renders with its factors), so these may load.
#[test]
fn images_the_gltf_crate_would_unwrap() {
    for image in [
        json!({ "mimeType": "image/png" }),
        json!({ "bufferView": 0 }),
    ] {
        let mut doc = sparse_ortho();
        doc["images"][0] = image.clone();
        if let Err(err) = gltf_outcome(&doc, false) {
            assert!(err.contains("mutant.gltf"), "{image}: {err}");
        }
    }
}

#[test]
fn orthographic_camera_without_its_object() {
    let mut doc = sparse_ortho();
    doc["cameras"][0] = json!({ "type": "orthographic" });
    let err = gltf_error(&doc, true);
    assert!(err.contains("cameras[0]"), "{err}");
}

#[test]
fn offsets_near_two_to_the_64() {
    for (what, edit) in [
        ("buffer view", json!(["bufferViews", 0, "byteOffset"])),
        ("accessor", json!(["accessors", 0, "byteOffset"])),
    ] {
        let mut doc = sparse_ortho();
        let path = edit.as_array().unwrap();
        let node = &mut doc[path[0].as_str().unwrap()][path[1].as_u64().unwrap() as usize]
            [path[2].as_str().unwrap()];
        *node = json!(u64::MAX - 3);
        let err = gltf_error(&doc, false);
        assert!(
            err.contains("2^64") || err.contains("byteOffset"),
            "{what}: {err}"
        );
    }
}

#[test]
fn sparse_values_past_their_view() {
    let mut doc = sparse_ortho();
    doc["accessors"][0]["sparse"]["values"]["byteOffset"] = json!(8);
    let err = gltf_error(&doc, false);
    assert!(err.contains("sparse values"), "{err}");
}

#[test]
fn camera_node_with_a_non_finite_transform() {
    let mut doc = boxes();
    let camera_node = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n.get("camera").is_some())
        .unwrap();
    doc["nodes"][camera_node]["scale"] = json!([1e300, 1e300, 1e300]);
    let err = gltf_error(&doc, true);
    assert!(
        err.contains("'mutant.gltf': node #") && err.contains("is not finite"),
        "{err}"
    );
}

#[test]
fn glb_declaring_less_than_its_header() {
    let mut glb = seed(scenes_dir().join("bench/textured.glb")).bytes;
    glb[8..12].copy_from_slice(&4u32.to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("mutant.glb"), glb).unwrap();
    let scene = scene_with_shape("gltf", "mutant.glb", PERSPECTIVE);
    let err = without_panic(|| load_scene(&scene, dir.path()).map(|_| ()))
        .unwrap_or_else(|panic| panic!("panicked: {panic}"))
        .expect_err("the mutant loaded")
        .to_string();
    assert!(err.contains("declares a length of 4 bytes"), "{err}");
}

#[test]
fn obj_face_index_at_the_end_of_i64() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//-9223372036854775808\n";
    std::fs::write(dir.path().join("mutant.obj"), obj).unwrap();
    let scene = crate::scene_with_shape("obj", "mutant.obj", PERSPECTIVE);
    let err = without_panic(|| load_scene(&scene, dir.path()).map(|_| ()))
        .unwrap_or_else(|panic| panic!("panicked: {panic}"))
        .expect_err("the mutant loaded")
        .to_string();
    assert!(
        err.contains("mutant.obj' line 5: face index -9223372036854775808 names no normal"),
        "{err}"
    );
}
