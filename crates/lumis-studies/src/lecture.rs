//! `lumis lecture`: the Monte Carlo lecture's experiments on test
//! integrands and point sets, as tables and PNG figures: stratified
//! sampling and its allocations, the spectra of 256-point jittered,
//! Poisson disk and white-noise sets, the lecture's bias example (half the
//! sample maximum against the sample mean) and the biased `N/(N+1)` mean.

mod half_max;

use std::fmt::Write as _;
use std::path::PathBuf;

use lumis_analysis::integrands::{self, Integrand};
use lumis_analysis::plot::{self, Axes, Series};
use lumis_analysis::sample_points;
use lumis_analysis::sample_variance::SampleVariance;
use lumis_analysis::scaled_mean::ScaledMean;
use lumis_analysis::stratification::{
    pilot_sigma, plain_estimate, repeated, stratified_estimate, Allocation, Strata, StratumMoments,
};
use lumis_core::{Error, Registry, Result, UVec2};

use crate::samplers_analyze::{make_sampler, Spectrum};

#[derive(clap::Args, Debug, Clone)]
pub struct LectureArgs {
    /// Output directory for the PNGs (created if missing).
    #[arg(long, default_value = "lecture")]
    pub out: PathBuf,
    /// Independent runs per estimator and N; the measured variances and
    /// biases are over these.
    #[arg(long, default_value_t = 2000)]
    pub runs: usize,
    /// Scrambles (seeds) averaged in each power spectrum.
    #[arg(long, default_value_t = 256)]
    pub realizations: u32,
    /// The first seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// The stratified study's strata, pilot and sample counts.
const STRATA: Strata = Strata {
    per_axis: 4,
    dims: 2,
};
const PILOT_PER_STRATUM: usize = 16;
const STRATIFIED_COUNTS: [usize; 9] = [16, 32, 64, 128, 256, 512, 1024, 2048, 4096];
/// Midpoint nodes per axis and stratum for the exact `sigma_i^2`.
const QUADRATURE: usize = 512;
/// The spectra's points per set, the sampler plugins that make them, and
/// the frequencies per axis.
const SPECTRUM_POINTS: u32 = 256;
const SPECTRUM_SAMPLERS: [(&str, &str); 3] = [
    ("stratified", "jittered 16x16"),
    ("poisson-disk", "Poisson disk"),
    ("independent", "white noise"),
];
const SPECTRUM_SIZE: usize = 64;
const SCALED_COUNTS: [u32; 12] = [1, 2, 3, 4, 5, 6, 8, 12, 16, 32, 64, 256];
/// The confidence of the printed intervals.
const ALPHA: f64 = 0.01;

/// Runs the four studies; returns the printed tables.
pub fn lecture(args: &LectureArgs, registry: &Registry) -> Result<String> {
    if args.runs < 2 || args.realizations == 0 {
        return Err(Error::msg(
            "--runs must be at least 2 and --realizations at least 1",
        ));
    }
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::msg(format!("{}: {e}", args.out.display())))?;
    let mut report = stratified_study(args)?;
    report += &spectrum_study(args, registry)?;
    report += &half_max::half_max_study(args)?;
    report += &scaled_mean_study(args)?;
    Ok(report)
}

fn integrand(name: &str) -> Integrand {
    integrands::integrand(name).expect("a built-in integrand")
}

fn ratio_cell(s: &SampleVariance, predicted: f64) -> String {
    let mark = if s.variance_agrees(predicted, ALPHA) {
        ""
    } else {
        "*"
    };
    format!("{:.3}{mark}", s.variance / predicted)
}

/// One estimator at one N: its measured variance with the interval, and
/// the formula's.
#[derive(Clone)]
struct VariancePoint {
    n: f64,
    measured: f64,
    interval: (f64, f64),
    formula: f64,
}

fn stratified_study(args: &LectureArgs) -> Result<String> {
    let mut report = format!(
        "Stratified sampling, {}x{} strata, {} runs per cell: variance measured | formula \
         (measured / formula; * outside the {}% interval)\n\
         Neyman: n_i ∝ v_i sigma_i with sigma_i from a pilot of {} samples per stratum \
         (not counted in N, not reused)\n",
        STRATA.per_axis,
        STRATA.per_axis,
        args.runs,
        100.0 * (1.0 - ALPHA),
        PILOT_PER_STRATUM
    );
    for (k, name) in ["gaussian", "disk"].into_iter().enumerate() {
        let g = integrand(name);
        let moments = StratumMoments::of(&g, STRATA, QUADRATURE);
        let sigma = pilot_sigma(&g, STRATA, PILOT_PER_STRATUM, args.seed + 7919);
        let optimal = moments
            .variance
            .iter()
            .map(|s2| STRATA.volume() * s2.sqrt())
            .sum::<f64>()
            .powi(2);
        writeln!(
            report,
            "\n{name} (I = {:.6}, sigma^2 = {:.4e}; Neyman with the exact sigma_i would give \
             {optimal:.4e} / N; the pilot saw sigma_i = 0 in {} strata, the exact sigma_i is 0 \
             in {})\n{:>6} {:>30} {:>30} {:>30}",
            moments.integral(),
            moments.total_variance(),
            sigma.iter().filter(|s| **s == 0.0).count(),
            moments.variance.iter().filter(|s| **s == 0.0).count(),
            "N",
            "plain",
            "proportional",
            "neyman"
        )
        .unwrap();
        // `None` is plain Monte Carlo.
        let methods = [
            None,
            Some(Allocation::Proportional),
            Some(Allocation::Neyman),
        ];
        let mut measured: Vec<Vec<VariancePoint>> = vec![Vec::new(); 3];
        for (c, &n) in STRATIFIED_COUNTS.iter().enumerate() {
            write!(report, "{n:>6}").unwrap();
            for (m, method) in methods.iter().enumerate() {
                let counts = method.map(|a| {
                    a.counts(STRATA, &sigma, n)
                        .expect("every count is at least the number of strata")
                });
                let predicted = match &counts {
                    None => moments.total_variance() / n as f64,
                    Some(counts) => moments.stratified_variance(counts),
                };
                let seed = args.seed + ((k * 100 + c) * 3 + m) as u64;
                let estimates = repeated(args.runs, seed, |rng| match &counts {
                    None => plain_estimate(&g, n, rng),
                    Some(counts) => stratified_estimate(&g, STRATA, counts, rng),
                });
                let s = SampleVariance::of(&estimates).expect("at least two runs");
                let cell = format!(
                    "{:.3e} | {predicted:.3e} ({})",
                    s.variance,
                    ratio_cell(&s, predicted)
                );
                write!(report, " {cell:>30}").unwrap();
                measured[m].push(VariancePoint {
                    n: n as f64,
                    measured: s.variance,
                    interval: s.variance_interval(ALPHA),
                    formula: predicted,
                });
            }
            report.push('\n');
        }
        let mut series = Vec::new();
        for (m, method) in methods.iter().enumerate() {
            let method = method.map_or("plain", |a| a.name());
            let rows = &measured[m];
            series.push(Series {
                name: format!("{method}, measured"),
                points: rows.iter().map(|r| (r.n, r.measured)).collect(),
                band: Some(
                    rows.iter()
                        .map(|r| (r.n, r.interval.0, r.interval.1))
                        .collect(),
                ),
            });
            series.push(Series {
                name: format!("{method}, formula"),
                points: rows.iter().map(|r| (r.n, r.formula)).collect(),
                band: None,
            });
        }
        let title = format!(
            "{name}: variance vs N, {}x{} strata, {} runs",
            STRATA.per_axis, STRATA.per_axis, args.runs
        );
        let axes = Axes {
            title: &title,
            x_label: "samples N",
            y_label: "variance",
            log_x: true,
            log_y: true,
        };
        plot::line_plot(
            &args.out.join(format!("stratified-variance-{name}.png")),
            &axes,
            &series,
        )?;
    }
    Ok(report)
}

fn spectrum_study(args: &LectureArgs, registry: &Registry) -> Result<String> {
    let mut radial = Vec::new();
    let mut report = format!(
        "\nPower spectra of {SPECTRUM_POINTS}-point sets, {} realisations: mean radial power \
         at |k| = 1..4 (low frequencies) and 24..31\n",
        args.realizations
    );
    let spectrum = Spectrum {
        count: SPECTRUM_POINTS,
        seed: args.seed,
        realizations: args.realizations,
        size: SPECTRUM_SIZE,
    };
    for (plugin, label) in SPECTRUM_SAMPLERS {
        let mut sampler = make_sampler(registry, plugin, &[], SPECTRUM_POINTS)?;
        let stem = format!("spectrum-{plugin}");
        let points = sample_points(
            sampler.as_mut(),
            SPECTRUM_POINTS,
            2,
            args.seed,
            UVec2::new(0, 0),
        );
        plot::scatter(
            &args.out.join(format!("{stem}-points.png")),
            &format!("{label}: {SPECTRUM_POINTS} points"),
            &points.pair(0, 1),
        )?;
        let series = spectrum.pictures(sampler.as_mut(), label, &args.out, &stem)?;
        let mean = |lo: f64, hi: f64| {
            let v: Vec<f64> = series
                .points
                .iter()
                .filter(|p| p.0 >= lo && p.0 <= hi)
                .map(|p| p.1)
                .collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        writeln!(
            report,
            "  {label:16} {:.3}  {:.3}   ({plugin}: {stem}-*.png)",
            mean(1.0, 4.0),
            mean(24.0, 31.0)
        )
        .unwrap();
        radial.push(series);
    }
    let axes = Axes {
        title: &format!("radially averaged power spectra, {SPECTRUM_POINTS} points"),
        x_label: "frequency |k|",
        y_label: "power",
        log_x: false,
        log_y: false,
    };
    plot::line_plot(&args.out.join("spectrum-radial.png"), &axes, &radial)?;
    Ok(report)
}

fn scaled_mean_study(args: &LectureArgs) -> Result<String> {
    let runs = args.runs * 10;
    let mut report = format!(
        "\nThe scaled mean N/(N+1) F_N, {runs} runs per N: measured | formula \
         (* outside the {}% interval)\n",
        100.0 * (1.0 - ALPHA)
    );
    let mut ratios = Vec::new();
    for (k, name) in ["gaussian-1d", "disk"].into_iter().enumerate() {
        let g = integrand(name);
        let whole = Strata {
            per_axis: 1,
            dims: g.dims,
        };
        let moments = StratumMoments::of(&g, whole, if g.dims == 1 { 1 << 20 } else { 2048 });
        let model = ScaledMean {
            integral: g.exact,
            sample_variance: moments.total_variance(),
        };
        let crossover = match model.crossover() {
            Some(n) => format!("its MSE is below F_N's for N < {n:.2}"),
            None => "sigma^2 >= I^2 / 2: its MSE is below F_N's for every N".into(),
        };
        writeln!(
            report,
            "\n{name} (I = {:.6}, sigma^2 = {:.4e}; {crossover})\n{:>4} {:>24} {:>26} {:>26} {:>11} {:>11}",
            g.exact,
            model.sample_variance,
            "N",
            "bias",
            "variance",
            "MSE",
            "MSE of F_N",
            "MSE ratio"
        )
        .unwrap();
        let mut rows = Vec::new();
        for (c, &n) in SCALED_COUNTS.iter().enumerate() {
            let seed = args.seed + 10_000 + (k * 100 + c) as u64;
            // The same runs give both estimators (common random numbers),
            // so their MSE ratio is measured precisely.
            let means = repeated(runs, seed, |rng| plain_estimate(&g, n as usize, rng));
            let scaled: Vec<f64> = means.iter().map(|&m| ScaledMean::estimate(n, m)).collect();
            let s = SampleVariance::of(&scaled).expect("at least two runs");
            let mse = |xs: &[f64]| {
                xs.iter().map(|x| (x - g.exact).powi(2)).sum::<f64>() / xs.len() as f64
            };
            let (mse_scaled, mse_plain) = (mse(&scaled), mse(&means));
            let bias_mark = if s.mean_agrees(g.exact + model.bias(n), ALPHA) {
                ""
            } else {
                "*"
            };
            let variance_mark = if s.variance_agrees(model.variance(n), ALPHA) {
                ""
            } else {
                "*"
            };
            writeln!(
                report,
                "{n:>4} {:>24} {:>26} {:>26} {:>11.4e} {:>11}",
                format!(
                    "{:+.2e}±{:.0e} | {:+.2e}{bias_mark}",
                    s.mean - g.exact,
                    s.standard_error(),
                    model.bias(n)
                ),
                format!(
                    "{:.4e} | {:.4e}{variance_mark}",
                    s.variance,
                    model.variance(n)
                ),
                format!("{mse_scaled:.4e} | {:.4e}", model.mse(n)),
                mse_plain,
                format!(
                    "{:.3} | {:.3}",
                    mse_scaled / mse_plain,
                    model.mse(n) / model.unbiased_mse(n)
                ),
            )
            .unwrap();
            rows.push((
                n as f64,
                s.mean - g.exact,
                s.variance,
                mse_scaled,
                mse_plain,
            ));
        }
        let formula = |f: &dyn Fn(u32) -> f64| -> Vec<(f64, f64)> {
            SCALED_COUNTS.iter().map(|&n| (n as f64, f(n))).collect()
        };
        let series = vec![
            Series {
                name: "MSE of N/(N+1) F_N, measured".into(),
                points: rows.iter().map(|r| (r.0, r.3)).collect(),
                band: None,
            },
            Series {
                name: "(I^2 + N sigma^2) / (N+1)^2".into(),
                points: formula(&|n| model.mse(n)),
                band: None,
            },
            Series {
                name: "MSE of F_N, measured".into(),
                points: rows.iter().map(|r| (r.0, r.4)).collect(),
                band: None,
            },
            Series {
                name: "sigma^2 / N".into(),
                points: formula(&|n| model.unbiased_mse(n)),
                band: None,
            },
            Series {
                name: "variance of N/(N+1) F_N, measured".into(),
                points: rows.iter().map(|r| (r.0, r.2)).collect(),
                band: None,
            },
            Series {
                name: "bias^2 = I^2 / (N+1)^2".into(),
                points: formula(&|n| model.bias(n).powi(2)),
                band: None,
            },
        ];
        let title = format!("{name}: N/(N+1) F_N against F_N, {runs} runs");
        let axes = Axes {
            title: &title,
            x_label: "samples N",
            y_label: "error",
            log_x: true,
            log_y: true,
        };
        plot::line_plot(
            &args.out.join(format!("scaled-mean-{name}.png")),
            &axes,
            &series,
        )?;
        ratios.push(Series {
            name: format!("{name}, measured"),
            points: rows.iter().map(|r| (r.0, r.3 / r.4)).collect(),
            band: None,
        });
        ratios.push(Series {
            name: format!("{name}, formula"),
            points: formula(&|n| model.mse(n) / model.unbiased_mse(n)),
            band: None,
        });
    }
    ratios.push(Series {
        name: "1 (equal MSE)".into(),
        points: vec![(1.0, 1.0), (*SCALED_COUNTS.last().unwrap() as f64, 1.0)],
        band: None,
    });
    let axes = Axes {
        title: "MSE of N/(N+1) F_N over MSE of F_N",
        x_label: "samples N",
        y_label: "MSE ratio",
        log_x: true,
        log_y: false,
    };
    plot::line_plot(&args.out.join("scaled-mean-ratio.png"), &axes, &ratios)?;
    Ok(report)
}
