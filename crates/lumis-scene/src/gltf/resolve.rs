//! Which BSDF, emission and texture coordinates each material of an asset
//! gets: the scene's `bsdf` and `bsdf_overrides` first, else the mapping of
//! [`super::material`], with textures decoded here while the asset's
//! buffers are still loaded.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use lumis_core::{Error, PluginEntity, Result};

use super::texture::{Texture, Wrap};
use super::{buffers, material, ImportRequest};
use crate::bsdf_ref::BsdfRef;

/// What a glTF material becomes.
pub(crate) struct ImportedMaterial {
    pub bsdf: MaterialBsdf,
    /// The light its triangles share, if it emits.
    pub emission: Option<AssetEmission>,
    /// The TEXCOORD set its textures read, if it has any.
    pub uv_set: Option<u32>,
}

/// A material's BSDF: the scene's, or the asset's own.
pub(crate) enum MaterialBsdf {
    /// Replaced by a `[[bsdf]]` of the scene.
    Scene(BsdfRef),
    Asset(AssetBsdf),
}

/// The BSDF of a material the scene does not replace.
pub(crate) struct AssetBsdf {
    pub entity: PluginEntity,
    /// `doubleSided`: the BSDF is seen from both sides.
    pub two_sided: bool,
    /// `baseColorTexture`: multiplies the BSDF's albedo.
    pub albedo_texture: Option<Arc<Texture>>,
}

/// The light plugin of an emissive material's triangles.
pub(crate) struct AssetEmission {
    pub entity: PluginEntity,
    /// `emissiveTexture`: scales the radiance, read at the material's uvs.
    pub texture: Option<Arc<Texture>>,
}

/// Every material of an asset, and what mapping them left out.
pub(crate) struct ResolvedMaterials {
    pub materials: HashMap<Option<usize>, ImportedMaterial>,
    pub warnings: Vec<String>,
    pub texture_bytes: usize,
}

/// Maps every material the asset's primitives use (and the default
/// material) to a BSDF, honouring `bsdf` and `bsdf_overrides`.
pub(crate) fn resolve_materials(
    request: &ImportRequest,
    asset: &buffers::Asset,
) -> Result<ResolvedMaterials> {
    let owner = &request.owner;
    let label = &request.label;
    let at = &request.file_location;
    let err = |e: String| Error::at(at, format!("{owner}: '{label}': {e}"));
    let document = &asset.document;
    for (name, bsdf) in &request.overrides {
        if !document
            .materials()
            .any(|m| m.name() == Some(name.as_str()))
        {
            let names: Vec<String> = document
                .materials()
                .filter_map(|m| m.name().map(|n| format!("\"{n}\"")))
                .collect();
            return Err(Error::at(
                &bsdf.location,
                format!(
                    "{owner} bsdf_overrides: '{label}' has no material named \"{name}\"; named materials: {}",
                    if names.is_empty() { "none".into() } else { names.join(", ") }
                ),
            ));
        }
    }
    let mut out = ResolvedMaterials {
        materials: HashMap::new(),
        warnings: Vec::new(),
        texture_bytes: 0,
    };
    let materials = std::iter::once(None).chain(document.materials().map(|m| m.index()));
    for index in materials {
        let material = match index {
            Some(i) => document
                .materials()
                .nth(i)
                .expect("index from the document"),
            None => {
                // The default material, used by primitives without one.
                let Some(m) = document
                    .meshes()
                    .flat_map(|m| m.primitives().collect::<Vec<_>>())
                    .map(|p| p.material())
                    .find(|m| m.index().is_none())
                else {
                    continue;
                };
                m
            }
        };
        let material_label = match (material.name(), index) {
            (Some(n), _) => format!("\"{n}\""),
            (None, Some(i)) => format!("#{i}"),
            (None, None) => "(default)".into(),
        };
        let replacement = match &request.bsdf {
            Some(bsdf) => Some(bsdf.clone()),
            None => request
                .overrides
                .iter()
                .find(|(m, _)| Some(m.as_str()) == material.name())
                .map(|(_, bsdf)| bsdf.clone()),
        };
        let mut uv_set = None;
        let bsdf = match replacement {
            Some(bsdf) => MaterialBsdf::Scene(bsdf),
            None => {
                let (entity, warnings) = material::bsdf_entity(
                    &material,
                    &material_label,
                    format!("{owner} '{label}' material {material_label}"),
                    at,
                )
                .map_err(err)?;
                out.warnings
                    .extend(warnings.into_iter().map(|w| format!("'{label}': {w}")));
                let mut albedo_texture = None;
                if let Some(info) = material.pbr_metallic_roughness().base_color_texture() {
                    match texture_of(asset, &info, &request.path) {
                        Ok((t, set)) => {
                            out.texture_bytes += t.byte_size();
                            albedo_texture = Some(Arc::new(t));
                            uv_set = Some(set);
                        }
                        Err(why) => out.warnings.push(format!(
                            "'{label}': material {material_label}: baseColorTexture ignored ({why}); using baseColorFactor"
                        )),
                    }
                }
                MaterialBsdf::Asset(AssetBsdf {
                    entity,
                    two_sided: material.index().is_some() && material.double_sided(),
                    albedo_texture,
                })
            }
        };
        let radiance = material::emission(&material, &material_label).map_err(err)?;
        let mut emission_texture = None;
        if let (Some(_), Some(info)) = (radiance, material.emissive_texture()) {
            let loaded = match (texture_of(asset, &info, &request.path), uv_set) {
                (Ok((_, set)), Some(base)) if base != set => Err(format!(
                    "it reads TEXCOORD_{set} but the base colour texture TEXCOORD_{base}"
                )),
                (loaded, _) => loaded,
            };
            match loaded {
                Ok((t, set)) => {
                    out.texture_bytes += t.byte_size();
                    emission_texture = Some(Arc::new(t));
                    uv_set = Some(set);
                }
                Err(why) => out.warnings.push(format!(
                    "'{label}': material {material_label}: emissiveTexture ignored ({why}); using emissiveFactor"
                )),
            }
        }
        let emission = radiance.map(|radiance| AssetEmission {
            entity: material::emission_entity(
                radiance,
                material.double_sided(),
                format!("{owner} '{label}' material {material_label} emission"),
                at,
            ),
            texture: emission_texture,
        });
        out.materials.insert(
            index,
            ImportedMaterial {
                bsdf,
                emission,
                uv_set,
            },
        );
    }
    Ok(out)
}

/// A material's texture with its sampler and `KHR_texture_transform`, and
/// the TEXCOORD set it reads (the transform's `texCoord` overrides the
/// texture info's).
fn texture_of(
    asset: &buffers::Asset,
    info: &gltf::texture::Info,
    asset_path: &Path,
) -> std::result::Result<(Texture, u32), String> {
    let t = load_texture(asset, &info.texture(), asset_path)?;
    Ok(match info.texture_transform() {
        Some(x) => (
            t.with_uv_transform(x.offset(), x.rotation(), x.scale()),
            x.tex_coord().unwrap_or(info.tex_coord()),
        ),
        None => (t, info.tex_coord()),
    })
}

/// Decodes a texture's image: PNG or JPEG from a buffer view, a file or a
/// data URI, with the texture's sampler.
fn load_texture(
    asset: &buffers::Asset,
    texture: &gltf::Texture,
    asset_path: &Path,
) -> std::result::Result<Texture, String> {
    let image = texture.source();
    // `Image::source` unwraps the uri when there is no buffer view, and the
    // mimeType when there is one (gltf 1.4): both are checked first.
    let json = &asset.document.as_json().images[image.index()];
    match (&json.uri, &json.buffer_view, &json.mime_type) {
        (None, None, _) => {
            return Err(format!(
                "images[{}] has neither a uri nor a bufferView",
                image.index()
            ))
        }
        (_, Some(_), None) => {
            return Err(format!(
                "images[{}] has a bufferView but no mimeType, which glTF 2.0 requires with one",
                image.index()
            ))
        }
        _ => {}
    }
    let (bytes, mime): (Vec<u8>, Option<&str>) = match image.source() {
        gltf::image::Source::View { view, mime_type } => {
            let data = asset.buffer(view.buffer().index());
            let range = view.offset()..view.offset().saturating_add(view.length());
            let bytes = data.get(range).ok_or_else(|| {
                format!(
                    "image #{} lies past the end of buffer #{} (truncated?)",
                    image.index(),
                    view.buffer().index()
                )
            })?;
            (bytes.to_vec(), Some(mime_type))
        }
        gltf::image::Source::Uri { uri, mime_type } => {
            let dir = asset_path.parent().unwrap_or(Path::new("."));
            (
                buffers::read_uri(uri, dir, buffers::IMAGE_FILE, None)?,
                mime_type,
            )
        }
    };
    const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
    const JPEG_MAGIC: &[u8] = &[0xff, 0xd8, 0xff];
    let decoded = if bytes.starts_with(PNG_MAGIC) {
        Texture::from_png(&bytes)
    } else if bytes.starts_with(JPEG_MAGIC) {
        Texture::from_jpeg(&bytes)
    } else {
        return Err(format!(
            "image #{} is {}, only PNG and JPEG are supported",
            image.index(),
            mime.unwrap_or("neither PNG nor JPEG")
        ));
    };
    let sampler = texture.sampler();
    let wrap = |mode: gltf::texture::WrappingMode| match mode {
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
        gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
    };
    let nearest = sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest);
    decoded
        .map(|t| t.with_sampler([wrap(sampler.wrap_s()), wrap(sampler.wrap_t())], nearest))
        .map_err(|e| format!("image #{}: {e}", image.index()))
}
