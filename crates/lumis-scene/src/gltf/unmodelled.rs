//! What an asset uses that lumis does not model yet.

/// What the asset uses that lumis does not model, so a render that looks
/// different from another viewer says why instead of differing silently.
pub(crate) fn unmodelled_features(document: &gltf::Document) -> Vec<String> {
    let mut out = Vec::new();
    let skins = document.nodes().filter(|n| n.skin().is_some()).count();
    if skins > 0 {
        out.push(format!(
            "{skins} skinned nodes rendered in their bind pose (skins are not modelled)"
        ));
    }
    let primitives = || {
        document
            .meshes()
            .flat_map(|m| m.primitives().collect::<Vec<_>>())
    };
    if primitives().any(|p| p.morph_targets().next().is_some()) {
        out.push("morph targets ignored (the base shape is rendered)".into());
    }
    if primitives().any(|p| p.get(&gltf::Semantic::Colors(0)).is_some()) {
        out.push("vertex colours (COLOR_0) ignored".into());
    }
    let see_through = document
        .materials()
        .filter(|m| m.alpha_mode() != gltf::material::AlphaMode::Opaque)
        .count();
    if see_through > 0 {
        out.push(format!(
            "{see_through} materials with alphaMode MASK or BLEND rendered opaque (alpha is not modelled)"
        ));
    }
    let transformed = document
        .extensions_used()
        .any(|e| e == "KHR_texture_transform");
    if transformed && document.materials().any(|m| m.normal_texture().is_some()) {
        out.push(
            "normal textures read without KHR_texture_transform (the glTF reader drops it on them)"
                .into(),
        );
    }
    const MODELLED: &[&str] = &["KHR_materials_emissive_strength", "KHR_texture_transform"];
    for ext in document.extensions_used() {
        if !MODELLED.contains(&ext) {
            out.push(format!("extension {ext} ignored"));
        }
    }
    out
}
