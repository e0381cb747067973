//! Which BSDF, emission and texture coordinates each material of an asset
//! gets: the scene's `bsdf` and `bsdf_overrides` first, else the mapping of
//! [`super::material`], with textures decoded here while the asset's
//! buffers are still loaded.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use lumis_core::doc::{Table, Value};
use lumis_core::{
    Error, ImageValues, Location, PluginEntity, PluginKind, Registry, Result, Rgb, Texture,
    Textures, UvTransform,
};
use lumis_files::IMAGE_FILE;
use lumis_image::texture_decode;

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
    /// What the entity's textured parameters name: the `baseColorTexture`
    /// (times `baseColorFactor`) as [`material::BASE_COLOR`], the
    /// roughness as [`material::ROUGHNESS`] and the `normalTexture` as
    /// [`material::NORMAL`].
    pub textures: Textures,
    /// The `normalTexture`'s `scale`, where the BSDF is normal-mapped.
    pub normal_scale: Option<f32>,
}

/// The light plugin of an emissive material's triangles.
pub(crate) struct AssetEmission {
    pub entity: PluginEntity,
    /// What its radiance names: the `emissiveTexture` (times the
    /// emission) as [`material::EMISSIVE`].
    pub textures: Textures,
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
    registry: &Registry,
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
        let mut loader = TextureLoader {
            asset,
            asset_path: &request.path,
            registry,
            at,
            material: format!("'{label}': material {material_label}"),
            uv_set: None,
            resolved: &mut out,
        };
        let bsdf = match replacement {
            Some(bsdf) => MaterialBsdf::Scene(bsdf),
            None => {
                let pbr = material.pbr_metallic_roughness();
                let mut textures = Textures::new();
                let [r, g, b, _] = pbr.base_color_factor();
                let base_color = loader.load(
                    pbr.base_color_texture().map(Slot::of),
                    TextureUse::Colour(Rgb::new(r, g, b)),
                    (material::BASE_COLOR, "baseColorFactor"),
                    &mut textures,
                );
                let roughness = loader.load(
                    pbr.metallic_roughness_texture().map(Slot::of),
                    TextureUse::Roughness(pbr.roughness_factor()),
                    (material::ROUGHNESS, "roughnessFactor"),
                    &mut textures,
                );
                let normal_texture = material.normal_texture();
                let normal_scale = normal_texture.as_ref().map(|n| n.scale());
                let normal_mapped = loader.load(
                    normal_texture.map(Slot::normal),
                    TextureUse::Normal,
                    (material::NORMAL, "the surface's normals"),
                    &mut textures,
                );
                let (entity, warnings) = material::bsdf_entity(
                    &material,
                    &material_label,
                    format!("{owner} '{label}' material {material_label}"),
                    at,
                    material::Textured {
                        base_color,
                        roughness,
                    },
                )
                .map_err(err)?;
                loader
                    .resolved
                    .warnings
                    .extend(warnings.into_iter().map(|w| format!("'{label}': {w}")));
                MaterialBsdf::Asset(AssetBsdf {
                    entity,
                    two_sided: material.index().is_some() && material.double_sided(),
                    textures,
                    normal_scale: normal_scale.filter(|_| normal_mapped),
                })
            }
        };
        let radiance = material::emission(&material, &material_label).map_err(err)?;
        let mut emission_textures = Textures::new();
        if let Some(radiance) = radiance {
            loader.load(
                material.emissive_texture().map(Slot::of),
                TextureUse::Colour(radiance),
                (material::EMISSIVE, "emissiveFactor"),
                &mut emission_textures,
            );
        }
        let uv_set = loader.uv_set;
        let emission = radiance.map(|radiance| AssetEmission {
            entity: material::emission_entity(
                radiance,
                !emission_textures.is_empty(),
                material.double_sided(),
                format!("{owner} '{label}' material {material_label} emission"),
                at,
            ),
            textures: emission_textures,
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

/// A material's reference to a texture: which, read at which TEXCOORD
/// set, through which uv transform.
struct Slot<'a> {
    texture: gltf::Texture<'a>,
    tex_coord: u32,
    transform: UvTransform,
}

impl<'a> Slot<'a> {
    /// A `textureInfo`, with its `KHR_texture_transform` (whose `texCoord`
    /// overrides the info's).
    fn of(info: gltf::texture::Info<'a>) -> Self {
        let (transform, tex_coord) = match info.texture_transform() {
            Some(x) => (
                khr_texture_transform(x.offset(), x.rotation(), x.scale()),
                x.tex_coord().unwrap_or(info.tex_coord()),
            ),
            None => (UvTransform::default(), info.tex_coord()),
        };
        Self {
            texture: info.texture(),
            tex_coord,
            transform,
        }
    }

    /// A `normalTextureInfo`. The gltf crate drops a
    /// `KHR_texture_transform` on it, so its uvs are untransformed (the
    /// import warns where the asset uses the extension).
    fn normal(info: gltf::material::NormalTexture<'a>) -> Self {
        Self {
            texture: info.texture(),
            tex_coord: info.tex_coord(),
            transform: UvTransform::default(),
        }
    }
}

/// Loads a material's textures, all of which must read one TEXCOORD set.
struct TextureLoader<'a> {
    asset: &'a buffers::Asset,
    asset_path: &'a Path,
    /// Makes the `image` textures, as it makes a scene's.
    registry: &'a Registry,
    /// Where the scene names the asset: the textures' location.
    at: &'a Location,
    /// The material, for warnings: `'file': material "name"`.
    material: String,
    /// The set the textures loaded so far read.
    uv_set: Option<u32>,
    resolved: &'a mut ResolvedMaterials,
}

impl TextureLoader<'_> {
    /// Loads the texture `info` refers to, as `usage` reads it, into `into`
    /// under `name`; whether it did. A texture that cannot be used is left
    /// out with a warning, and the material keeps its `factor`.
    fn load(
        &mut self,
        slot: Option<Slot>,
        usage: TextureUse,
        (name, factor): (&'static str, &str),
        into: &mut Textures,
    ) -> bool {
        let Some(slot) = slot else {
            return false;
        };
        let loaded = match (
            texture_of(self.asset, &slot, self.asset_path, usage, self.at),
            self.uv_set,
        ) {
            (Ok((_, set)), Some(other)) if other != set => Err(format!(
                "it reads TEXCOORD_{set}, the material's other textures TEXCOORD_{other}"
            )),
            (Ok((table, set)), _) => {
                let owner = format!("{} {name} texture", self.material);
                let entity =
                    PluginEntity::new(PluginKind::Texture, owner, "image", table, self.at.clone());
                self.registry
                    .create::<dyn Texture>(&entity, ())
                    .map(|texture| (texture, set))
                    .map_err(|e| e.to_string())
            }
            (Err(why), _) => Err(why),
        };
        match loaded {
            Ok((texture, set)) => {
                self.resolved.texture_bytes += texture.memory_bytes();
                into.insert(name, texture);
                self.uv_set = Some(set);
                true
            }
            Err(why) => {
                self.resolved.warnings.push(format!(
                    "{}: {name} ignored ({why}); using {factor}",
                    self.material
                ));
                false
            }
        }
    }
}

/// What a material reads a texture as.
#[derive(Debug, Clone, Copy)]
enum TextureUse {
    /// An sRGB colour (base colour, emission) times a factor (the
    /// specification, 3.9.6).
    Colour(Rgb),
    /// The green channel of a linear metallic-roughness texture times
    /// `roughnessFactor`: the perceptual roughness, stored squared as
    /// the GGX alpha that [`material::bsdf_entity`]'s lobes take (alpha is
    /// then what the mip map averages).
    Roughness(f32),
    /// A linear tangent-space normal map, its colours as stored (the
    /// `normalmap` BSDF decodes and scales them).
    Normal,
}

/// The parameter table (located `at`) of the `image` texture that reads a
/// material's texture as `usage` says, with its sampler and uv transform
/// (the texels decoded here, while the asset's buffers are loaded); and
/// the TEXCOORD set it reads.
fn texture_of(
    asset: &buffers::Asset,
    slot: &Slot,
    asset_path: &Path,
    usage: TextureUse,
    at: &Location,
) -> std::result::Result<(Table, u32), String> {
    let (texture, transform, set) = (&slot.texture, slot.transform, slot.tex_coord);
    let image = texture.source();
    let bytes = image_bytes(asset, &image, asset_path)?;
    let mut texels = texture_decode::decode(&bytes).map_err(|e| {
        let mime = match image.source() {
            gltf::image::Source::View { mime_type, .. } => Some(mime_type),
            gltf::image::Source::Uri { mime_type, .. } => mime_type,
        };
        format!(
            "image #{}{}: {e}",
            image.index(),
            mime.map_or(String::new(), |m| format!(" ({m})"))
        )
    })?;
    let sampler = texture.sampler();
    let wrap = |mode: gltf::texture::WrappingMode| match mode {
        gltf::texture::WrappingMode::Repeat => "repeat",
        gltf::texture::WrappingMode::MirroredRepeat => "mirror",
        gltf::texture::WrappingMode::ClampToEdge => "clamp",
    };
    // Mip-mapped minification, as the sampler asks or by default (the
    // specification leaves an absent filter to the renderer), is the
    // trilinear lookup over the pixel footprint.
    let filter = {
        use gltf::texture::{MagFilter, MinFilter};
        match (sampler.min_filter(), sampler.mag_filter()) {
            (Some(MinFilter::Nearest), _) | (None, Some(MagFilter::Nearest)) => "nearest",
            (Some(MinFilter::Linear), _) => "bilinear",
            _ => "trilinear",
        }
    };
    let (encoding, scale) = match usage {
        TextureUse::Colour(factor) => ("srgb", factor),
        TextureUse::Roughness(factor) => {
            let alpha = |v: Rgb| Rgb::splat((factor * v.g).clamp(0.0, 1.0).powi(2));
            texels.values = ImageValues::Floats {
                values: texels.floats().into_iter().map(alpha).collect(),
                is_float: false,
            };
            ("linear", Rgb::WHITE)
        }
        TextureUse::Normal => ("linear", Rgb::WHITE),
    };
    let params = [
        ("texels", Value::Image(Arc::new(texels))),
        ("encoding", encoding.into()),
        ("wrap", wrap(sampler.wrap_s()).into()),
        ("wrap_v", wrap(sampler.wrap_t()).into()),
        ("filter", filter.into()),
        ("scale", scale.to_array().into()),
        ("uv_scale", transform.uv_scale.to_array().into()),
        ("uv_rotation", transform.uv_rotation.into()),
        ("uv_offset", transform.uv_offset.to_array().into()),
    ];
    Ok((Table::built(at, params), set))
}

/// `KHR_texture_transform` as the texture plugins' uv transform: scale,
/// then rotate, then offset. The extension rotates by `rotation` radians
/// counter-clockwise in its prose and examples (an offset of [0, 1],
/// rotation pi/2 and scale 0.5 selects the image's lower left quadrant);
/// in uv with v down that is a clockwise turn of the coordinates, so the
/// plugins' counter-clockwise `uv_rotation` is its negative. (The
/// extension's GLSL snippet has the sign flipped against its prose.)
fn khr_texture_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> UvTransform {
    UvTransform {
        uv_scale: scale.into(),
        uv_rotation: -rotation.to_degrees(),
        uv_offset: offset.into(),
    }
}

/// The encoded bytes of an image: from a buffer view, a file or a data URI.
fn image_bytes(
    asset: &buffers::Asset,
    image: &gltf::Image,
    asset_path: &Path,
) -> std::result::Result<Vec<u8>, String> {
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
    Ok(match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = asset.buffer(view.buffer().index());
            let end = view.offset().saturating_add(view.length());
            data.get(view.offset()..end)
                .ok_or_else(|| {
                    format!(
                        "image #{} lies past the end of buffer #{} (truncated?)",
                        image.index(),
                        view.buffer().index()
                    )
                })?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => {
            let dir = asset_path.parent().unwrap_or(Path::new("."));
            buffers::read_uri(uri, dir, IMAGE_FILE, None)?
        }
    })
}

#[cfg(test)]
mod tests {
    use lumis_core::{TextureQuery, Vec2};

    use super::*;

    #[test]
    fn texture_transform_follows_the_extension_examples() {
        // "utilizes only the lower left quadrant of the source image,
        // rotated clockwise 90 degrees".
        let t = khr_texture_transform([0.0, 1.0], std::f32::consts::FRAC_PI_2, [0.5, 0.5]);
        for (uv, expected) in [
            ((0.0, 0.0), (0.0, 1.0)),
            ((1.0, 0.0), (0.0, 0.5)),
            ((0.0, 1.0), (0.5, 1.0)),
            ((1.0, 1.0), (0.5, 0.5)),
        ] {
            let got = t.apply(&TextureQuery::at(Vec2::new(uv.0, uv.1))).uv;
            assert!(
                (got - Vec2::new(expected.0, expected.1)).length() < 1e-6,
                "{uv:?} -> {got}"
            );
        }
        // "inverts the T axis": offset [0, 1], scale [1, -1].
        let flip = khr_texture_transform([0.0, 1.0], 0.0, [1.0, -1.0]);
        let got = flip.apply(&TextureQuery::at(Vec2::new(0.25, 0.25))).uv;
        assert_eq!(got, Vec2::new(0.25, 0.75));
    }
}
