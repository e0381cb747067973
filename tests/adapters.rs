//! BSDF adapters from scene files: `twosided` and `normalmap` name a
//! `[[bsdf]]` declared
//! before it; its mistakes are located errors.

use lumis_core::{Ray, Scene, Vec3};
use lumis_tests::{f_at_hit, load_error, render_toml, scenes_dir};

/// A diffuse quad seen from behind (its front faces away from the camera)
/// under a light behind the camera, with `bsdfs` declared.
fn scene(bsdfs: &str, quad_bsdf: &str) -> String {
    format!(
        r#"seed = 1
[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "sobol"
spp = 4
[integrator]
type = "path"
max_depth = 3
{bsdfs}
[[bsdf]]
name = "black"
type = "diffuse"
reflectance = 0.0
[[shape]]
type = "quad"
corner = [-1.0, -1.0, 0.0]
edge_u = [0.0, 2.0, 0.0]
edge_v = [2.0, 0.0, 0.0]
bsdf = "{quad_bsdf}"
[[shape]]
type = "sphere"
center = [0.0, 0.0, 5.0]
radius = 0.5
bsdf = "black"
emission = {{ radiance = 20.0 }}
"#
    )
}

const WHITE: &str = "[[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 0.5\n";

#[test]
fn twosided_shows_the_back_of_a_one_sided_bsdf() {
    let one_sided = render_toml(&scene(WHITE, "white"), &[], 2);
    assert_eq!(
        one_sided.image.mean(),
        [0.0; 3],
        "one-sided: black from behind"
    );
    let twosided =
        format!("{WHITE}[[bsdf]]\nname = \"both\"\ntype = \"twosided\"\nbsdf = \"white\"\n");
    let both = render_toml(&scene(&twosided, "both"), &[], 2);
    assert!(both.image.mean()[0] > 0.0);
    // The same as diffuse's own two_sided flag, to the bit: both mirror
    // the directions to the front.
    let flag =
        "[[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 0.5\ntwo_sided = true\n";
    let flagged = render_toml(&scene(flag, "white"), &[], 2);
    assert_eq!(both.image.pixels, flagged.image.pixels);
}

#[test]
fn twosided_mistakes_are_located_errors() {
    let later =
        format!("[[bsdf]]\nname = \"both\"\ntype = \"twosided\"\nbsdf = \"white\"\n{WHITE}");
    let err = load_error(&scene(&later, "both"));
    assert!(
        err.starts_with("bad.toml:")
            && err.contains("bsdf \"both\" (type = \"twosided\") key 'bsdf'")
            && err.contains("no [[bsdf]] named \"white\" is declared before this one"),
        "{err}"
    );
    let glass = "[[bsdf]]\nname = \"glass\"\ntype = \"dielectric\"\n[[bsdf]]\nname = \"both\"\ntype = \"twosided\"\nbsdf = \"glass\"\n";
    let err = load_error(&scene(glass, "both"));
    assert!(
        err.contains("key 'bsdf'") && err.contains("the inner BSDF transmits"),
        "{err}"
    );
}

/// A quad facing +z (u along +x, v along +y) under a rough metal with a
/// constant normal map of `normals`.
fn normal_mapped(normals: [f32; 3]) -> String {
    let shape = "[[shape]]\ntype = \"quad\"\ncorner = [-1.0, -1.0, 0.0]\nedge_u = [2.0, 0.0, 0.0]\nedge_v = [0.0, 2.0, 0.0]\nbsdf = \"bumpy\"\n";
    let metal = "[[bsdf]]\nname = \"metal\"\ntype = \"conductor\"\nroughness = 0.3\n";
    let bumpy = format!("[[bsdf]]\nname = \"bumpy\"\ntype = \"normalmap\"\nbsdf = \"metal\"\nnormals = {normals:?}\n");
    let head = scene("", "metal");
    let head = &head[..head.find("[[bsdf]]").unwrap()];
    format!("{head}{metal}{bumpy}{shape}")
}

#[test]
fn normalmap_leans_toward_u_and_the_images_up_in_a_scene_file() {
    let registry = lumis_app::builtin_registry().unwrap();
    let (s, c) = (0.5f32.sqrt() * 0.5, 0.5 + 0.5 * 0.5f32.sqrt());
    for (normals, lean) in [
        ([0.5 + s, 0.5, c], Vec3::X),
        ([0.5 - s, 0.5, c], Vec3::NEG_X),
        ([0.5, 0.5 + s, c], Vec3::NEG_Y),
    ] {
        let toml = normal_mapped(normals);
        let scene =
            lumis_scene::load_str(&toml, &scenes_dir().join("n.toml"), &[], &registry).unwrap();
        let hit = scene
            .scene
            .intersect(&Ray::new(Vec3::new(0.2, 0.3, 1.0), Vec3::NEG_Z))
            .expect("hit");
        // Seen and lit from the same side, 39 and 56 degrees off the
        // normal: the metal's highlight is nearer when the map leans that
        // way (the mirror facet reflects a virtual copy of it the other way,
        // so the two differ by about 20%).
        let from = |d: Vec3| {
            f_at_hit(
                &hit,
                (Vec3::Z + 0.8 * d).normalize(),
                (Vec3::Z + 1.5 * d).normalize(),
            )
        };
        let (near, far) = (from(lean), from(-lean));
        assert!(
            near > 1.1 * far,
            "{normals:?} leaning to {lean}: {near} {far}"
        );
    }
}

#[test]
fn normalmap_mistakes_are_located_errors() {
    let glass = "[[bsdf]]\nname = \"glass\"\ntype = \"dielectric\"\n[[bsdf]]\nname = \"bumpy\"\ntype = \"normalmap\"\nbsdf = \"glass\"\n";
    let err = load_error(&scene(glass, "bumpy"));
    assert!(
        err.contains("key 'bsdf'") && err.contains("the inner BSDF transmits"),
        "{err}"
    );
    let bad = format!("{WHITE}[[bsdf]]\nname = \"bumpy\"\ntype = \"normalmap\"\nbsdf = \"white\"\nnormals = [0.5, 1.5, 1.0]\n");
    let err = load_error(&scene(&bad, "bumpy"));
    assert!(
        err.contains("key 'normals'") && err.contains("must be in [0, 1]"),
        "{err}"
    );
}
