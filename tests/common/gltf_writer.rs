//! A minimal glTF 2.0 writer for tests and benchmarks: Khronos-style small
//! assets (meshes, primitives, materials, nodes, cameras) written as
//! `.gltf` + `.bin`, `.gltf` with a data URI, or `.glb`, so each loader
//! feature is tested on a file made for it.

use std::fmt::Write as _;
use std::path::Path;

/// One primitive's attributes.
#[derive(Debug, Clone, Default)]
pub struct Primitive {
    pub positions: Vec<[f32; 3]>,
    /// `None`: non-indexed.
    pub indices: Option<Vec<u32>>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub material: Option<usize>,
    /// glTF primitive mode; 4 = TRIANGLES.
    pub mode: u32,
    /// Write the indices as u16 instead of u32.
    pub u16_indices: bool,
}

impl Primitive {
    pub fn triangles(positions: Vec<[f32; 3]>, indices: Vec<u32>) -> Self {
        Self {
            positions,
            indices: Some(indices),
            mode: 4,
            ..Self::default()
        }
    }
}

#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub name: String,
    pub primitives: Vec<Primitive>,
}

#[derive(Debug, Clone)]
pub struct Material {
    pub name: String,
    pub base_color: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
    pub emissive: [f32; 3],
    pub double_sided: bool,
    /// Index into [`Asset::images`] (one texture per image).
    pub base_color_texture: Option<usize>,
    pub emissive_texture: Option<usize>,
    /// Index into [`Asset::images`]: roughness in green, metallic in blue.
    pub metallic_roughness_texture: Option<usize>,
    /// `KHR_texture_transform` of the base colour texture: offset,
    /// rotation (radians), scale.
    pub base_color_transform: Option<([f32; 2], f32, [f32; 2])>,
    /// Index into [`Asset::images`] of a tangent-space normal map, with
    /// its `scale`.
    pub normal_texture: Option<(usize, f32)>,
}

impl Material {
    /// A rough (roughness 1) non-metal of base colour `rgb`.
    pub fn dielectric(name: &str, rgb: [f32; 3]) -> Self {
        Self {
            name: name.into(),
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            metallic: 0.0,
            roughness: 1.0,
            emissive: [0.0; 3],
            double_sided: false,
            base_color_texture: None,
            emissive_texture: None,
            metallic_roughness_texture: None,
            base_color_transform: None,
            normal_texture: None,
        }
    }
}

#[derive(Debug, Clone, Default)]
pub struct Node {
    pub name: String,
    pub mesh: Option<usize>,
    pub camera: Option<usize>,
    /// Column-major 4x4, written as `matrix` when set.
    pub matrix: Option<[f32; 16]>,
    pub translation: Option<[f32; 3]>,
    pub scale: Option<[f32; 3]>,
    /// Quaternion x, y, z, w.
    pub rotation: Option<[f32; 4]>,
    pub children: Vec<usize>,
}

#[derive(Debug, Clone)]
pub struct Camera {
    pub name: String,
    pub yfov: f32,
}

#[derive(Debug, Clone, Default)]
pub struct Asset {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub nodes: Vec<Node>,
    pub cameras: Vec<Camera>,
    /// Root nodes of the one scene.
    pub roots: Vec<usize>,
    /// PNG or JPEG files, stored in the buffer.
    pub images: Vec<Vec<u8>>,
}

/// How the buffer is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Container {
    /// `NAME.gltf` and `NAME.bin` beside it.
    External,
    /// `NAME.gltf` with the buffer as a base64 data URI.
    DataUri,
    /// `NAME.glb` with the buffer in its binary chunk.
    Glb,
}

fn floats(v: &[f32]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// The JSON and the binary buffer of `asset`; `uri` is the buffer's URI
/// (`None` for the GLB chunk).
pub fn encode(asset: &Asset, uri: Option<&str>) -> (String, Vec<u8>) {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    // Adds a view + accessor over `bytes`; returns the accessor index.
    let mut add = |bytes: &[u8], count: usize, ty: &str, component: u32, extra: String| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(format!(
            "{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{}}}",
            bin.len(),
            bytes.len()
        ));
        bin.extend_from_slice(bytes);
        accessors.push(format!(
            "{{\"bufferView\":{},\"componentType\":{component},\"count\":{count},\"type\":\"{ty}\"{extra}}}",
            views.len() - 1
        ));
        accessors.len() - 1
    };
    let f32_bytes = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut meshes_json = Vec::new();
    for mesh in &asset.meshes {
        let mut prims = Vec::new();
        for p in &mesh.primitives {
            let flat: Vec<f32> = p.positions.iter().flatten().copied().collect();
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for q in &p.positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
            let pos = add(
                &f32_bytes(&flat),
                p.positions.len(),
                "VEC3",
                5126,
                format!(",\"min\":[{}],\"max\":[{}]", floats(&lo), floats(&hi)),
            );
            let mut attributes = format!("\"POSITION\":{pos}");
            if let Some(n) = &p.normals {
                let flat: Vec<f32> = n.iter().flatten().copied().collect();
                let a = add(&f32_bytes(&flat), n.len(), "VEC3", 5126, String::new());
                write!(attributes, ",\"NORMAL\":{a}").unwrap();
            }
            if let Some(uv) = &p.uvs {
                let flat: Vec<f32> = uv.iter().flatten().copied().collect();
                let a = add(&f32_bytes(&flat), uv.len(), "VEC2", 5126, String::new());
                write!(attributes, ",\"TEXCOORD_0\":{a}").unwrap();
            }
            let mut prim = format!("{{\"attributes\":{{{attributes}}},\"mode\":{}", p.mode);
            if let Some(indices) = &p.indices {
                let (bytes, component): (Vec<u8>, u32) = if p.u16_indices {
                    let b = indices
                        .iter()
                        .flat_map(|&i| (i as u16).to_le_bytes())
                        .collect();
                    (b, 5123)
                } else {
                    (indices.iter().flat_map(|i| i.to_le_bytes()).collect(), 5125)
                };
                let a = add(&bytes, indices.len(), "SCALAR", component, String::new());
                write!(prim, ",\"indices\":{a}").unwrap();
            }
            if let Some(m) = p.material {
                write!(prim, ",\"material\":{m}").unwrap();
            }
            prim.push('}');
            prims.push(prim);
        }
        meshes_json.push(format!(
            "{{\"name\":\"{}\",\"primitives\":[{}]}}",
            mesh.name,
            prims.join(",")
        ));
    }
    let mut images = Vec::new();
    for png in &asset.images {
        let mime = if png.starts_with(&[0xff, 0xd8]) {
            "image/jpeg"
        } else {
            "image/png"
        };
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(format!(
            "{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{}}}",
            bin.len(),
            png.len()
        ));
        bin.extend_from_slice(png);
        images.push(format!(
            "{{\"bufferView\":{},\"mimeType\":\"{mime}\"}}",
            views.len() - 1
        ));
    }
    let materials: Vec<String> = asset
        .materials
        .iter()
        .map(|m| {
            let transform = m.base_color_transform.map_or(String::new(), |(o, r, k)| {
                format!(
                    ",\"extensions\":{{\"KHR_texture_transform\":{{\"offset\":[{}],\"rotation\":{r:?},\"scale\":[{}]}}}}",
                    floats(&o),
                    floats(&k)
                )
            });
            let texture = m.base_color_texture.map_or(String::new(), |t| {
                format!(",\"baseColorTexture\":{{\"index\":{t}{transform}}}")
            });
            let metallic_roughness = m.metallic_roughness_texture.map_or(String::new(), |t| {
                format!(",\"metallicRoughnessTexture\":{{\"index\":{t}}}")
            });
            let emissive_texture = m
                .emissive_texture
                .map_or(String::new(), |t| format!(",\"emissiveTexture\":{{\"index\":{t}}}"));
            let normal_texture = m.normal_texture.map_or(String::new(), |(t, scale)| {
                format!(",\"normalTexture\":{{\"index\":{t},\"scale\":{scale:?}}}")
            });
            format!(
                "{{\"name\":\"{}\",\"pbrMetallicRoughness\":{{\"baseColorFactor\":[{}],\"metallicFactor\":{:?},\"roughnessFactor\":{:?}{texture}{metallic_roughness}}},\"emissiveFactor\":[{}],\"doubleSided\":{}{emissive_texture}{normal_texture}}}",
                m.name,
                floats(&m.base_color),
                m.metallic,
                m.roughness,
                floats(&m.emissive),
                m.double_sided
            )
        })
        .collect();
    let nodes: Vec<String> = asset
        .nodes
        .iter()
        .map(|n| {
            let mut s = format!("{{\"name\":\"{}\"", n.name);
            if let Some(m) = n.mesh {
                write!(s, ",\"mesh\":{m}").unwrap();
            }
            if let Some(c) = n.camera {
                write!(s, ",\"camera\":{c}").unwrap();
            }
            if let Some(m) = n.matrix {
                write!(s, ",\"matrix\":[{}]", floats(&m)).unwrap();
            }
            if let Some(t) = n.translation {
                write!(s, ",\"translation\":[{}]", floats(&t)).unwrap();
            }
            if let Some(r) = n.rotation {
                write!(s, ",\"rotation\":[{}]", floats(&r)).unwrap();
            }
            if let Some(k) = n.scale {
                write!(s, ",\"scale\":[{}]", floats(&k)).unwrap();
            }
            if !n.children.is_empty() {
                let c: Vec<String> = n.children.iter().map(|c| c.to_string()).collect();
                write!(s, ",\"children\":[{}]", c.join(",")).unwrap();
            }
            s.push('}');
            s
        })
        .collect();
    let cameras: Vec<String> = asset
        .cameras
        .iter()
        .map(|c| {
            format!(
                "{{\"name\":\"{}\",\"type\":\"perspective\",\"perspective\":{{\"yfov\":{:?},\"znear\":0.01}}}}",
                c.name, c.yfov
            )
        })
        .collect();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let buffer = match uri {
        Some(u) => format!("{{\"byteLength\":{},\"uri\":\"{u}\"}}", bin.len()),
        None => format!("{{\"byteLength\":{}}}", bin.len()),
    };
    let roots: Vec<String> = asset.roots.iter().map(|r| r.to_string()).collect();
    let mut json = format!(
        "{{\"asset\":{{\"version\":\"2.0\",\"generator\":\"lumis tests\"}},\"scene\":0,\"scenes\":[{{\"nodes\":[{}]}}],\"nodes\":[{}],\"meshes\":[{}],\"buffers\":[{buffer}],\"bufferViews\":[{}],\"accessors\":[{}]",
        roots.join(","),
        nodes.join(","),
        meshes_json.join(","),
        views.join(","),
        accessors.join(",")
    );
    if !materials.is_empty() {
        write!(json, ",\"materials\":[{}]", materials.join(",")).unwrap();
    }
    if !images.is_empty() {
        let textures: Vec<String> = (0..images.len())
            .map(|i| format!("{{\"source\":{i}}}"))
            .collect();
        write!(
            json,
            ",\"images\":[{}],\"textures\":[{}]",
            images.join(","),
            textures.join(",")
        )
        .unwrap();
    }
    if asset
        .materials
        .iter()
        .any(|m| m.base_color_transform.is_some())
    {
        json.push_str(",\"extensionsUsed\":[\"KHR_texture_transform\"]");
    }
    if !cameras.is_empty() {
        write!(json, ",\"cameras\":[{}]", cameras.join(",")).unwrap();
    }
    json.push('}');
    (json, bin)
}

/// Writes `asset` into `dir` as `name.gltf` (+ `name.bin`) or `name.glb`;
/// returns the file name of the asset.
pub fn write(dir: &Path, name: &str, asset: &Asset, container: Container) -> String {
    std::fs::create_dir_all(dir).unwrap();
    match container {
        Container::External => {
            let bin_name = format!("{name}.bin");
            let (json, bin) = encode(asset, Some(&bin_name));
            std::fs::write(dir.join(&bin_name), bin).unwrap();
            std::fs::write(dir.join(format!("{name}.gltf")), json).unwrap();
            format!("{name}.gltf")
        }
        Container::DataUri => {
            use base64::Engine;
            let (_, bin) = encode(asset, Some(""));
            let uri = format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bin)
            );
            let (json, _) = encode(asset, Some(&uri));
            std::fs::write(dir.join(format!("{name}.gltf")), json).unwrap();
            format!("{name}.gltf")
        }
        Container::Glb => {
            let (json, bin) = encode(asset, None);
            let mut json = json.into_bytes();
            while !json.len().is_multiple_of(4) {
                json.push(b' ');
            }
            let total = 12 + 8 + json.len() + 8 + bin.len();
            let mut out = Vec::with_capacity(total);
            out.extend_from_slice(b"glTF");
            out.extend_from_slice(&2u32.to_le_bytes());
            out.extend_from_slice(&(total as u32).to_le_bytes());
            out.extend_from_slice(&(json.len() as u32).to_le_bytes());
            out.extend_from_slice(b"JSON");
            out.extend_from_slice(&json);
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
            std::fs::write(dir.join(format!("{name}.glb")), out).unwrap();
            format!("{name}.glb")
        }
    }
}

/// A PNG of `width x height` RGB8 pixels, rows from the top.
pub fn png_rgb8(width: u32, height: u32, pixels: &[[u8; 3]]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        let flat: Vec<u8> = pixels.iter().flatten().copied().collect();
        writer.write_image_data(&flat).unwrap();
    }
    out
}
