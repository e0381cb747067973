//! Textures from scene files: a constant texture renders what the
//! untextured BSDF renders, to the bit; textured parameters of a scene and
//! their errors name the file, key and what was expected.

use lumis_tests::{load_error, render_toml, scenes_dir};

/// A diffuse quad filling the view under a quad light, its reflectance
/// given by `reflectance` (with any `[[texture]]`s in `textures`).
fn scene(textures: &str, reflectance: &str) -> String {
    format!(
        r#"seed = 3
[film]
resolution = [24, 16]
[camera]
type = "perspective"
origin = [0.0, 1.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 50.0
[sampler]
type = "sobol"
spp = 8
[integrator]
type = "path"
max_depth = 4
{textures}
[[bsdf]]
name = "floor"
type = "diffuse"
reflectance = {reflectance}
[[bsdf]]
name = "black"
type = "diffuse"
reflectance = 0.0
[[shape]]
type = "quad"
corner = [-2.0, 0.0, 2.0]
edge_u = [4.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -4.0]
bsdf = "floor"
[[shape]]
type = "quad"
corner = [-0.5, 2.0, 0.5]
edge_u = [0.0, 0.0, -1.0]
edge_v = [1.0, 0.0, 0.0]
bsdf = "black"
emission = {{ radiance = 5.0 }}
"#
    )
}

#[test]
fn a_constant_texture_renders_the_untextured_bsdf_bit_for_bit() {
    let plain = render_toml(&scene("", "[0.3, 0.5, 0.7]"), &[], 2);
    let constant = render_toml(
        &scene(
            "[[texture]]\nname = \"c\"\ntype = \"constant\"\nvalue = [0.3, 0.5, 0.7]\n",
            "{ texture = \"c\" }",
        ),
        &[],
        2,
    );
    assert!(plain.image.mean()[0] > 0.0);
    assert_eq!(plain.image.pixels, constant.image.pixels);
    // A checkerboard of two equal colours is the same constant.
    let checks = render_toml(
        &scene(
            "[[texture]]\nname = \"c\"\ntype = \"checkerboard\"\ncolor0 = [0.3, 0.5, 0.7]\ncolor1 = [0.3, 0.5, 0.7]\nuv_scale = [3.0, 3.0]\n",
            "{ texture = \"c\" }",
        ),
        &[],
        2,
    );
    assert_eq!(plain.image.pixels, checks.image.pixels);
}

#[test]
fn a_checkerboard_changes_the_image_where_its_squares_are() {
    let plain = render_toml(&scene("", "0.5"), &[], 2);
    let checks = render_toml(
        &scene(
            "[[texture]]\nname = \"c\"\ntype = \"checkerboard\"\ncolor0 = 0.5\ncolor1 = 0.1\n",
            "{ texture = \"c\" }",
        ),
        &[],
        2,
    );
    let darker = plain
        .image
        .pixels
        .iter()
        .zip(&checks.image.pixels)
        .filter(|(p, c)| c[1] < p[1])
        .count();
    // The quad fills most of the view; about half of it is color1.
    let n = plain.image.pixels.len();
    assert!(darker > n / 5 && darker < 4 * n / 5, "{darker} of {n}");
}

#[test]
fn bad_texture_references_are_located_errors() {
    let err = load_error(&scene("", "{ texture = \"wood\" }"));
    assert!(
        err.starts_with("bad.toml:")
            && err.contains("bsdf \"floor\" (type = \"diffuse\") key 'reflectance'")
            && err.contains("unknown texture \"wood\"; the scene declares no [[texture]]"),
        "{err}"
    );
    let err = load_error(&scene(
        "[[texture]]\nname = \"a\"\ntype = \"constant\"\nvalue = 1\n[[texture]]\nname = \"a\"\ntype = \"constant\"\nvalue = 1\n",
        "0.5",
    ));
    assert!(
        err.contains("a [[texture]] named \"a\" already exists"),
        "{err}"
    );
    let err = load_error(&scene(
        "[[texture]]\nname = \"img\"\ntype = \"image\"\nfilename = \"no-such-image.png\"\n",
        "{ texture = \"img\" }",
    ));
    assert!(
        err.contains("texture \"img\" (type = \"image\") key 'filename'")
            && err.contains("no-such-image.png")
            && err.contains("cannot read the file"),
        "{err}"
    );
    // An emission names the scene's textures like a BSDF...
    let err = load_error(&scene("", "0.5").replace(
        "emission = { radiance = 5.0 }",
        "emission = { radiance = { texture = \"c\" } }",
    ));
    assert!(
        err.contains("emission (type = \"quad\") key 'radiance'")
            && err.contains("unknown texture \"c\""),
        "{err}"
    );
    // ... and an environment's radiance takes no texture.
    let err = load_error(
        &(scene(
            "[[texture]]\nname = \"c\"\ntype = \"constant\"\nvalue = 1\n",
            "0.5",
        ) + "[[light]]\ntype = \"constant\"\nradiance = { texture = \"c\" }\n"),
    );
    assert!(
        err.contains("'radiance'") && err.contains("this parameter takes no texture"),
        "{err}"
    );
    let err = load_error(&scene(
        "[[texture]]\ntype = \"constant\"\nvalue = 1\n",
        "0.5",
    ));
    assert!(
        err.contains("[[texture]] #0 needs a name = \"...\" that BSDF parameters refer to"),
        "{err}"
    );
}

#[test]
fn the_example_scene_loads() {
    let registry = lumis_app::builtin_registry().unwrap();
    let text = lumis_tests::read_scene("textured-quads.toml");
    let path = scenes_dir().join("textured-quads.toml");
    lumis_scene::load_str(&text, &path, &[], &registry).unwrap_or_else(|e| panic!("{e}"));
}

/// A floor receding to the horizon under a white sky, its reflectance an
/// image repeated 1024 times, lit so that each pixel is exactly its
/// texture's value (one bounce, cosine-sampled diffuse). A pixel there
/// covers several repeats of the image, so at one sample per pixel a
/// bilinear lookup picks one texel and aliases, while the
/// filters driven by the camera's pixel footprint average the texels the
/// pixel covers.
fn receding_floor(filter: &str) -> Vec<f32> {
    let image = scenes_dir().join("textures/quadrants.png");
    let image = image.display();
    let toml = format!(
        r#"seed = 1
[film]
resolution = [48, 32]
[camera]
type = "perspective"
origin = [0.0, 0.5, 0.0]
target = [0.0, 0.45, -1.0]
fov = 40.0
[sampler]
type = "independent"
spp = 1
[integrator]
type = "path"
max_depth = 2
strategy = "bsdf"
[[texture]]
name = "tiles"
type = "image"
filename = "{image}"
filter = "{filter}"
uv_scale = [1024.0, 1024.0]
[[bsdf]]
name = "floor"
type = "diffuse"
reflectance = {{ texture = "tiles" }}
[[shape]]
type = "quad"
corner = [-50.0, 0.0, 1.0]
edge_u = [100.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -100.0]
bsdf = "floor"
[[light]]
type = "constant"
radiance = 1.0
"#
    );
    let out = render_toml(&toml, &[], 2);
    // The far floor: the rows just below the horizon.
    let (w, h) = (out.image.width, out.image.height);
    (h / 2 + 2..h / 2 + 8)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| out.image.pixels[y * w + x][1])
        .collect()
}

fn mean_and_variance(v: &[f32]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / n;
    let var = v.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

#[test]
fn the_pixel_footprint_filters_distant_texels() {
    let (bilinear_mean, bilinear_var) = mean_and_variance(&receding_floor("bilinear"));
    for filter in ["trilinear", "ewa"] {
        let (mean, var) = mean_and_variance(&receding_floor(filter));
        // The same average colour, without the aliasing.
        assert!(
            var < 0.01 * bilinear_var && bilinear_var > 0.0,
            "{filter}: variance {var} against bilinear's {bilinear_var} (means {mean}, {bilinear_mean})"
        );
        assert!(
            (mean - bilinear_mean).abs() < 4.0 * (bilinear_var / 288.0).sqrt(),
            "{filter}: mean {mean} against bilinear's {bilinear_mean}"
        );
    }
}

/// The floor of [`scene`] as a microfacet BSDF of type `bsdf` whose
/// `roughness` is `roughness`.
fn rough_scene(textures: &str, bsdf: &str, roughness: &str) -> String {
    scene(textures, "0.5").replacen(
        "type = \"diffuse\"\nreflectance = 0.5",
        &format!("type = \"{bsdf}\"\nroughness = {roughness}"),
        1,
    )
}

/// Roughness textures: a constant one renders the constant roughness to
/// the bit (the textured lobe is the fixed one, evaluated per hit), and a
/// checkerboard of two roughnesses changes the image.
#[test]
fn every_microfacet_bsdf_takes_a_roughness_texture() {
    let constant = "[[texture]]\nname = \"r\"\ntype = \"constant\"\nvalue = 0.3\n";
    let checks =
        "[[texture]]\nname = \"r\"\ntype = \"checkerboard\"\ncolor0 = 0.05\ncolor1 = 0.6\n";
    for bsdf in ["conductor", "plastic", "dielectric"] {
        let plain = render_toml(&rough_scene("", bsdf, "0.3"), &[], 2);
        let textured = render_toml(&rough_scene(constant, bsdf, "{ texture = \"r\" }"), &[], 2);
        assert!(plain.image.mean().iter().any(|&c| c > 0.0), "{bsdf}");
        assert_eq!(plain.image.pixels, textured.image.pixels, "{bsdf}");
        let checked = render_toml(&rough_scene(checks, bsdf, "{ texture = \"r\" }"), &[], 2);
        assert_ne!(plain.image.pixels, checked.image.pixels, "{bsdf}");
    }
}

/// The other textured parameters: a constant texture renders the constant
/// to the bit.
#[test]
fn colour_and_exponent_parameters_take_textures() {
    for (bsdf, key, value) in [
        ("blinn", "reflectance", "0.7"),
        ("blinn", "exponent", "40.0"),
        ("plastic", "specular_reflectance", "0.6"),
    ] {
        let floor = |textures: &str, value: &str| {
            scene(textures, "0.5").replacen(
                "type = \"diffuse\"\nreflectance = 0.5",
                &format!("type = \"{bsdf}\"\n{key} = {value}"),
                1,
            )
        };
        let constant = format!("[[texture]]\nname = \"t\"\ntype = \"constant\"\nvalue = {value}\n");
        let plain = render_toml(&floor("", value), &[], 2);
        let textured = render_toml(&floor(&constant, "{ texture = \"t\" }"), &[], 2);
        assert!(plain.image.mean().iter().any(|&c| c > 0.0), "{bsdf} {key}");
        assert_eq!(plain.image.pixels, textured.image.pixels, "{bsdf} {key}");
    }
}

/// A shape's emission takes a texture too: a constant one renders the
/// constant radiance to the bit, and a sphere light, which has no texture
/// coordinates of its own to offer, refuses one by name.
#[test]
fn an_emitting_quad_takes_a_radiance_texture() {
    let emitting = |textures: &str, radiance: &str| {
        scene(textures, "0.5").replace(
            "emission = { radiance = 5.0 }",
            &format!("emission = {{ radiance = {radiance} }}"),
        )
    };
    let constant = "[[texture]]\nname = \"glow\"\ntype = \"constant\"\nvalue = 5.0\n";
    let plain = render_toml(&emitting("", "5.0"), &[], 2);
    let textured = render_toml(&emitting(constant, "{ texture = \"glow\" }"), &[], 2);
    assert!(plain.image.mean()[0] > 0.0);
    assert_eq!(plain.image.pixels, textured.image.pixels);
    // Half the panel dark: less light on the floor.
    let checks = "[[texture]]\nname = \"glow\"\ntype = \"checkerboard\"\ncolor0 = 5.0\ncolor1 = 0.0\nuv_scale = [2.0, 1.0]\n";
    let half = render_toml(&emitting(checks, "{ texture = \"glow\" }"), &[], 2);
    let (full, part) = (plain.image.mean()[1], half.image.mean()[1]);
    assert!(
        part < 0.75 * full && part > 0.25 * full,
        "{part} against {full}"
    );

    let sphere = scene(constant, "0.5")
        + "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 1.0, 0.0]\nradius = 0.2\nbsdf = \"black\"\nemission = { radiance = { texture = \"glow\" } }\n";
    let err = load_error(&sphere);
    assert!(
        err.contains("radiance") && err.contains("quads and triangles"),
        "{err}"
    );
}
