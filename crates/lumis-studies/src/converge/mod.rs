//! `lumis converge`: error against a reference vs samples and vs time, for
//! several variants of one scene, over several seeds.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use lumis_analysis::convergence::loglog_slope;
use lumis_analysis::image_error::{check_same_size, error_metrics};
use lumis_app::{render, threads_capped, ImageMetadata, RenderArgs, Session};
use lumis_core::{Error, Registry, Result};
use lumis_files::read_text_bounded;
use lumis_image::{read_exr, Image};

mod report;
mod variants;

use report::{ranked_table, summarise, write_outputs};
pub use report::{ConvergeReport, Point, Run};
use variants::VARIANTS_FILE;
pub use variants::{parse_variants, variant_of, MeasuredImage, Variant};

#[derive(clap::Args, Debug, Clone)]
pub struct ConvergeArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// The converged reference image (EXR) of the same scene.
    #[arg(long)]
    pub reference: PathBuf,
    /// Variants (TOML: `[[variant]] name = "...", set = ["sampler.type=sobol", ...]`,
    /// optionally `image = "denoised"`).
    #[arg(long, value_name = "variants.toml")]
    pub variants: PathBuf,
    /// Samples per pixel to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8,16,32,64")]
    pub spp: Vec<u32>,
    /// Seeds per (variant, spp): the spread gives the standard errors, and
    /// two or more split the error into bias² and variance.
    #[arg(long, default_value_t = 4)]
    pub seeds: u64,
    /// The first seed: renders use seeds FIRST .. FIRST + --seeds. Keep
    /// them apart from the reference's (a `lumis reference` of N passes
    /// from seed S used S .. S + N), or the shared samples make bias² low.
    #[arg(long, value_name = "FIRST", default_value_t = 0)]
    pub first_seed: u64,
    /// Equal time instead of equal samples: each variant doubles its spp
    /// from the smallest --spp while one render fits in this many seconds.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub time_budget: Option<f64>,
    /// Overrides applied to every variant (like `lumis render --set`).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub set: Vec<String>,
    /// Worker threads; 0 means one per core.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Output directory for converge.csv, converge.json and the plots.
    #[arg(long, default_value = "converge")]
    pub out: PathBuf,
}

/// `10`, `10s` or `2.5s`: a positive number of seconds.
fn parse_seconds(text: &str) -> std::result::Result<f64, String> {
    let number = text.trim().trim_end_matches('s');
    match number.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!(
            "expected a positive number of seconds such as 10s, got \"{text}\""
        )),
    }
}

/// Renders every variant of the file `args.variants` at each spp and seed
/// and measures its error ([`converge_variants`]).
pub fn converge(
    args: &ConvergeArgs,
    registry: &Registry,
    stop: &AtomicBool,
) -> Result<ConvergeReport> {
    converge_variants(args, &read_variants(&args.variants)?, registry, stop)
}

/// The variants of the variants file at `path`.
pub fn read_variants(path: &Path) -> Result<Vec<Variant>> {
    let text = read_text_bounded(path, VARIANTS_FILE).map_err(Error::msg)?;
    parse_variants(&text, &path.display().to_string())
}

/// Renders every one of `variants` at each spp and seed and measures its
/// error (`args.variants` is not read). When `stop` becomes true (Ctrl-C)
/// it finishes the render in flight, then writes and reports everything
/// measured so far.
pub fn converge_variants(
    args: &ConvergeArgs,
    variants: &[Variant],
    registry: &Registry,
    stop: &AtomicBool,
) -> Result<ConvergeReport> {
    if let Some(warning) = threads_capped(args.threads) {
        eprintln!("{warning}");
    }
    if variants.is_empty() {
        return Err(Error::msg("no variants to measure"));
    }
    let reference = read_exr(&args.reference).map_err(|e| Error::msg(e.to_string()))?;
    let provenance = reference_provenance(args);
    if args.seeds == 0 || args.spp.is_empty() || args.spp.contains(&0) {
        return Err(Error::msg(
            "--seeds and every --spp value must be at least 1",
        ));
    }
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::msg(format!("{}: {e}", args.out.display())))?;

    // Each render goes through `lumis render` itself (adaptive sampling,
    // clamping, the denoiser), one pass of all its samples; `renders/`
    // keeps each variant's last render.
    let renders = args.out.join("renders");
    std::fs::create_dir_all(&renders)
        .map_err(|e| Error::msg(format!("{}: {e}", renders.display())))?;
    let never = AtomicBool::new(false);
    let session = Session::silent(registry, &never);
    let render_once =
        |index: usize, variant: &Variant, spp: u32, seed: u64| -> Result<(Run, Image)> {
            let mut set = args.set.clone();
            set.extend(variant.set.iter().cloned());
            let render_args = RenderArgs {
                scene: args.scene.clone(),
                spp: Some(spp),
                seed: Some(seed),
                threads: args.threads,
                output: Some(renders.join(format!("{index}-{}.exr", file_stem(&variant.name)))),
                set,
                quiet: true,
                no_checkpoint: true,
                pass_spp: Some(spp),
                // `renders/` is this command's own: each render replaces
                // the variant's last, whatever its samples.
                force: true,
                ..Default::default()
            };
            let context = |e: Error| Error::msg(format!("variant \"{}\": {e}", variant.name));
            let report = render(&render_args, &session).map_err(context)?;
            // A loaded plugin that panicked answered with neutral values.
            registry.faults().check()?;
            let (image, seconds) = match (variant.image, report.denoised) {
            (MeasuredImage::Raw, _) => (report.image, report.seconds),
            (MeasuredImage::Denoised, Some(denoised)) => {
                (denoised.image, report.seconds + denoised.seconds)
            }
            (MeasuredImage::Denoised, None) => return Err(context(Error::msg(
                "image = \"denoised\" needs a [denoiser]; add \"denoiser.type=oidn\" to its set",
            ))),
        };
            check_same_size(&image, &reference).map_err(|e| {
                Error::msg(format!(
                    "variant \"{}\" vs {}: {e}",
                    variant.name,
                    args.reference.display()
                ))
            })?;
            let m = error_metrics(&image, &reference, None);
            let run = Run {
                variant: variant.name.clone(),
                spp,
                seed,
                seconds,
                samples_per_second: report.stats.samples as f64 / report.seconds,
                rays_per_second: report.stats.total_rays() as f64 / report.seconds,
                mse: m.mse,
                rel_mse: m.rel_mse,
                psnr_db: m.psnr_db,
            };
            Ok((run, image))
        };

    let style = ProgressStyle::with_template("{msg:28} [{bar:40}] {pos}/{len} {elapsed}")
        .expect("valid template")
        .progress_chars("=> ");
    let bars = MultiProgress::new();
    let overall = bars.add(ProgressBar::new(variants.len() as u64));
    overall.set_style(style.clone());
    overall.set_message("variants");
    let mut runs = Vec::new();
    let mut points = Vec::new();
    let mut interrupted = false;
    'variants: for (index, variant) in variants.iter().enumerate() {
        let mut spp_list: Vec<u32> = match args.time_budget {
            Some(_) => args.spp.iter().min().into_iter().copied().collect(),
            None => args.spp.clone(),
        };
        let per_spp = args.seeds;
        let bar = bars.add(ProgressBar::new(spp_list.len() as u64 * per_spp));
        bar.set_style(style.clone());
        let mut i = 0;
        while i < spp_list.len() {
            let spp = spp_list[i];
            bar.set_message(format!("{} @ {spp} spp", variant.name));
            let mut these = Vec::new();
            let mut images = Vec::new();
            for s in args.first_seed..args.first_seed + args.seeds {
                if stop.load(Ordering::Relaxed) {
                    interrupted = true;
                    runs.extend(these);
                    bar.abandon();
                    break 'variants;
                }
                let (run, image) = render_once(index, variant, spp, s)?;
                these.push(run);
                images.push(image);
                bar.inc(1);
            }
            let point = summarise(&these, &images, &reference);
            runs.extend(these);
            if let Some(budget) = args.time_budget {
                if point.seconds > budget && i > 0 {
                    break;
                }
                // Keep doubling while the next render would still fit.
                if point.seconds * 2.0 <= budget {
                    spp_list.push(spp * 2);
                    bar.inc_length(per_spp);
                }
            }
            points.push(point);
            i += 1;
        }
        bar.finish_and_clear();
        overall.inc(1);
    }
    overall.finish_and_clear();
    if points.is_empty() {
        return Err(Error::msg(
            "interrupted before the first (variant, spp) was measured: nothing to report",
        ));
    }

    let slopes: Vec<(String, Option<f64>)> = variants
        .iter()
        .map(|v| {
            let (xs, ys): (Vec<f64>, Vec<f64>) = points
                .iter()
                .filter(|p| p.variant == v.name)
                .map(|p| (p.spp as f64, p.rel_mse))
                .unzip();
            (v.name.clone(), loglog_slope(&xs, &ys))
        })
        .collect();
    write_outputs(args, variants, &runs, &points)?;
    let mut table = provenance + &ranked_table(variants, &points, &slopes, args.time_budget);
    if interrupted {
        table += "(interrupted: the rows above are those measured before Ctrl-C)\n";
    }
    Ok(ConvergeReport {
        runs,
        points,
        slopes,
        table,
        interrupted,
    })
}

/// A variant's name as a file name: letters, digits, `-` and `_` kept,
/// anything else `-`.
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// What the reference's metadata (in its EXR header) says, and a warning
/// when it was rendered from another version of the scene file.
fn reference_provenance(args: &ConvergeArgs) -> String {
    let Ok(Some(meta)) = ImageMetadata::read(&args.reference) else {
        return String::new();
    };
    let mut out = format!(
        "reference: {} spp, {} passes from seed {}, {:.1} s (lumis {})\n",
        meta.spp, meta.passes, meta.seed, meta.seconds, meta.version
    );
    let same_scene =
        lumis_scene::scene_file_hash(&args.scene).is_ok_and(|hash| hash == meta.scene_file_hash);
    if !same_scene {
        out += "warning: the reference was rendered from a different version of the scene file\n";
    }
    let reference_seeds = meta.seed..meta.seed.saturating_add(meta.passes);
    let seeds = args.first_seed..args.first_seed.saturating_add(args.seeds);
    if reference_seeds.start < seeds.end && seeds.start < reference_seeds.end {
        writeln!(
            out,
            "warning: the reference's seeds {reference_seeds:?} overlap the seeds measured {seeds:?}: \
             their shared samples make the error, and bias², look smaller (see --first-seed)"
        )
        .unwrap();
    }
    out
}
