//! `transform = { ... }` tables: an affine placement written in TOML.
//!
//! Either a full `matrix` or any of `scale`, `rotate`, `translate`, applied
//! in that order (`M = T R S`), the convention of most DCC tools and of
//! glTF's own TRS nodes.

use lumis_core::doc::Table;
use lumis_core::glam::{Mat4, Quat};
use lumis_core::{Error, Location, ParamSpec, ParamType, Params, Result, Vec3};

pub(crate) const TRANSFORM_PARAMS: &[ParamSpec] = &[
    ParamSpec::optional(
        "matrix",
        ParamType::FloatArray,
        "16 numbers, a row-major 4x4 affine matrix (last row 0 0 0 1); excludes the other keys",
    ),
    ParamSpec::optional(
        "scale",
        ParamType::Vec3,
        "scale factors per axis, applied first",
    ),
    ParamSpec::optional(
        "rotate",
        ParamType::FloatArray,
        "[axis_x, axis_y, axis_z, degrees]: rotation about the axis (right-handed), after scale",
    ),
    ParamSpec::optional("translate", ParamType::Vec3, "translation, applied last"),
];

/// Parses a transform table; `owner` names it in errors (e.g.
/// `[[shape]] #2 (type = "gltf") transform`).
pub(crate) fn parse_transform(owner: &str, table: &Table, location: Location) -> Result<Mat4> {
    let params = Params::new(owner, table, location.clone(), TRANSFORM_PARAMS, &[])?;
    let matrix = match params.get_opt::<Vec<f32>>("matrix")? {
        Some(m) => {
            if ["scale", "rotate", "translate"]
                .iter()
                .any(|k| params.is_given(k))
            {
                return Err(params.error(
                    "matrix",
                    "give either 'matrix' or scale/rotate/translate, not both",
                ));
            }
            if m.len() != 16 {
                return Err(params.error(
                    "matrix",
                    format!("needs 16 numbers (row-major 4x4), got {}", m.len()),
                ));
            }
            let last_row = [m[12], m[13], m[14], m[15]];
            if last_row != [0.0, 0.0, 0.0, 1.0] {
                return Err(params.error(
                    "matrix",
                    format!("must be affine: last row [0, 0, 0, 1], got {last_row:?}"),
                ));
            }
            Mat4::from_cols_slice(&m).transpose()
        }
        None => {
            let scale: Vec3 = params.get_opt("scale")?.unwrap_or(Vec3::ONE);
            let rotation = match params.get_opt::<Vec<f32>>("rotate")? {
                None => Quat::IDENTITY,
                Some(r) if r.len() == 4 => {
                    let axis = Vec3::new(r[0], r[1], r[2]);
                    if !(axis.length_squared() > 0.0 && axis.is_finite()) {
                        return Err(params.error("rotate", "the axis must be a non-zero vector"));
                    }
                    Quat::from_axis_angle(axis.normalize(), r[3].to_radians())
                }
                Some(r) => {
                    return Err(params.error(
                        "rotate",
                        format!(
                            "needs [axis_x, axis_y, axis_z, degrees], got {} numbers",
                            r.len()
                        ),
                    ))
                }
            };
            let translate: Vec3 = params.get_opt("translate")?.unwrap_or(Vec3::ZERO);
            Mat4::from_scale_rotation_translation(scale, rotation, translate)
        }
    };
    let det = matrix.determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err(Error::at(
            &location,
            format!("{owner}: the matrix is singular (determinant {det})"),
        ));
    }
    params.finish()?;
    Ok(matrix)
}
