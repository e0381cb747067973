//! `lumis reference`: a high-spp render of a scene with its own settings,
//! written pass by pass with its metadata so an interrupted run resumes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use lumis_core::{Error, Registry, Result};
use lumis_image::{read_exr, write_exr, Image};
use lumis_render::{render, RenderSettings};

use crate::render::{load, output_paths, RenderArgs};

#[derive(clap::Args, Debug, Clone)]
pub struct ReferenceArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Total samples per pixel.
    #[arg(long)]
    pub spp: u32,
    /// Samples per pixel per pass; the image and its metadata are saved
    /// after every pass, so at most one pass is lost to an interruption.
    #[arg(long, default_value_t = 256)]
    pub pass_spp: u32,
    /// Output EXR [default: SCENE-NAME-reference.exr]; metadata goes to
    /// PATH.json beside it.
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Scene overrides, as for `lumis render`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub set: Vec<String>,
    /// Worker threads; 0 means one per core.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// What a reference was rendered from, stored beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceMetadata {
    /// FNV-1a of the scene text and the overrides: a changed scene starts over.
    pub scene_hash: u64,
    /// FNV-1a of the scene text alone: `converge` warns when the scene it
    /// measures is not the one the reference was rendered from.
    pub scene_text_hash: u64,
    pub spp: u32,
    /// Passes rendered; pass `k` used seed `base_seed + k`.
    pub passes: u64,
    pub base_seed: u64,
    pub seconds: f64,
}

/// FNV-1a 64 (Fowler, Noll, Vo): stable across Rust versions, unlike
/// `DefaultHasher`, so a hash written today still matches tomorrow.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

impl ReferenceMetadata {
    fn to_json(&self) -> String {
        format!(
            "{{\n  \"scene_hash\": \"{:016x}\",\n  \"scene_text_hash\": \"{:016x}\",\n  \"spp\": {},\n  \"passes\": {},\n  \"base_seed\": {},\n  \"seconds\": {:.3}\n}}\n",
            self.scene_hash, self.scene_text_hash, self.spp, self.passes, self.base_seed, self.seconds
        )
    }

    /// Reads the fields `to_json` writes (a fixed, flat format).
    pub fn from_json(text: &str) -> Option<Self> {
        let field = |name: &str| -> Option<&str> {
            let start = text.find(&format!("\"{name}\":"))? + name.len() + 3;
            let rest = text[start..].trim_start();
            let end = rest.find([',', '\n', '}']).unwrap_or(rest.len());
            Some(rest[..end].trim().trim_matches('"'))
        };
        Some(Self {
            scene_hash: u64::from_str_radix(field("scene_hash")?, 16).ok()?,
            scene_text_hash: u64::from_str_radix(field("scene_text_hash")?, 16).ok()?,
            spp: field("spp")?.parse().ok()?,
            passes: field("passes")?.parse().ok()?,
            base_seed: field("base_seed")?.parse().ok()?,
            seconds: field("seconds")?.parse().ok()?,
        })
    }
}

/// Where a reference's metadata lives: `PATH.exr.json`.
pub fn metadata_path(exr: &Path) -> PathBuf {
    let mut name = exr.as_os_str().to_owned();
    name.push(".json");
    PathBuf::from(name)
}

fn write_metadata(path: &Path, meta: &ReferenceMetadata) -> Result<()> {
    lumis_image::write_atomically(path, |w| {
        use std::io::Write;
        w.write_all(meta.to_json().as_bytes())
            .map_err(|e| e.to_string())
    })
    .map_err(|e| Error::msg(e.to_string()))
}

/// Renders (or continues) the reference; returns its path and metadata.
/// Pass `k` uses seed `base_seed + k`, so a resumed run never reuses the
/// samples of an earlier pass, and the image is the sample-weighted mean of
/// independent passes.
pub fn render_reference(
    args: &ReferenceArgs,
    registry: &Registry,
    stop: &AtomicBool,
) -> Result<(PathBuf, ReferenceMetadata)> {
    crate::warn_if_threads_capped(args.threads);
    if args.spp == 0 || args.pass_spp == 0 {
        return Err(Error::msg("--spp and --pass-spp must be at least 1"));
    }
    let scene_text = std::fs::read_to_string(&args.scene)
        .map_err(|e| Error::msg(format!("{}: {e}", args.scene.display())))?;
    let hash = fnv1a(format!("{scene_text}\n{}", args.set.join("\n")).as_bytes());
    let probe = load(
        &RenderArgs {
            scene: args.scene.clone(),
            set: args.set.clone(),
            spp: Some(1),
            ..Default::default()
        },
        registry,
    )?;
    let base_seed = probe.seed;
    let name = format!("{}-reference", probe.name);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{name}.exr")));
    let (exr, _) = output_paths(&output, &name);
    let meta_path = metadata_path(&exr);
    let resumed = std::fs::read_to_string(&meta_path)
        .ok()
        .and_then(|t| ReferenceMetadata::from_json(&t))
        .filter(|m| m.scene_hash == hash && m.base_seed == base_seed && m.spp <= args.spp)
        .and_then(|m| read_exr(&exr).ok().map(|img| (m, img)));
    let (mut meta, mut sum): (ReferenceMetadata, Option<Image>) = match resumed {
        Some((m, img)) => {
            eprintln!(
                "resuming {} at {} of {} spp",
                exr.display(),
                m.spp,
                args.spp
            );
            (m, Some(img))
        }
        None => (
            ReferenceMetadata {
                scene_hash: hash,
                scene_text_hash: fnv1a(scene_text.as_bytes()),
                spp: 0,
                passes: 0,
                base_seed,
                seconds: 0.0,
            },
            None,
        ),
    };
    while meta.spp < args.spp {
        if stop.load(Ordering::Relaxed) {
            eprintln!(
                "interrupted at {} of {} spp; run again to resume",
                meta.spp, args.spp
            );
            break;
        }
        let pass = args.pass_spp.min(args.spp - meta.spp);
        let pass_index = meta.passes;
        let loaded = load(
            &RenderArgs {
                scene: args.scene.clone(),
                set: args.set.clone(),
                spp: Some(pass),
                seed: Some(base_seed.wrapping_add(pass_index)),
                ..Default::default()
            },
            registry,
        )?;
        let out = render(
            &loaded.camera,
            &loaded.scene,
            loaded.integrator.as_ref(),
            loaded.sampler.as_ref(),
            &RenderSettings {
                spp: pass,
                seed: base_seed.wrapping_add(pass_index),
                threads: args.threads,
                progress: true,
            },
        )?;
        // Running mean weighted by samples.
        let done = meta.spp as f32;
        let mean = match sum.take() {
            None => out.image,
            Some(mut acc) => {
                let total = done + pass as f32;
                for (a, p) in acc.pixels.iter_mut().zip(&out.image.pixels) {
                    for c in 0..3 {
                        a[c] = (a[c] * done + p[c] * pass as f32) / total;
                    }
                }
                acc
            }
        };
        meta.spp += pass;
        meta.passes += 1;
        meta.seconds += out.seconds;
        write_exr(&exr, &mean).map_err(|e| Error::msg(e.to_string()))?;
        write_metadata(&meta_path, &meta)?;
        sum = Some(mean);
    }
    Ok((exr, meta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metadata_round_trips_and_hash_is_stable() {
        let m = ReferenceMetadata {
            scene_hash: 0x0123_4567_89ab_cdef,
            scene_text_hash: 42,
            spp: 4096,
            passes: 16,
            base_seed: 7,
            seconds: 12.5,
        };
        assert_eq!(ReferenceMetadata::from_json(&m.to_json()), Some(m));
        // FNV-1a 64 of "a", from the published test vectors.
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
