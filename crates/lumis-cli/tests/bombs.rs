//! Decompression bombs: image files a few bytes long whose headers claim
//! billions of pixels, one per format and per way lumis reads an image
//! (texture, environment map, embedded in glTF, `diff`, `denoise`,
//! `merge`). Each run is held to a 4 GiB address space, as a machine with
//! little memory would: an image whose claim were trusted would abort or
//! be killed; every one must be a clean error naming the file, the claim
//! and the limit (in a glTF asset, a warning: the importer falls back to
//! the material's factor for any texture it cannot use).

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{path_in, scratch};

/// The address space each run may use.
const MEMORY_LIMIT_KIB: u64 = 4 << 20;

/// Runs `lumis` with `args` under [`MEMORY_LIMIT_KIB`].
fn lumis_limited(args: &[&str]) -> Output {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(format!(
            "ulimit -v {MEMORY_LIMIT_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_lumis"))
        .args(args);
    command.output().expect("sh runs")
}

/// The run ended with an error (exit 1, no signal) whose message names
/// `file` and says what its header claims against which limit.
fn assert_refused(run: &Output, file: &Path, claim: &str) {
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let name = file.file_name().unwrap().to_string_lossy();
    assert!(
        stderr.contains(&*name)
            && stderr.contains(claim)
            && stderr.contains("LUMIS_MAX_IMAGE_PIXELS"),
        "expected an error naming {name} and \"{claim}\":\n{stderr}"
    );
}

fn png_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut chunk = (data.len() as u32).to_be_bytes().to_vec();
    chunk.extend_from_slice(kind);
    chunk.extend_from_slice(data);
    let mut crc_input = kind.to_vec();
    crc_input.extend_from_slice(data);
    chunk.extend_from_slice(&crc32fast::hash(&crc_input).to_be_bytes());
    chunk
}

/// A PNG of a few dozen bytes whose header claims `width` x `height` RGB
/// pixels.
fn png_bomb(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(png_chunk(b"IHDR", &ihdr));
    // A zlib stream of one empty stored block.
    png.extend(png_chunk(
        b"IDAT",
        &[
            0x78, 0x01, 0x01, 0x00, 0x00, 0xff, 0xff, 0x00, 0x00, 0x00, 0x01,
        ],
    ));
    png.extend(png_chunk(b"IEND", &[]));
    png
}

/// A baseline JPEG header whose frame claims 65535 x 65535 pixels.
fn jpeg_bomb() -> Vec<u8> {
    let mut jpeg = vec![0xff, 0xd8];
    // One quantisation table of ones.
    jpeg.extend([0xff, 0xdb, 0x00, 0x43, 0x00]);
    jpeg.extend([1u8; 64]);
    // The frame: 8-bit, 65535 lines of 65535 samples, one component.
    jpeg.extend([
        0xff, 0xc0, 0x00, 0x0b, 0x08, 0xff, 0xff, 0xff, 0xff, 0x01, 0x01, 0x11, 0x00,
    ]);
    // A DC table with one code, an AC table with one code.
    jpeg.extend([0xff, 0xc4, 0x00, 0x14, 0x00, 1]);
    jpeg.extend([0u8; 15]);
    jpeg.push(0);
    jpeg.extend([0xff, 0xc4, 0x00, 0x14, 0x10, 1]);
    jpeg.extend([0u8; 15]);
    jpeg.push(0);
    // The scan, then a little entropy-coded data.
    jpeg.extend([0xff, 0xda, 0x00, 0x08, 0x01, 0x01, 0x00, 0x00, 0x3f, 0x00]);
    jpeg.extend([0u8; 64]);
    jpeg.extend([0xff, 0xd9]);
    jpeg
}

/// Widens the data window of the EXR at `path` to 100000 x 100000 pixels
/// in its header, leaving its few bytes of pixels.
fn widen_exr(path: &Path) {
    let mut bytes = std::fs::read(path).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("an EXR header has a data window")
        + key.len()
        + 4;
    // xMin, yMin, xMax, yMax.
    bytes[at + 8..at + 12].copy_from_slice(&99_999i32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
    std::fs::write(path, bytes).unwrap();
}

/// A one-pixel EXR widened by [`widen_exr`].
fn exr_bomb(path: &Path) {
    exr::prelude::write_rgb_file(path, 1, 1, |_, _| (0.5f32, 0.5f32, 0.5f32)).unwrap();
    widen_exr(path);
}

/// A Radiance header claiming 100000 x 100000 pixels, and two bytes.
fn hdr_bomb() -> Vec<u8> {
    b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n\x02\x02".to_vec()
}

/// A scene of one textured quad lit by a point light, its texture the
/// image `texture`; or, with `envmap`, lit by that environment map.
fn scene_with(dir: &Path, texture: Option<&str>, envmap: Option<&str>) -> String {
    let mut text = String::from(
        "[film]\nresolution = [8, 8]\n\n[camera]\ntype = \"perspective\"\norigin = [0.0, 0.0, 3.0]\n\
         target = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nfov = 40.0\n\n[sampler]\n\
         type = \"independent\"\nspp = 1\n\n[integrator]\ntype = \"path\"\n\n",
    );
    let reflectance = match texture {
        Some(file) => {
            text +=
                &format!("[[texture]]\nname = \"t\"\ntype = \"image\"\nfilename = \"{file}\"\n\n");
            "{ texture = \"t\" }"
        }
        None => "0.5",
    };
    text += &format!("[[bsdf]]\nname = \"b\"\ntype = \"diffuse\"\nreflectance = {reflectance}\n\n");
    text += "[[shape]]\ntype = \"quad\"\ncorner = [-1.0, -1.0, 0.0]\nedge_u = [2.0, 0.0, 0.0]\n\
             edge_v = [0.0, 2.0, 0.0]\nbsdf = \"b\"\n\n";
    text += &match envmap {
        Some(file) => format!("[[light]]\ntype = \"envmap\"\nfilename = \"{file}\"\n"),
        None => "[[light]]\ntype = \"point\"\nposition = [0.0, 0.0, 2.0]\nintensity = 1.0\n".into(),
    };
    let path = dir.join(format!(
        "scene-{}.toml",
        texture.or(envmap).unwrap_or("plain")
    ));
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn render(dir: &Path, scene: &str) -> Output {
    let out = path_in(dir, "out.exr");
    lumis_limited(&["render", scene, "-o", &out, "-q", "--threads", "2"])
}

/// The limited runs can render at all: a scene without a bomb renders
/// under the same limit, so the refusals below are the decoders'.
#[test]
fn a_plain_scene_renders_under_the_memory_limit() {
    let tmp = scratch("bombs-plain");
    let run = render(tmp.path(), &scene_with(tmp.path(), None, None));
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn texture_bombs_are_refused() {
    let tmp = scratch("bombs-texture");
    let dir = tmp.path();
    std::fs::write(dir.join("bomb.png"), png_bomb(100_000, 100_000)).unwrap();
    std::fs::write(dir.join("bomb.jpg"), jpeg_bomb()).unwrap();
    exr_bomb(&dir.join("bomb.exr"));
    for (file, claim) in [
        ("bomb.png", "claims 100000 x 100000 pixels"),
        ("bomb.jpg", "claims 65535 x 65535 pixels"),
        ("bomb.exr", "claims 100000 x 100000 pixels"),
    ] {
        let run = render(dir, &scene_with(dir, Some(file), None));
        assert_refused(&run, &dir.join(file), claim);
    }
}

/// A PNG within the pixel limit whose header claims more bytes than its
/// deflate stream can hold.
#[test]
fn a_png_that_claims_more_than_deflate_holds_is_refused() {
    let tmp = scratch("bombs-deflate");
    let dir = tmp.path();
    std::fs::write(dir.join("dense.png"), png_bomb(8000, 8000)).unwrap();
    let run = lumis_limited(&[
        "render",
        &scene_with(dir, Some("dense.png"), None),
        "-o",
        &path_in(dir, "out.exr"),
        "-q",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("dense.png") && stderr.contains("more than its compression can hold"),
        "{stderr}"
    );
}

#[test]
fn environment_map_bombs_are_refused() {
    let tmp = scratch("bombs-envmap");
    let dir = tmp.path();
    exr_bomb(&dir.join("sky.exr"));
    std::fs::write(dir.join("sky.hdr"), hdr_bomb()).unwrap();
    for file in ["sky.exr", "sky.hdr"] {
        let run = render(dir, &scene_with(dir, None, Some(file)));
        assert_refused(&run, &dir.join(file), "claims 100000 x 100000 pixels");
    }
}

/// A PNG inside a glTF asset (a GLB's buffer view its material uses),
/// its header rewritten to claim 100000 x 65535 pixels. The importer
/// treats it as every texture it cannot use: a warning naming the asset,
/// the image and the claim, and the material's factor instead; the render
/// goes on within the memory limit.
#[test]
fn an_image_embedded_in_gltf_is_refused() {
    let tmp = scratch("bombs-gltf");
    let dir = tmp.path();
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bench");
    let mut glb = std::fs::read(bench.join("textured.glb")).unwrap();
    let png = glb
        .windows(8)
        .position(|w| w == b"\x89PNG\r\n\x1a\n")
        .expect("textured.glb embeds a PNG");
    // IHDR: length, type, then width and height; its CRC covers type and
    // data.
    let ihdr = png + 8;
    glb[ihdr + 8..ihdr + 12].copy_from_slice(&100_000u32.to_be_bytes());
    glb[ihdr + 12..ihdr + 16].copy_from_slice(&65_535u32.to_be_bytes());
    let crc = crc32fast::hash(&glb[ihdr + 4..ihdr + 21]);
    glb[ihdr + 21..ihdr + 25].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(dir.join("textured.glb"), glb).unwrap();
    std::fs::copy(bench.join("textured-gltf.toml"), dir.join("textured.toml")).unwrap();
    let run = lumis_limited(&[
        "render",
        &path_in(dir, "textured.toml"),
        "--set",
        "film.resolution=[8, 8]",
        "--spp",
        "1",
        "-o",
        &path_in(dir, "out.exr"),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: 'textured.glb'")
            && stderr.contains("image #0 (image/png): its PNG header claims 100000 x 65535 pixels")
            && stderr.contains("LUMIS_MAX_IMAGE_PIXELS"),
        "{stderr}"
    );
}

/// `diff` and `denoise` read the images they are given, `merge` the parts.
#[test]
fn image_commands_refuse_bombs() {
    let tmp = scratch("bombs-commands");
    let dir = tmp.path();
    let bomb = dir.join("bomb.exr");
    exr_bomb(&bomb);
    let fine = dir.join("fine.exr");
    exr::prelude::write_rgb_file(&fine, 1, 1, |_, _| (0.5f32, 0.5f32, 0.5f32)).unwrap();
    let (bomb_arg, fine_arg) = (bomb.display().to_string(), fine.display().to_string());
    let claim = "claims 100000 x 100000 pixels";
    assert_refused(
        &lumis_limited(&["diff", &bomb_arg, &fine_arg]),
        &bomb,
        claim,
    );
    assert_refused(
        &lumis_limited(&["diff", &fine_arg, &bomb_arg]),
        &bomb,
        claim,
    );
    let denoised = path_in(dir, "denoised.exr");
    assert_refused(
        &lumis_limited(&["denoise", &bomb_arg, "-o", &denoised]),
        &bomb,
        claim,
    );
    // A real part of a render, widened.
    let plain = scene_with(dir, None, None);
    let part = path_in(dir, "part.exr");
    let rendered = lumis_limited(&[
        "render", &plain, "--spp", "2", "--part", "0/2", "-o", &part, "-q",
    ]);
    assert!(
        rendered.status.success(),
        "{}",
        String::from_utf8_lossy(&rendered.stderr)
    );
    widen_exr(Path::new(&part));
    let merged = path_in(dir, "merged.exr");
    assert_refused(
        &lumis_limited(&["merge", &part, &part, "-o", &merged]),
        Path::new(&part),
        claim,
    );
}

/// The limit is the user's to raise or lower.
#[test]
fn the_limit_follows_the_environment() {
    let tmp = scratch("bombs-limit");
    let dir = tmp.path();
    exr::prelude::write_rgb_file(dir.join("four.exr"), 2, 2, |_, _| (0.5f32, 0.5f32, 0.5f32))
        .unwrap();
    let four = path_in(dir, "four.exr");
    let run = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["diff", &four, &four])
        .env("LUMIS_MAX_IMAGE_PIXELS", "3")
        .output()
        .unwrap();
    assert_refused(&run, &dir.join("four.exr"), "claims 2 x 2 pixels");
    let run = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["diff", &four, &four])
        .env("LUMIS_MAX_IMAGE_PIXELS", "4")
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}
