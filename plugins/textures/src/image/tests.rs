//! The image plugin through the registry: files of each format, encodings,
//! and the errors of bad input.

use std::path::Path;

use lumis_core::doc;
use lumis_core::entity::TYPE_KEY;
use lumis_core::{Location, PluginEntity, PluginKind, Registry, Rgb, Texture, TextureQuery, Vec2};

fn registry() -> Registry {
    let mut registry = Registry::new();
    crate::register(&mut registry).unwrap();
    registry
}

/// The texture a scene table of `text` (written in `dir`) describes.
fn create(dir: &Path, text: &str) -> lumis_core::Result<std::sync::Arc<dyn Texture>> {
    let scene = dir.join("scene.toml");
    let table = doc::parse(text, scene.to_str().unwrap()).unwrap();
    let entity = PluginEntity::from_table(
        PluginKind::Texture,
        "texture \"t\"",
        table,
        Location::Builtin,
        TYPE_KEY,
    )?;
    registry().create::<dyn Texture>(&entity, ())
}

/// 2 x 1 PNG: 8-bit sRGB values 0 and 188 (linear 0 and 0.5029).
fn write_png(path: &Path) {
    lumis_image::write_rgb8_png(path, 2, 1, &[0, 0, 0, 188, 188, 188]).unwrap();
}

fn at(t: &dyn Texture, u: f32, v: f32) -> Rgb {
    t.eval(&TextureQuery::at(Vec2::new(u, v)))
}

#[test]
fn png_decodes_srgb_unless_told_linear() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("two.png"));
    let srgb = create(
        dir.path(),
        "type = \"image\"\nfilename = \"two.png\"\nfilter = \"nearest\"\n",
    )
    .unwrap();
    assert_eq!(at(&*srgb, 0.25, 0.5), Rgb::BLACK);
    assert!((at(&*srgb, 0.75, 0.5).g - 0.502_886).abs() < 1e-5);
    let linear = create(
        dir.path(),
        "type = \"image\"\nfilename = \"two.png\"\nfilter = \"nearest\"\nencoding = \"linear\"\n",
    )
    .unwrap();
    assert_eq!(at(&*linear, 0.75, 0.5), Rgb::splat(188.0 / 255.0));
}

/// Texels a host decoded (a glTF asset's image) make the texture the file
/// does, and `wrap_v` wraps v alone; a table with neither a filename nor
/// texels, or with both, is refused at the key.
#[test]
fn decoded_texels_make_the_texture_their_file_makes() {
    use lumis_core::doc::{Table, Value};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.png");
    write_png(&path);
    let from_file = create(dir.path(), "type = \"image\"\nfilename = \"two.png\"\n").unwrap();
    let texels = lumis_image::texture_decode::read(&path).unwrap();
    let with = |entries: Vec<(&str, Value)>| {
        let table = Table::built(&Location::Builtin, entries);
        let entity = PluginEntity::new(
            PluginKind::Texture,
            "asset texture",
            "image",
            table,
            Location::Builtin,
        );
        registry().create::<dyn Texture>(&entity, ())
    };
    let image = || Value::Image(std::sync::Arc::new(texels.clone()));
    let from_texels = with(vec![("texels", image())]).unwrap();
    for (u, v) in [(0.1, 0.5), (0.5, 0.5), (0.9, 0.2), (1.3, -0.4)] {
        assert_eq!(at(&*from_texels, u, v), at(&*from_file, u, v), "({u}, {v})");
    }
    // One column, two rows (black over grey): v = 1.2 is the grey row
    // clamped and the black one repeated; u repeats either way.
    let column = lumis_core::DecodedImage {
        width: 1,
        height: 2,
        values: lumis_core::ImageValues::Bytes(vec![[0; 3], [188; 3]]),
    };
    let column = |wrap_v: &str| {
        with(vec![
            ("texels", Value::Image(std::sync::Arc::new(column.clone()))),
            ("filter", "nearest".into()),
            ("wrap_v", wrap_v.into()),
        ])
        .unwrap()
    };
    assert_eq!(at(&*column("repeat"), 5.5, 1.2), Rgb::BLACK);
    assert!(at(&*column("clamp"), 5.5, 1.2).g > 0.5);
    let neither = with(vec![]).err().unwrap().to_string();
    assert!(
        neither.contains("filename") && neither.contains("required"),
        "{neither}"
    );
    let both = with(vec![("texels", image()), ("filename", "two.png".into())])
        .err()
        .unwrap()
        .to_string();
    assert!(
        both.contains("texels") && both.contains("not both"),
        "{both}"
    );
}

/// An 8-bit image keeps its bytes, 3 a texel (and a table of 256 linear
/// values), and reads as the float decoding of each byte; an EXR keeps
/// its floats.
#[test]
fn eight_bit_images_take_three_bytes_a_texel() {
    use super::{ImageFilter, ImageTexture, Wrap};
    use lumis_core::UvTransform;
    let pixels: Vec<u8> = (0..64 * 32 * 3).map(|i| (i * 37 % 256) as u8).collect();
    let png = {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("noise.png");
        lumis_image::write_rgb8_png(&path, 64, 32, &pixels).unwrap();
        std::fs::read(path).unwrap()
    };
    let texture = |filter| {
        ImageTexture::new(
            lumis_image::texture_decode::decode(&png).unwrap(),
            super::Encoding::Srgb,
            [Wrap::Repeat; 2],
            filter,
            UvTransform::default(),
            Rgb::WHITE,
        )
    };
    let bilinear = texture(ImageFilter::Bilinear);
    assert_eq!(bilinear.byte_size(), 64 * 32 * 3 + 256 * 4);
    let texel = |x: usize, y: usize| {
        let byte = |c: usize| {
            lumis_image::texture_decode::srgb_to_linear(pixels[(y * 64 + x) * 3 + c] as f32 / 255.0)
        };
        Rgb::new(byte(0), byte(1), byte(2))
    };
    for (x, y) in [(0, 0), (17, 5), (63, 31)] {
        let uv = Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0);
        assert_eq!(
            bilinear
                .texels()
                .texel(x as i64, y as i64, [Wrap::Repeat; 2]),
            texel(x, y)
        );
        let (got, want) = (at(&bilinear, uv.x, uv.y), texel(x, y));
        assert!(
            (got - want).max_component() < 1e-6 && (want - got).max_component() < 1e-6,
            "{got:?} against {want:?}"
        );
    }
    // The mip levels above the image are float, a third as many texels.
    let mipmapped = texture(ImageFilter::Trilinear);
    assert!(mipmapped.byte_size() < 64 * 32 * (3 + 12 / 3 + 1));
}

#[test]
fn exr_is_linear_and_keeps_values_above_one() {
    let dir = tempfile::tempdir().unwrap();
    let mut image = lumis_image::Image::new(1, 2);
    image.set(0, 0, [2.5, 0.25, 0.0]);
    image.set(0, 1, [0.5, 0.5, 0.5]);
    lumis_image::write_exr(&dir.path().join("hdr.exr"), &image).unwrap();
    let t = create(
        dir.path(),
        "type = \"image\"\nfilename = \"hdr.exr\"\nfilter = \"nearest\"\n",
    )
    .unwrap();
    assert_eq!(at(&*t, 0.5, 0.25), Rgb::new(2.5, 0.25, 0.0));
    assert_eq!(at(&*t, 0.5, 0.75), Rgb::splat(0.5));
}

#[test]
fn uv_transform_applies_before_the_lookup() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("two.png"));
    let t = create(
        dir.path(),
        "type = \"image\"\nfilename = \"two.png\"\nfilter = \"nearest\"\nuv_offset = [0.5, 0.0]\n",
    )
    .unwrap();
    // u = 0.25 is looked up at 0.75: the second texel.
    assert!(at(&*t, 0.25, 0.5).g > 0.5);
}

#[test]
fn bad_files_are_errors_naming_the_key_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let err = create(dir.path(), "type = \"image\"\nfilename = \"missing.png\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("texture \"t\" (type = \"image\") key 'filename'")
            && err.contains("missing.png")
            && err.contains("cannot read the file"),
        "{err}"
    );
    std::fs::write(dir.path().join("notes.png"), "not an image").unwrap();
    let err = create(dir.path(), "type = \"image\"\nfilename = \"notes.png\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("notes.png") && err.contains("not a PNG, JPEG or EXR image"),
        "{err}"
    );
    let err = create(
        dir.path(),
        "type = \"image\"\nfilename = \"notes.png\"\nwrap = \"tile\"\n",
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("\"repeat\", \"mirror\", \"clamp\""), "{err}");
}
