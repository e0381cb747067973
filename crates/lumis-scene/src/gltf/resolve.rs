//! Which BSDF, emission and texture coordinates each material of an asset
//! gets: the TOML's `bsdf` and `bsdf_overrides` first, else the mapping of
//! [`super::material`], with base colour textures decoded here while the
//! asset's buffers are still loaded.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use lumis_core::doc::{self, Node, Table, Value};
use lumis_core::registry::TableRef;
use lumis_core::{Error, Location, Result};

use super::{buffers, material, texture, two_sided, GltfShape};
use crate::Assembly;

/// What a glTF material became: a BSDF of the scene and, if it emits, the
/// light table its triangles share.
#[derive(Clone)]
pub(crate) struct Resolved {
    pub bsdf: u32,
    pub emission: Option<Table>,
    /// An emissive texture scaling the emission, read at the same uv set.
    pub emission_texture: Option<Arc<texture::Texture>>,
    /// The TEXCOORD set the BSDF's texture reads, if it has one.
    pub uv_set: Option<u32>,
}

/// Maps every material the asset's primitives use (and the default
/// material) to a BSDF of the scene, honouring `bsdf` and `bsdf_overrides`.
pub(crate) fn resolve_materials(
    owner: &str,
    shape: &GltfShape,
    asset: &buffers::Asset,
    asm: &mut Assembly,
) -> Result<HashMap<Option<usize>, Resolved>> {
    let at = &shape.file_location;
    let err = |e: String| Error::at(at, format!("{owner}: '{}': {e}", shape.label));
    let document = &asset.document;
    for (name, _, location) in &shape.overrides {
        if !document
            .materials()
            .any(|m| m.name() == Some(name.as_str()))
        {
            let names: Vec<String> = document
                .materials()
                .filter_map(|m| m.name().map(|n| format!("\"{n}\"")))
                .collect();
            return Err(Error::at(
                location,
                format!(
                    "{owner} bsdf_overrides: '{}' has no material named \"{name}\"; named materials: {}",
                    shape.label,
                    if names.is_empty() { "none".into() } else { names.join(", ") }
                ),
            ));
        }
    }
    let named = |name: &str, location: &Location, asm: &Assembly| -> Result<u32> {
        asm.bsdfs
            .iter()
            .position(|(n, _)| n == name)
            .map(|i| i as u32)
            .ok_or_else(|| Error::at(location, format!("{owner}: no [[bsdf]] named \"{name}\"")))
    };
    let mut out = HashMap::new();
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
        let label = match (material.name(), index) {
            (Some(n), _) => format!("\"{n}\""),
            (None, Some(i)) => format!("#{i}"),
            (None, None) => "(default)".into(),
        };
        let override_ = match &shape.bsdf {
            Some((b, l)) => Some((b.clone(), l.clone())),
            None => shape
                .overrides
                .iter()
                .find(|(m, _, _)| Some(m.as_str()) == material.name())
                .map(|(_, b, l)| (b.clone(), l.clone())),
        };
        let mut uv_set = None;
        let bsdf = match override_ {
            Some((name, location)) => named(&name, &location, asm)?,
            None => {
                let (text, warnings) = material::bsdf_table(&material, &label).map_err(err)?;
                asm.report.warnings.extend(
                    warnings
                        .into_iter()
                        .map(|w| format!("'{}': {w}", shape.label)),
                );
                let source = format!("{} material {label}", shape.label);
                let table = doc::parse(&text, &source)?;
                let Some(Node {
                    value: Value::String(kind),
                    ..
                }) = table.get("type")
                else {
                    unreachable!("bsdf_table writes a type")
                };
                let mut bsdf = asm.registry.create_bsdf(&TableRef {
                    owner: &format!("{owner} material {label}"),
                    table: &table,
                    location: at,
                    type_name: kind,
                    type_location: at,
                    structural: &["type"],
                })?;
                if material.index().is_some() && material.double_sided() {
                    bsdf = Arc::new(two_sided::TwoSided { inner: bsdf });
                }
                if let Some(info) = material.pbr_metallic_roughness().base_color_texture() {
                    match texture_of(asset, &info, &shape.path) {
                        Ok((t, set)) => {
                            asm.report.texture_bytes += t.byte_size();
                            bsdf = Arc::new(texture::AlbedoTextured::new(bsdf, Arc::new(t)));
                            uv_set = Some(set);
                        }
                        Err(why) => asm.report.warnings.push(format!(
                            "'{}': material {label}: baseColorTexture ignored ({why}); using baseColorFactor",
                            shape.label
                        )),
                    }
                }
                asm.bsdfs.push((format!("{}#{label}", shape.label), bsdf));
                asm.bsdfs.len() as u32 - 1
            }
        };
        let emission = material::emission(&material, &label).map_err(err)?;
        let mut emission_texture = None;
        if let (Some(_), Some(info)) = (emission, material.emissive_texture()) {
            let loaded = match (texture_of(asset, &info, &shape.path), uv_set) {
                (Ok((_, set)), Some(base)) if base != set => Err(format!(
                    "it reads TEXCOORD_{set} but the base colour texture TEXCOORD_{base}"
                )),
                (loaded, _) => loaded,
            };
            match loaded {
                Ok((t, set)) => {
                    asm.report.texture_bytes += t.byte_size();
                    emission_texture = Some(Arc::new(t));
                    uv_set = Some(set);
                }
                Err(why) => asm.report.warnings.push(format!(
                    "'{}': material {label}: emissiveTexture ignored ({why}); using emissiveFactor",
                    shape.label
                )),
            }
        }
        let emission = match emission {
            Some(radiance) => Some(doc::parse(
                &material::emission_table(radiance, material.double_sided()),
                &format!("{} material {label} emission", shape.label),
            )?),
            None => None,
        };
        out.insert(
            index,
            Resolved {
                bsdf,
                emission,
                emission_texture,
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
) -> std::result::Result<(texture::Texture, u32), String> {
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
) -> std::result::Result<texture::Texture, String> {
    let image = texture.source();
    let (bytes, mime): (Vec<u8>, Option<&str>) = match image.source() {
        gltf::image::Source::View { view, mime_type } => {
            let data = asset.buffer(view.buffer().index());
            let end = view.offset() + view.length();
            let bytes = data.get(view.offset()..end).ok_or_else(|| {
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
            (buffers::read_uri(uri, dir)?, mime_type)
        }
    };
    const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
    const JPEG_MAGIC: &[u8] = &[0xff, 0xd8, 0xff];
    let decoded = if bytes.starts_with(PNG_MAGIC) {
        texture::Texture::from_png(&bytes)
    } else if bytes.starts_with(JPEG_MAGIC) {
        texture::Texture::from_jpeg(&bytes)
    } else {
        return Err(format!(
            "image #{} is {}, only PNG and JPEG are supported",
            image.index(),
            mime.unwrap_or("neither PNG nor JPEG")
        ));
    };
    let sampler = texture.sampler();
    let wrap = |mode: gltf::texture::WrappingMode| match mode {
        gltf::texture::WrappingMode::Repeat => texture::Wrap::Repeat,
        gltf::texture::WrappingMode::MirroredRepeat => texture::Wrap::Mirror,
        gltf::texture::WrappingMode::ClampToEdge => texture::Wrap::Clamp,
    };
    let nearest = sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest);
    decoded
        .map(|t| t.with_sampler([wrap(sampler.wrap_s()), wrap(sampler.wrap_t())], nearest))
        .map_err(|e| format!("image #{}: {e}", image.index()))
}
