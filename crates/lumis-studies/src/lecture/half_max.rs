//! The lecture's bias example: half the sample maximum against the sample
//! mean as estimators of the mean of U[0, 1] (`lumis_analysis::half_max`),
//! measured over many runs against the closed forms.

use std::fmt::Write as _;

use lumis_analysis::half_max::{self, asymptotic_slopes, measured_mse, simulate};
use lumis_analysis::plot::{self, Axes, Series};
use lumis_analysis::sample_variance::SampleVariance;
use lumis_core::Result;

use super::{LectureArgs, ALPHA};

/// The sample counts, one to 10^4.
const COUNTS: [u32; 11] = [1, 2, 3, 5, 10, 30, 100, 300, 1000, 3000, 10_000];

/// One N: the two estimators' measured errors.
struct Row {
    n: u32,
    half_max: SampleVariance,
    mse_half_max: f64,
    mse_mean: f64,
}

pub(super) fn half_max_study(args: &LectureArgs) -> Result<String> {
    let runs = args.runs;
    let rows: Vec<Row> = COUNTS
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let (means, halves) = simulate(n, runs, args.seed + 20_000 + k as u64);
            Row {
                n,
                half_max: SampleVariance::of(&halves).expect("at least two runs"),
                mse_half_max: measured_mse(&halves),
                mse_mean: measured_mse(&means),
            }
        })
        .collect();
    let mut report = format!(
        "\nThe bias example: the mean of U[0, 1] estimated by H_N = max(X_i) / 2 \
         against the sample mean F_N, {runs} runs per N, the same draws for both: \
         measured | formula (* outside the {}% interval)\n{:>6} {:>26} {:>24} {:>24} {:>24} {:>14}\n",
        100.0 * (1.0 - ALPHA),
        "N",
        "bias of H_N",
        "variance of H_N",
        "MSE of H_N",
        "MSE of F_N",
        "MSE ratio"
    );
    for r in &rows {
        let n = r.n;
        let mark = |agrees: bool| if agrees { "" } else { "*" };
        let bias_mark = mark(
            r.half_max
                .mean_agrees(half_max::MEAN + half_max::bias(n), ALPHA),
        );
        let variance_mark = mark(r.half_max.variance_agrees(half_max::variance(n), ALPHA));
        writeln!(
            report,
            "{n:>6} {:>26} {:>24} {:>24} {:>24} {:>20}",
            format!(
                "{:+.3e}±{:.0e} | {:+.3e}{bias_mark}",
                r.half_max.mean - half_max::MEAN,
                r.half_max.standard_error(),
                half_max::bias(n)
            ),
            format!(
                "{:.3e} | {:.3e}{variance_mark}",
                r.half_max.variance,
                half_max::variance(n)
            ),
            format!("{:.3e} | {:.3e}", r.mse_half_max, half_max::mse(n)),
            format!("{:.3e} | {:.3e}", r.mse_mean, half_max::sample_mean_mse(n)),
            format!(
                "{:.2e} | {:.2e}",
                r.mse_half_max / r.mse_mean,
                half_max::mse(n) / half_max::sample_mean_mse(n)
            ),
        )
        .unwrap();
    }
    let mse_mean: Vec<f64> = rows.iter().map(|r| r.mse_mean).collect();
    let mse_half_max: Vec<f64> = rows.iter().map(|r| r.mse_half_max).collect();
    let (slope_mean, slope_half_max) = asymptotic_slopes(&COUNTS, &mse_mean, &mse_half_max);
    let measured_crossing = rows
        .iter()
        .position(|r| {
            rows.iter()
                .skip_while(|s| s.n < r.n)
                .all(|s| s.mse_half_max < s.mse_mean)
        })
        .map_or("never".to_string(), |i| format!("N = {}", rows[i].n));
    writeln!(
        report,
        "log-log slopes of the MSE from N = 100 on: F_N {slope_mean:.3} (formula -1), \
         H_N {slope_half_max:.3} (formula -2); H_N's MSE is below F_N's from N = {} on \
         by the formulas (equal at N = 1 and 2), from {measured_crossing} on as measured",
        half_max::first_n_below()
    )
    .unwrap();

    let formula = |f: fn(u32) -> f64| -> Vec<(f64, f64)> {
        COUNTS.iter().map(|&n| (f64::from(n), f(n))).collect()
    };
    let measured = |f: &dyn Fn(&Row) -> f64| -> Vec<(f64, f64)> {
        rows.iter().map(|r| (f64::from(r.n), f(r))).collect()
    };
    let series = vec![
        Series {
            name: "MSE of H_N = max/2, measured".into(),
            points: measured(&|r| r.mse_half_max),
            band: None,
        },
        Series {
            name: "1 / (2 (N+1)(N+2))".into(),
            points: formula(half_max::mse),
            band: None,
        },
        Series {
            name: "MSE of the sample mean, measured".into(),
            points: measured(&|r| r.mse_mean),
            band: None,
        },
        Series {
            name: "1 / (12 N)".into(),
            points: formula(half_max::sample_mean_mse),
            band: None,
        },
        Series {
            name: "bias^2 of H_N = 1 / (4 (N+1)^2)".into(),
            points: formula(|n| half_max::bias(n).powi(2)),
            band: None,
        },
    ];
    let title = format!("mean of U[0,1]: max/2 (biased) against the sample mean, {runs} runs");
    let axes = Axes {
        title: &title,
        x_label: "samples N",
        y_label: "mean squared error",
        log_x: true,
        log_y: true,
    };
    plot::line_plot(&args.out.join("half-max.png"), &axes, &series)?;
    Ok(report)
}
