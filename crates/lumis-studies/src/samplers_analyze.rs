//! `lumis samplers analyze`: pictures and numbers that tell samplers apart.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use lumis_analysis::convergence::{
    loglog_slope, powers_of_two, sampler_rmse, simpson_errors, EXACT,
};
use lumis_analysis::integrands::{integrands_1d, integrands_2d, Integrand};
use lumis_analysis::plot::{self, Axes, Series};
use lumis_analysis::spectrum::{periodogram, radial_average};
use lumis_analysis::{l2_star_discrepancy, sample_points, PointSet};
use lumis_core::doc;
use lumis_core::{Error, Location, PluginEntity, PluginKind, Registry, Result, Sampler, UVec2};

use lumis_app::parameter_text;

#[derive(clap::Args, Debug, Clone)]
pub struct AnalyzeArgs {
    /// Sampler plugin to analyse, or `all` for every registered sampler.
    #[arg(long)]
    pub sampler: String,
    /// Points (samples of one pixel) for the pictures, dump and discrepancy.
    #[arg(long, default_value_t = 1024)]
    pub count: u32,
    /// Seed of the pictured point set (the spectrum and the mean
    /// discrepancy also use the following seeds).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Dimensions per point in the dump, pictured as consecutive pairs.
    #[arg(long, default_value_t = 2)]
    pub dims: usize,
    /// Output directory for PNGs and CSVs (created if missing).
    #[arg(long, default_value = "sampler-analysis")]
    pub out: PathBuf,
    /// Write the raw points (one row per sample, one column per dimension);
    /// with `--sampler all` the sampler's name is inserted before `.csv`.
    #[arg(long, value_name = "FILE.csv")]
    pub dump: Option<PathBuf>,
    /// Extra sampler parameters, e.g. `--set min_distance=0.02`.
    #[arg(long = "set", value_name = "key=value")]
    pub params: Vec<String>,
    /// Scrambles (seeds) averaged in the power spectrum.
    #[arg(long, default_value_t = 16)]
    pub realizations: u32,
    /// Frequencies per axis of the power spectrum picture.
    #[arg(long, default_value_t = 128)]
    pub spectrum_size: usize,
    /// Seeds averaged in the mean discrepancy.
    #[arg(long, default_value_t = 16)]
    pub discrepancy_seeds: u64,
    /// Largest point count of the convergence study (powers of two from 4).
    #[arg(long, default_value_t = 65536)]
    pub max_count: u32,
    /// Randomisations (seeds) per count in the convergence study.
    #[arg(long, default_value_t = 64)]
    pub seeds: u64,
    /// Skip the convergence study (pictures, dump and discrepancy only).
    #[arg(long)]
    pub no_convergence: bool,
}

/// A sampler plugin with `spp = count` and the user's parameters.
pub(crate) fn make_sampler(
    registry: &Registry,
    name: &str,
    params: &[String],
    count: u32,
) -> Result<Box<dyn Sampler>> {
    let text = format!("spp = {count}\n{}", parameter_text(params)?);
    let table = doc::parse(&text, "--set")?;
    let entity = PluginEntity::new(
        PluginKind::Sampler,
        "sampler",
        name,
        table,
        Location::Builtin,
    );
    registry.create::<dyn Sampler>(&entity, ())
}

fn sampler_names(registry: &Registry, requested: &str) -> Result<Vec<String>> {
    let mut all: Vec<String> = registry
        .names(PluginKind::Sampler)
        .into_iter()
        .map(str::to_string)
        .collect();
    all.sort();
    if requested == "all" {
        return Ok(all);
    }
    if all.iter().any(|n| n == requested) {
        Ok(vec![requested.to_string()])
    } else {
        Err(Error::msg(format!(
            "unknown sampler \"{requested}\"; available: {}, or all",
            all.join(", ")
        )))
    }
}

fn dump_path(dump: &Path, name: &str, several: bool) -> PathBuf {
    if !several {
        return dump.to_path_buf();
    }
    let stem = dump
        .file_stem()
        .map_or("points".into(), |s| s.to_string_lossy());
    let ext = dump
        .extension()
        .map_or("csv".into(), |e| e.to_string_lossy());
    dump.with_file_name(format!("{stem}-{name}.{ext}"))
}

pub(crate) fn progress_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{msg:24} [{bar:40}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// The power spectrum pictures of a sampler's first `count` film samples:
/// the periodogram averaged over `realizations` seeds from `seed`
/// (`STEM-psd.png`) and its radial average (`STEM-radial-psd.png`).
pub(crate) struct Spectrum {
    pub count: u32,
    pub seed: u64,
    pub realizations: u32,
    pub size: usize,
}

impl Spectrum {
    /// Frequencies per axis of the periodogram.
    fn size(&self) -> usize {
        self.size.max(4)
    }

    /// The periodogram of the sampler's film samples averaged over the
    /// realizations, `size()` by `size()` with zero frequency at the centre;
    /// `progress` is called after each realization.
    pub fn average_psd(&self, sampler: &mut dyn Sampler, mut progress: impl FnMut()) -> Vec<f64> {
        let size = self.size();
        let mut psd = vec![0.0; size * size];
        for r in 0..self.realizations {
            let seed = self.seed + u64::from(r);
            let p = sample_points(sampler, self.count, 2, seed, UVec2::new(0, 0)).pair(0, 1);
            for (acc, v) in psd.iter_mut().zip(periodogram(&p, size)) {
                *acc += v / f64::from(self.realizations);
            }
            progress();
        }
        psd
    }

    /// Writes the two pictures into `out`; returns the radial average as a
    /// series named `name`.
    pub fn pictures(
        &self,
        sampler: &mut dyn Sampler,
        name: &str,
        out: &Path,
        stem: &str,
    ) -> Result<Series> {
        let size = self.size();
        let bar = progress_bar(self.realizations as u64, &format!("{name} spectrum"));
        let psd = self.average_psd(sampler, || bar.inc(1));
        bar.finish_and_clear();
        let title = format!(
            "{name}: power spectrum, {} points, {} scrambles",
            self.count, self.realizations
        );
        let half = (size / 2) as i64;
        let grid = plot::Grid {
            width: size,
            height: size,
            origin: (-half, -half),
            x_label: "k_x",
            y_label: "k_y",
            value_label: "log10 power",
        };
        plot::heat_map(
            &out.join(format!("{stem}-psd.png")),
            &title,
            &psd,
            &grid,
            None,
        )?;
        let (radial, _) = radial_average(&psd, size);
        let series = Series {
            name: name.to_string(),
            points: radial
                .iter()
                .enumerate()
                .skip(1)
                .map(|(r, v)| (r as f64, *v))
                .collect(),
            band: None,
        };
        let axes = Axes {
            title: &format!("{name}: radially averaged power spectrum"),
            x_label: "frequency |k|",
            y_label: "power",
            log_x: false,
            log_y: false,
        };
        plot::line_plot(
            &out.join(format!("{stem}-radial-psd.png")),
            &axes,
            std::slice::from_ref(&series),
        )?;
        Ok(series)
    }
}

#[cfg(test)]
mod tests;

/// Convergence results of one sampler: RMSE per integrand and count.
struct Convergence {
    name: String,
    rmse: Vec<Vec<f64>>,
}

/// Runs the analysis and returns the printed report.
pub fn analyze(args: &AnalyzeArgs, registry: &Registry) -> Result<String> {
    if args.count == 0 || args.dims == 0 {
        return Err(Error::msg("--count and --dims must be at least 1"));
    }
    let names = sampler_names(registry, &args.sampler)?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::msg(format!("{}: {e}", args.out.display())))?;
    let io = |e: lumis_image::ImageError| Error::msg(e.to_string());
    let mut report = String::new();
    let mut radial_series = Vec::new();
    writeln!(
        report,
        "{} points, seed {}; L2-star discrepancy of dimensions 0-1 (this seed | mean of {} seeds):",
        args.count, args.seed, args.discrepancy_seeds
    )
    .unwrap();
    for name in &names {
        let mut sampler = make_sampler(registry, name, &args.params, args.count)?;
        let pixel = UVec2::new(0, 0);
        let points = sample_points(sampler.as_mut(), args.count, args.dims, args.seed, pixel);
        if let Some(dump) = &args.dump {
            points
                .write_csv(&dump_path(dump, name, names.len() > 1))
                .map_err(io)?;
        }
        let pairs = points.dims.max(2) / 2;
        for k in 0..pairs.min(points.dims / 2) {
            let file = if k == 0 {
                format!("{name}-points.png")
            } else {
                format!("{name}-points-d{}-d{}.png", 2 * k, 2 * k + 1)
            };
            let title = format!(
                "{name}: {} points, dimensions {} and {}",
                args.count,
                2 * k,
                2 * k + 1
            );
            plot::scatter(&args.out.join(file), &title, &points.pair(2 * k, 2 * k + 1))?;
        }
        let film = |seed: u64, s: &mut dyn Sampler| -> PointSet {
            sample_points(s, args.count, 2, seed, pixel)
        };
        let this = l2_star_discrepancy(&film(args.seed, sampler.as_mut()));
        let mean = (0..args.discrepancy_seeds)
            .map(|i| l2_star_discrepancy(&film(args.seed + i, sampler.as_mut())))
            .sum::<f64>()
            / args.discrepancy_seeds.max(1) as f64;
        writeln!(report, "  {name:14} {this:.3e} | {mean:.3e}").unwrap();

        let spectrum = Spectrum {
            count: args.count,
            seed: args.seed,
            realizations: args.realizations,
            size: args.spectrum_size,
        };
        let series = spectrum.pictures(sampler.as_mut(), name, &args.out, name)?;
        radial_series.push(series);
    }
    if names.len() > 1 {
        let axes = Axes {
            title: "radially averaged power spectra",
            x_label: "frequency |k|",
            y_label: "power",
            log_x: false,
            log_y: false,
        };
        plot::line_plot(&args.out.join("radial-psd.png"), &axes, &radial_series)?;
    }
    if !args.no_convergence {
        report += &convergence_study(args, registry, &names)?;
    }
    Ok(report)
}

fn convergence_study(args: &AnalyzeArgs, registry: &Registry, names: &[String]) -> Result<String> {
    let counts = powers_of_two(4, args.max_count.max(4));
    let integrands: Vec<Integrand> = integrands_2d().into_iter().chain(integrands_1d()).collect();
    // Build every sampler once up front so a bad parameter fails before
    // the long part.
    for name in names {
        make_sampler(registry, name, &args.params, 4)?;
    }
    let bar = progress_bar((names.len() * counts.len()) as u64, "convergence");
    let mut results = Vec::new();
    for name in names {
        bar.set_message(format!("convergence: {name}"));
        let make = |n: u32| {
            make_sampler(registry, name, &args.params, n).expect("parameters checked above")
        };
        let rmse = sampler_rmse(&make, &integrands, &counts, args.seeds, || bar.inc(1));
        results.push(Convergence {
            name: name.clone(),
            rmse,
        });
    }
    bar.finish_and_clear();

    let xs: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
    let mut csv = String::from("sampler,integrand,evaluations,rmse\n");
    let mut table = format!(
        "\nRMSE vs N = 4..{} ({} seeds): fitted log-log slope (RMSE at the largest N)\n{:14}",
        counts.last().unwrap(),
        args.seeds,
        "sampler"
    );
    for g in &integrands {
        write!(table, " {:>22}", g.name).unwrap();
    }
    table.push('\n');
    // The rate over the errors above the rounding floor, then the last
    // error or where the floor was reached.
    let slope_text = |xs: &[f64], errors: &[f64]| {
        let last = *errors.last().unwrap();
        let floor = xs
            .iter()
            .zip(errors)
            .find(|(_, e)| **e <= EXACT)
            .map(|p| *p.0);
        match (loglog_slope(xs, errors), floor) {
            (Some(s), None) => format!("{s:+.2} ({last:.1e})"),
            (Some(s), Some(n)) => format!("{s:+.2} (exact N>={n})"),
            (None, Some(n)) => format!("exact N>={n}"),
            (None, None) => format!("- ({last:.1e})"),
        }
    };
    for r in &results {
        write!(table, "{:14}", r.name).unwrap();
        for (g, rmse) in integrands.iter().zip(&r.rmse) {
            let cell = slope_text(&xs, rmse);
            write!(table, " {cell:>22}").unwrap();
            for (c, e) in counts.iter().zip(rmse) {
                writeln!(csv, "{},{},{c},{e:.6e}", r.name, g.name).unwrap();
            }
        }
        table.push('\n');
    }
    write!(table, "{:14}", "simpson").unwrap();
    let simpson: Vec<Vec<(u32, f64)>> = integrands
        .iter()
        .map(|g| simpson_errors(g, &counts))
        .collect();
    for (g, errors) in integrands.iter().zip(&simpson) {
        let (ex, ey): (Vec<f64>, Vec<f64>) = errors.iter().map(|&(n, e)| (n as f64, e)).unzip();
        let cell = slope_text(&ex, &ey);
        write!(table, " {cell:>22}").unwrap();
        for (n, e) in errors {
            writeln!(csv, "simpson,{},{n},{e:.6e}", g.name).unwrap();
        }
    }
    table.push('\n');
    table += "(Simpson: composite rule on an odd grid, tensor product in 2D, at most N \
              evaluations; the error is deterministic, \"exact\" below 1e-11.)\n";

    let csv_path = args.out.join("convergence.csv");
    lumis_image::write_atomically(&csv_path, |w| {
        use std::io::Write;
        w.write_all(csv.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| Error::msg(e.to_string()))?;
    for (i, g) in integrands.iter().enumerate() {
        let mut series: Vec<Series> = results
            .iter()
            .map(|r| Series {
                name: r.name.clone(),
                points: xs.iter().copied().zip(r.rmse[i].iter().copied()).collect(),
                band: None,
            })
            .collect();
        series.push(Series {
            name: "simpson".into(),
            points: simpson[i].iter().map(|&(n, e)| (n as f64, e)).collect(),
            band: None,
        });
        let title = format!("{}: RMSE vs number of points", g.name);
        let axes = Axes {
            title: &title,
            x_label: "points N",
            y_label: "RMSE",
            log_x: true,
            log_y: true,
        };
        plot::line_plot(
            &args.out.join(format!("convergence-{}.png", g.name)),
            &axes,
            &series,
        )?;
    }
    Ok(table)
}
