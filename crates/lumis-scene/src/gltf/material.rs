//! glTF metallic-roughness materials to lumis BSDF plugins and emission.
//!
//! The mapping is one function, [`bsdf_table`], that writes the TOML table
//! of a BSDF plugin, which the registry then instantiates like any
//! `[[bsdf]]`; a conductor or plastic plugin for metallic and rough
//! materials only has to change that function.

use lumis_core::Rgb;

/// A BSDF plugin table (`type = ...` and its parameters) for `material`,
/// and what the mapping had to leave out.
///
/// Today every material maps to `diffuse` with its base colour factor (a
/// base colour texture multiplies it; the caller wraps the BSDF):
/// lumis has no conductor or rough dielectric yet, so `metallic` and
/// `roughness` are not modelled (said in the warnings when they would
/// matter). `doubleSided` maps to `two_sided`.
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
    // but means "untextured grey"; only declared materials are reported.
    let metallic = pbr.metallic_factor() > 0.0 || pbr.metallic_roughness_texture().is_some();
    if material.index().is_some() && metallic {
        warnings.push(format!(
            "material {label}: metallic {} / roughness {} not modelled (no conductor BSDF yet); rendered as diffuse",
            pbr.metallic_factor(),
            pbr.roughness_factor()
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
