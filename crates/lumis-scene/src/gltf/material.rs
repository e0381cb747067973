//! glTF metallic-roughness materials to lumis BSDF plugins and emission.
//!
//! The mapping is one function, [`bsdf_entity`], that describes a BSDF
//! plugin as a [`PluginEntity`], which the assembly then creates like any
//! `[[bsdf]]`.

use lumis_core::doc::{Table, Value};
use lumis_core::{Location, PluginEntity, PluginKind, Rgb};

/// Materials at least this metallic are rendered as metal; glTF's blend
/// of a metal and a dielectric lobe by `metallic` has no lumis BSDF.
const METALLIC_THRESHOLD: f32 = 0.5;

/// The name under which a material's BSDF parameters find its base colour
/// texture (already multiplied by `baseColorFactor`).
pub(crate) const BASE_COLOR: &str = "baseColorTexture";

/// The name under which they find its roughness texture: GGX alpha, the
/// square of `roughnessFactor` times the metallic-roughness texture's
/// green channel.
pub(crate) const ROUGHNESS: &str = "metallicRoughnessTexture";

/// The name under which the `normalmap` adapter finds a material's
/// `normalTexture` (its linear colours).
pub(crate) const NORMAL: &str = "normalTexture";

/// Which of a material's parameters its textures give.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Textured {
    pub base_color: bool,
    pub roughness: bool,
}

/// The glTF dielectric's coat: IOR 1.5 (its specular F0 of 0.04).
const DIELECTRIC_IOR: f32 = 1.5;

/// The BSDF plugin for `material` (its parameters located at `at`, named
/// `owner` in messages), and what the mapping had to leave out. Both kinds have GGX normals of
/// `alpha = roughness^2` (the glTF specification's remapping; below the
/// plugins' 1e-3 floor the lobe is a mirror).
///
/// - Metals (`metallicFactor >= 0.5`): `conductor`, Fresnel 1 scaled by
///   the base colour, the glTF metal's reflectance at normal incidence (its
///   Schlick rise towards white at grazing angles is not modelled).
/// - Dielectrics: `plastic`, a diffuse base of the base colour under a
///   white coat of IOR 1.5, the two layers of glTF's dielectric. The base
///   colour is the base's albedo seen through the coat at normal incidence
///   (plastic's linear mode), where glTF mixes the two by Schlick's Fresnel.
///
/// A `normalTexture` wraps either in the `normalmap` BSDF plugin
/// ([`normal_map_params`]), and `doubleSided` wraps that in `twosided`. Where
/// `textured` says so, the conductor's reflectance or the plastic's base is
/// `{ texture = BASE_COLOR }`, and the roughness `{ texture = ROUGHNESS }`
/// (the textures carry the factors), which the caller creates the BSDF
/// with. What is approximated is said in the warnings.
pub(crate) fn bsdf_entity(
    material: &gltf::Material,
    label: &str,
    owner: String,
    at: &Location,
    textured: Textured,
) -> Result<(PluginEntity, Vec<String>), String> {
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, _alpha] = pbr.base_color_factor();
    let rgb = [r, g, b];
    if !rgb.iter().all(|c| (0.0..=1.0).contains(c)) {
        return Err(format!(
            "material {label}: baseColorFactor {rgb:?} must lie in [0, 1]"
        ));
    }
    let base_color = || -> Value {
        if textured.base_color {
            Value::Table(Table::built(at, [("texture", BASE_COLOR.into())]))
        } else {
            rgb.into()
        }
    };
    let entity = |type_name: &str, params: Vec<(&str, Value)>| {
        let table = Table::built(at, params);
        PluginEntity::new(PluginKind::Bsdf, owner, type_name, table, at.clone())
    };
    let mut warnings = Vec::new();
    // The default material (no index) is metallic 1 and roughness 1 by the
    // spec's defaults, a rough white metal; lumis renders it as the matte
    // grey most exporters mean by "no material", and reports nothing.
    let Some(_) = material.index() else {
        return Ok((
            entity("diffuse", vec![("reflectance", base_color())]),
            warnings,
        ));
    };
    let metallic = pbr.metallic_factor();
    let roughness = pbr.roughness_factor();
    if pbr.metallic_roughness_texture().is_some() {
        warnings.push(format!(
            "material {label}: metallicRoughnessTexture's metallic channel not modelled; metallic {metallic} used everywhere"
        ));
    }
    if metallic > 0.0 && metallic < 1.0 {
        warnings.push(format!(
            "material {label}: metallic {metallic} rendered as {} (no blend of metal and dielectric)",
            if metallic >= METALLIC_THRESHOLD { "metal" } else { "dielectric" }
        ));
    }
    let alpha = || -> Value {
        if textured.roughness {
            Value::Table(Table::built(at, [("texture", ROUGHNESS.into())]))
        } else {
            (roughness * roughness).clamp(0.0, 1.0).into()
        }
    };
    let bsdf = if metallic >= METALLIC_THRESHOLD {
        entity(
            "conductor",
            vec![
                ("distribution", "ggx".into()),
                ("roughness", alpha()),
                ("specular_reflectance", base_color()),
            ],
        )
    } else {
        entity(
            "plastic",
            vec![
                ("diffuse_reflectance", base_color()),
                ("int_ior", DIELECTRIC_IOR.into()),
                ("ext_ior", 1.0f32.into()),
                ("distribution", "ggx".into()),
                ("roughness", alpha()),
            ],
        )
    };
    Ok((bsdf, warnings))
}

/// The parameters of the `normalmap` adapter around a material's BSDF
/// (named `inner`), besides it: the `normalTexture` as [`NORMAL`] and its
/// `scale`.
pub(crate) fn normal_map_params(at: &Location, scale: f32) -> Vec<(&'static str, Value)> {
    vec![
        (
            "normals",
            Value::Table(Table::built(at, [("texture", NORMAL.into())])),
        ),
        ("scale", scale.into()),
    ]
}

/// The name under which its emission finds its `emissiveTexture`,
/// already multiplied by the emitted radiance.
pub(crate) const EMISSIVE: &str = "emissiveTexture";

/// Emitted radiance of `material`: `emissiveFactor` times
/// `KHR_materials_emissive_strength`, or `None` for a black emitter.
/// An `emissiveTexture` scales this per point.
pub(crate) fn emission(material: &gltf::Material, label: &str) -> Result<Option<Rgb>, String> {
    let [r, g, b] = material.emissive_factor();
    let strength = material.emissive_strength().unwrap_or(1.0);
    let radiance = Rgb::new(r, g, b) * strength;
    if !(radiance.min_component() >= 0.0 && radiance.max_component().is_finite()) {
        return Err(format!(
            "material {label}: emission {:?} x strength {strength} must be finite and non-negative",
            [r, g, b]
        ));
    }
    Ok((radiance.max_component() > 0.0).then_some(radiance))
}

/// The light plugin every triangle of an emissive material gets (its
/// parameters located at `at`, named `owner` in messages): `radiance`, or
/// with `textured` the `{ texture = EMISSIVE }` that carries it.
pub(crate) fn emission_entity(
    radiance: Rgb,
    textured: bool,
    two_sided: bool,
    owner: String,
    at: &Location,
) -> PluginEntity {
    let radiance = if textured {
        Value::Table(Table::built(at, [("texture", EMISSIVE.into())]))
    } else {
        [radiance.r, radiance.g, radiance.b].into()
    };
    let params = vec![("radiance", radiance), ("two_sided", two_sided.into())];
    let table = Table::built(at, params);
    PluginEntity::new(PluginKind::Light, owner, "triangle", table, at.clone())
}
