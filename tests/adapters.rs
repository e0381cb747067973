//! BSDF adapters from scene files: `twosided` names a `[[bsdf]]` declared
//! before it; its mistakes are located errors.

use lumis_tests::{render_toml, scenes_dir};

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

fn load_error(toml: &str) -> String {
    let registry = lumis_cli::builtin_registry().unwrap();
    match lumis_scene::load_str(toml, "bad.toml", "bad", &scenes_dir(), &[], &registry) {
        Ok(_) => panic!("scene unexpectedly loaded:\n{toml}"),
        Err(e) => e.to_string(),
    }
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
