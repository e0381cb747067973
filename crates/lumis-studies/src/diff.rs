//! `lumis diff`: error metrics of an image against a reference, over the
//! whole image and named regions, and a false-colour error picture.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use lumis_analysis::image_error::{
    check_same_size, error_metrics, rel_error_map, ErrorMetrics, Rect,
};
use lumis_analysis::plot::{self, Grid};
use lumis_core::doc::{self, Node, Value};
use lumis_core::{Error, Result};
use lumis_files::{read_text_bounded, FileKind, MIB};
use lumis_image::{read_exr, Image, OutputLock};

use lumis_app::same_file;

#[derive(clap::Args, Debug, Clone)]
pub struct DiffArgs {
    /// The image to assess (EXR).
    pub image: PathBuf,
    /// The reference (EXR), e.g. a converged render.
    pub reference: PathBuf,
    /// Named pixel regions (TOML: `[[region]] name = "floor"`,
    /// `min = [x, y]`, `max = [x, y]`, max exclusive, y down from the top).
    #[arg(long, value_name = "regions.toml")]
    pub mask: Option<PathBuf>,
    /// Write the per-pixel relative squared error as a false-colour PNG
    /// (log scale, with a colour bar).
    #[arg(long, value_name = "PATH.png")]
    pub error_image: Option<PathBuf>,
}

/// A named region of a mask file.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    pub name: String,
    pub rect: Rect,
}

/// A region mask is a short TOML list written by hand.
const MASK_FILE: FileKind = FileKind::new("region mask", 16 * MIB);

fn read(path: &Path) -> Result<Image> {
    read_exr(path).map_err(|e| Error::msg(e.to_string()))
}

fn pixel_pair(node: Option<&Node>, key: &str, owner: &str, at: &Node) -> Result<[usize; 2]> {
    let node = node.ok_or_else(|| {
        Error::at(
            &at.location,
            format!("{owner}: missing '{key}' (expected [x, y] in pixels)"),
        )
    })?;
    let bad = || {
        Error::at(
            &node.location,
            format!(
                "{owner} key '{key}': expected [x, y] of non-negative integers, found {}",
                node.value.type_name()
            ),
        )
    };
    match &node.value {
        Value::Array(items) if items.len() == 2 => {
            let mut out = [0usize; 2];
            for (o, item) in out.iter_mut().zip(items) {
                match item.value {
                    Value::Int(v) if v >= 0 => *o = v as usize,
                    _ => return Err(bad()),
                }
            }
            Ok(out)
        }
        _ => Err(bad()),
    }
}

/// Reads `[[region]]` tables; every error names the file, line and key.
pub fn parse_regions(text: &str, path: &str, width: usize, height: usize) -> Result<Vec<Region>> {
    let root = doc::parse(text, path)?;
    let mut regions = Vec::new();
    for entry in &root.entries {
        if entry.key != "region" {
            return Err(Error::at(
                &entry.key_location,
                format!(
                    "unknown key '{}': a mask file holds only [[region]] tables",
                    entry.key
                ),
            ));
        }
        let Value::Array(items) = &entry.node.value else {
            return Err(Error::at(
                &entry.node.location,
                "'region' must be an array of tables ([[region]])",
            ));
        };
        for (i, item) in items.iter().enumerate() {
            let Value::Table(table) = &item.value else {
                return Err(Error::at(&item.location, "each region must be a table"));
            };
            let owner = format!("region {i}");
            for key in table.keys() {
                if !["name", "min", "max"].contains(&key) {
                    return Err(Error::at(
                        &table.entry(key).unwrap().key_location,
                        format!("{owner}: unknown key '{key}'; accepted: name, min, max"),
                    ));
                }
            }
            let name = match table.get("name").map(|n| &n.value) {
                Some(Value::String(s)) => s.clone(),
                _ => {
                    return Err(Error::at(
                        &item.location,
                        format!("{owner}: expected name = \"...\""),
                    ))
                }
            };
            let owner = format!("region \"{name}\"");
            let min = pixel_pair(table.get("min"), "min", &owner, item)?;
            let max = pixel_pair(table.get("max"), "max", &owner, item)?;
            if min[0] >= max[0] || min[1] >= max[1] || max[0] > width || max[1] > height {
                return Err(Error::at(
                    &item.location,
                    format!(
                        "{owner}: min {min:?} .. max {max:?} must be a non-empty rectangle inside the {width}x{height} image"
                    ),
                ));
            }
            regions.push(Region {
                name,
                rect: Rect { min, max },
            });
        }
    }
    Ok(regions)
}

fn row(label: &str, m: &ErrorMetrics) -> String {
    format!(
        "{label:16} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>+11.4e} {:>8.2}\n",
        m.mse, m.rmse, m.rel_mse, m.mean_abs_rel_error, m.mean_signed_rel_error, m.psnr_db
    )
}

/// Runs `lumis diff` and returns the printed report.
pub fn diff(args: &DiffArgs) -> Result<String> {
    // The error image is an output like a render's: locked against other
    // writers, and never one of the inputs.
    let _lock = match &args.error_image {
        Some(path) => {
            if [&args.image, &args.reference]
                .iter()
                .any(|input| same_file(input, path))
            {
                return Err(Error::msg(format!(
                    "--error-image {} is one of the images compared; name another file",
                    path.display()
                )));
            }
            Some(OutputLock::acquire(path).map_err(|e| Error::msg(e.to_string()))?)
        }
        None => None,
    };
    let (a, b) = (read(&args.image)?, read(&args.reference)?);
    check_same_size(&a, &b).map_err(|e| {
        Error::msg(format!(
            "{} vs {}: {e}; render the image at the reference's resolution",
            args.image.display(),
            args.reference.display()
        ))
    })?;
    let regions = match &args.mask {
        Some(path) => {
            let text = read_text_bounded(path, MASK_FILE).map_err(Error::msg)?;
            parse_regions(&text, &path.display().to_string(), a.width, a.height)?
        }
        None => Vec::new(),
    };
    let mut out = format!(
        "{:16} {:>11} {:>11} {:>11} {:>11} {:>11} {:>8}\n",
        "region", "MSE", "RMSE", "relMSE", "mean|rel|", "mean rel", "PSNR dB"
    );
    out += &row("image", &error_metrics(&a, &b, None));
    for r in &regions {
        out += &row(&r.name, &error_metrics(&a, &b, Some(r.rect)));
    }
    writeln!(
        out,
        "(relative errors divide by b^2 + 0.01 or |b| + 0.01; PSNR on sRGB-encoded values clamped to [0, 1])"
    )
    .unwrap();
    if let Some(path) = &args.error_image {
        // Rows flipped so the picture is upright (plot rows grow upwards).
        let map = rel_error_map(&a, &b);
        let flipped: Vec<f64> = (0..a.height)
            .rev()
            .flat_map(|y| map[y * a.width..(y + 1) * a.width].iter().copied())
            .collect();
        let grid = Grid {
            width: a.width,
            height: a.height,
            origin: (0, 0),
            x_label: "x",
            y_label: "y (from the bottom)",
            value_label: "log10 relative squared error",
        };
        let title = format!("relative squared error of {}", args.image.display());
        plot::heat_map(path, &title, &flipped, &grid, None)?;
        writeln!(out, "error image: {}", path.display()).unwrap();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_parse_and_bad_ones_are_located() {
        let ok = "[[region]]\nname = \"floor\"\nmin = [0, 2]\nmax = [4, 3]\n";
        let r = parse_regions(ok, "m.toml", 4, 4).unwrap();
        assert_eq!(
            r[0].rect,
            Rect {
                min: [0, 2],
                max: [4, 3]
            }
        );
        let outside = "[[region]]\nname = \"x\"\nmin = [0, 0]\nmax = [5, 1]\n";
        let e = parse_regions(outside, "m.toml", 4, 4)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.toml:1") && e.contains("inside the 4x4 image"),
            "{e}"
        );
        let typo = "[[region]]\nname = \"x\"\nmin = [0, 0]\nmax = [1, 1]\nmxa = 3\n";
        let e = parse_regions(typo, "m.toml", 4, 4).unwrap_err().to_string();
        assert!(
            e.contains("m.toml:5") && e.contains("unknown key 'mxa'"),
            "{e}"
        );
        let float = "[[region]]\nname = \"x\"\nmin = [0.5, 0]\nmax = [1, 1]\n";
        let e = parse_regions(float, "m.toml", 4, 4)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.toml:3") && e.contains("non-negative integers"),
            "{e}"
        );
    }
}
