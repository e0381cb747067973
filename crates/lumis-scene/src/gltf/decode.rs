//! glTF mesh primitives to triangle lists, checked before they are read.
//!
//! Every accessor is checked against its buffer view and buffer first, so a
//! truncated buffer or a bad offset is an error naming the asset, the mesh
//! and the primitive, never a panic or a silently shortened mesh.

use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use lumis_core::{Vec2, Vec3};

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
        Some(set) => Some(
            reader
                .read_tex_coords(set)
                .ok_or_else(|| format!("cannot read TEXCOORD_{set}"))?
                .into_f32()
                .map(Vec2::from)
                .collect::<Vec<_>>(),
        ),
        None => None,
    };
    // Capacities are exact, plus the one spare element PaddedBuffer adds,
    // so no vector is reallocated or over-allocated on the way to Embree.
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(position_accessor.count() + 1);
    positions.extend(reader.read_positions().ok_or("cannot read POSITION")?);
    if positions.iter().flatten().any(|c| !c.is_finite()) {
        return Err("POSITION holds a NaN or infinite coordinate".into());
    }
    let n = positions.len();
    let flat: Vec<u32> = match reader.read_indices() {
        Some(indices) => indices.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if !flat.len().is_multiple_of(3) {
        return Err(format!(
            "{} indices is not a whole number of triangles",
            flat.len()
        ));
    }
    if let Some((i, bad)) = flat.iter().enumerate().find(|(_, &v)| v as usize >= n) {
        return Err(format!(
            "index {bad} (element {i}) is out of range for {n} vertices"
        ));
    }
    let indices: Vec<[u32; 3]> = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    drop(flat);
    if indices.is_empty() {
        return Err("has no triangles".into());
    }

    let (normals, pending_normals) = match normal_accessor {
        Some(_) => {
            let mut normals: Vec<Vec3> = Vec::with_capacity(n);
            normals.extend(
                reader
                    .read_normals()
                    .ok_or("cannot read NORMAL")?
                    .map(Vec3::from),
            );
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

/// Checks an accessor's type and that its bytes lie within its buffer
/// view and the view within its buffer.
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
    // lumis indexes vertices with u32; larger counts are also what a
    // corrupt count would look like, refused before anything is allocated.
    if accessor.count() > u32::MAX as usize {
        return Err(format!(
            "{name} has {} elements, more than lumis indexes (2^32 - 1)",
            accessor.count()
        ));
    }
    let Some(view) = accessor.view() else {
        // Sparse-only accessors have no view; the reader fills them in from
        // the sparse values, so their count must be backed by those.
        return match accessor.sparse() {
            Some(sparse) if accessor.count() <= sparse.count() * 64 + (1 << 20) => Ok(()),
            Some(_) => Err(format!(
                "{name} has no buffer view and {} elements for {} sparse values",
                accessor.count(),
                accessor.sparse().map_or(0, |s| s.count())
            )),
            None => Err(format!(
                "{name} has neither a buffer view nor sparse values"
            )),
        };
    };
    let buffer = view.buffer();
    let data_len = asset.buffer(buffer.index()).len();
    let view_end = view.offset() + view.length();
    if view_end > data_len {
        return Err(format!(
            "{name}: buffer view #{} ends at byte {view_end}, past the {data_len} bytes of buffer #{} (truncated buffer?)",
            view.index(),
            buffer.index()
        ));
    }
    if accessor.count() == 0 {
        return Ok(());
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    let end = accessor.offset() + stride * (accessor.count() - 1) + size;
    if end > view.length() {
        return Err(format!(
            "{name}: {} elements need {end} bytes but buffer view #{} has {}",
            accessor.count(),
            view.index(),
            view.length()
        ));
    }
    Ok(())
}
