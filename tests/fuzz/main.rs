//! Mutation fuzzing of every parser that reads a user's file: TOML scenes,
//! OBJ meshes, glTF/GLB assets (JSON and binary) and their node
//! transforms, their PNG and JPEG textures (bytes, and headers claiming
//! other sizes), and MERL tables; and every file key given a special file
//! (a FIFO, a device, a directory) in place of one.
//!
//! Each target mutates files of its seed corpus (the repository's own
//! scenes and assets, plus `tests/fuzz/corpus/`) with a seeded stream and
//! loads every mutant. The property: a result, or an error that names the
//! file; never a panic. A mutant that breaks it is saved under the target
//! directory's `fuzz-failures/`, named by target and iteration.
//!
//! The default budget is small and fixed. A longer run, or other streams:
//!
//! ```text
//! LUMIS_FUZZ_ITERATIONS=20000 LUMIS_FUZZ_SEED=7 \
//!     cargo test --release -p lumis-tests --test fuzz
//! ```

mod mutate;
mod regressions;

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, Once};

use base64::Engine;
use lumis_tests::scenes_dir;
use mutate::Rng;
use serde_json::Value;

/// A file of a seed corpus.
struct Seed {
    name: String,
    bytes: Vec<u8>,
}

fn seed(path: PathBuf) -> Seed {
    Seed {
        name: path.file_name().unwrap().to_string_lossy().into_owned(),
        bytes: std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    }
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus")
}

/// Mutants per target: `LUMIS_FUZZ_ITERATIONS`, else a budget that keeps
/// the default test tier fast.
fn iterations(default: usize) -> usize {
    std::env::var("LUMIS_FUZZ_ITERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn base_seed() -> u64 {
    std::env::var("LUMIS_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

/// The messages of panics caught since the last call, with where they
/// happened (a panic may be raised on a rayon worker thread and resumed on
/// the caller's).
static PANICS: Mutex<Vec<String>> = Mutex::new(Vec::new());
/// How many [`without_panic`] calls are running: outside them, panics (a
/// failed assertion) are reported as usual.
static CATCHING: AtomicUsize = AtomicUsize::new(0);

/// Runs `f`, turning a panic into `Err` with its message and location.
fn without_panic<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let report = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if CATCHING.load(Ordering::SeqCst) == 0 {
                report(info);
            } else {
                PANICS.lock().unwrap().push(info.to_string());
            }
        }));
    });
    CATCHING.fetch_add(1, Ordering::SeqCst);
    let result = std::panic::catch_unwind(AssertUnwindSafe(f));
    CATCHING.fetch_sub(1, Ordering::SeqCst);
    result.map_err(|_| std::mem::take(&mut *PANICS.lock().unwrap()).join("; "))
}

/// Mutates and loads `count` mutants; returns each broken property as
/// "iteration: what", with the mutant saved for replay.
fn fuzz(
    target: &str,
    seeds: &[Seed],
    count: usize,
    mutate: impl Fn(&mut Rng, &Seed) -> Vec<u8>,
    load: impl Fn(&Path, &Seed, &[u8]) -> Result<(), String>,
) {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for i in 0..count {
        let mut rng = Rng::new(base_seed() ^ (i as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
        let seed = rng.pick(seeds);
        let mutant = mutate(&mut rng, seed);
        let broken = match without_panic(|| load(dir.path(), seed, &mutant)) {
            Err(panic) => Some(format!("panicked: {panic}")),
            Ok(Err(unlocated)) => Some(format!("error names no file: {unlocated}")),
            Ok(Ok(())) => None,
        };
        if let Some(broken) = broken {
            let saved = save_failure(target, i, &seed.name, &mutant);
            failures.push(format!(
                "#{i} (from {}, saved as {}): {broken}",
                seed.name,
                saved.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{target}: {} of {count} mutants broke the property:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

fn save_failure(target: &str, iteration: usize, seed_name: &str, bytes: &[u8]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-failures");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{target}-{iteration}-{seed_name}"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// `Ok` for a loaded scene, and for an error that mentions `file`.
fn located(result: lumis_core::Result<lumis_scene::LoadedScene>, file: &str) -> Result<(), String> {
    match result {
        Ok(_) => Ok(()),
        Err(e) if e.to_string().contains(file) => Ok(()),
        Err(e) => Err(e.to_string()),
    }
}

fn load_scene(text: &str, dir: &Path) -> lumis_core::Result<lumis_scene::LoadedScene> {
    let registry = lumis_app::builtin_registry().unwrap();
    lumis_scene::load_str(text, &dir.join("fuzz.toml"), &[], &registry)
}

/// A scene around one mesh file, with `camera` for its camera table. An
/// OBJ gets the scene's BSDF; a glTF asset keeps its own materials, so
/// that they are parsed too.
fn scene_with_shape(shape_type: &str, file: &str, camera: &str) -> String {
    let bsdf = if shape_type == "gltf" {
        ""
    } else {
        "bsdf = \"white\""
    };
    format!(
        r#"[film]
resolution = [8, 8]
{camera}
[sampler]
type = "independent"
spp = 1
[integrator]
type = "path"
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.5
[[shape]]
type = "{shape_type}"
file = "{file}"
{bsdf}
"#
    )
}

const PERSPECTIVE: &str = r#"[camera]
type = "perspective"
origin = [0.0, 1.0, 6.0]
target = [0.0, 0.0, 0.0]
fov = 40.0"#;

#[test]
fn toml_scenes() {
    let mut seeds: Vec<Seed> = ["cornell-box.toml", "glossy-plates.toml", "gltf-boxes.toml"]
        .iter()
        .map(|name| seed(scenes_dir().join(name)))
        .collect();
    seeds.push(seed(corpus_dir().join("every-table.toml")));
    fuzz(
        "toml",
        &seeds,
        iterations(300),
        |rng, seed| mutate::text(rng, &seed.bytes),
        |_, _, mutant| {
            located(
                load_scene(&String::from_utf8_lossy(mutant), &scenes_dir()),
                "fuzz.toml",
            )
        },
    );
}

#[test]
fn obj_meshes() {
    let seeds: Vec<Seed> = ["large_box.obj", "light.obj"]
        .iter()
        .map(|name| seed(scenes_dir().join("cornell-box").join(name)))
        .chain([seed(corpus_dir().join("normals-and-uvs.obj"))])
        .collect();
    fuzz(
        "obj",
        &seeds,
        iterations(300),
        |rng, seed| mutate::text(rng, &seed.bytes),
        |dir, _, mutant| {
            std::fs::write(dir.join("mutant.obj"), mutant).unwrap();
            let scene = scene_with_shape("obj", "mutant.obj", PERSPECTIVE);
            located(load_scene(&scene, dir), "mutant.obj")
        },
    );
}

#[test]
fn gltf_assets() {
    let seeds = [
        seed(scenes_dir().join("gltf/boxes.gltf")),
        seed(scenes_dir().join("bench/textured.glb")),
        seed(corpus_dir().join("sparse-ortho.gltf")),
    ];
    fuzz(
        "gltf",
        &seeds,
        iterations(400),
        |rng, seed| match (seed.name.ends_with(".glb"), rng.below(3)) {
            (true, 0) => mutate::binary(rng, &seed.bytes),
            (true, _) => mutate_glb_json(rng, &seed.bytes),
            (false, 0) => mutate::text(rng, &seed.bytes),
            (false, _) => {
                let doc: Value = serde_json::from_slice(&seed.bytes).unwrap();
                serde_json::to_vec(&mutate::json(rng, &doc)).unwrap()
            }
        },
        |dir, seed, mutant| {
            let file = if seed.name.ends_with(".glb") {
                "mutant.glb"
            } else {
                "mutant.gltf"
            };
            std::fs::write(dir.join(file), mutant).unwrap();
            let as_shape = scene_with_shape("gltf", file, PERSPECTIVE);
            located(load_scene(&as_shape, dir), file)?;
            let camera = format!("[camera]\ntype = \"gltf\"\nfile = \"{file}\"");
            let as_camera = scene_with_shape("gltf", file, &camera);
            located(load_scene(&as_camera, dir), file)
        },
    );
}

/// The PNG and JPEG decoders, reached as a glTF material's base-colour
/// texture: the image's bytes are mutated, the asset around them is valid.
#[test]
fn gltf_texture_images() {
    let (w, h) = (8u32, 8u32);
    let pixels: Vec<u8> = (0..w * h * 3).map(|i| (i * 37 % 251) as u8).collect();
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
        .encode(&pixels, w, h, image::ColorType::Rgb8)
        .unwrap();
    let asset: Value =
        serde_json::from_slice(&seed(corpus_dir().join("sparse-ortho.gltf")).bytes).unwrap();
    let png = asset["images"][0]["uri"]
        .as_str()
        .and_then(|uri| uri.split_once(";base64,"))
        .map(|(_, data)| {
            base64::engine::general_purpose::STANDARD
                .decode(data)
                .unwrap()
        })
        .unwrap();
    let seeds = [
        Seed {
            name: "texture.png".into(),
            bytes: png,
        },
        Seed {
            name: "texture.jpg".into(),
            bytes: jpeg,
        },
    ];
    // A third of the mutants claim another size in their header, up to
    // billions of pixels: a decoder that allocated the claim would abort
    // this process, which fails the test as surely as a panic.
    fuzz(
        "image",
        &seeds,
        iterations(300),
        |rng, seed| match rng.below(3) {
            0 => mutate::image_claim(rng, &seed.bytes),
            _ => mutate::binary(rng, &seed.bytes),
        },
        |dir, seed, mutant| {
            let mime = if seed.name.ends_with(".png") {
                "image/png"
            } else {
                "image/jpeg"
            };
            let mut doc = asset.clone();
            doc["images"][0] = serde_json::json!({
                "uri": format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(mutant)),
            });
            std::fs::write(dir.join("mutant.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
            let scene = scene_with_shape("gltf", "mutant.gltf", PERSPECTIVE);
            located(load_scene(&scene, dir), "mutant.gltf")
        },
    );
}

/// glTF node transforms that are not finite, not affine, singular or out
/// of Embree's range. The property is stronger than the other targets':
/// a mutant that loads has every triangle of its seed, unless the load
/// report says which node scaled its mesh to nothing.
#[test]
fn gltf_node_transforms() {
    let seeds = [
        seed(scenes_dir().join("gltf/boxes.gltf")),
        seed(corpus_dir().join("sparse-ortho.gltf")),
    ];
    let dir = tempfile::tempdir().unwrap();
    let triangles_of = |seed: &Seed| {
        std::fs::write(dir.path().join("seed.gltf"), &seed.bytes).unwrap();
        let scene = scene_with_shape("gltf", "seed.gltf", PERSPECTIVE);
        load_scene(&scene, dir.path())
            .unwrap()
            .scene
            .counts()
            .triangles
    };
    let triangles: Vec<(String, usize)> = seeds
        .iter()
        .map(|s| (s.name.clone(), triangles_of(s)))
        .collect();
    fuzz(
        "transform",
        &seeds,
        iterations(400) / 4,
        |rng, seed| {
            let doc: Value = serde_json::from_slice(&seed.bytes).unwrap();
            serde_json::to_vec(&mutate::node_transform(rng, &doc)).unwrap()
        },
        |dir, seed, mutant| {
            std::fs::write(dir.join("mutant.gltf"), mutant).unwrap();
            let scene = scene_with_shape("gltf", "mutant.gltf", PERSPECTIVE);
            let loaded = match load_scene(&scene, dir) {
                Ok(loaded) => loaded,
                Err(e) => return located(Err(e), "mutant.gltf"),
            };
            let expected = triangles.iter().find(|(n, _)| *n == seed.name).unwrap().1;
            let placed = loaded.scene.counts().triangles;
            let said = loaded
                .scene
                .load_report()
                .warnings
                .iter()
                .any(|w| w.contains("is not placed"));
            if placed < expected && !said {
                return Err(format!(
                    "{} of {expected} triangles placed, and no warning says why",
                    placed
                ));
            }
            let camera = "[camera]\ntype = \"gltf\"\nfile = \"mutant.gltf\"";
            located(
                load_scene(&scene_with_shape("gltf", "mutant.gltf", camera), dir),
                "mutant.gltf",
            )
        },
    );
}

/// Every key that names a file, given a FIFO, a device or a directory:
/// an error naming it, within a deadline (opening a FIFO would block).
#[test]
fn special_files_in_place_of_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    let have_fifo = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if !have_fifo {
        eprintln!("skipped the FIFO cases: mkfifo is missing");
    }
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero")).unwrap();
    std::fs::create_dir(dir.path().join("folder")).unwrap();
    let specials = ["fifo", "zero", "folder"]
        .into_iter()
        .filter(|s| have_fifo || *s != "fifo");
    let light = scenes_dir()
        .join("cornell-box/light.obj")
        .display()
        .to_string();
    let scenes = |file: &str| -> Vec<String> {
        let lit = scene_with_shape("obj", &light, PERSPECTIVE);
        let textured = format!(
            "[[texture]]\nname = \"t\"\ntype = \"image\"\nfilename = \"{file}\"\n\
             [[bsdf]]\nname = \"b\"\ntype = \"diffuse\"\nreflectance = {{ texture = \"t\" }}\n"
        );
        let envmap = format!("[[light]]\ntype = \"envmap\"\nfilename = \"{file}\"\n");
        let measured = format!("[[bsdf]]\nname = \"m\"\ntype = \"measured\"\nfile = \"{file}\"\n");
        vec![
            scene_with_shape("obj", file, PERSPECTIVE),
            scene_with_shape("gltf", file, PERSPECTIVE),
            lit.clone() + &textured,
            lit.clone() + &envmap,
            lit + &measured,
        ]
    };
    let mut failures = Vec::new();
    for special in specials {
        for scene in scenes(special) {
            let at = dir.path().to_path_buf();
            let (send, receive) = std::sync::mpsc::channel();
            let text = scene.clone();
            std::thread::spawn(move || {
                let outcome = without_panic(|| load_scene(&text, &at).map(|_| ()));
                let _ = send.send(outcome);
            });
            match receive.recv_timeout(std::time::Duration::from_secs(60)) {
                Err(_) => failures.push(format!("{special}: blocked for a minute:\n{scene}")),
                Ok(Err(panic)) => failures.push(format!("{special}: panicked: {panic}")),
                Ok(Ok(Ok(()))) => failures.push(format!("{special}: loaded:\n{scene}")),
                Ok(Ok(Err(e))) => {
                    let e = e.to_string();
                    let said = e.contains("not a regular file") || e.contains("is a directory");
                    if !(said && e.contains(special)) {
                        failures.push(format!("{special}: {e}"));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A GLB with its JSON chunk mutated as JSON and the container's lengths
/// made consistent again, so the mutation reaches the document.
fn mutate_glb_json(rng: &mut Rng, glb: &[u8]) -> Vec<u8> {
    let u32_at = |o: usize| u32::from_le_bytes(glb[o..o + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let doc: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let mut json = serde_json::to_vec(&mutate::json(rng, &doc)).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let rest = &glb[20 + json_len..];
    let total = 12 + 8 + json.len() + rest.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&glb[..8]);
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&glb[16..20]);
    out.extend_from_slice(&json);
    out.extend_from_slice(rest);
    out
}

#[test]
fn merl_tables() {
    use lumis_measured::merl::{
        MerlTable, FILE_BYTES, HEADER_BYTES, PHI_D_RES, THETA_D_RES, THETA_H_RES,
    };
    let mut valid = Vec::with_capacity(FILE_BYTES);
    for dim in [THETA_H_RES, THETA_D_RES, PHI_D_RES] {
        valid.extend_from_slice(&(dim as i32).to_le_bytes());
    }
    valid.resize(FILE_BYTES, 0);
    for value in valid[HEADER_BYTES..].chunks_exact_mut(8) {
        value.copy_from_slice(&0.25f64.to_le_bytes());
    }
    let seeds = [Seed {
        name: "constant.binary".into(),
        bytes: valid,
    }];
    fuzz(
        "merl",
        &seeds,
        iterations(400) / 25,
        |rng, seed| mutate::binary(rng, &seed.bytes),
        |_, _, mutant| match MerlTable::from_bytes(mutant, "mutant.binary") {
            Ok(_) => Ok(()),
            Err(e) if e.to_string().contains("mutant.binary") => Ok(()),
            Err(e) => Err(e.to_string()),
        },
    );
}
