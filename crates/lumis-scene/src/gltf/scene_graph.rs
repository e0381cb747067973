//! Walking a glTF scene's node hierarchy to world transforms.

use lumis_core::glam::Mat4;

/// Visits every node of the asset's scene (the default one, else the
/// first) with its world transform `base * parent ... * node`.
fn walk(
    document: &gltf::Document,
    base: Mat4,
    mut visit: impl FnMut(&gltf::Node, Mat4),
) -> Result<(), String> {
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or("has no scene")?;
    let mut visited = vec![false; document.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, base)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(format!(
                "node #{} is reached twice: the node hierarchy must be a tree",
                node.index()
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        visit(&node, world);
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(())
}

/// For each mesh of the document, the world transforms of the nodes that
/// use it (empty for meshes no node of the scene uses). Nodes scaled to
/// nothing (a common way to hide an object in glTF) place no geometry.
pub(crate) fn mesh_uses(document: &gltf::Document, base: Mat4) -> Result<Vec<Vec<Mat4>>, String> {
    let mut uses = vec![Vec::new(); document.meshes().len()];
    walk(document, base, |node, world| {
        if let Some(mesh) = node.mesh() {
            let det = world.determinant();
            if det != 0.0 && det.is_finite() {
                uses[mesh.index()].push(world);
            }
        }
    })?;
    Ok(uses)
}

/// Every (camera index, world transform) of the scene's camera nodes, in
/// node order.
pub(crate) fn camera_nodes(
    document: &gltf::Document,
    base: Mat4,
) -> Result<Vec<(usize, Mat4)>, String> {
    let mut out = Vec::new();
    walk(document, base, |node, world| {
        if let Some(camera) = node.camera() {
            out.push((camera.index(), world));
        }
    })?;
    Ok(out)
}
