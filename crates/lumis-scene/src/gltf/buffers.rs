//! Reading a glTF asset: the JSON (or GLB container) and its buffers.
//!
//! The `gltf` crate's `import` feature would do this but pulls in image
//! decoding; lumis reads the three buffer sources itself (the GLB binary
//! chunk, files next to the asset, base64 data URIs) and checks each
//! buffer's length against its declaration, so a truncated `.bin` is an
//! error naming the file and the buffer instead of a short read later.

use std::path::{Path, PathBuf};

use base64::Engine;
use gltf::buffer::Source;
use lumis_files::{read_bounded, read_prefix, FileKind, GIB};

/// A `.gltf` (JSON, perhaps with data URIs) or `.glb` file: GLB's length
/// field is 32 bits, and no JSON asset lumis can hold in memory is larger.
const GLTF_FILE: FileKind = FileKind::new("glTF asset", 4 * GIB);
/// An external buffer: read up to its declared `byteLength` (a file may
/// carry padding past it), which may not pass this.
const BUFFER_FILE: FileKind = FileKind::new("glTF buffer", 16 * GIB);

/// A parsed and validated glTF document with its buffer data.
pub(crate) struct Asset {
    pub document: gltf::Document,
    /// Buffer `i`'s bytes, at least as long as it declares.
    pub buffers: Vec<Vec<u8>>,
    /// The asset's path as the user wrote it, for messages.
    pub label: String,
}

impl Asset {
    /// The bytes of buffer `index`.
    pub fn buffer(&self, index: usize) -> &[u8] {
        &self.buffers[index]
    }
}

/// Reads and validates the JSON part only (cameras need no buffers).
pub(crate) fn document(
    path: &Path,
    label: &str,
) -> Result<(gltf::Document, Option<Vec<u8>>), String> {
    let bytes = read_bounded(path, GLTF_FILE)?;
    let invalid =
        |e: &dyn std::fmt::Display| format!("'{label}' is not a valid glTF 2.0 file: {e}");
    // gltf 1.4 subtracts the 12-byte GLB header from the declared length
    // without checking that it is at least that.
    if let Some(declared) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|length| u32::from_le_bytes(length.try_into().expect("4 bytes")))
    {
        if declared < 12 {
            return Err(invalid(&format!(
                "the GLB header declares a length of {declared} bytes, less than the header's own 12"
            )));
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| invalid(&e))?;
    let json = gltf.document.into_json();
    check_position_indices(&json).map_err(|e| invalid(&e))?;
    let document = gltf::Document::from_json(json).map_err(|e| invalid(&e))?;
    Ok((document, gltf.blob))
}

/// The `gltf` crate's validation indexes the accessors with each
/// primitive's `POSITION` before it checks that index (gltf-json 1.4,
/// `primitive_validate_hook`), and panics on one out of range; checked here
/// first.
fn check_position_indices(json: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::Checked;
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= accessors) {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not exist ({accessors} accessors)",
                    index.value()
                ));
            }
        }
    }
    Ok(())
}

/// Reads the asset and every buffer it declares.
pub(crate) fn load(path: &Path, label: &str) -> Result<Asset, String> {
    let (document, mut blob) = document(path, label)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut buffers = Vec::with_capacity(document.buffers().len());
    for buffer in document.buffers() {
        let what = match buffer.name() {
            Some(name) => format!("'{label}': buffer #{} (\"{name}\")", buffer.index()),
            None => format!("'{label}': buffer #{}", buffer.index()),
        };
        let data = match buffer.source() {
            Source::Bin => blob.take().ok_or_else(|| {
                format!("{what} refers to the GLB binary chunk, which is missing")
            })?,
            Source::Uri(uri) => {
                let declared = Some(buffer.length() as u64);
                read_uri(uri, &dir, BUFFER_FILE, declared).map_err(|e| format!("{what}: {e}"))?
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "{what} declares {} bytes but holds only {} (truncated?)",
                buffer.length(),
                data.len()
            ));
        }
        buffers.push(data);
    }
    Ok(Asset {
        document,
        buffers,
        label: label.to_string(),
    })
}

/// A buffer's or image's bytes from a `data:` URI or a file relative to the
/// asset: the first `declared` bytes of the file if its length is
/// declared, else all of it, within `kind`'s bound either way.
pub(crate) fn read_uri(
    uri: &str,
    dir: &Path,
    kind: FileKind,
    declared: Option<u64>,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or("a data URI must be base64 encoded (data:...;base64,...)")?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 in data URI: {e}"));
    }
    let path: PathBuf = dir.join(percent_decode(uri));
    match declared {
        Some(len) => read_prefix(&path, len, kind),
        None => read_bounded(&path, kind),
    }
}

/// URIs in glTF are percent-encoded (`my%20mesh.bin`).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decode("plain.bin"), "plain.bin");
        assert_eq!(percent_decode("odd%2"), "odd%2");
    }
}
