//! `transform = { ... }` tables: an affine placement written in TOML.
//!
//! Either a full `matrix` or any of `scale`, `rotate`, `translate`, applied
//! in that order (`M = T R S`), the convention of most DCC tools and of
//! glTF's own TRS nodes.

use lumis_core::doc::Table;
use lumis_core::glam::{Mat4, Quat};
use lumis_core::{Error, Location, Params, PluginParams, Result, Vec3};

/// The keys of a `transform = { ... }` table.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct TransformParams {
    /// 16 numbers, a row-major 4x4 affine matrix (last row 0 0 0 1);
    /// excludes the other keys
    matrix: Option<Vec<f32>>,
    /// scale factors per axis, applied first
    scale: Option<Vec3>,
    /// [axis_x, axis_y, axis_z, degrees]: rotation about the axis
    /// (right-handed), after scale
    rotate: Option<Vec<f32>>,
    /// translation, applied last
    translate: Option<Vec3>,
}

/// Parses a transform table; `owner` names it in errors (e.g.
/// `[[shape]] #2 (type = "gltf") transform`).
pub(crate) fn parse_transform(owner: &str, table: &Table, location: Location) -> Result<Mat4> {
    let params = Params::new(owner, table, location.clone(), TransformParams::SPECS, &[])?;
    let p = TransformParams::read(&params)?;
    let keys = TransformParams::KEYS;
    let matrix = match p.matrix {
        Some(m) => {
            if p.scale.is_some() || p.rotate.is_some() || p.translate.is_some() {
                return Err(params.error(
                    keys.matrix,
                    "give either 'matrix' or scale/rotate/translate, not both",
                ));
            }
            if m.len() != 16 {
                return Err(params.error(
                    keys.matrix,
                    format!("needs 16 numbers (row-major 4x4), got {}", m.len()),
                ));
            }
            let last_row = [m[12], m[13], m[14], m[15]];
            if last_row != [0.0, 0.0, 0.0, 1.0] {
                return Err(params.error(
                    keys.matrix,
                    format!("must be affine: last row [0, 0, 0, 1], got {last_row:?}"),
                ));
            }
            Mat4::from_cols_slice(&m).transpose()
        }
        None => {
            let scale = p.scale.unwrap_or(Vec3::ONE);
            let rotation = match p.rotate {
                None => Quat::IDENTITY,
                Some(r) if r.len() == 4 => {
                    let axis = Vec3::new(r[0], r[1], r[2]);
                    if !(axis.length_squared() > 0.0 && axis.is_finite()) {
                        return Err(params.error(keys.rotate, "the axis must be a non-zero vector"));
                    }
                    Quat::from_axis_angle(axis.normalize(), r[3].to_radians())
                }
                Some(r) => {
                    return Err(params.error(
                        keys.rotate,
                        format!(
                            "needs [axis_x, axis_y, axis_z, degrees], got {} numbers",
                            r.len()
                        ),
                    ))
                }
            };
            let translate = p.translate.unwrap_or(Vec3::ZERO);
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
