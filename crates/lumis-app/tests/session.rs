//! The render session as a library caller drives it: its notes and
//! progress reach the caller, a stop flag ends it with the passes done,
//! and the image is the one the command line writes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use lumis_app::{
    builtin_registry, render, render_film, FilmRequest, ImageMetadata, Progress, RenderArgs,
    SampleSlice, Session,
};
use lumis_core::{DenoiseInput, Denoiser, Params, PluginKind, PluginParams, PluginSpec, Registrar};
use lumis_scene::SceneDocument;

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// A small Cornell box render of `spp` samples in passes of one, written
/// under `dir`.
fn small_box(dir: &Path, spp: u32) -> RenderArgs {
    RenderArgs {
        scene: scene("cornell-box.toml"),
        spp: Some(spp),
        threads: 2,
        set: vec!["film.resolution=[32, 32]".into()],
        output: Some(dir.join("box.exr")),
        pass_spp: Some(1),
        ..Default::default()
    }
}

/// The start-up report arrives as notes, the progress counts up to its
/// total, and the image is written where asked.
#[test]
fn notes_and_progress_reach_the_caller() {
    let dir = tempfile::tempdir().unwrap();
    let registry = builtin_registry().unwrap();
    let stop = AtomicBool::new(false);
    let notes = Mutex::new(Vec::<String>::new());
    let last = Arc::new(Mutex::new((0u64, 0u64)));
    let seen = last.clone();
    let session = Session {
        registry: &registry,
        stop: &stop,
        notes: &|line| notes.lock().unwrap().push(line.to_string()),
        progress: Progress::Reported(Arc::new(move |done, total| {
            let mut seen = seen.lock().unwrap();
            *seen = (seen.0.max(done), total);
        })),
        thread_host: None,
    };
    let report = render(&small_box(dir.path(), 4), &session).unwrap();
    assert_eq!(report.spp, 4);
    assert!(report.exr.exists() && report.png.exists());
    let notes = notes.into_inner().unwrap();
    for expected in ["loaded", "memory:", "SIMD kernels:"] {
        assert!(
            notes.iter().any(|line| line.starts_with(expected)),
            "no note starting {expected:?} in {notes:?}"
        );
    }
    let (done, total) = *last.lock().unwrap();
    assert!(total > 0 && done == total, "progress {done} of {total}");

    // Quiet: no start-up report and no progress; the same image.
    let quiet_notes = Mutex::new(Vec::<String>::new());
    let calls = Arc::new(AtomicU64::new(0));
    let counted = calls.clone();
    let quiet = Session {
        notes: &|line| quiet_notes.lock().unwrap().push(line.to_string()),
        progress: Progress::Reported(Arc::new(move |_, _| {
            counted.fetch_add(1, Ordering::Relaxed);
        })),
        ..Session::silent(&registry, &stop)
    };
    let args = RenderArgs {
        quiet: true,
        output: Some(dir.path().join("quiet.exr")),
        ..small_box(dir.path(), 4)
    };
    let again = render(&args, &quiet).unwrap();
    assert_eq!(quiet_notes.into_inner().unwrap(), Vec::<String>::new());
    assert_eq!(calls.load(Ordering::Relaxed), 0);
    assert_eq!(again.image.pixels, report.image.pixels);
}

/// A stop set while the render runs ends it after the pass in flight:
/// the report says interrupted, holds fewer samples than asked, and the
/// image so far is on disk beside the outputs with a note saying where.
#[test]
fn a_stop_ends_the_render_with_the_passes_done() {
    let dir = tempfile::tempdir().unwrap();
    let registry = builtin_registry().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let notes = Mutex::new(Vec::<String>::new());
    let spp = 16;
    let stopper = stop.clone();
    // Stopped once a quarter of the units are done: after some passes.
    let session = Session {
        registry: &registry,
        stop: &stop,
        notes: &|line| notes.lock().unwrap().push(line.to_string()),
        progress: Progress::Reported(Arc::new(move |done, total| {
            if done * 4 >= total {
                stopper.store(true, Ordering::Relaxed);
            }
        })),
        thread_host: None,
    };
    let report = render(&small_box(dir.path(), spp), &session).unwrap();
    assert!(report.interrupted);
    assert!(report.spp >= 1 && report.spp < spp, "{} spp", report.spp);
    let notes = notes.into_inner().unwrap();
    assert!(
        notes.iter().any(|line| line.starts_with("interrupted at")),
        "{notes:?}"
    );
    assert!(
        !report.exr.exists(),
        "an unfinished render is not the image"
    );
}

/// A render in memory is the render to files, bit for bit; a slice of it
/// written from memory is the partial image `lumis merge` reads.
#[test]
fn a_render_in_memory_is_the_render_to_files() {
    let dir = tempfile::tempdir().unwrap();
    let registry = builtin_registry().unwrap();
    let stop = AtomicBool::new(false);
    let session = Session::silent(&registry, &stop);
    let args = small_box(dir.path(), 4);
    let on_disk = render(&args, &session).unwrap();
    let document = SceneDocument::read(&args.scene)
        .unwrap()
        .with_overrides(args.set.clone());
    let loaded = document
        .load(&["sampler.spp=4".to_string()], &registry)
        .unwrap();
    let request = FilmRequest {
        threads: 2,
        ..Default::default()
    };
    let in_memory = render_film(&loaded, &request, &session).unwrap();
    assert_eq!(in_memory.spp(), 4);
    assert!(!in_memory.interrupted);
    assert_eq!(in_memory.film.image().pixels, on_disk.image.pixels);

    // Written, it is the command line's image with the same header.
    let (exr, png) = in_memory
        .write(&dir.path().join("memory"), &document, false)
        .unwrap();
    assert!(png.is_some_and(|p| p.exists()));
    let written = ImageMetadata::read(&exr).unwrap().unwrap();
    let expected = ImageMetadata::read(&on_disk.exr).unwrap().unwrap();
    assert_eq!(
        (
            written.scene_hash,
            written.scene_file_hash,
            written.spp,
            written.seed
        ),
        (
            expected.scene_hash,
            expected.scene_file_hash,
            expected.spp,
            expected.seed
        )
    );

    // A slice outside the scene's samples is refused.
    let beyond = FilmRequest {
        samples: Some(SampleSlice {
            start: 2,
            end: 9,
            total: 4,
        }),
        ..Default::default()
    };
    let refused = render_film(&loaded, &beyond, &session).err().unwrap();
    assert!(
        refused.message.contains("expected sample indices"),
        "{refused}"
    );
}

/// A denoiser that halves the colour, or (`fails = true`) fails.
struct Halving {
    fails: bool,
}

impl Denoiser for Halving {
    fn denoise(&self, input: &DenoiseInput<'_>) -> lumis_core::Result<Vec<[f32; 3]>> {
        match self.fails {
            true => Err(lumis_core::Error::msg("no device")),
            false => Ok(input.color.iter().map(|c| c.map(|v| 0.5 * v)).collect()),
        }
    }
}

#[derive(Debug, PluginParams)]
struct HalvingParams {
    /// fail instead
    #[param(default = false)]
    fails: bool,
}

const HALVING: PluginSpec = PluginSpec {
    kind: PluginKind::Denoiser,
    name: "halving",
    source: lumis_api::source_file!(),
    doc: "halves the colour, or fails",
    params: HalvingParams::SPECS,
};

fn halving(params: &Params) -> lumis_core::Result<Box<dyn Denoiser>> {
    let p = HalvingParams::read(params)?;
    Ok(Box::new(Halving { fails: p.fails }))
}

/// A render in memory of a scene with a `[denoiser]` denoises its image
/// once finished, and writes it beside the raw one; a part is not
/// denoised; a denoiser that fails leaves the render, with the error.
#[test]
fn a_render_in_memory_runs_the_scenes_denoiser() {
    let dir = tempfile::tempdir().unwrap();
    let mut registry = builtin_registry().unwrap();
    registry.add_denoiser(HALVING, halving).unwrap();
    let stop = AtomicBool::new(false);
    let session = Session::silent(&registry, &stop);
    let document = SceneDocument::read(&scene("cornell-box.toml"))
        .unwrap()
        .with_overrides(vec!["film.resolution=[16, 16]".into()]);
    let load = |denoiser: &str| {
        let set = ["sampler.spp=2".to_string(), denoiser.to_string()];
        document.load(&set, &registry).unwrap()
    };
    let request = FilmRequest {
        threads: 2,
        ..Default::default()
    };

    let loaded = load("denoiser.type=\"halving\"");
    let rendered = render_film(&loaded, &request, &session).unwrap();
    let halved: Vec<[f32; 3]> = rendered
        .film
        .image()
        .pixels
        .iter()
        .map(|c| c.map(|v| 0.5 * v))
        .collect();
    assert_eq!(rendered.denoised_image().unwrap().pixels, halved);
    let (exr, _) = rendered
        .write(&dir.path().join("box"), &document, false)
        .unwrap();
    let denoised_exr = dir.path().join("box.denoised.exr");
    assert!(exr.exists() && denoised_exr.exists());
    assert!(dir.path().join("box.denoised.png").exists());
    let image = lumis_image::read_exr(&denoised_exr).unwrap();
    assert_eq!(image.pixels, halved);

    let part = FilmRequest {
        samples: Some(SampleSlice {
            start: 0,
            end: 1,
            total: 2,
        }),
        ..request.clone()
    };
    assert!(render_film(&loaded, &part, &session)
        .unwrap()
        .denoised
        .is_none());

    let failing = load("denoiser={ type = \"halving\", fails = true }");
    let rendered = render_film(&failing, &request, &session).unwrap();
    let error = rendered.denoised.as_ref().unwrap().as_ref().unwrap_err();
    assert!(error.to_string().contains("no device"), "{error}");
    assert_eq!(rendered.spp(), 2);
    rendered
        .write(&dir.path().join("failed"), &document, false)
        .unwrap();
    assert!(dir.path().join("failed.exr").exists());
    assert!(!dir.path().join("failed.denoised.exr").exists());
}
