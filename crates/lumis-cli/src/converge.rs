//! `lumis converge`: error against a reference vs samples and vs time, for
//! several variants of one scene, over several seeds.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use lumis_analysis::bias_variance::{bias_variance, BiasVariance, Split};
use lumis_analysis::convergence::loglog_slope;
use lumis_analysis::image_error::{check_same_size, error_metrics};
use lumis_analysis::plot::{self, Axes, Series};
use lumis_core::doc::{self, Value};
use lumis_core::{Error, Registry, Result};
use lumis_files::{read_text_bounded, FileKind, MIB};
use lumis_image::{read_exr, Image};

use lumis_app::{render, threads_capped, ImageMetadata, RenderArgs, Session};

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

/// Which image of a render a variant is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeasuredImage {
    /// The film's image (`NAME.exr`).
    #[default]
    Raw,
    /// The `[denoiser]`'s image (`NAME.denoised.exr`); the denoiser's time
    /// counts in the variant's.
    Denoised,
}

impl MeasuredImage {
    const NAMES: &'static str = "\"raw\" or \"denoised\"";

    fn parse(text: &str) -> Option<Self> {
        match text {
            "raw" => Some(Self::Raw),
            "denoised" => Some(Self::Denoised),
            _ => None,
        }
    }
}

/// One variant: a name, its scene overrides and the image measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    pub name: String,
    pub set: Vec<String>,
    pub image: MeasuredImage,
}

/// Reads `[[variant]]` tables, with located errors.
pub fn parse_variants(text: &str, path: &str) -> Result<Vec<Variant>> {
    let root = doc::parse(text, path)?;
    let mut variants = Vec::new();
    for entry in &root.entries {
        let Value::Array(items) = &entry.node.value else {
            return Err(Error::at(
                &entry.key_location,
                "expected [[variant]] tables only",
            ));
        };
        if entry.key != "variant" {
            return Err(Error::at(
                &entry.key_location,
                format!("unknown key '{}'; expected [[variant]]", entry.key),
            ));
        }
        for item in items {
            let Value::Table(table) = &item.value else {
                return Err(Error::at(&item.location, "each variant must be a table"));
            };
            for key in table.keys() {
                if !["name", "set", "image"].contains(&key) {
                    return Err(Error::at(
                        &table.entry(key).unwrap().key_location,
                        format!("unknown variant key '{key}'; accepted: name, set, image"),
                    ));
                }
            }
            let Some(Value::String(name)) = table.get("name").map(|n| &n.value) else {
                return Err(Error::at(&item.location, "variant needs name = \"...\""));
            };
            let mut set = Vec::new();
            if let Some(node) = table.get("set") {
                let bad = || {
                    Error::at(
                        &node.location,
                        format!("variant \"{name}\": set must be an array of \"key.path=value\" strings"),
                    )
                };
                let Value::Array(values) = &node.value else {
                    return Err(bad());
                };
                for v in values {
                    match &v.value {
                        Value::String(s) if s.contains('=') => set.push(s.clone()),
                        _ => return Err(bad()),
                    }
                }
            }
            let image = match table.get("image") {
                None => MeasuredImage::default(),
                Some(node) => match &node.value {
                    Value::String(text) => MeasuredImage::parse(text),
                    _ => None,
                }
                .ok_or_else(|| {
                    Error::at(
                        &node.location,
                        format!("variant \"{name}\": image must be {}", MeasuredImage::NAMES),
                    )
                })?,
            };
            variants.push(Variant {
                name: name.clone(),
                set,
                image,
            });
        }
    }
    if variants.is_empty() {
        return Err(Error::msg(format!("{path}: no [[variant]] tables")));
    }
    Ok(variants)
}

/// One render: a variant at one spp and seed.
#[derive(Debug, Clone)]
pub struct Run {
    pub variant: String,
    pub spp: u32,
    pub seed: u64,
    pub seconds: f64,
    pub samples_per_second: f64,
    pub rays_per_second: f64,
    pub mse: f64,
    pub rel_mse: f64,
    /// PSNR of the sRGB-encoded image ([`error_metrics`]).
    pub psnr_db: f64,
}

/// The seeds of one (variant, spp), summarised.
#[derive(Debug, Clone)]
pub struct Point {
    pub variant: String,
    pub spp: u32,
    pub seconds: f64,
    pub mse: f64,
    pub mse_se: f64,
    pub rel_mse: f64,
    pub rel_mse_se: f64,
    pub rel_mse_min: f64,
    pub rel_mse_max: f64,
    /// The mean PSNR of the seeds' renders, in dB.
    pub psnr_db: f64,
    /// 1 / (relMSE x seconds).
    pub efficiency: f64,
    /// The error split into bias² and variance across the seeds (with two
    /// or more seeds).
    pub split: Option<BiasVariance>,
}

fn mean_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    if values.len() < 2 {
        return (mean, f64::NAN);
    }
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Summarises the seeds of one (variant, spp), `images` their renders.
fn summarise(runs: &[Run], images: &[Image], reference: &Image) -> Point {
    let rel: Vec<f64> = runs.iter().map(|r| r.rel_mse).collect();
    let mse: Vec<f64> = runs.iter().map(|r| r.mse).collect();
    let (rel_mse, rel_mse_se) = mean_se(&rel);
    let (mse, mse_se) = mean_se(&mse);
    let seconds = runs.iter().map(|r| r.seconds).sum::<f64>() / runs.len() as f64;
    Point {
        variant: runs[0].variant.clone(),
        spp: runs[0].spp,
        seconds,
        mse,
        mse_se,
        rel_mse,
        rel_mse_se,
        rel_mse_min: rel.iter().cloned().fold(f64::INFINITY, f64::min),
        rel_mse_max: rel.iter().cloned().fold(0.0, f64::max),
        psnr_db: runs.iter().map(|r| r.psnr_db).sum::<f64>() / runs.len() as f64,
        efficiency: 1.0 / (rel_mse * seconds),
        split: bias_variance(&images.iter().collect::<Vec<_>>(), reference).ok(),
    }
}

/// What `converge` measured, and where it wrote it.
pub struct ConvergeReport {
    pub runs: Vec<Run>,
    pub points: Vec<Point>,
    /// Per variant: fitted log-log slope of relMSE vs spp.
    pub slopes: Vec<(String, Option<f64>)>,
    pub table: String,
    /// Stopped by `stop` (Ctrl-C) before every render was done.
    pub interrupted: bool,
}

/// A variants file is a short TOML list written by hand.
const VARIANTS_FILE: FileKind = FileKind::new("variants", 16 * MIB);

/// Renders every variant at each spp and seed and measures its error.
/// When `stop` becomes true (Ctrl-C) it finishes the render in flight,
/// then writes and reports everything measured so far.
pub fn converge(
    args: &ConvergeArgs,
    registry: &Registry,
    stop: &AtomicBool,
) -> Result<ConvergeReport> {
    if let Some(warning) = threads_capped(args.threads) {
        eprintln!("{warning}");
    }
    let reference = read_exr(&args.reference).map_err(|e| Error::msg(e.to_string()))?;
    let provenance = reference_provenance(args);
    let variants_path = args.variants.display().to_string();
    let text = read_text_bounded(&args.variants, VARIANTS_FILE).map_err(Error::msg)?;
    let variants = parse_variants(&text, &variants_path)?;
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
    write_outputs(args, &variants, &runs, &points)?;
    let mut table = provenance + &ranked_table(&variants, &points, &slopes, args.time_budget);
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

/// Ranks the variants by efficiency at their last (largest) spp.
fn ranked_table(
    variants: &[Variant],
    points: &[Point],
    slopes: &[(String, Option<f64>)],
    budget: Option<f64>,
) -> String {
    let mut last: Vec<&Point> = variants
        .iter()
        .filter_map(|v| points.iter().rev().find(|p| p.variant == v.name))
        .collect();
    match budget {
        Some(_) => last.sort_by(|a, b| a.rel_mse.total_cmp(&b.rel_mse)),
        None => last.sort_by(|a, b| b.efficiency.total_cmp(&a.efficiency)),
    }
    let mut out = format!(
        "{:20} {:>6} {:>9} {:>11} {:>10} {:>11} {:>11} {:>11} {:>8}\n",
        "variant", "spp", "seconds", "relMSE", "+-se", "bias²", "variance", "efficiency", "slope"
    );
    for p in last {
        let slope = slopes
            .iter()
            .find(|s| s.0 == p.variant)
            .and_then(|s| s.1)
            .map_or("-".into(), |s| format!("{s:+.2}"));
        let (bias2, variance) = p.split.map_or(("-".into(), "-".into()), |s| {
            (
                format!("{:.4e}", s.rel_mse.bias2),
                format!("{:.4e}", s.rel_mse.variance),
            )
        });
        writeln!(
            out,
            "{:20} {:>6} {:>9.3} {:>11.4e} {:>10.2e} {:>11} {:>11} {:>11.1} {:>8}",
            p.variant,
            p.spp,
            p.seconds,
            p.rel_mse,
            p.rel_mse_se,
            bias2,
            variance,
            p.efficiency,
            slope
        )
        .unwrap();
    }
    out += match budget {
        Some(b) => format!("(equal time: each variant at the largest spp rendered within {b} s; ranked by relMSE)\n"),
        None => "(ranked by efficiency 1 / (relMSE x seconds) at the largest spp; slope: log-log relMSE vs spp)\n".to_string(),
    }
    .as_str();
    out +=
        "(bias² + variance: the relMSE of one render split over the seeds; they need 2 or more)\n";
    out
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    lumis_image::write_atomically(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| Error::msg(e.to_string()))
}

/// `{"bias2": .., "bias2_se": .., "variance": .., "variance_se": ..}`; the
/// standard errors are over pixels (see [`lumis_analysis::bias_variance`]).
fn split_json(s: &Split) -> String {
    let number = |v: f64| {
        if v.is_finite() {
            format!("{v:.6e}")
        } else {
            "null".into()
        }
    };
    format!(
        "{{\"bias2\": {}, \"bias2_se\": {}, \"variance\": {}, \"variance_se\": {}}}",
        number(s.bias2),
        number(s.bias2_se),
        number(s.variance),
        number(s.variance_se)
    )
}

fn write_outputs(
    args: &ConvergeArgs,
    variants: &[Variant],
    runs: &[Run],
    points: &[Point],
) -> Result<()> {
    let mut csv = String::from(
        "variant,spp,seed,seconds,samples_per_second,rays_per_second,mse,rel_mse,psnr_db,\
         bias2,variance,rel_bias2,rel_variance\n",
    );
    for r in runs {
        // The split belongs to the run's (variant, spp), repeated on each
        // seed's row; empty with one seed.
        let split = points
            .iter()
            .find(|p| p.variant == r.variant && p.spp == r.spp)
            .and_then(|p| p.split)
            .map_or(",,,".to_string(), |s| {
                format!(
                    "{:.6e},{:.6e},{:.6e},{:.6e}",
                    s.mse.bias2, s.mse.variance, s.rel_mse.bias2, s.rel_mse.variance
                )
            });
        writeln!(
            csv,
            "{},{},{},{:.6},{:.1},{:.1},{:.6e},{:.6e},{:.3},{split}",
            r.variant,
            r.spp,
            r.seed,
            r.seconds,
            r.samples_per_second,
            r.rays_per_second,
            r.mse,
            r.rel_mse,
            r.psnr_db
        )
        .unwrap();
    }
    write_text(&args.out.join("converge.csv"), &csv)?;
    let json_points: Vec<String> = points
        .iter()
        .map(|p| {
            format!(
                "    {{\"variant\": {:?}, \"spp\": {}, \"seconds\": {:.6}, \"mse\": {:.6e}, \"mse_se\": {:.6e}, \"rel_mse\": {:.6e}, \"rel_mse_se\": {:.6e}, \"psnr_db\": {:.3}, \"efficiency\": {:.6e}{}}}",
                p.variant, p.spp, p.seconds, p.mse, p.mse_se.max(0.0), p.rel_mse, p.rel_mse_se.max(0.0), p.psnr_db, p.efficiency,
                p.split.map_or(String::new(), |s| format!(", \"mse_split\": {}, \"rel_mse_split\": {}", split_json(&s.mse), split_json(&s.rel_mse)))
            )
        })
        .collect();
    let json = format!(
        "{{\n  \"scene\": {:?},\n  \"reference\": {:?},\n  \"seeds\": {},\n  \"points\": [\n{}\n  ]\n}}\n",
        args.scene.display().to_string(),
        args.reference.display().to_string(),
        args.seeds,
        json_points.join(",\n")
    );
    write_text(&args.out.join("converge.json"), &json)?;
    for (file, x_label, by_time) in [
        ("relmse-vs-spp.png", "samples per pixel", false),
        ("relmse-vs-seconds.png", "seconds", true),
    ] {
        let series: Vec<Series> = variants
            .iter()
            .filter(|v| points.iter().any(|p| p.variant == v.name))
            .map(|v| {
                let mine: Vec<&Point> = points.iter().filter(|p| p.variant == v.name).collect();
                let x = |p: &Point| if by_time { p.seconds } else { p.spp as f64 };
                Series {
                    name: v.name.clone(),
                    points: mine.iter().map(|p| (x(p), p.rel_mse)).collect(),
                    band: Some(
                        mine.iter()
                            .map(|p| (x(p), p.rel_mse_min, p.rel_mse_max))
                            .collect(),
                    ),
                }
            })
            .collect();
        let title = format!("relMSE vs {x_label} (band: seed spread)");
        let axes = Axes {
            title: &title,
            x_label,
            y_label: "relMSE",
            log_x: true,
            log_y: true,
        };
        plot::line_plot(&args.out.join(file), &axes, &series)?;
    }
    Ok(())
}
