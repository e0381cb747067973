//! The parameter settings a check sweeps a plugin over, from its declared
//! parameters alone: the defaults, both ends of every range, seeded values
//! inside it, every choice, both booleans, and each colour at its maximum.
//! Every plugin kind's suite checks the same sweep.

use lumis_core::doc::{self, Table};
use lumis_core::params::ParamDefault;
use lumis_core::{Error, ParamType, PluginKind, PluginSpec, Registry, Result};
use lumis_sampling::Pcg32;

/// One parameter setting of the sweep.
#[derive(Debug, Clone)]
pub struct Variant {
    /// E.g. `base` or `exponent = 1000000`.
    pub label: String,
    pub table: Table,
    /// For a value inside a range: which of its [`STRATA`] it lies in.
    pub stratum: Option<usize>,
}

impl Variant {
    /// The share of a full case's samples this variant is checked with. A
    /// range's ends and every other setting take them all; the values
    /// inside a range take [`INTERIOR_BUDGET`] / [`STRATA`] each, so the
    /// strata of a range cost together what [`INTERIOR_BUDGET`] full
    /// variants cost, and each is still met by every case of a suite (every
    /// reference point, every test scene): a defect at one value is a NaN,
    /// a negative value, an inconsistent pdf or energy created, each found
    /// with few samples. (The BSDF suite, whose chi-square test costs as
    /// much per bin as per sample, shares its incident directions among
    /// the strata instead: `bsdf_suite::directions_of`.)
    pub fn share(&self) -> f64 {
        match self.stratum {
            Some(_) => INTERIOR_BUDGET as f64 / STRATA as f64,
            None => 1.0,
        }
    }

    /// `samples` scaled by [`Variant::share`], at least one.
    pub fn samples(&self, samples: usize) -> usize {
        ((samples as f64 * self.share()).ceil() as usize).max(1)
    }
}

/// A value to use for a required parameter with no default.
fn stand_in(
    name: &str,
    ty: ParamType,
    range: Option<(f64, f64)>,
    choices: &[&str],
) -> Result<String> {
    Ok(match ty {
        ParamType::Rgb | ParamType::TexturedRgb => "0.5".into(),
        ParamType::Bsdf => format!("\"{}\"", STAND_IN_BSDFS[0].0),
        ParamType::Float | ParamType::TexturedFloat => range.map_or("0.5".into(), |(a, b)| format!("{:?}", 0.5 * (a + b))),
        ParamType::Int => range.map_or("1".into(), |(a, _)| format!("{}", a as i64)),
        ParamType::Bool => "false".into(),
        ParamType::String if !choices.is_empty() => format!("\"{}\"", choices[0]),
        _ => {
            return Err(Error::msg(format!(
                "parameter '{name}' is required and of type {}: declare a default, a range or choices so it can be swept",
                ty.name()
            )))
        }
    })
}

/// A value inside `(a, b)` at fraction `t` of it: log-uniform over a range
/// spanning decades (roughness from 1e-4, exponents to 1e6), where the
/// interesting values are small, else uniform.
fn interior(a: f64, b: f64, t: f64) -> f64 {
    if a > 0.0 && b / a > 100.0 {
        (a.ln() + t * (b.ln() - a.ln())).exp()
    } else {
        a + t * (b - a)
    }
}

/// FNV-1a of the two names.
fn name_seed(plugin: &str, parameter: &str) -> u64 {
    plugin
        .bytes()
        .chain([0])
        .chain(parameter.bytes())
        .fold(0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

/// The declaration of the `kind` plugin `name`, or an error naming what
/// is missing: where every suite starts.
pub fn declared(registry: &Registry, kind: PluginKind, name: &str) -> Result<PluginSpec> {
    registry
        .find(kind, name)
        .map(|p| p.spec)
        .ok_or_else(|| Error::msg(format!("no {} plugin named \"{name}\"", kind.table_name())))
}

/// A named parameter setting, from TOML text (`"roughness = 0.01\n..."`).
pub fn variant(label: impl Into<String>, toml: &str) -> Result<Variant> {
    Ok(Variant {
        label: label.into(),
        table: doc::parse(toml, "<sweep>")?,
        stratum: None,
    })
}

/// A ranged parameter is checked at a seeded value in each of this many
/// equal parts of its range (log-spaced where the range spans decades):
/// a defect confined to a tenth of the range (a panic for 0.6 < sigma <
/// 0.7) is met, which the ends and the default miss. Seeded by the
/// plugin's and the parameter's names, so a check is repeatable.
pub const STRATA: usize = 10;

/// What the [`STRATA`] of one range cost together, in full variants: each
/// stratum is checked with its share of a case's samples
/// ([`Variant::share`]).
pub const INTERIOR_BUDGET: usize = 2;

/// The parameter settings to check: the defaults (with stand-ins for
/// required parameters), then one parameter at a time at each end of its
/// range and at a seeded value in each of its [`STRATA`], at each declared
/// choice, at each boolean value, and each colour at its maximum (where a
/// BSDF that creates energy shows it most).
pub fn parameter_sweep(spec: &PluginSpec) -> Result<Vec<Variant>> {
    parameter_sweep_with(spec, &[])
}

/// [`parameter_sweep`] with some parameters held at given values (TOML
/// text, e.g. `("file", "\"table.binary\"")`) in every variant: for
/// plugins with a required parameter no stand-in can supply, such as a
/// file.
pub fn parameter_sweep_with(spec: &PluginSpec, fixed: &[(String, String)]) -> Result<Vec<Variant>> {
    let mut base: Vec<(String, String)> = fixed.to_vec();
    for (name, _) in fixed {
        if !spec.params.iter().any(|p| p.name == name) {
            return Err(Error::msg(format!(
                "{} \"{}\" has no parameter '{name}'; it has: {}",
                spec.kind.table_name(),
                spec.name,
                spec.params
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    }
    for p in spec.params {
        if fixed.iter().any(|(k, _)| k == p.name) {
            continue;
        }
        if p.default == ParamDefault::Required {
            base.push((
                p.name.to_string(),
                stand_in(p.name, p.ty, p.range, p.choices)?,
            ));
        }
    }
    let mut settings: Vec<(String, Setting, Option<usize>)> =
        vec![("base".into(), base.clone(), None)];
    for p in spec
        .params
        .iter()
        .filter(|p| !fixed.iter().any(|(k, _)| k == p.name))
    {
        let mut values: Vec<(String, Option<usize>)> = Vec::new();
        match p.ty {
            ParamType::Float | ParamType::TexturedFloat | ParamType::Int => {
                if let Some((a, b)) = p.range {
                    let fmt = |v: f64| {
                        if p.ty == ParamType::Int {
                            format!("{}", v as i64)
                        } else {
                            format!("{v:?}")
                        }
                    };
                    values.extend([(fmt(a), None), (fmt(b), None)]);
                    let mut rng = Pcg32::new(name_seed(spec.name, p.name), 0x5eed);
                    for k in 0..STRATA {
                        let t = (k as f64 + rng.next_f32() as f64) / STRATA as f64;
                        let v = fmt(interior(a, b, t));
                        // An integer range narrower than the strata
                        // repeats values: each is checked once.
                        if !values.iter().any(|(seen, _)| *seen == v) {
                            values.push((v, Some(k)));
                        }
                    }
                }
            }
            ParamType::Rgb => {
                // A colour at its maximum and the other colours (those
                // with defaults) at zero: each lobe at full strength alone,
                // where a BSDF that creates energy shows it most.
                let max = p.range.map_or("1.0".into(), |(_, b)| format!("{b:?}"));
                let others = spec.params.iter().filter(|q| {
                    q.ty == ParamType::Rgb
                        && q.name != p.name
                        && matches!(q.default, ParamDefault::Value(_))
                        && !fixed.iter().any(|(k, _)| k == q.name)
                });
                let mut s: Vec<(String, String)> = base
                    .iter()
                    .filter(|(k, _)| k != p.name && !others.clone().any(|q| q.name == k))
                    .cloned()
                    .collect();
                s.extend(
                    others
                        .clone()
                        .map(|q| (q.name.to_string(), "0.0".to_string())),
                );
                s.push((p.name.to_string(), max.clone()));
                let zeroed = if others.clone().next().is_some() {
                    ", other colours 0"
                } else {
                    ""
                };
                settings.push((format!("{} = {max}{zeroed}", p.name), s, None));
            }
            ParamType::Bool => values.extend(["true", "false"].map(|b| (b.to_string(), None))),
            ParamType::String => {
                values.extend(p.choices.iter().map(|c| (format!("\"{c}\""), None)))
            }
            ParamType::Bsdf => values.extend(
                STAND_IN_BSDFS
                    .iter()
                    .map(|(name, ..)| (format!("\"{name}\""), None)),
            ),
            _ => {}
        }
        for (v, stratum) in values {
            let mut s: Vec<(String, String)> =
                base.iter().filter(|(k, _)| k != p.name).cloned().collect();
            s.push((p.name.to_string(), v.clone()));
            settings.push((format!("{} = {v}", p.name), s, stratum));
        }
    }
    settings
        .into_iter()
        .map(|(label, kv, stratum)| {
            let text: String = kv.iter().map(|(k, v)| format!("{k} = {v}\n")).collect();
            let table = doc::parse(&text, "<sweep>")?;
            Ok(Variant {
                label,
                table,
                stratum,
            })
        })
        .collect()
}

/// A parameter setting as `(key, TOML value)` pairs.
type Setting = Vec<(String, String)>;

/// The BSDFs that a BSDF parameter (an adapter's inner BSDF, e.g.
/// `twosided`'s) is swept over: name, built-in plugin, parameters.
pub const STAND_IN_BSDFS: &[(&str, &str, &str)] = &[
    (
        "rough-plastic",
        "plastic",
        "roughness = 0.3\nnonlinear = true\n",
    ),
    ("diffuse", "diffuse", "reflectance = 0.5\n"),
    ("gold", "conductor", "material = \"Au\"\nroughness = 0.2\n"),
];

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::{ParamChoice, PluginKind, PluginParams, Rgb};

    #[derive(Clone, Copy, ParamChoice)]
    enum Mode {
        A,
        B,
    }

    /// The sweeps read the declaration the derive writes.
    #[derive(PluginParams)]
    #[allow(dead_code)]
    struct TestParams {
        /// albedo
        albedo: Rgb,
        /// roughness
        #[param(default = 0.5, range = (1e-4, 1.0))]
        roughness: f32,
        /// mode
        #[param(default = A)]
        mode: Mode,
        /// two-sided
        #[param(default = false)]
        two_sided: bool,
    }

    const SPEC: PluginSpec = PluginSpec {
        kind: PluginKind::Bsdf,
        name: "t",
        source: lumis_api::source_file!(),
        doc: "",
        params: TestParams::SPECS,
    };

    #[test]
    fn fixed_parameters_are_in_every_variant_and_not_swept() {
        let fixed = [("roughness".to_string(), "0.25".to_string())];
        let sweep = parameter_sweep_with(&SPEC, &fixed).unwrap();
        assert!(sweep.iter().all(|v| !v.label.starts_with("roughness")));
        assert!(sweep.iter().all(|v| v.table.get("roughness").is_some()));
        assert!(sweep.iter().any(|v| v.label == "mode = \"b\""));
        let bad = [("roughnes".to_string(), "0.25".to_string())];
        let err = parameter_sweep_with(&SPEC, &bad).unwrap_err().to_string();
        assert!(err.contains("no parameter 'roughnes'"), "{err}");
    }

    /// The strata of a range take together the samples of
    /// [`INTERIOR_BUDGET`] full variants.
    #[test]
    fn strata_share_the_samples() {
        let sweep = parameter_sweep(&SPEC).unwrap();
        let strata: usize = sweep
            .iter()
            .filter(|v| v.stratum.is_some())
            .map(|v| v.samples(1_000_000))
            .sum();
        assert_eq!(strata, INTERIOR_BUDGET * 1_000_000);
        assert_eq!(sweep[0].samples(1000), 1000);
    }

    #[test]
    fn sweep_covers_range_ends_choices_and_booleans() {
        let labels: Vec<String> = parameter_sweep(&SPEC)
            .unwrap()
            .into_iter()
            .map(|v| v.label)
            .collect();
        for want in [
            "base",
            "roughness = 0.0001",
            "roughness = 1.0",
            "mode = \"a\"",
            "mode = \"b\"",
            "two_sided = true",
            "two_sided = false",
        ] {
            assert!(
                labels.iter().any(|l| l == want),
                "missing {want} in {labels:?}"
            );
        }
    }

    /// Seeded interior values lie inside the range, one in each of its
    /// tenths (log-spaced over a range of decades), the same on every run;
    /// each colour is swept at its maximum with the other colours that
    /// have defaults at zero.
    #[test]
    fn sweep_adds_interior_values_and_colours_at_their_maximum() {
        let sweep = parameter_sweep(&SPEC).unwrap();
        let inside: Vec<(f64, usize)> = sweep
            .iter()
            .filter_map(|v| Some((v.label.strip_prefix("roughness = ")?, v.stratum?)))
            .map(|(v, k)| (v.parse().unwrap(), k))
            .collect();
        assert_eq!(inside.len(), STRATA, "{inside:?}");
        for (k, &(v, stratum)) in inside.iter().enumerate() {
            assert_eq!(stratum, k);
            // The tenth of the log range, from 1e-4 to 1: [1e-4 10^(0.4k), ...).
            let (lo, hi) = (
                1e-4 * 10f64.powf(0.4 * k as f64),
                1e-4 * 10f64.powf(0.4 * (k + 1) as f64),
            );
            assert!(
                lo <= v && v < hi * (1.0 + 1e-12),
                "{k}: {v} not in [{lo}, {hi})"
            );
        }
        let again: Vec<String> = parameter_sweep(&SPEC)
            .unwrap()
            .into_iter()
            .map(|v| v.label)
            .collect();
        assert_eq!(
            again,
            sweep.iter().map(|v| v.label.clone()).collect::<Vec<_>>()
        );
        // Half-way is the geometric mean over decades, the mean otherwise.
        assert!((interior(1e-4, 1.0, 0.5) - 1e-2).abs() < 1e-12);
        assert_eq!(interior(0.0, 2.0, 0.25), 0.5);
        let albedo = sweep.iter().find(|v| v.label == "albedo = 1.0").unwrap();
        assert!(albedo.table.get("albedo").is_some());
    }
}
