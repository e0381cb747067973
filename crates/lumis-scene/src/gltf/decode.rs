//! glTF mesh primitives to triangle lists, checked before they are read.
//!
//! Every accessor is checked against its buffer view and buffer first, so a
//! truncated buffer or a bad offset is an error naming the asset, the mesh
//! and the primitive, never a panic or a silently shortened mesh.

use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use lumis_core::{Vec2, Vec3};
use rayon::prelude::*;

use super::buffers::Asset;
use super::normals;

/// One primitive, decoded: what a lumis mesh needs.
pub(crate) struct Part {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    /// `None`: flat shading (no normals in the file and none generated).
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates, read only when the material has a texture.
    pub uvs: Option<Vec<Vec2>>,
    /// `None`: the glTF default material.
    pub material: Option<usize>,
    /// Set when normals are missing and must be generated with this crease
    /// threshold: [`Part::generate_normals`] does it once the asset's
    /// buffers are freed, to lower peak memory.
    pub pending_normals: Option<f32>,
}

impl Part {
    /// Generates the normals this part is waiting for, if any.
    pub fn generate_normals(&mut self) {
        let Some(cos_crease) = self.pending_normals.take() else {
            return;
        };
        let positions = std::mem::take(&mut self.positions);
        let indices = std::mem::take(&mut self.indices);
        let g = normals::generate(positions, indices, self.uvs.take(), cos_crease);
        self.positions = g.positions;
        self.indices = g.indices;
        self.normals = Some(g.normals);
        self.uvs = g.uvs;
    }
}

/// How to obtain shading normals a file does not have.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum MissingNormals {
    /// Flat shading: nothing stored, nothing interpolated.
    Flat,
    /// Generated with this crease threshold (cosine of the crease angle).
    Generate { cos_crease: f32 },
}

/// `mesh "name" (#3)` or `mesh #3`, the way errors name a mesh.
pub(crate) fn mesh_label(mesh: &gltf::Mesh) -> String {
    match mesh.name() {
        Some(name) => format!("mesh \"{name}\" (#{})", mesh.index()),
        None => format!("mesh #{}", mesh.index()),
    }
}

/// Decodes every primitive of `mesh`; `uv_set` says which TEXCOORD set a
/// material's textures read (`None`: no texture, no uvs stored).
pub(crate) fn mesh(
    asset: &Asset,
    mesh: &gltf::Mesh,
    missing_normals: MissingNormals,
    uv_set: &(dyn Fn(Option<usize>) -> Option<u32> + Sync),
) -> Result<Vec<Part>, String> {
    mesh.primitives()
        .map(|p| {
            primitive(asset, &p, missing_normals, uv_set(p.material().index())).map_err(|e| {
                format!(
                    "'{}': {} primitive #{}: {e}",
                    asset.label,
                    mesh_label(mesh),
                    p.index()
                )
            })
        })
        .collect()
}

fn primitive(
    asset: &Asset,
    primitive: &gltf::Primitive,
    missing_normals: MissingNormals,
    uv_set: Option<u32>,
) -> Result<Part, String> {
    if primitive.mode() != Mode::Triangles {
        return Err(format!(
            "mode {:?} is not supported; only TRIANGLES (mode 4) is",
            primitive.mode()
        ));
    }
    let position_accessor = primitive
        .get(&Semantic::Positions)
        .ok_or("has no POSITION attribute")?;
    check_accessor(
        asset,
        &position_accessor,
        "POSITION",
        &[DataType::F32],
        Dimensions::Vec3,
    )?;
    let normal_accessor = primitive.get(&Semantic::Normals);
    if let Some(a) = &normal_accessor {
        check_accessor(asset, a, "NORMAL", &[DataType::F32], Dimensions::Vec3)?;
        if a.count() != position_accessor.count() {
            return Err(format!(
                "NORMAL has {} entries for {} positions",
                a.count(),
                position_accessor.count()
            ));
        }
    }
    if let Some(a) = primitive.indices() {
        check_accessor(
            asset,
            &a,
            "indices",
            &[DataType::U8, DataType::U16, DataType::U32],
            Dimensions::Scalar,
        )?;
    }

    if let Some(set) = uv_set {
        let a = primitive.get(&Semantic::TexCoords(set)).ok_or_else(|| {
            format!("its material has a texture but the primitive has no TEXCOORD_{set}")
        })?;
        check_accessor(
            asset,
            &a,
            &format!("TEXCOORD_{set}"),
            &[DataType::F32, DataType::U8, DataType::U16],
            Dimensions::Vec2,
        )?;
        if a.count() != position_accessor.count() {
            return Err(format!(
                "TEXCOORD_{set} has {} entries for {} positions",
                a.count(),
                position_accessor.count()
            ));
        }
    }
    let reader = primitive.reader(|b| Some(asset.buffer(b.index())));
    let uvs = match uv_set {
        Some(set) => {
            let accessor = primitive
                .get(&Semantic::TexCoords(set))
                .ok_or_else(|| format!("cannot read TEXCOORD_{set}"))?;
            match dense_f32(asset, &accessor, 0, Vec2::from) {
                Some(uvs) => Some(uvs),
                None => Some(
                    reader
                        .read_tex_coords(set)
                        .ok_or_else(|| format!("cannot read TEXCOORD_{set}"))?
                        .into_f32()
                        .map(Vec2::from)
                        .collect::<Vec<_>>(),
                ),
            }
        }
        None => None,
    };
    // Capacities are exact, plus the one spare element PaddedBuffer adds,
    // so no vector is reallocated or over-allocated on the way to Embree.
    let positions: Vec<[f32; 3]> = match dense_f32(asset, &position_accessor, 1, |p: [f32; 3]| p) {
        Some(p) => p,
        None => {
            let mut p = Vec::with_capacity(position_accessor.count() + 1);
            p.extend(reader.read_positions().ok_or("cannot read POSITION")?);
            p
        }
    };
    if positions.par_iter().flatten().any(|c| !c.is_finite()) {
        return Err("POSITION holds a NaN or infinite coordinate".into());
    }
    let n = positions.len();
    let indices: Vec<[u32; 3]> = match primitive.indices() {
        Some(accessor) => {
            if !accessor.count().is_multiple_of(3) {
                return Err(format!(
                    "{} indices is not a whole number of triangles",
                    accessor.count()
                ));
            }
            match dense_triangles(asset, &accessor) {
                Some(t) => t,
                None => {
                    let flat: Vec<u32> = reader
                        .read_indices()
                        .ok_or("cannot read indices")?
                        .into_u32()
                        .collect();
                    let mut t = Vec::with_capacity(flat.len() / 3 + 1);
                    t.extend(flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
                    t
                }
            }
        }
        None => {
            if !n.is_multiple_of(3) {
                return Err(format!(
                    "{n} vertices without indices is not a whole number of triangles"
                ));
            }
            let mut t = Vec::with_capacity(n / 3 + 1);
            (0..(n / 3) as u32)
                .into_par_iter()
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect_into_vec(&mut t);
            t
        }
    };
    if let Some((i, t)) = indices
        .par_iter()
        .enumerate()
        .find_first(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        let (k, bad) = t
            .iter()
            .enumerate()
            .find(|(_, &v)| v as usize >= n)
            .expect("found above");
        return Err(format!(
            "index {bad} (element {}) is out of range for {n} vertices",
            3 * i + k
        ));
    }
    if indices.is_empty() {
        return Err("has no triangles".into());
    }

    let (normals, pending_normals) = match normal_accessor {
        Some(_) => {
            let normals: Vec<Vec3> = match normal_accessor
                .as_ref()
                .and_then(|a| dense_f32(asset, a, 0, Vec3::from))
            {
                Some(ns) => ns,
                None => {
                    let mut ns = Vec::with_capacity(n);
                    ns.extend(
                        reader
                            .read_normals()
                            .ok_or("cannot read NORMAL")?
                            .map(Vec3::from),
                    );
                    ns
                }
            };
            (Some(normals), None)
        }
        None => match missing_normals {
            MissingNormals::Flat => (None, None),
            MissingNormals::Generate { cos_crease } => (None, Some(cos_crease)),
        },
    };
    Ok(Part {
        positions,
        indices,
        normals,
        uvs,
        material: primitive.material().index(),
        pending_normals,
    })
}

/// The common case decoded in parallel: a dense (not sparse) accessor of
/// little-endian f32 vectors, checked by [`check_accessor`] first. `None`
/// for anything else, which the gltf crate's reader decodes. `spare` is
/// extra capacity (PaddedBuffer's padding element).
fn dense_f32<const N: usize, T: Send>(
    asset: &Asset,
    accessor: &gltf::Accessor,
    spare: usize,
    convert: impl Fn([f32; N]) -> T + Sync,
) -> Option<Vec<T>> {
    if accessor.sparse().is_some() || accessor.data_type() != DataType::F32 {
        return None;
    }
    let view = accessor.view()?;
    let data = asset.buffer(view.buffer().index());
    let stride = view.stride().unwrap_or(4 * N);
    let base = view.offset() + accessor.offset();
    let mut out = Vec::with_capacity(accessor.count() + spare);
    (0..accessor.count())
        .into_par_iter()
        .map(|i| {
            let o = base + i * stride;
            convert(std::array::from_fn(|k| {
                let b = &data[o + 4 * k..o + 4 * k + 4];
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            }))
        })
        .collect_into_vec(&mut out);
    Some(out)
}

/// Dense u8/u16/u32 indices as triangles, decoded in parallel (`None`
/// for sparse ones); the count is a multiple of 3 and the bytes were
/// checked by [`check_accessor`].
fn dense_triangles(asset: &Asset, accessor: &gltf::Accessor) -> Option<Vec<[u32; 3]>> {
    if accessor.sparse().is_some() {
        return None;
    }
    let view = accessor.view()?;
    let data = asset.buffer(view.buffer().index());
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    let base = view.offset() + accessor.offset();
    let read: fn(&[u8], usize) -> u32 = match accessor.data_type() {
        DataType::U8 => |d, o| d[o] as u32,
        DataType::U16 => |d, o| u16::from_le_bytes([d[o], d[o + 1]]) as u32,
        DataType::U32 => |d, o| u32::from_le_bytes([d[o], d[o + 1], d[o + 2], d[o + 3]]),
        _ => return None,
    };
    let mut out = Vec::with_capacity(accessor.count() / 3 + 1);
    (0..accessor.count() / 3)
        .into_par_iter()
        .map(|t| std::array::from_fn(|k| read(data, base + (3 * t + k) * stride)))
        .collect_into_vec(&mut out);
    Some(out)
}

/// Checks an accessor's type and that its bytes, and its sparse indices
/// and values, lie within their buffer views and the views within their
/// buffers, so the `gltf` crate's reader only ever slices in bounds.
fn check_accessor(
    asset: &Asset,
    accessor: &gltf::Accessor,
    what: &str,
    types: &[DataType],
    dimensions: Dimensions,
) -> Result<(), String> {
    let name = format!("{what} (accessor #{})", accessor.index());
    if !types.contains(&accessor.data_type()) || accessor.dimensions() != dimensions {
        return Err(format!(
            "{name} is {:?} {:?}; expected {dimensions:?} of {types:?}",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    // glTF 2.0 requires count >= 1. lumis indexes vertices with u32;
    // larger counts are also what a corrupt count would look like,
    // refused before anything is allocated.
    if accessor.count() == 0 || accessor.count() > u32::MAX as usize {
        return Err(format!(
            "{name} has {} elements; lumis reads 1 to 2^32 - 1",
            accessor.count()
        ));
    }
    let size = accessor.size();
    if let Some(view) = accessor.view() {
        let span = Span {
            offset: accessor.offset(),
            count: accessor.count(),
            size,
        };
        check_span(asset, &view, span, &name)?;
    }
    match accessor.sparse() {
        Some(sparse) => {
            // Without a view the reader makes `count` zeros for the sparse
            // values to land on: bounded by what the values could mean.
            if accessor.view().is_none()
                && accessor.count() > sparse.count().saturating_mul(64) + (1 << 20)
            {
                return Err(format!(
                    "{name} has no buffer view and {} elements for {} sparse values",
                    accessor.count(),
                    sparse.count()
                ));
            }
            if sparse.count() == 0 || sparse.count() > accessor.count() {
                return Err(format!(
                    "{name} has {} sparse values for {} elements",
                    sparse.count(),
                    accessor.count()
                ));
            }
            let indices = sparse.indices();
            let span = Span {
                offset: indices.offset(),
                count: sparse.count(),
                size: indices.index_type().size(),
            };
            check_span(
                asset,
                &indices.view(),
                span,
                &format!("{name}'s sparse indices"),
            )?;
            let values = sparse.values();
            let span = Span {
                offset: values.offset(),
                count: sparse.count(),
                size,
            };
            check_span(
                asset,
                &values.view(),
                span,
                &format!("{name}'s sparse values"),
            )
        }
        None if accessor.view().is_none() => Err(format!(
            "{name} has neither a buffer view nor sparse values"
        )),
        None => Ok(()),
    }
}

/// `count` elements of `size` bytes from `offset` in a buffer view.
struct Span {
    offset: usize,
    count: usize,
    size: usize,
}

/// Checks that `span` lies within `view` and `view` within its buffer.
/// Offsets and lengths come from the file: a sum past `usize::MAX` is as
/// out of bounds as any other.
fn check_span(
    asset: &Asset,
    view: &gltf::buffer::View,
    span: Span,
    name: &str,
) -> Result<(), String> {
    let buffer = view.buffer();
    let data_len = asset.buffer(buffer.index()).len();
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|end| end > data_len) {
        let view_end = view_end.map_or("beyond 2^64".to_string(), |e| e.to_string());
        return Err(format!(
            "{name}: buffer view #{} ends at byte {view_end}, past the {data_len} bytes of buffer #{} (truncated buffer?)",
            view.index(),
            buffer.index()
        ));
    }
    let stride = view.stride().unwrap_or(span.size);
    if stride < span.size {
        return Err(format!(
            "{name}: buffer view #{} has a byteStride of {stride}, less than the {}-byte elements",
            view.index(),
            span.size
        ));
    }
    let end = stride
        .checked_mul(span.count - 1)
        .and_then(|e| e.checked_add(span.size))
        .and_then(|e| e.checked_add(span.offset));
    if end.is_none_or(|end| end > view.length()) {
        let end = end.map_or("more than 2^64".to_string(), |e| e.to_string());
        return Err(format!(
            "{name}: {} elements need {end} bytes but buffer view #{} has {}",
            span.count,
            view.index(),
            view.length()
        ));
    }
    Ok(())
}
