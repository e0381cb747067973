//! Walking a glTF scene's node hierarchy to world transforms.
//!
//! Each node's transform is checked as a scene file's is: glTF requires a
//! finite affine matrix, or a finite translation, rotation and scale that
//! make one (glTF 2.0, section 3.5.3 "Transformations"). A transform that
//! is not one, or whose product with its parents overflows, is an error
//! naming the node; a mesh a node scales to nothing is said, never
//! dropped silently.

use lumis_core::glam::{Mat4, Vec4};

/// How messages name a node: `node #3 "panel"`.
pub(crate) fn describe(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("node #{} \"{name}\"", node.index()),
        None => format!("node #{}", node.index()),
    }
}

/// A node's own transform, refused where it is not a finite affine one.
fn local_transform(node: &gltf::Node) -> Result<Mat4, String> {
    let named = describe(node);
    if let gltf::scene::Transform::Decomposed {
        translation,
        rotation,
        scale,
    } = node.transform()
    {
        if !translation
            .iter()
            .chain(&rotation)
            .chain(&scale)
            .all(|v| v.is_finite())
        {
            return Err(format!(
                "{named}: its translation, rotation or scale is not finite"
            ));
        }
    }
    let matrix = Mat4::from_cols_array_2d(&node.transform().matrix());
    if !matrix.is_finite() {
        return Err(format!(
            "{named}: its transform is not finite (a rotation far from a unit quaternion, or a \
             scale or translation past the range of a 32-bit float)"
        ));
    }
    if matrix.row(3) != Vec4::W {
        return Err(format!(
            "{named}: its matrix is not affine: last row {:?}, expected [0, 0, 0, 1]",
            matrix.row(3).to_array()
        ));
    }
    Ok(matrix)
}

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
        let world = parent * local_transform(&node)?;
        if !world.is_finite() {
            return Err(format!(
                "{}: its world transform (its own times its parents') overflows",
                describe(&node)
            ));
        }
        visit(&node, world);
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(())
}

/// A node that places a mesh: its world transform, and how messages name
/// it.
#[derive(Debug, Clone)]
pub(crate) struct Placement {
    pub world: Mat4,
    pub node: String,
}

/// Where the document's meshes are placed.
pub(crate) struct MeshUses {
    /// For each mesh, the nodes that place it (empty for meshes no node
    /// of the scene uses).
    pub placements: Vec<Vec<Placement>>,
    /// The meshes nodes scale to nothing (a common way to hide an object
    /// in glTF), which place no geometry, each named.
    pub warnings: Vec<String>,
}

/// Where the document's meshes are placed, from base transform `base`.
pub(crate) fn mesh_uses(document: &gltf::Document, base: Mat4) -> Result<MeshUses, String> {
    let mut placements = vec![Vec::new(); document.meshes().len()];
    let mut warnings = Vec::new();
    walk(document, base, |node, world| {
        if let Some(mesh) = node.mesh() {
            let det = world.determinant();
            if det != 0.0 && det.is_finite() {
                placements[mesh.index()].push(Placement {
                    world,
                    node: describe(node),
                });
            } else {
                warnings.push(format!(
                    "{} scales its mesh #{}{} to nothing (determinant {det}): it is not placed",
                    describe(node),
                    mesh.index(),
                    mesh.name().map(|n| format!(" \"{n}\"")).unwrap_or_default()
                ));
            }
        }
    })?;
    Ok(MeshUses {
        placements,
        warnings,
    })
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
