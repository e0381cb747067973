//! glTF metallic-roughness materials to lumis BSDF plugins and emission.
//!
//! The mapping is one function, [`bsdf_table`], that writes the TOML table
//! of a BSDF plugin, which the registry then instantiates like any
//! `[[bsdf]]`.

use lumis_core::Rgb;

/// Materials at least this metallic are rendered as metal; glTF's blend
/// of a metal and a dielectric lobe by `metallic` has no lumis BSDF.
const METALLIC_THRESHOLD: f32 = 0.5;

/// A BSDF plugin table (`type = ...` and its parameters) for `material`,
/// and what the mapping had to leave out.
///
/// - Metals (`metallicFactor >= 0.5`): `conductor` with GGX normals of
///   `alpha = roughness^2` (the glTF specification's remapping), Fresnel 1
///   scaled by the base colour, the glTF metal's reflectance at normal
///   incidence (its Schlick rise towards white at grazing angles is not
///   modelled). One-sided.
/// - Dielectrics: `diffuse` with the base colour; the specular coat of
///   glTF's dielectric (IOR 1.5, `roughness`) is left out, since most
///   assets' dielectrics are meant matte, and `doubleSided` maps to
///   `two_sided`.
///
/// A base colour texture multiplies either (the caller wraps the BSDF).
/// What is approximated is said in the warnings.
pub(crate) fn bsdf_table(
    material: &gltf::Material,
    label: &str,
) -> Result<(String, Vec<String>), String> {
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, _alpha] = pbr.base_color_factor();
    if ![r, g, b].iter().all(|c| (0.0..=1.0).contains(c)) {
        return Err(format!(
            "material {label}: baseColorFactor {:?} must lie in [0, 1]",
            [r, g, b]
        ));
    }
    let mut warnings = Vec::new();
    // The default material (no index) is metallic 1 by the spec's defaults
    // but means "untextured grey": it stays diffuse, and only declared
    // materials are reported.
    let declared = material.index().is_some();
    let metallic = pbr.metallic_factor();
    let roughness = pbr.roughness_factor();
    if declared && pbr.metallic_roughness_texture().is_some() {
        warnings.push(format!(
            "material {label}: metallicRoughnessTexture not modelled; metallic {metallic} and roughness {roughness} used everywhere"
        ));
    }
    if declared && metallic > 0.0 && metallic < 1.0 {
        warnings.push(format!(
            "material {label}: metallic {metallic} rendered as {} (no blend of metal and dielectric)",
            if metallic >= METALLIC_THRESHOLD { "metal" } else { "dielectric" }
        ));
    }
    if declared && metallic >= METALLIC_THRESHOLD {
        if material.double_sided() {
            warnings.push(format!(
                "material {label}: doubleSided metal rendered one-sided (the conductor is black from behind)"
            ));
        }
        let alpha = (roughness * roughness).clamp(0.0, 1.0);
        let table = format!(
            "type = \"conductor\"\ndistribution = \"ggx\"\nroughness = {alpha:?}\nspecular_reflectance = [{r:?}, {g:?}, {b:?}]\n"
        );
        return Ok((table, warnings));
    }
    if declared && roughness < 1.0 {
        warnings.push(format!(
            "material {label}: dielectric with roughness {roughness} rendered as diffuse (its specular coat is not modelled)"
        ));
    }
    let table = format!(
        "type = \"diffuse\"\nreflectance = [{r:?}, {g:?}, {b:?}]\ntwo_sided = {}\n",
        material.double_sided()
    );
    Ok((table, warnings))
}

/// Emitted radiance of `material`: `emissiveFactor` times
/// `KHR_materials_emissive_strength`, or `None` for a black emitter.
/// An `emissiveTexture` scales this per point (the caller wraps the lights).
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

/// The light plugin table of an emissive material's triangles.
pub(crate) fn emission_table(radiance: Rgb, two_sided: bool) -> String {
    format!(
        "radiance = [{:?}, {:?}, {:?}]\ntwo_sided = {two_sided}\n",
        radiance.r, radiance.g, radiance.b
    )
}
