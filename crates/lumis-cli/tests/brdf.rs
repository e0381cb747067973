//! `lumis brdf tabulate`, `lumis brdf precompute`, `lumis brdf compress`
//! and `lumis check-plugin --set` on a measured table, as a user runs them.

use std::process::{Command, Output};

fn lumis(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(args)
        .output()
        .expect("lumis runs")
}

/// A fresh directory for one test's files, removed when the test ends.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("lumis-cli-brdf-{name}-"))
        .tempdir()
        .unwrap()
}

/// Fails unless `out` contains every one of `wanted`.
fn assert_mentions(out: &str, wanted: &[&str]) {
    for want in wanted {
        assert!(out.contains(want), "missing {want}:\n{out}");
    }
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn tabulate_precompute_and_check_a_measured_table() {
    let tmp = scratch("flow");
    let dir = tmp.path();
    let table = dir.join("gold.binary");
    let table_arg = table.display().to_string();
    let run = lumis(&[
        "brdf",
        "tabulate",
        "--bsdf",
        "conductor",
        "--set",
        "roughness=0.3",
        "--set",
        "material=Au",
        "-o",
        &table_arg,
        "--quiet",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    assert!(text(&run).contains("34992012 bytes"), "{}", text(&run));
    assert_eq!(std::fs::metadata(&table).unwrap().len(), 34_992_012);

    // The measured scene renders the table given with --set, though the
    // table it names itself is absent (the copy's directory has none).
    let scene = dir.join("measured-sphere.toml");
    let source = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/measured-sphere.toml"
    );
    std::fs::copy(source, &scene).unwrap();
    let image = dir.join("sphere.exr").display().to_string();
    let run = lumis(&[
        "render",
        &scene.display().to_string(),
        "--set",
        &format!("bsdf.sample.file={table_arg}"),
        "--set",
        "film.resolution=[8, 8]",
        "--spp",
        "1",
        "-q",
        "-o",
        &image,
    ]);
    assert!(run.status.success(), "{}", text(&run));

    let run = lumis(&[
        "brdf",
        "precompute",
        &table_arg,
        "--sampling",
        "factored",
        "--terms",
        "2",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    assert!(text(&run).contains("precomputed in"), "{}", text(&run));
    assert!(dir
        .join("gold.binary.factored-L2-32x64x64s4.lumis-cache")
        .exists());
    let run = lumis(&[
        "brdf",
        "precompute",
        &table_arg,
        "--sampling",
        "tabulated",
        "--parameterization",
        "pdv",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    assert!(dir
        .join("gold.binary.tabulated-L0-32x64x64s4-pdv.lumis-cache")
        .exists());

    // The tensor approximation: its size, its error, its factors.
    let factors = dir.join("gold.factors");
    let factors_arg = factors.display().to_string();
    let run = lumis(&[
        "brdf",
        "compress",
        &table_arg,
        "--rank",
        "2",
        "--parameterization",
        "pdv",
        "-o",
        &factors_arg,
    ]);
    let out = text(&run);
    assert!(run.status.success(), "{out}");
    assert_mentions(
        &out,
        &[
            "rank-2 CP tensor over pdv",
            "table 4374000 floats",
            "tensor 2160 floats",
            "2025x smaller",
            "relative RMSE of f",
            "PSNR of ln(1 + f)",
        ],
    );
    // Header, 2160 f32, hash.
    assert_eq!(
        std::fs::metadata(&factors).unwrap().len(),
        56 + 4 * 2160 + 8
    );

    // The check kit over the plugin's own parameters, the table held fixed.
    let file = format!("file={table_arg}");
    let run = lumis(&[
        "check-plugin",
        "--bsdf",
        "measured",
        "--set",
        &file,
        "--samples",
        "20000",
        "--bins",
        "16",
    ]);
    let out = text(&run);
    assert!(run.status.success(), "{out}");
    assert_mentions(
        &out,
        &[
            "sampling = \"cosine\"",
            "sampling = \"tabulated\"",
            "sampling = \"tensor\"",
            "parameterization = \"pdv\"",
            "parameterization = \"in-out\"",
            "representation = \"tensor\"",
            "terms = 16",
            "passed, 0 failed",
        ],
    );
    // Without a table the sweep checks the plugin on the kit's analytic
    // stand-ins (`bsdf`), and says why the settings without a source are
    // not tested.
    let run = lumis(&["check-plugin", "--bsdf", "measured", "--samples", "1000"]);
    let out = text(&run);
    assert!(run.status.success(), "{out}");
    assert_mentions(
        &out,
        &[
            "bsdf = \"gold\"",
            "missing: give a MERL table file (or an analytic bsdf)",
            "passed, 0 failed",
        ],
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_requests_fail_with_the_reason() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    let out = dir.join("x.binary").display().to_string();
    let run = lumis(&[
        "brdf",
        "tabulate",
        "--bsdf",
        "dielectric",
        "-o",
        &out,
        "--quiet",
    ]);
    assert!(!run.status.success());
    assert!(text(&run).contains("transmits"), "{}", text(&run));
    let run = lumis(&["brdf", "precompute", "/no/such.binary"]);
    assert!(!run.status.success());
    assert!(text(&run).contains("/no/such.binary"), "{}", text(&run));
    let run = lumis(&["brdf", "precompute", &out, "--sampling", "cosine"]);
    assert!(
        text(&run).contains("needs no precomputation"),
        "{}",
        text(&run)
    );
    let run = lumis(&["brdf", "precompute", &out, "--parameterization", "polar"]);
    assert!(!run.status.success());
    assert!(
        text(&run)
            .contains("--parameterization must be one of half-diff, pdv, in-out, got \"polar\""),
        "{}",
        text(&run)
    );
    let run = lumis(&["brdf", "compress", &out, "--rank", "0"]);
    assert!(!run.status.success());
    assert!(
        text(&run).contains("--rank must be in [1, 32], got 0"),
        "{}",
        text(&run)
    );
    std::fs::remove_dir_all(dir).unwrap();
}
