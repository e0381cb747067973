//! Measured BRDFs end to end: tables written by `lumis brdf tabulate` match
//! the analytic BSDFs they come from; the `measured` plugin works from a
//! scene (paths, errors, cache); and the table of docs/src/studies/measured.md
//! ("Measured results"):
//! `scenes/measured-sphere.toml` (direct lighting, BSDF sampling only) for
//! three tabulated BSDFs of increasing glossiness, rendered at 4 and 64 spp
//! with every strategy (the lecture's model-quality comparison among
//! them: factored in half-vector and in deviation-vector coordinates, and
//! sampling from a tensor's factors), relMSE and PSNR against one converged
//! render, render time, precomputation time and memory. Regenerate the table with
//!
//! ```sh
//! cargo test -p lumis-tests --test measured_render measured_results_table -- --nocapture
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use indicatif::ProgressBar;
use lumis_analysis::image_error::error_metrics;
use lumis_brdf::{tabulate_bsdf, TabulateArgs};
use lumis_core::{Bsdf, BsdfContext, Vec2, Vec3};
use lumis_measured::grid::{Grid, Parameterization};
use lumis_measured::merl::MerlTable;
use lumis_measured::precompute::{prepare, Plan, PrecomputeReport, Prepared};
use lumis_measured::reflectance::Reflectance;
use lumis_measured::tensor::node_grid;
use lumis_sampling::Pcg32;
use lumis_tests::{read_scene, render_toml_with, scenes_dir, tabulated};

/// Name, plugin, parameters of the tabulated BSDF, and the same as a
/// `[[bsdf]]` table for the analytic render.
const MATERIALS: [(&str, &str, &[&str], &str); 3] = [
    (
        "plastic-0.3",
        "plastic",
        &["roughness=0.3", "diffuse_reflectance=[0.6,0.3,0.1]"],
        "type = \"plastic\"\nroughness = 0.3\ndiffuse_reflectance = [0.6, 0.3, 0.1]\n",
    ),
    (
        "conductor-0.2",
        "conductor",
        &["roughness=0.2", "material=Au"],
        "type = \"conductor\"\nroughness = 0.2\nmaterial = \"Au\"\n",
    ),
    (
        "conductor-0.05",
        "conductor",
        &["roughness=0.05", "material=Cu"],
        "type = \"conductor\"\nroughness = 0.05\nmaterial = \"Cu\"\n",
    ),
];

const GRID: Grid = Grid {
    n_o: 32,
    n_w: 64,
    n_phi: 64,
    supersamples: 4,
    parameterization: Parameterization::HalfDiff,
};

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lumis-measured-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bsdf(toml: &str) -> std::sync::Arc<dyn Bsdf> {
    let registry = lumis_app::builtin_registry().unwrap();
    let table = lumis_core::doc::parse(toml, "<test>").unwrap();
    let entity = lumis_core::PluginEntity::from_table(
        lumis_core::PluginKind::Bsdf,
        "bsdf",
        table,
        lumis_core::Location::Builtin,
        lumis_core::entity::TYPE_KEY,
    )
    .unwrap();
    registry
        .create::<dyn Bsdf>(&entity, lumis_core::texture::BsdfScope::EMPTY)
        .unwrap()
}

/// Directional albedo (luminance) from `wo` by the BSDF's own sampling,
/// with its standard error.
fn albedo(b: &dyn Bsdf, wo: Vec3, n: usize) -> (f64, f64) {
    let ctx = BsdfContext::default();
    let mut rng = Pcg32::new(5, 17);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(smp) = b.sample_f(&ctx, wo, u1, u2) {
            let v = (smp.f.luminance() * smp.wi.z / smp.pdf) as f64;
            s += v;
            s2 += v * v;
        }
    }
    let m = s / n as f64;
    (m, ((s2 / n as f64 - m * m).max(0.0) / n as f64).sqrt())
}

#[test]
fn tables_match_the_analytic_bsdfs_they_were_made_from() {
    let dir = temp_dir("truth");
    for (name, plugin, set, analytic) in MATERIALS {
        let file = tabulated(&dir, name, plugin, set);
        let measured = bsdf(&format!(
            "type = \"measured\"\nfile = \"{}\"\nsampling = \"tabulated\"\n",
            file.display()
        ));
        let reference = bsdf(analytic);
        let ctx = BsdfContext::default();
        // Pointwise: away from the lobe's sharpest part and the horizon,
        // trilinear interpolation is within a few percent.
        let mut rng = Pcg32::new(1, 2);
        let mut rel = Vec::new();
        for _ in 0..2000 {
            let dir = |rng: &mut Pcg32| {
                let z = 0.2 + 0.8 * rng.next_f32();
                let phi = std::f32::consts::TAU * rng.next_f32();
                let s = (1.0 - z * z).sqrt();
                Vec3::new(s * phi.cos(), s * phi.sin(), z)
            };
            let (wo, wi) = (dir(&mut rng), dir(&mut rng));
            let (m, r) = (
                measured.f(&ctx, wo, wi).luminance(),
                reference.f(&ctx, wo, wi).luminance(),
            );
            if r > 1e-3 {
                rel.push(((m - r) / r).abs());
            }
        }
        rel.sort_by(f32::total_cmp);
        let median = rel[rel.len() / 2];
        assert!(median < 0.02, "{name}: median relative error of f {median}");
        // Albedo from several elevations: the table holds the energy.
        for cos_o in [0.2f32, 0.6, 1.0] {
            let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            let (am, sm) = albedo(measured.as_ref(), wo, 200_000);
            let (ar, sr) = albedo(reference.as_ref(), wo, 200_000);
            let tol = 0.03 * ar + 5.0 * (sm * sm + sr * sr).sqrt();
            assert!(
                (am - ar).abs() < tol,
                "{name} at cos {cos_o}: albedo {am} (table) vs {ar} (analytic)"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_strategy_estimates_the_same_albedo() {
    // Unbiasedness where it can be measured sharply: the directional
    // albedo of one table by each strategy, against the tabulated one.
    let dir = temp_dir("albedo");
    for (name, plugin, set, _) in MATERIALS {
        let file = tabulated(&dir, name, plugin, set);
        let make = |s: &str| {
            bsdf(&format!(
                "type = \"measured\"\nfile = \"{}\"\n{s}",
                file.display()
            ))
        };
        let reference = make("sampling = \"tabulated\"\n");
        for s in [
            "sampling = \"cosine\"\n",
            "sampling = \"factored\"\nterms = 1\n",
            "sampling = \"factored\"\nterms = 2\n",
            "sampling = \"factored\"\nterms = 4\n",
        ] {
            let b = make(s);
            for cos_o in [0.1f32, 0.5, 1.0] {
                let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let (a, sa) = albedo(b.as_ref(), wo, 1_000_000);
                let (r, sr) = albedo(reference.as_ref(), wo, 1_000_000);
                assert!(
                    (a - r).abs() < 6.0 * (sa * sa + sr * sr).sqrt() + 2e-3 * r,
                    "{name} {s:?} at cos {cos_o}: albedo {a} +- {sa} vs tabulated {r} +- {sr}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tabulate_refuses_what_the_format_cannot_hold() {
    let dir = temp_dir("refuse");
    let registry = lumis_app::builtin_registry().unwrap();
    let try_tab = |plugin: &str, set: &[&str]| {
        tabulate_bsdf(
            &TabulateArgs {
                bsdf: plugin.into(),
                set: set.iter().map(|s| s.to_string()).collect(),
                output: dir.join("x.binary"),
                quiet: true,
            },
            &registry,
        )
        .unwrap_err()
        .to_string()
    };
    let e = try_tab("conductor", &["roughness=0.05", "roughness_v=0.5"]);
    assert!(e.contains("anisotropic"), "{e}");
    let e = try_tab("dielectric", &["roughness=0.2"]);
    assert!(e.contains("transmits"), "{e}");
    let e = try_tab("mirror", &[]);
    assert!(e.contains("delta"), "{e}");
    let e = try_tab("conductor", &["roughnes=0.1"]);
    assert!(e.contains("unknown key 'roughnes'"), "{e}");
    assert!(!dir.join("x.binary").exists(), "nothing written on refusal");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The precomputation of `plan` for `table` (written at `file`), through
/// its cache.
fn prepare_cached(table: &MerlTable, file: &Path, plan: Plan) -> (Prepared, PrecomputeReport) {
    prepare_on(table, file, plan, GRID)
}

/// [`prepare_cached`] on `grid`.
fn prepare_on(
    table: &MerlTable,
    file: &Path,
    plan: Plan,
    grid: Grid,
) -> (Prepared, PrecomputeReport) {
    let reflectance = Reflectance::Table(Arc::new(table.clone()));
    prepare(&reflectance, Some(file), plan, grid, true).unwrap()
}

#[test]
fn the_cache_is_reused_and_invalidated_when_the_table_changes() {
    let dir = temp_dir("cache");
    let file = tabulated(&dir, "c", "conductor", &["roughness=0.2"]);
    let table = MerlTable::read(&file).unwrap();
    let plan = Plan::Factored { terms: 2 };
    let (_, first) = prepare_cached(&table, &file, plan);
    assert!(!first.from_cache, "{}", first.message);
    let (_, second) = prepare_cached(&table, &file, plan);
    assert!(second.from_cache, "{}", second.message);
    // Another table at the same path: the old cache is stale.
    let file = tabulated(&dir, "c", "conductor", &["roughness=0.3"]);
    let table = MerlTable::read(&file).unwrap();
    let (_, third) = prepare_cached(&table, &file, plan);
    assert!(
        !third.from_cache && third.message.contains("another version"),
        "{}",
        third.message
    );
    let (_, tab) = prepare_cached(&table, &file, Plan::Tabulated);
    assert!(
        !tab.from_cache,
        "a different strategy has its own cache: {}",
        tab.message
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn scene_with(material_block: &str) -> String {
    let text = read_scene("measured-sphere.toml");
    let analytic =
        "name = \"analytic\"\ntype = \"conductor\"\nroughness = 0.05\nmaterial = \"Cu\"\n";
    assert!(
        text.contains(analytic),
        "scenes/measured-sphere.toml changed its analytic bsdf"
    );
    text.replace(analytic, &format!("name = \"analytic\"\n{material_block}"))
}

#[test]
fn scene_errors_name_the_file() {
    let registry = lumis_app::builtin_registry().unwrap();
    let text = read_scene("measured-sphere.toml");
    let load = |overrides: &[String]| {
        lumis_scene::load_str(&text, &scenes_dir().join("s.toml"), overrides, &registry)
            .err()
            .expect("scene must not load")
            .to_string()
    };
    let e = load(&["bsdf.sample.file=/no/such/table.binary".into()]);
    assert!(
        e.contains("/no/such/table.binary") && e.contains("'file'"),
        "{e}"
    );
    let dir = temp_dir("bad");
    let bad = dir.join("short.binary");
    std::fs::write(&bad, [90u8, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0, 1, 2, 3]).unwrap();
    let e = load(&[format!("bsdf.sample.file={}", bad.display())]);
    assert!(e.contains("short.binary") && e.contains("truncated"), "{e}");
    let e = load(&[
        "bsdf.sample.grid=[1024, 1024, 64]".into(),
        "bsdf.sample.file=/no/such".into(),
    ]);
    assert!(
        e.contains("'grid'") && e.contains("at most"),
        "settings are checked before the file: {e}"
    );
    let e = load(&["bsdf.sample.terms=2.5".into()]);
    assert!(e.contains("'terms'") && e.contains("integer"), "{e}");
    let e = load(&["bsdf.sample.terms=17".into()]);
    assert!(e.contains("'terms'") && e.contains("[1, 16]"), "{e}");
    let e = load(&["bsdf.sample.sampling=lobes".into()]);
    assert!(e.contains("\"cosine\", \"factored\", \"tabulated\""), "{e}");
    let e = load(&[
        "bsdf.sample.sampling=cosine".into(),
        "bsdf.sample.file=/no/such".into(),
    ]);
    assert!(e.contains("/no/such"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An analytic source (`bsdf`) must be declared before, must be
/// representable, and excludes a table file; each mistake is named.
#[test]
fn analytic_source_errors_name_the_key() {
    let registry = lumis_app::builtin_registry().unwrap();
    let table = "file = \"measured/conductor-0.05.binary\"\n";
    let text = read_scene("measured-sphere.toml");
    assert!(
        text.contains(table),
        "scenes/measured-sphere.toml changed its table"
    );
    // The sphere's BSDF with `keys` in place of its table, after a BSDF
    // "source" of `source`.
    let load = |keys: &str, source: &str| {
        let text = text.replace(table, keys);
        let sample = "[[bsdf]]\nname = \"sample\"\n";
        let declared = format!("[[bsdf]]\nname = \"source\"\n{source}\n{sample}");
        let text = text.replace(sample, &declared);
        lumis_scene::load_str(&text, &scenes_dir().join("s.toml"), &[], &registry)
            .err()
            .map(|e| e.to_string())
    };
    let gold = "type = \"conductor\"\nroughness = 0.2\nmaterial = \"Au\"\n";
    assert_eq!(
        load("bsdf = \"source\"\n", gold),
        None,
        "an analytic source loads"
    );
    let both = load(&format!("{table}bsdf = \"source\"\n"), gold).unwrap();
    assert!(
        both.contains("'bsdf'") && both.contains("not both"),
        "{both}"
    );
    let neither = load("", gold).unwrap();
    assert!(
        neither.contains("'file'") && neither.contains("analytic bsdf"),
        "{neither}"
    );
    let glass = load("bsdf = \"source\"\n", "type = \"dielectric\"\n").unwrap();
    assert!(
        glass.contains("'bsdf'") && glass.contains("transmits"),
        "{glass}"
    );
}

/// One row of the results table.
struct Row {
    strategy: String,
    rel_mse: Vec<f64>,
    render_seconds: Vec<f64>,
    psnr: Vec<f64>,
    /// The same at LOW_SPP.
    low_rel_mse: Vec<f64>,
    low_psnr: Vec<f64>,
    seconds: f64,
    memory: usize,
}

/// A row's label, its scene overrides, and what it precomputes on which
/// grid.
type Strategy = (String, Vec<String>, Option<(Plan, Grid)>);

const SPP: u32 = 64;
/// The low sample count of the lecture's model-quality comparison.
const LOW_SPP: u32 = 4;
const SEEDS: u64 = 8;
const REFERENCE_SPP: u32 = 4096;

#[test]
fn measured_results_table() {
    let dir = temp_dir("table");
    let registry = lumis_app::builtin_registry().unwrap();
    let mut out = String::new();
    out.push_str(&format!(
        "scenes/measured-sphere.toml, {LOW_SPP} and {SPP} spp x {SEEDS} seeds, BSDF sampling only; reference {REFERENCE_SPP} spp (tabulated sampling for the tables, the model's own for the analytic BSDFs)\n"
    ));
    out.push_str(&format!("| material | strategy | relMSE {LOW_SPP} spp | PSNR dB {LOW_SPP} spp | relMSE {SPP} spp | PSNR dB {SPP} spp | render s | precompute s | sampler memory |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"));
    let mut glossy_cosine_over_factored = 0.0;
    let mut glossy_cosine_over_tensor = 0.0;
    let mut worst_factored_over_analytic = 0.0f64;
    for (name, plugin, set, analytic) in MATERIALS {
        let file = tabulated(&dir, name, plugin, set);
        let table = MerlTable::read(&file).unwrap();
        let scene = scene_with(analytic);
        let file_set = format!("bsdf.sample.file={}", file.display());
        let render = |extra: &[String], spp: u32, seed: u64| {
            let mut o = vec![
                file_set.clone(),
                format!("sampler.spp={spp}"),
                format!("seed={seed}"),
            ];
            o.extend_from_slice(extra);
            let refs: Vec<&str> = o.iter().map(String::as_str).collect();
            let output = render_toml_with(&registry, &scene, &refs, 0);
            (output.image, output.seconds)
        };
        let (measured_ref, _) = render(
            &["bsdf.sample.sampling=tabulated".into()],
            REFERENCE_SPP,
            1000,
        );
        let (analytic_ref, _) = render(&["shape.0.bsdf=analytic".into()], REFERENCE_SPP, 1000);
        let mut strategies: Vec<Strategy> = vec![(
            "cosine".into(),
            vec!["bsdf.sample.sampling=cosine".into()],
            None,
        )];
        for terms in [1, 2, 4] {
            strategies.push((
                format!("factored L={terms}"),
                vec![
                    "bsdf.sample.sampling=factored".into(),
                    format!("bsdf.sample.terms={terms}"),
                ],
                Some((Plan::Factored { terms }, GRID)),
            ));
        }
        // The lecture's model-quality comparison: the projected deviation
        // vector's factored model, and sampling from a tensor's factors.
        strategies.push((
            "pdv factored L=2".into(),
            vec![
                "bsdf.sample.sampling=factored".into(),
                "bsdf.sample.parameterization=pdv".into(),
            ],
            Some((
                Plan::Factored { terms: 2 },
                Grid {
                    parameterization: Parameterization::Pdv,
                    ..GRID
                },
            )),
        ));
        strategies.push((
            "tensor L=2".into(),
            vec!["bsdf.sample.sampling=tensor".into()],
            Some((
                Plan::Tensor { terms: 2 },
                node_grid(Parameterization::HalfDiff),
            )),
        ));
        strategies.push((
            "tabulated".into(),
            vec!["bsdf.sample.sampling=tabulated".into()],
            Some((Plan::Tabulated, GRID)),
        ));
        strategies.push((
            "analytic model".into(),
            vec!["shape.0.bsdf=analytic".into()],
            None,
        ));
        let mut rows = Vec::new();
        for (label, overrides, plan) in strategies {
            let (seconds, memory) = match plan {
                Some((plan, grid)) => {
                    let start = Instant::now();
                    let payload = lumis_measured::precompute::compute(
                        &Reflectance::Table(Arc::new(table.clone())),
                        plan,
                        grid,
                        &ProgressBar::hidden(),
                    );
                    let seconds = start.elapsed().as_secs_f64();
                    drop(payload);
                    let (prepared, _) = prepare_on(&table, &file, plan, grid);
                    (seconds, prepared.memory_bytes())
                }
                None => (0.0, 0),
            };
            let reference = if label == "analytic model" {
                &analytic_ref
            } else {
                &measured_ref
            };
            let mut row = Row {
                strategy: label.clone(),
                rel_mse: Vec::new(),
                render_seconds: Vec::new(),
                psnr: Vec::new(),
                low_rel_mse: Vec::new(),
                low_psnr: Vec::new(),
                seconds,
                memory,
            };
            for seed in 0..SEEDS {
                let (image, seconds) = render(&overrides, SPP, seed);
                row.render_seconds.push(seconds);
                let m = error_metrics(&image, reference, None);
                row.rel_mse.push(m.rel_mse);
                row.psnr.push(m.psnr_db);
                let (image, _) = render(&overrides, LOW_SPP, 100 + seed);
                let m = error_metrics(&image, reference, None);
                row.low_rel_mse.push(m.rel_mse);
                row.low_psnr.push(m.psnr_db);
            }
            rows.push(row);
        }
        let avg = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let se = |v: &[f64]| {
            let m = avg(v);
            (v.iter().map(|x| (x - m).powi(2)).sum::<f64>()
                / (v.len() as f64 * (v.len() - 1) as f64))
                .sqrt()
        };
        for r in &rows {
            out.push_str(&format!(
                "| {name} | {} | {:.4e} ± {:.1e} | {:.2} | {:.4e} ± {:.1e} | {:.2} | {:.3} | {} | {} |\n",
                r.strategy,
                avg(&r.low_rel_mse),
                se(&r.low_rel_mse),
                avg(&r.low_psnr),
                avg(&r.rel_mse),
                se(&r.rel_mse),
                avg(&r.psnr),
                avg(&r.render_seconds),
                if r.memory == 0 {
                    "-".into()
                } else {
                    format!("{:.2}", r.seconds)
                },
                if r.memory == 0 {
                    "-".into()
                } else {
                    format!("{:.1} KiB", r.memory as f64 / 1024.0)
                }
            ));
        }
        let rel = |label: &str| {
            avg(&rows
                .iter()
                .find(|r| r.strategy == label)
                .expect("row")
                .rel_mse)
        };
        let factored = rel("factored L=2");
        if name == "conductor-0.05" {
            glossy_cosine_over_factored = rel("cosine") / factored;
            glossy_cosine_over_tensor = rel("cosine") / rel("tensor L=2");
        }
        worst_factored_over_analytic =
            worst_factored_over_analytic.max(factored / rel("analytic model"));
    }
    println!("{out}");
    std::fs::remove_dir_all(&dir).unwrap();
    // The point of the factorization, and the published claim (Lawrence et
    // al. 2004, section 6): on the glossiest table factored sampling beats
    // cosine sampling by a wide margin (measured: 12x), and on every table
    // it comes within 1.3x of the analytic model's own sampling (measured:
    // 1.02-1.13x; the standard errors are about 2%).
    assert!(
        glossy_cosine_over_factored > 4.0,
        "cosine / factored relMSE only {glossy_cosine_over_factored} on conductor-0.05\n{out}"
    );
    // Sampling the tensor's own factors beats cosine sampling on the
    // glossiest table too.
    assert!(
        glossy_cosine_over_tensor > 4.0,
        "cosine / tensor relMSE only {glossy_cosine_over_tensor} on conductor-0.05\n{out}"
    );
    assert!(
        worst_factored_over_analytic < 1.3,
        "factored / analytic relMSE up to {worst_factored_over_analytic}\n{out}"
    );
}
