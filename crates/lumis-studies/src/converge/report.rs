//! What a converge study measured: each render, each variant's summary
//! over its seeds, the ranked table and the files written.

use std::fmt::Write as _;
use std::path::Path;

use lumis_analysis::bias_variance::{bias_variance, BiasVariance, Split};
use lumis_analysis::plot::{self, Axes, Series};
use lumis_core::{Error, Result};
use lumis_image::Image;

use super::variants::Variant;
use super::ConvergeArgs;

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
    /// PSNR of the sRGB-encoded image
    /// ([`lumis_analysis::image_error::error_metrics`]).
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
pub(super) fn summarise(runs: &[Run], images: &[Image], reference: &Image) -> Point {
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

/// Ranks the variants by efficiency at their last (largest) spp.
pub(super) fn ranked_table(
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
        "{:20} {:>6} {:>9} {:>11} {:>10} {:>11} {:>10} {:>11} {:>10} {:>11} {:>8}\n",
        "variant",
        "spp",
        "seconds",
        "relMSE",
        "+-se",
        "bias²",
        "+-se",
        "variance",
        "+-se",
        "efficiency",
        "slope"
    );
    for p in last {
        let slope = slopes
            .iter()
            .find(|s| s.0 == p.variant)
            .and_then(|s| s.1)
            .map_or("-".into(), |s| format!("{s:+.2}"));
        let [bias2, bias2_se, variance, variance_se] =
            p.split
                .map_or(["-".to_string(), "-".into(), "-".into(), "-".into()], |s| {
                    let s = s.rel_mse;
                    [
                        format!("{:.4e}", s.bias2),
                        format!("{:.2e}", s.bias2_se),
                        format!("{:.4e}", s.variance),
                        format!("{:.2e}", s.variance_se),
                    ]
                });
        writeln!(
            out,
            "{:20} {:>6} {:>9.3} {:>11.4e} {:>10.2e} {:>11} {:>10} {:>11} {:>10} {:>11.1} {:>8}",
            p.variant,
            p.spp,
            p.seconds,
            p.rel_mse,
            p.rel_mse_se,
            bias2,
            bias2_se,
            variance,
            variance_se,
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
        "(bias² + variance: the relMSE of one render split over the seeds, which need to be 2 or more; their standard errors are over pixels)\n";
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

pub(super) fn write_outputs(
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
