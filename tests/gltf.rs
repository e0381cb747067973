//! glTF 2.0 import: small assets written by the tests (node transforms,
//! missing normals and uvs, multiple primitives, instancing, .glb and data
//! URIs, broken files), checked through ray queries on the loaded scene and
//! through renders that must equal the same geometry given inline in TOML.

use std::path::Path;

use lumis_core::entity::TYPE_KEY;
use lumis_core::{Bsdf, BsdfContext, Location, PluginEntity, PluginKind, Ray, Scene, Vec2, Vec3};
use lumis_render::{render, RenderSettings};
use lumis_scene::LoadedScene;
use lumis_tests::f_at_hit;
use lumis_tests::gltf_writer::{self, Asset, Camera, Container, Material, Mesh, Node, Primitive};

const BASE: &str = r#"[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "independent"
spp = 1
[integrator]
type = "path"
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.5
"#;

/// A fresh directory for one test's files, removed when the test ends.
fn test_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("lumis-gltf-tests-{name}-"))
        .tempdir()
        .unwrap()
}

fn try_load(dir: &Path, toml: &str) -> Result<LoadedScene, String> {
    let registry = lumis_app::builtin_registry().unwrap();
    lumis_scene::load_str(toml, &dir.join("test.toml"), &[], &registry).map_err(|e| e.to_string())
}

fn load(dir: &Path, toml: &str) -> LoadedScene {
    try_load(dir, toml).unwrap_or_else(|e| panic!("scene failed to load: {e}"))
}

fn gltf_shape(file: &str, extra: &str) -> String {
    format!("{BASE}[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n{extra}\n")
}

/// The unit right triangle in the xy plane, front +z.
fn triangle() -> Primitive {
    Primitive::triangles(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![0, 1, 2],
    )
}

fn one_mesh(primitive: Primitive, nodes: Vec<Node>, roots: Vec<usize>) -> Asset {
    Asset {
        meshes: vec![Mesh {
            name: "tri".into(),
            primitives: vec![primitive],
        }],
        nodes,
        roots,
        ..Asset::default()
    }
}

fn mesh_node(mesh: usize) -> Node {
    Node {
        mesh: Some(mesh),
        ..Node::default()
    }
}

/// Hit point and geometric and shading normals of a ray straight down -z
/// from `(x, y, 10)`.
fn down(scene: &LoadedScene, x: f32, y: f32) -> Option<(Vec3, Vec3, Vec3)> {
    let ray = Ray::new(Vec3::new(x, y, 10.0), Vec3::NEG_Z);
    scene
        .scene
        .intersect(&ray)
        .map(|h| (h.p(), h.n(), h.shading.normal()))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn node_transforms_compose_with_the_toml_transform() {
    let tmp = test_dir("transforms");
    let dir = tmp.path();
    // Parent translates by +5 in x, child scales by 2: the triangle spans
    // (5, 0)-(7, 0)-(5, 2).
    let asset = one_mesh(
        triangle(),
        vec![
            Node {
                translation: Some([5.0, 0.0, 0.0]),
                children: vec![1],
                ..Node::default()
            },
            Node {
                scale: Some([2.0, 2.0, 2.0]),
                ..mesh_node(0)
            },
        ],
        vec![0],
    );
    let file = gltf_writer::write(dir, "nodes", &asset, Container::External);
    let scene = load(dir, &gltf_shape(&file, ""));
    let (p, n, _) = down(&scene, 5.4, 1.5).expect("inside the scaled, moved triangle");
    assert!(
        close(p, Vec3::new(5.4, 1.5, 0.0)) && close(n, Vec3::Z),
        "{p} {n}"
    );
    assert!(
        down(&scene, 0.2, 0.2).is_none(),
        "nothing left at the origin"
    );

    // The TOML transform applies on top: rotate 90 degrees about x, then
    // lift by 1 in y. The triangle now lies in the xz plane at y = 1.
    let scene = load(
        dir,
        &gltf_shape(
            &file,
            "transform = { rotate = [1.0, 0.0, 0.0, 90.0], translate = [0.0, 1.0, 0.0] }",
        ),
    );
    let ray = Ray::new(Vec3::new(5.4, 10.0, 1.5), Vec3::NEG_Y);
    let hit = scene.scene.intersect(&ray).expect("rotated triangle");
    assert!(close(hit.p(), Vec3::new(5.4, 1.0, 1.5)), "{}", hit.p());
    assert!(
        close(hit.n(), Vec3::NEG_Y),
        "front +z rotated to -y: {}",
        hit.n()
    );

    // A node matrix is the same as its TRS.
    let asset = one_mesh(
        triangle(),
        vec![Node {
            matrix: Some([
                2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 5.0, 0.0, 0.0, 1.0,
            ]),
            ..mesh_node(0)
        }],
        vec![0],
    );
    let file = gltf_writer::write(dir, "matrix", &asset, Container::External);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert!(close(
        down(&scene, 5.4, 1.5).unwrap().0,
        Vec3::new(5.4, 1.5, 0.0)
    ));
}

/// A node transform that is not one is an error naming the node, as a
/// TOML transform's is; a mesh scaled to nothing is said, not dropped
/// silently.
#[test]
fn bad_node_transforms_are_named_never_dropped_silently() {
    let tmp = test_dir("bad-transforms");
    let dir = tmp.path();
    let named = |node: Node| Node {
        name: "panel".into(),
        ..node
    };
    let refused = [
        (
            "rotation",
            named(Node {
                rotation: Some([1e30, 0.0, 0.0, 0.0]),
                ..mesh_node(0)
            }),
            "is not finite",
        ),
        (
            "projective",
            named(Node {
                matrix: Some([
                    1.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
                ]),
                ..mesh_node(0)
            }),
            "is not affine",
        ),
        (
            "far",
            named(Node {
                translation: Some([3.4e38, 0.0, 0.0]),
                scale: Some([1e20, 1.0, 1.0]),
                ..mesh_node(0)
            }),
            "beyond the 1.844e18 at which Embree drops triangles",
        ),
    ];
    for (name, node, says) in refused {
        let file = gltf_writer::write(
            dir,
            name,
            &one_mesh(triangle(), vec![node], vec![0]),
            Container::External,
        );
        let err = try_load(dir, &gltf_shape(&file, ""))
            .err()
            .unwrap_or_else(|| panic!("{name} loaded"));
        assert!(
            err.contains("node #0 \"panel\"") && err.contains(says),
            "{name}: {err}"
        );
    }
    let hidden = named(Node {
        scale: Some([0.0, 1.0, 1.0]),
        ..mesh_node(0)
    });
    let file = gltf_writer::write(
        dir,
        "hidden",
        &one_mesh(triangle(), vec![hidden], vec![0]),
        Container::External,
    );
    let scene = load(dir, &gltf_shape(&file, ""));
    let warnings = &scene.scene.load_report().warnings;
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("node #0 \"panel\" scales its mesh #0 \"tri\" to nothing")),
        "{warnings:?}"
    );
}

#[test]
fn a_mesh_used_by_several_nodes_is_instanced_once() {
    let tmp = test_dir("instancing");
    let dir = tmp.path();
    let quad = Primitive::triangles(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![0, 1, 2, 0, 2, 3],
    );
    let at = |x: f32| Node {
        translation: Some([x, 0.0, 0.0]),
        ..mesh_node(0)
    };
    // Three copies and a mirrored one (x -> -x, spanning x in [9, 10]).
    let mirrored = Node {
        translation: Some([10.0, 0.0, 0.0]),
        scale: Some([-1.0, 1.0, 1.0]),
        ..mesh_node(0)
    };
    let asset = one_mesh(
        quad,
        vec![at(0.0), at(3.0), at(6.0), mirrored],
        vec![0, 1, 2, 3],
    );
    let file = gltf_writer::write(dir, "instances", &asset, Container::External);
    let scene = load(dir, &gltf_shape(&file, ""));
    let c = scene.scene.counts();
    assert_eq!(
        (c.instances, c.prototypes, c.unique_triangles, c.triangles),
        (4, 1, 2, 8),
        "{c:?}"
    );
    for x in [0.5, 3.5, 6.5, 9.5] {
        let (p, n, ns) = down(&scene, x, 0.25).unwrap_or_else(|| panic!("instance at {x}"));
        assert!(close(p, Vec3::new(x, 0.25, 0.0)), "{p}");
        // The glTF spec: a mirroring transform flips the winding, so the
        // front stays +z for the mirrored copy too.
        assert!(
            close(n, Vec3::Z) && close(ns, Vec3::Z),
            "at {x}: n {n}, ns {ns}"
        );
    }
    assert!(down(&scene, 2.0, 0.5).is_none());
    // One copy of the mesh data, not four.
    let one = load(
        dir,
        &gltf_shape(
            &gltf_writer::write(
                dir,
                "single",
                &one_mesh(
                    asset.meshes[0].primitives[0].clone(),
                    vec![at(0.0)],
                    vec![0],
                ),
                Container::External,
            ),
            "",
        ),
    );
    assert_eq!(
        one.scene.counts().instances,
        0,
        "a mesh used once is not instanced"
    );
    let mesh_bytes = one.scene.load_report().geometry_bytes;
    assert!(
        scene.scene.load_report().geometry_bytes < 2 * mesh_bytes + 1024,
        "{} vs {mesh_bytes}",
        scene.scene.load_report().geometry_bytes
    );
}

/// Two triangles folded along the x axis: the second is tilted by `angle`
/// degrees out of the xy plane.
fn hinge(angle_deg: f32) -> Primitive {
    let a = angle_deg.to_radians();
    Primitive::triangles(
        vec![
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -a.cos(), -a.sin()],
        ],
        vec![0, 1, 2, 1, 0, 3],
    )
}

#[test]
fn missing_normals_are_generated_with_a_crease_angle() {
    let tmp = test_dir("normals");
    let dir = tmp.path();
    let gentle = gltf_writer::write(
        dir,
        "gentle",
        &one_mesh(hinge(10.0), vec![mesh_node(0)], vec![0]),
        Container::External,
    );
    let sharp = gltf_writer::write(
        dir,
        "sharp",
        &one_mesh(hinge(60.0), vec![mesh_node(0)], vec![0]),
        Container::External,
    );

    // Near the fold of a gentle bend the shading normal leans toward the
    // other face.
    let scene = load(dir, &gltf_shape(&gentle, ""));
    assert!(scene.scene.counts().shading_normals);
    let (_, n, ns) = down(&scene, 0.0, 0.01).unwrap();
    assert!(
        close(n, Vec3::Z) && ns.dot(n) < 0.9999 && ns.dot(n) > 0.99,
        "n {n}, ns {ns}"
    );
    // Far from the fold, at the apex, the vertex belongs to one face only.
    let (_, n, ns) = down(&scene, 0.0, 0.99).unwrap();
    assert!(ns.dot(n) > 0.99999, "n {n}, ns {ns}");

    // A fold sharper than the crease angle stays sharp.
    let scene = load(dir, &gltf_shape(&sharp, ""));
    let (_, n, ns) = down(&scene, 0.0, 0.01).unwrap();
    assert!(close(ns, n), "n {n}, ns {ns}");
    // ...unless the crease angle allows it.
    let scene = load(dir, &gltf_shape(&sharp, "crease_angle = 90.0"));
    let (_, n, ns) = down(&scene, 0.0, 0.01).unwrap();
    assert!(ns.dot(n) < 0.99, "n {n}, ns {ns}");

    // crease_angle = 0: flat shading, no normals stored.
    let scene = load(dir, &gltf_shape(&gentle, "crease_angle = 0.0"));
    assert!(!scene.scene.counts().shading_normals);
    let (_, n, ns) = down(&scene, 0.0, 0.01).unwrap();
    assert_eq!(n, ns);

    // Normals in the file are used as they are.
    let mut with_normals = triangle();
    let tilted = Vec3::new(0.0, 0.6, 0.8);
    with_normals.normals = Some(vec![tilted.into(); 3]);
    let file = gltf_writer::write(
        dir,
        "given",
        &one_mesh(with_normals, vec![mesh_node(0)], vec![0]),
        Container::External,
    );
    let scene = load(dir, &gltf_shape(&file, ""));
    let (_, _, ns) = down(&scene, 0.2, 0.2).unwrap();
    assert!(close(ns, tilted), "{ns}");
}

fn reflectance_at(scene: &LoadedScene, x: f32, y: f32) -> [f32; 3] {
    let ray = Ray::new(Vec3::new(x, y, 10.0), Vec3::NEG_Z);
    let hit = scene.scene.intersect(&ray).expect("hit");
    let f = hit.bsdf.f(&BsdfContext::default(), Vec3::Z, Vec3::Z);
    let pi = std::f32::consts::PI;
    [f.r * pi, f.g * pi, f.b * pi]
}

/// The parameters of the `plastic` a glTF dielectric of base colour `rgb`
/// and GGX `alpha` (= roughness^2) maps to.
fn plastic_params(rgb: [f32; 3], alpha: f32) -> String {
    format!(
        "diffuse_reflectance = [{:?}, {:?}, {:?}]\nint_ior = 1.5\ndistribution = \"ggx\"\nroughness = {alpha:?}\n",
        rgb[0], rgb[1], rgb[2]
    )
}

/// What [`reflectance_at`] reads on a glTF dielectric of base colour `rgb`
/// and roughness 1: pi f(z, z) of that plastic, made from a TOML table.
fn dielectric(rgb: [f32; 3]) -> [f32; 3] {
    let text = format!("type = \"plastic\"\n{}", plastic_params(rgb, 1.0));
    let table = lumis_core::doc::parse(&text, "expected").unwrap();
    let registry = lumis_app::builtin_registry().unwrap();
    let entity = PluginEntity::from_table(
        PluginKind::Bsdf,
        "expected",
        table,
        Location::Builtin,
        TYPE_KEY,
    )
    .unwrap();
    let bsdf = registry
        .create::<dyn Bsdf>(&entity, lumis_core::texture::BsdfScope::EMPTY)
        .unwrap();
    let f = bsdf.f(&BsdfContext::default(), Vec3::Z, Vec3::Z);
    let pi = std::f32::consts::PI;
    [f.r * pi, f.g * pi, f.b * pi]
}

fn near(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
}

/// Two primitives of one mesh: an indexed red one with uvs, and a
/// non-indexed green one without uvs, 2 units to the right.
fn two_primitives() -> Asset {
    let mut red = triangle();
    red.material = Some(0);
    red.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let green = Primitive {
        positions: vec![[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.0, 1.0, 0.0]],
        indices: None,
        material: Some(1),
        mode: 4,
        ..Primitive::default()
    };
    Asset {
        meshes: vec![Mesh {
            name: "two".into(),
            primitives: vec![red, green],
        }],
        materials: vec![
            Material::dielectric("red", [0.8, 0.1, 0.1]),
            Material::dielectric("green", [0.1, 0.7, 0.2]),
        ],
        nodes: vec![mesh_node(0)],
        roots: vec![0],
        ..Asset::default()
    }
}

#[test]
fn primitives_materials_and_overrides() {
    let tmp = test_dir("materials");
    let dir = tmp.path();
    let file = gltf_writer::write(dir, "two", &two_primitives(), Container::External);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert_eq!(scene.scene.counts().meshes, 2);
    assert!(near(
        reflectance_at(&scene, 0.2, 0.2),
        dielectric([0.8, 0.1, 0.1])
    ));
    assert!(near(
        reflectance_at(&scene, 2.2, 0.2),
        dielectric([0.1, 0.7, 0.2])
    ));

    let scene = load(
        dir,
        &gltf_shape(&file, "bsdf_overrides = { red = \"white\" }"),
    );
    assert!(near(reflectance_at(&scene, 0.2, 0.2), [0.5; 3]));
    assert!(near(
        reflectance_at(&scene, 2.2, 0.2),
        dielectric([0.1, 0.7, 0.2])
    ));

    let scene = load(dir, &gltf_shape(&file, "bsdf = \"white\""));
    assert!(near(reflectance_at(&scene, 2.2, 0.2), [0.5; 3]));

    let err = try_load(
        dir,
        &gltf_shape(&file, "bsdf_overrides = { blue = \"white\" }"),
    )
    .err()
    .unwrap();
    assert!(
        err.contains("test.toml:")
            && err.contains("no material named \"blue\"")
            && err.contains("\"red\", \"green\""),
        "{err}"
    );
    let err = try_load(
        dir,
        &gltf_shape(&file, "bsdf_overrides = { red = \"chrome\" }"),
    )
    .err()
    .unwrap();
    assert!(err.contains("no [[bsdf]] named \"chrome\""), "{err}");
}

fn render_image(scene: &LoadedScene) -> Vec<f32> {
    let settings = RenderSettings {
        spp: scene.sampler.samples_per_pixel(),
        seed: scene.seed,
        threads: 2,
        progress: false,
        clamp: scene.clamp,
    };
    let out = render(
        &scene.camera,
        &scene.scene,
        scene.integrator.as_ref(),
        scene.sampler.as_ref(),
        &settings,
    )
    .unwrap();
    out.image.pixels.iter().flatten().copied().collect()
}

#[test]
fn glb_data_uri_and_external_buffers_load_the_same() {
    let tmp = test_dir("containers");
    let dir = tmp.path();
    let asset = two_primitives();
    let mut images = Vec::new();
    for (name, container) in [
        ("external", Container::External),
        ("embedded", Container::DataUri),
        ("binary", Container::Glb),
    ] {
        let file = gltf_writer::write(dir, name, &asset, container);
        let toml = gltf_shape(&file, "")
            + "[[light]]\ntype = \"point\"\nposition = [1.0, 0.5, 2.0]\nintensity = [4.0, 4.0, 4.0]\n";
        let scene = load(dir, &toml);
        assert!(
            near(
                reflectance_at(&scene, 2.2, 0.2),
                dielectric([0.1, 0.7, 0.2])
            ),
            "{name}"
        );
        images.push(render_image(&scene));
    }
    assert!(
        images[0].iter().any(|&v| v > 0.0),
        "the light reaches the mesh"
    );
    assert_eq!(images[0], images[1]);
    assert_eq!(images[0], images[2]);
}

/// A scene with a quad light above: the glTF asset's triangle, or the same
/// triangle inline.
fn lit_scene(shape: &str) -> String {
    format!(
        r#"seed = 7
[film]
resolution = [24, 24]
[camera]
type = "perspective"
origin = [0.3, 0.3, 1.2]
target = [0.3, 0.3, 0.0]
fov = 60.0
[sampler]
type = "independent"
spp = 8
[integrator]
type = "path"
max_depth = 3
[[bsdf]]
name = "grey"
type = "plastic"
{grey}
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.5
[[shape]]
type = "quad"
corner = [-1.0, -1.0, 1.5]
edge_u = [0.0, 3.0, 0.0]
edge_v = [3.0, 0.0, 0.0]
bsdf = "white"
emission = {{ radiance = [3.0, 3.0, 3.0] }}
{shape}
"#,
        grey = plastic_params([0.8, 0.6, 0.4], 1.0)
    )
}

#[test]
fn a_gltf_triangle_renders_bit_for_bit_like_the_inline_one() {
    let tmp = test_dir("bit-for-bit");
    let dir = tmp.path();
    let mut tri = triangle();
    tri.material = Some(0);
    tri.normals = Some(vec![[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [0.6, 0.0, 0.8]]);
    let asset = Asset {
        materials: vec![Material::dielectric("grey", [0.8, 0.6, 0.4])],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "tri", &asset, Container::Glb);
    let from_gltf = load(
        dir,
        &lit_scene(&format!("[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n")),
    );
    let inline = load(
        dir,
        &lit_scene(
            "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n\
             indices = [0, 1, 2]\nnormals = [[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [0.6, 0.0, 0.8]]\nbsdf = \"grey\"\n",
        ),
    );
    let a = render_image(&from_gltf);
    let b = render_image(&inline);
    assert!(
        a.iter().filter(|&&v| v > 0.0).count() > 50,
        "the triangle is lit"
    );
    assert_eq!(a, b, "same image bit for bit");
}

#[test]
fn metals_render_as_the_conductor_they_map_to() {
    // metallic 1, roughness 0.5: a GGX conductor of alpha = 0.5^2 whose
    // reflectance is the base colour.
    let tmp = test_dir("metal");
    let dir = tmp.path();
    let mut tri = triangle();
    tri.material = Some(0);
    let asset = Asset {
        materials: vec![Material {
            metallic: 1.0,
            roughness: 0.5,
            ..Material::dielectric("gold", [1.0, 0.8, 0.3])
        }],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "metal", &asset, Container::Glb);
    let from_gltf = load(
        dir,
        &lit_scene(&format!("[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n")),
    );
    assert!(from_gltf.scene.load_report().warnings.is_empty());
    let inline = load(
        dir,
        &lit_scene(
            "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n\
             indices = [0, 1, 2]\nbsdf = \"gold\"\n\
             [[bsdf]]\nname = \"gold\"\ntype = \"conductor\"\ndistribution = \"ggx\"\nroughness = 0.25\n\
             specular_reflectance = [1.0, 0.8, 0.3]\n",
        ),
    );
    let a = render_image(&from_gltf);
    let b = render_image(&inline);
    assert!(
        a.iter().filter(|&&v| v > 0.0).count() > 50,
        "the metal is lit"
    );
    assert_eq!(a, b, "same image bit for bit");
}

/// A metallic-roughness texture gives the roughness per texel: GGX alpha
/// `(roughnessFactor x green)^2`, the glTF remapping. Each half of a 2x1
/// texture renders as the untextured metal of that roughness.
#[test]
fn a_metallic_roughness_texture_gives_the_roughness_per_texel() {
    let tmp = test_dir("roughness-texture");
    let dir = tmp.path();
    let metal = |name: &str, roughness: f32, texture: Option<usize>| Material {
        metallic: 1.0,
        roughness,
        metallic_roughness_texture: texture,
        ..Material::dielectric(name, [0.9, 0.8, 0.7])
    };
    let asset_of = |material: Material, images: Vec<Vec<u8>>| {
        let mut tri = triangle();
        tri.material = Some(0);
        tri.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        Asset {
            materials: vec![material],
            images,
            ..one_mesh(tri, vec![mesh_node(0)], vec![0])
        }
    };
    // Green 51 (0.2) on the left, 255 on the right; factor 1.
    let png = gltf_writer::png_rgb8(2, 1, &[[0, 51, 0], [0, 255, 0]]);
    let textured = gltf_writer::write(
        dir,
        "textured",
        &asset_of(metal("m", 1.0, Some(0)), vec![png]),
        Container::Glb,
    );
    let f_at = |file: &str, x: f32| {
        let scene = load(
            dir,
            &lit_scene(&format!("[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n")),
        );
        let hit = scene
            .scene
            .intersect(&Ray::new(Vec3::new(x, 0.1, 1.0), Vec3::NEG_Z))
            .expect("hit");
        // At the texel's centre, without the camera's footprint: the
        // texel's own value.
        let ctx = BsdfContext {
            texture: lumis_core::TextureQuery::at(hit.texture.uv),
            ..BsdfContext::default()
        };
        let (wo, wi) = (
            Vec3::new(0.3, 0.0, 0.95).normalize(),
            Vec3::new(-0.25, 0.05, 0.96).normalize(),
        );
        hit.bsdf.f(&ctx, wo, wi).g
    };
    for (x, roughness) in [(0.25, 0.2), (0.75, 1.0)] {
        let plain = gltf_writer::write(
            dir,
            &format!("plain{x}"),
            &asset_of(metal("m", roughness, None), Vec::new()),
            Container::Glb,
        );
        let (got, want) = (f_at(&textured, x), f_at(&plain, x));
        assert!(
            want > 0.0 && (got - want).abs() <= 1e-4 * want,
            "x = {x}: {got} against {want}"
        );
    }
    assert!(f_at(&textured, 0.25) > 2.0 * f_at(&textured, 0.75));
}

#[test]
fn a_textured_dielectric_tints_its_base_and_not_its_coat() {
    // A smooth (roughness 0) white dielectric with a pure red base colour
    // texture renders as the inline plastic whose base is red: the coat
    // still mirrors the white light.
    let tmp = test_dir("textured-coat");
    let dir = tmp.path();
    let mut tri = triangle();
    tri.material = Some(0);
    tri.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let asset = Asset {
        materials: vec![Material {
            roughness: 0.0,
            base_color_texture: Some(0),
            ..Material::dielectric("red-plastic", [1.0, 1.0, 1.0])
        }],
        images: vec![gltf_writer::png_rgb8(1, 1, &[[255, 0, 0]])],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "red", &asset, Container::Glb);
    let from_gltf = load(
        dir,
        &lit_scene(&format!("[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n")),
    );
    assert!(from_gltf.scene.load_report().warnings.is_empty());

    // At a hit (below the light): the mirror sample is white, the base red.
    let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z);
    let hit = from_gltf.scene.intersect(&ray).expect("hit");
    let ctx = BsdfContext {
        texture: hit.texture,
        ..BsdfContext::default()
    };
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let mirror = hit.bsdf.sample_f(&ctx, wo, 0.0, Vec2::splat(0.5)).unwrap();
    assert!(mirror.flags.is_specular(), "{mirror:?}");
    assert!(
        mirror.f.g == mirror.f.r && mirror.f.b == mirror.f.r && mirror.f.r > 0.0,
        "the coat is white: {:?}",
        mirror.f
    );
    let base = hit.bsdf.f(&ctx, wo, Vec3::new(0.0, 0.6, 0.8));
    assert!(base.r > 0.0 && base.g == 0.0 && base.b == 0.0, "{base:?}");

    // The image: that of the inline plastic with a red base, up to the
    // rounding of the bilinear lookup; its green and blue are the
    // highlights of the white coat.
    let inline = load(
        dir,
        &lit_scene(&format!(
            "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n\
             indices = [0, 1, 2]\nbsdf = \"red\"\n\
             [[bsdf]]\nname = \"red\"\ntype = \"plastic\"\n{}",
            plastic_params([1.0, 0.0, 0.0], 0.0)
        )),
    );
    let a = render_image(&from_gltf);
    let b = render_image(&inline);
    let green: f32 = a.iter().skip(1).step_by(3).sum();
    assert!(green > 0.0, "the coat reflects the white light");
    let diff: f32 = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).sum();
    let total: f32 = b.iter().sum();
    assert!(diff <= 1e-4 * total, "relative difference {}", diff / total);
}

#[test]
fn double_sided_materials_reflect_from_behind_as_from_the_front() {
    let tmp = test_dir("double-sided");
    let dir = tmp.path();
    let mut tri = triangle();
    tri.material = Some(0);
    let asset = Asset {
        materials: vec![Material {
            double_sided: true,
            ..Material::dielectric("leaf", [0.2, 0.6, 0.1])
        }],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "leaf", &asset, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    let hit = scene
        .scene
        .intersect(&Ray::new(Vec3::new(0.2, 0.2, -10.0), Vec3::Z))
        .expect("hit from behind");
    let ctx = BsdfContext::default();
    let (wo, wi) = (
        Vec3::new(0.3, 0.0, 0.9).normalize(),
        Vec3::new(0.0, 0.5, 0.8).normalize(),
    );
    let below = |v: Vec3| Vec3::new(v.x, v.y, -v.z);
    let front = hit.bsdf.f(&ctx, wo, wi);
    assert!(front.g > 0.0);
    assert_eq!(hit.bsdf.f(&ctx, below(wo), below(wi)), front);
    assert_eq!(
        hit.bsdf.pdf(&ctx, below(wo), below(wi)),
        hit.bsdf.pdf(&ctx, wo, wi)
    );
    let s = hit
        .bsdf
        .sample_f(&ctx, below(wo), 0.9, Vec2::splat(0.3))
        .unwrap();
    assert!(s.wi.z < 0.0 && s.pdf > 0.0, "{s:?}");
}

#[test]
fn emissive_materials_become_triangle_lights() {
    let tmp = test_dir("emissive");
    let dir = tmp.path();
    // An emitting triangle above a white floor, facing down.
    let mut light = Primitive::triangles(
        vec![[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 0.0, 1.0]],
        vec![0, 1, 2],
    );
    light.material = Some(0);
    let asset = Asset {
        materials: vec![Material {
            emissive: [1.0, 0.9, 0.8],
            ..Material::dielectric("lamp", [0.5, 0.5, 0.5])
        }],
        ..one_mesh(light, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "lamp", &asset, Container::External);
    let floor = "[[shape]]\ntype = \"quad\"\ncorner = [-1.0, -1.0, 0.0]\nedge_u = [3.0, 0.0, 0.0]\nedge_v = [0.0, 3.0, 0.0]\nbsdf = \"white\"\n";
    let scene = |shape: &str| {
        format!(
            "seed = 3\n[film]\nresolution = [24, 24]\n[camera]\ntype = \"perspective\"\norigin = [0.3, -2.0, 2.5]\ntarget = [0.3, 0.3, 0.0]\nfov = 45.0\n\
             [sampler]\ntype = \"independent\"\nspp = 8\n[integrator]\ntype = \"path\"\nmax_depth = 3\n\
             [[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 0.5\n{floor}{shape}"
        )
    };
    let from_gltf = load(
        dir,
        &scene(&format!(
            "[[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\nbsdf = \"white\"\n"
        )),
    );
    assert_eq!(from_gltf.scene.counts().area_lights, 1);
    let inline = load(
        dir,
        &scene(
            "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 0.0, 1.0]]\n\
             indices = [0, 1, 2]\nbsdf = \"white\"\nemission = { radiance = [1.0, 0.9, 0.8] }\n",
        ),
    );
    let a = render_image(&from_gltf);
    assert!(
        a.iter().filter(|&&v| v > 0.0).count() > 100,
        "the floor is lit by the triangle"
    );
    assert_eq!(a, render_image(&inline), "same image as the inline emitter");
}

#[test]
fn cameras_are_selected_by_name_or_index() {
    let tmp = test_dir("cameras");
    let dir = tmp.path();
    let mut asset = one_mesh(triangle(), vec![mesh_node(0)], vec![0, 1, 2]);
    asset.cameras = vec![
        Camera {
            name: "wide".into(),
            yfov: 1.2,
        },
        Camera {
            name: "front".into(),
            yfov: 0.7,
        },
    ];
    asset.nodes.push(Node {
        camera: Some(0),
        translation: Some([0.0, 0.0, 9.0]),
        ..Node::default()
    });
    asset.nodes.push(Node {
        camera: Some(1),
        translation: Some([0.2, 0.3, 5.0]),
        ..Node::default()
    });
    let file = gltf_writer::write(dir, "cams", &asset, Container::External);
    let with_camera = |camera: &str| {
        BASE.replace(
            "type = \"perspective\"\norigin = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 40.0\n",
            &format!("type = \"gltf\"\nfile = \"{file}\"\n{camera}\n"),
        )
    };
    let expected = lumis_render::PerspectiveCamera::new(
        Vec3::new(0.2, 0.3, 5.0),
        Vec3::new(0.2, 0.3, 4.0),
        Vec3::Y,
        0.7f32.to_degrees(),
        lumis_core::UVec2::new(16, 16),
    )
    .unwrap();
    let pixel = lumis_core::UVec2::new(3, 11);
    let offset = lumis_core::Vec2::new(0.25, 0.5);
    for selector in ["name = \"front\"", "index = 1"] {
        let scene = load(dir, &with_camera(selector));
        let (a, b) = (
            scene.camera.generate_ray(pixel, offset),
            expected.generate_ray(pixel, offset),
        );
        assert!(
            close(a.o, b.o) && close(a.d, b.d),
            "{selector}: {a:?} vs {b:?}"
        );
    }
    let first = load(dir, &with_camera(""));
    assert!(close(
        first.camera.generate_ray(pixel, offset).o,
        Vec3::new(0.0, 0.0, 9.0)
    ));
    let err = try_load(dir, &with_camera("name = \"back\""))
        .err()
        .unwrap();
    assert!(
        err.contains("no camera named \"back\"") && err.contains("\"wide\", \"front\""),
        "{err}"
    );
}

fn broken(dir: &Path, name: &str, primitive: Primitive) -> String {
    let asset = Asset {
        meshes: vec![Mesh {
            name: "broken".into(),
            primitives: vec![triangle(), primitive],
        }],
        nodes: vec![mesh_node(0)],
        roots: vec![0],
        ..Asset::default()
    };
    let file = gltf_writer::write(dir, name, &asset, Container::External);
    try_load(dir, &gltf_shape(&file, ""))
        .err()
        .expect("the broken asset is refused")
}

fn assert_names(err: &str, parts: &[&str]) {
    for part in parts {
        assert!(
            err.contains(part),
            "error does not mention '{part}':\n{err}"
        );
    }
}

#[test]
fn broken_files_get_errors_naming_file_and_mesh() {
    let tmp = test_dir("broken");
    let dir = tmp.path();
    let mut out_of_range = triangle();
    out_of_range.indices = Some(vec![0, 1, 7]);
    let err = broken(dir, "range", out_of_range);
    assert_names(
        &err,
        &[
            "test.toml:",
            "range.gltf",
            "mesh \"broken\" (#0) primitive #1",
            "index 7",
            "out of range for 3 vertices",
        ],
    );

    let mut lines = triangle();
    lines.mode = 1;
    let err = broken(dir, "lines", lines);
    assert_names(
        &err,
        &[
            "lines.gltf",
            "mesh \"broken\" (#0) primitive #1",
            "Lines",
            "only TRIANGLES",
        ],
    );

    let mut ragged = triangle();
    ragged.indices = Some(vec![0, 1]);
    let err = broken(dir, "ragged", ragged);
    assert_names(
        &err,
        &["mesh \"broken\"", "not a whole number of triangles"],
    );

    // Truncated buffer: cut the .bin short.
    let file = gltf_writer::write(dir, "short", &two_primitives(), Container::External);
    let bin = dir.join("short.bin");
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() / 2]).unwrap();
    let err = try_load(dir, &gltf_shape(&file, "")).err().unwrap();
    assert_names(
        &err,
        &["test.toml:", "short.gltf", "buffer #0", "truncated"],
    );

    // A missing .bin.
    std::fs::remove_file(&bin).unwrap();
    let err = try_load(dir, &gltf_shape(&file, "")).err().unwrap();
    assert_names(
        &err,
        &["short.gltf", "buffer #0", "cannot read", "short.bin"],
    );

    // Not glTF at all, and a missing file.
    std::fs::write(dir.join("junk.gltf"), "{ not json").unwrap();
    let err = try_load(dir, &gltf_shape("junk.gltf", "")).err().unwrap();
    assert_names(&err, &["junk.gltf", "not a valid glTF 2.0 file"]);
    let err = try_load(dir, &gltf_shape("nowhere.glb", "")).err().unwrap();
    assert_names(&err, &["nowhere.glb", "cannot read glTF"]);

    // TOML errors are located too.
    let err = try_load(dir, &gltf_shape("range.gltf", "crease_angle = 200.0"))
        .err()
        .unwrap();
    assert_names(&err, &["test.toml:", "crease_angle", "[0, 180]"]);
    let err = try_load(
        dir,
        &gltf_shape("range.gltf", "transform = { scale = [0.0, 1.0, 1.0] }"),
    )
    .err()
    .unwrap();
    assert_names(&err, &["test.toml:", "transform", "singular"]);
}

#[test]
fn accel_options_are_checked() {
    let tmp = test_dir("accel");
    let dir = tmp.path();
    let file = gltf_writer::write(
        dir,
        "tri",
        &one_mesh(triangle(), vec![mesh_node(0)], vec![0]),
        Container::Glb,
    );
    for quality in ["low", "medium", "high"] {
        let toml = gltf_shape(&file, "")
            + &format!("[accel]\nquality = \"{quality}\"\nrobust = true\ncompact = true\n");
        let scene = load(dir, &toml);
        assert!(down(&scene, 0.2, 0.2).is_some(), "{quality}");
    }
    let err = try_load(
        dir,
        &(gltf_shape(&file, "") + "[accel]\nquality = \"ultra\"\n"),
    )
    .err()
    .unwrap();
    assert_names(
        &err,
        &["test.toml:", "quality", "\"low\", \"medium\", \"high\""],
    );
}

#[test]
fn base_colour_textures_are_looked_up_at_the_interpolated_uv() {
    let tmp = test_dir("textures");
    let dir = tmp.path();
    // 2x2 texels, rows from the top: red, green / blue, white (sRGB 255 and
    // 0 are linear 1 and 0).
    let png = gltf_writer::png_rgb8(
        2,
        2,
        &[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]],
    );
    let mut tri = Primitive::triangles(
        vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
        vec![0, 1, 2],
    );
    tri.material = Some(0);
    tri.uvs = Some(vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]);
    let asset = Asset {
        materials: vec![Material {
            base_color_texture: Some(0),
            ..Material::dielectric("checker", [0.5, 0.8, 1.0])
        }],
        images: vec![png],
        ..one_mesh(tri.clone(), vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "checker", &asset, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert!(
        scene.scene.load_report().warnings.is_empty(),
        "{:?}",
        scene.scene.load_report().warnings
    );
    let approx = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-3);
    for ((x, y), expected) in [
        ((0.25, 0.25), [0.5, 0.0, 0.0]),
        ((0.75, 0.25), [0.0, 0.8, 0.0]),
        ((0.25, 0.75), [0.0, 0.0, 1.0]),
        ((0.75, 0.75), [0.5, 0.8, 1.0]),
        ((1.25, 0.25), [0.5, 0.0, 0.0]), // repeat
    ] {
        let got = reflectance_at_uv(&scene, x, y);
        let expected = dielectric(expected);
        assert!(
            approx(got, expected),
            "at ({x}, {y}): {got:?} vs {expected:?}"
        );
    }

    // KHR_texture_transform: shifted by half the image in u, the red texel
    // shows green and the green one red.
    let shifted = Asset {
        materials: vec![Material {
            base_color_transform: Some(([0.5, 0.0], 0.0, [1.0, 1.0])),
            ..asset.materials[0].clone()
        }],
        ..asset.clone()
    };
    let file = gltf_writer::write(dir, "shifted", &shifted, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert!(
        scene.scene.load_report().warnings.is_empty(),
        "{:?}",
        scene.scene.load_report().warnings
    );
    assert!(approx(
        reflectance_at_uv(&scene, 0.25, 0.25),
        dielectric([0.0, 0.8, 0.0])
    ));
    assert!(approx(
        reflectance_at_uv(&scene, 0.75, 0.25),
        dielectric([0.5, 0.0, 0.0])
    ));

    // A textured material on a primitive without uvs is refused.
    tri.uvs = None;
    let asset = Asset {
        meshes: vec![Mesh {
            name: "no-uvs".into(),
            primitives: vec![tri],
        }],
        ..asset
    };
    let file = gltf_writer::write(dir, "no-uvs", &asset, Container::Glb);
    let err = try_load(dir, &gltf_shape(&file, "")).err().unwrap();
    assert_names(
        &err,
        &[
            "no-uvs.glb",
            "mesh \"no-uvs\" (#0) primitive #0",
            "no TEXCOORD_0",
        ],
    );
}

/// The BSDF's reflectance at a hit, with the hit's own uv in the context.
fn reflectance_at_uv(scene: &LoadedScene, x: f32, y: f32) -> [f32; 3] {
    let ray = Ray::new(Vec3::new(x, y, 10.0), Vec3::NEG_Z);
    let hit = scene.scene.intersect(&ray).expect("hit");
    let ctx = BsdfContext {
        texture: hit.texture,
        ..BsdfContext::default()
    };
    let f = hit.bsdf.f(&ctx, Vec3::Z, Vec3::Z);
    let pi = std::f32::consts::PI;
    [f.r * pi, f.g * pi, f.b * pi]
}

#[test]
fn what_is_not_modelled_is_reported() {
    let tmp = test_dir("warnings");
    let dir = tmp.path();
    let mut tri = triangle();
    tri.material = Some(0);
    let asset = Asset {
        materials: vec![Material {
            metallic: 0.7,
            roughness: 0.2,
            ..Material::dielectric("gold", [1.0, 0.8, 0.3])
        }],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "gold", &asset, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    let report = scene.scene.load_report();
    assert!(
        report.warnings.iter().any(|w| w.contains("gold.glb")
            && w.contains("\"gold\"")
            && w.contains("metallic 0.7")),
        "{:?}",
        report.warnings
    );
    // The start-up report shows them.
    let lines = report.lines(scene.scene.counts());
    assert!(lines[0].starts_with("loaded 1 triangles"), "{}", lines[0]);
    assert!(lines
        .iter()
        .any(|l| l.starts_with("warning:") && l.contains("gold")));
    // Overridden, the material's BSDF is not used: no warning.
    let scene = load(dir, &gltf_shape(&file, "bsdf = \"white\""));
    assert!(scene.scene.load_report().warnings.is_empty());
}

#[test]
fn emissive_instances_get_their_own_world_space_lights() {
    let tmp = test_dir("emissive-instances");
    let dir = tmp.path();
    let mut panel = Primitive::triangles(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![0, 1, 2, 0, 2, 3],
    );
    panel.material = Some(0);
    let at = |x: f32| Node {
        translation: Some([x, 0.0, 0.0]),
        ..mesh_node(0)
    };
    let asset = Asset {
        materials: vec![Material {
            emissive: [0.5, 0.5, 0.5],
            ..Material::dielectric("lamp", [0.2, 0.2, 0.2])
        }],
        ..one_mesh(panel, vec![at(0.0), at(4.0)], vec![0, 1])
    };
    let file = gltf_writer::write(dir, "panels", &asset, Container::External);
    let scene = load(dir, &gltf_shape(&file, ""));
    let c = scene.scene.counts();
    assert_eq!((c.instances, c.area_lights), (2, 4), "{c:?}");
    let mut seen = Vec::new();
    for x in [0.5, 4.5] {
        let hit = scene
            .scene
            .intersect(&Ray::new(Vec3::new(x, 0.25, 10.0), Vec3::NEG_Z))
            .expect("panel");
        let index = hit.light.expect("the panel emits").get();
        let light = &scene.scene.lights()[index as usize];
        // The light is the triangle of this instance, in world space: its
        // radiance is seen from the front, at this point.
        let le = light.l(hit.p(), hit.n(), hit.texture.uv, Vec3::Z);
        assert!((le.r - 0.5).abs() < 1e-6, "{le:?}");
        // Sampled points of the light lie on this instance.
        let ctx = lumis_core::LightSampleContext::at(Vec3::new(x, 0.5, 1.0));
        for u in [(0.1, 0.2), (0.7, 0.4), (0.95, 0.95)] {
            let s = light
                .sample_li(&ctx, lumis_core::Vec2::new(u.0, u.1))
                .expect("the light faces the point");
            let p = s.p.p;
            assert!(
                p.x >= x - 0.5 - 1e-5 && p.x <= x + 0.5 + 1e-5 && p.z.abs() < 1e-5,
                "{p}"
            );
        }
        seen.push(index);
    }
    assert_ne!(seen[0], seen[1], "each instance has its own lights");
}

#[test]
fn the_example_scene_loads() {
    let registry = lumis_app::builtin_registry().unwrap();
    let scene = lumis_scene::load_file(
        &lumis_tests::scenes_dir().join("gltf-boxes.toml"),
        &[],
        &registry,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let c = scene.scene.counts();
    assert_eq!(
        (c.instances, c.prototypes, c.area_lights),
        (3, 1, 2),
        "{c:?}"
    );
}

/// A bumpy 8x8 heightfield over [0, 1]^2 (front +z), without normals.
fn bumps() -> Primitive {
    let n = 8;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            let z = 0.15 * (6.0 * x).sin() * (5.0 * y).cos();
            positions.push([x, y, z]);
        }
    }
    let mut indices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = (j * (n + 1) + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32 + 2, a + n as u32 + 1);
            indices.extend([a, b, c, a, c, d]);
        }
    }
    Primitive::triangles(positions, indices)
}

#[test]
fn instanced_and_baked_meshes_render_alike() {
    let tmp = test_dir("instanced-vs-baked");
    let dir = tmp.path();
    let placed = [
        Node {
            translation: Some([-1.1, -0.5, 0.0]),
            rotation: Some([0.0, 0.0, 0.258819, 0.9659258]), // 30 degrees about z
            scale: Some([1.0, 1.2, 0.8]),
            ..mesh_node(0)
        },
        Node {
            translation: Some([1.1, -0.5, 0.0]),
            scale: Some([-1.0, 1.0, 1.0]), // mirrored
            ..mesh_node(0)
        },
    ];
    let instanced = gltf_writer::write(
        dir,
        "both",
        &one_mesh(bumps(), placed.to_vec(), vec![0, 1]),
        Container::Glb,
    );
    let first = gltf_writer::write(
        dir,
        "first",
        &one_mesh(bumps(), vec![placed[0].clone()], vec![0]),
        Container::Glb,
    );
    let second = gltf_writer::write(
        dir,
        "second",
        &one_mesh(bumps(), vec![placed[1].clone()], vec![0]),
        Container::Glb,
    );
    let scene = |shapes: &str| {
        format!(
            "seed = 5\n[film]\nresolution = [48, 32]\n[camera]\ntype = \"perspective\"\norigin = [0.0, -1.5, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 45.0\n\
             [sampler]\ntype = \"independent\"\nspp = 32\n[integrator]\ntype = \"path\"\nmax_depth = 4\n\
             [[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 0.7\n\
             [[shape]]\ntype = \"quad\"\ncorner = [-2.0, -2.0, 2.0]\nedge_u = [0.0, 4.0, 0.0]\nedge_v = [4.0, 0.0, 0.0]\nbsdf = \"white\"\nemission = {{ radiance = [2.0, 2.0, 2.0] }}\n\
             [[shape]]\ntype = \"quad\"\ncorner = [-3.0, -3.0, -0.3]\nedge_u = [6.0, 0.0, 0.0]\nedge_v = [0.0, 6.0, 0.0]\nbsdf = \"white\"\n{shapes}"
        )
    };
    let a = load(
        dir,
        &scene(&format!(
            "[[shape]]\ntype = \"gltf\"\nfile = \"{instanced}\"\nbsdf = \"white\"\n"
        )),
    );
    assert_eq!(a.scene.counts().instances, 2);
    let b = load(
        dir,
        &scene(&format!(
            "[[shape]]\ntype = \"gltf\"\nfile = \"{first}\"\nbsdf = \"white\"\n[[shape]]\ntype = \"gltf\"\nfile = \"{second}\"\nbsdf = \"white\"\n"
        )),
    );
    assert_eq!(b.scene.counts().instances, 0);
    let render_one = |s: &LoadedScene| {
        render(
            &s.camera,
            &s.scene,
            s.integrator.as_ref(),
            s.sampler.as_ref(),
            &RenderSettings {
                spp: s.sampler.samples_per_pixel(),
                seed: s.seed,
                threads: 2,
                progress: false,
                clamp: s.clamp,
            },
        )
        .unwrap()
        .image
    };
    let (ia, ib) = (render_one(&a), render_one(&b));
    let blocks = (48 / 8) * (32 / 8) * 3;
    let z = lumis_tests::bonferroni_z(0.01, blocks);
    lumis_tests::assert_same_mean(&ia, &ib, 8, z, "instanced vs baked");
    // The meshes are in the picture: the images are not just the floor.
    let differs_from_floor = ia
        .pixels
        .iter()
        .zip(&ib.pixels)
        .filter(|(p, q)| p == q)
        .count();
    assert!(differs_from_floor > 0);
}

#[test]
fn jpeg_base_colour_textures_are_decoded() {
    let tmp = test_dir("jpeg");
    let dir = tmp.path();
    let (w, h) = (16u32, 16u32);
    let rgb = [200u8, 100, 50];
    let pixels: Vec<u8> = (0..w * h).flat_map(|_| rgb).collect();
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 100)
        .encode(&pixels, w, h, image::ColorType::Rgb8)
        .unwrap();
    let mut tri = triangle();
    tri.material = Some(0);
    tri.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let asset = Asset {
        materials: vec![Material {
            base_color_texture: Some(0),
            ..Material::dielectric("photo", [1.0, 1.0, 1.0])
        }],
        images: vec![jpeg],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "photo", &asset, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert!(
        scene.scene.load_report().warnings.is_empty(),
        "{:?}",
        scene.scene.load_report().warnings
    );
    let srgb = |c: u8| {
        let v = c as f32 / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    let got = reflectance_at_uv(&scene, 0.3, 0.3);
    let want = dielectric(rgb.map(srgb));
    for (g, w) in got.iter().zip(want) {
        // JPEG at quality 100 reproduces a flat colour within a step or two.
        assert!((g - w).abs() < 0.01, "{got:?} vs {want:?}");
    }
}

#[test]
fn emissive_textures_modulate_the_triangle_lights() {
    let tmp = test_dir("emissive-texture");
    let dir = tmp.path();
    // 4x1 texels: black, black, white, white.
    let png = gltf_writer::png_rgb8(
        4,
        1,
        &[[0, 0, 0], [0, 0, 0], [255, 255, 255], [255, 255, 255]],
    );
    let mut tri = Primitive::triangles(
        vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
        vec![0, 1, 2],
    );
    tri.material = Some(0);
    tri.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let asset = Asset {
        materials: vec![Material {
            emissive: [1.0, 1.0, 1.0],
            emissive_texture: Some(0),
            ..Material::dielectric("sign", [0.1, 0.1, 0.1])
        }],
        images: vec![png],
        ..one_mesh(tri, vec![mesh_node(0)], vec![0])
    };
    let file = gltf_writer::write(dir, "sign", &asset, Container::Glb);
    let scene = load(dir, &gltf_shape(&file, ""));
    assert!(
        scene.scene.load_report().warnings.is_empty(),
        "{:?}",
        scene.scene.load_report().warnings
    );
    assert_eq!(scene.scene.counts().area_lights, 1);
    // Hits: u = x / 2, so x = 0.5 is in the black half, x = 1.5 in the white.
    let le_at = |x: f32, y: f32| {
        let hit = scene
            .scene
            .intersect(&Ray::new(Vec3::new(x, y, 10.0), Vec3::NEG_Z))
            .unwrap();
        let light = &scene.scene.lights()[hit.light.expect("emissive").get() as usize];
        light.l(hit.p(), hit.n(), hit.texture.uv, Vec3::Z).r
    };
    assert!(le_at(0.5, 0.5).abs() < 1e-6);
    assert!((le_at(1.5, 0.2) - 1.0).abs() < 1e-5);
    // Light samples carry the texel at the sampled point.
    let light = &scene.scene.lights()[0];
    let ctx = lumis_core::LightSampleContext::at(Vec3::new(0.7, 0.7, 1.0));
    let (mut dark, mut bright) = (0, 0);
    for i in 0..64 {
        let u = lumis_core::Vec2::new((i % 8) as f32 / 8.0 + 0.06, (i / 8) as f32 / 8.0 + 0.06);
        let s = light.sample_li(&ctx, u).expect("faces the point");
        let texel_u = s.p.p.x / 2.0;
        if (0.13..0.37).contains(&texel_u) {
            assert!(s.l.r.abs() < 1e-6, "{s:?}");
            dark += 1;
        } else if (0.63..0.87).contains(&texel_u) {
            assert!((s.l.r - 1.0).abs() < 1e-5, "{s:?}");
            bright += 1;
        }
    }
    assert!(dark > 0 && bright > 0, "{dark} {bright}");
}

/// A normal texture tilts the surface as glTF means it: its x along +u and
/// its y toward the image's up (-v), whichever way the uvs run.
#[test]
fn a_normal_texture_tilts_toward_u_and_the_images_up() {
    let tmp = test_dir("normal-texture");
    let dir = tmp.path();
    let s = 30f32.to_radians().sin();
    let texel = |x: f32, y: f32| -> [u8; 3] {
        [x, y, (1.0 - x * x - y * y).sqrt()].map(|c| ((c * 0.5 + 0.5) * 255.0).round() as u8)
    };
    let upright = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let mirrored = [[1.0, 0.0], [0.0, 0.0], [1.0, 1.0]];
    // The triangle's uvs, the map's tilt, and where the normal must lean.
    let cases = [
        (upright, (s, 0.0), Vec3::X),
        (upright, (0.0, s), Vec3::NEG_Y),
        (mirrored, (s, 0.0), Vec3::NEG_X),
    ];
    for (i, (uvs, (x, y), lean)) in cases.into_iter().enumerate() {
        let mut tri = triangle();
        tri.material = Some(0);
        tri.uvs = Some(uvs.to_vec());
        let asset = Asset {
            materials: vec![Material {
                normal_texture: Some((0, 1.0)),
                ..Material::dielectric("bumpy", [1.0; 3])
            }],
            images: vec![gltf_writer::png_rgb8(1, 1, &[texel(x, y)])],
            ..one_mesh(tri, vec![mesh_node(0)], vec![0])
        };
        let file = gltf_writer::write(dir, &format!("bumpy{i}"), &asset, Container::Glb);
        let scene = load(dir, &gltf_shape(&file, ""));
        let hit = scene
            .scene
            .intersect(&Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z))
            .expect("hit");
        // Seen from straight above, lit from 56 degrees off the normal (the
        // mirror facet sends light from the other side to the map's facet
        // too, so the two differ by about 10%).
        let f_toward = |d: Vec3| f_at_hit(&hit, Vec3::Z, (Vec3::Z + 1.5 * d).normalize());
        let at = format!("case {i}: leaning to {lean}");
        assert!(f_toward(lean) > 1.05 * f_toward(-lean), "{at}");
        // The other axis stays (nearly: the texel's 8 bits) symmetric.
        let side = lean.cross(Vec3::Z);
        let (a, b) = (f_toward(side), f_toward(-side));
        assert!((a - b).abs() < 0.01 * a, "{at}: {a} {b}");
    }
}
