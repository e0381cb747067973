//! A fingerprint of what a scene renders, so that a saved render (a
//! checkpoint, a reference) is continued only with the scene it came from.
//!
//! It hashes the scene's meaning, not its text: the parsed document after
//! `--set` overrides, tables with their keys in sorted order, so comments,
//! whitespace, key order and number spelling (`1e3` or `1000.0`) do not
//! count; and the bytes of every file the document names with a `file` or
//! `filename` key (meshes, glTF files, measured BRDF tables, image textures,
//! environment maps), found where the loader finds it
//! ([`lumis_core::Location::resolve`]). It leaves out what a render
//! records on its own or what does not change the image: `seed`,
//! `sampler.spp` and `film.output`. Not covered: files that a named file
//! itself refers to (a glTF's external buffers), and the code of plugin
//! libraries in `[plugins] load`, which count by their path only (a
//! rebuild, whose bytes differ, is not another scene).

use std::io::{BufRead, Read};
use std::path::Path;

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, Result};
use lumis_files::{open_bounded, FileKind, GIB};

use crate::document::SceneDocument;

/// FNV-1a 64 (Fowler, Noll, Vo): stable across Rust versions and
/// platforms, unlike `DefaultHasher`, so a hash written today still matches
/// tomorrow.
#[derive(Debug, Clone, Copy)]
pub struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// Writes the length first, so that consecutive fields cannot run into
    /// each other ("ab" + "c" differs from "a" + "bc").
    fn write_field(&mut self, bytes: &[u8]) {
        self.write(&(bytes.len() as u64).to_le_bytes());
        self.write(bytes);
    }

    /// Writes a file's size, then its bytes, read in pieces: a mesh can be
    /// larger than is worth holding twice.
    fn write_file(&mut self, path: &Path) -> std::result::Result<(), String> {
        let (file, size) = open_bounded(path, HASHED_FILE)?;
        self.write(&size.to_le_bytes());
        let mut reader = std::io::BufReader::new(file.take(HASHED_FILE.max_bytes));
        loop {
            let chunk = reader
                .fill_buf()
                .map_err(|e| format!("cannot read '{}': {e}", path.display()))?;
            if chunk.is_empty() {
                return Ok(());
            }
            let n = chunk.len();
            self.write(chunk);
            reader.consume(n);
        }
    }

    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// The hash of the scene file at `path` with `overrides` applied, as the
/// module documentation describes ([`SceneDocument::hash`]).
pub fn scene_hash(path: &Path, overrides: &[String]) -> Result<u64> {
    SceneDocument::read(path)?
        .with_overrides(overrides.iter().cloned())
        .hash()
}

/// The hash of the scene file at `path` as written, without the render's
/// overrides ([`SceneDocument::file_hash`]).
pub fn scene_file_hash(path: &Path) -> Result<u64> {
    SceneDocument::read(path)?.file_hash()
}

/// What a named file that cannot be read does to a hash.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Unreadable {
    Fails,
    CountsByName,
}

/// The hash of a document whose overrides are applied.
pub(crate) fn hash_document(root: &Table, unreadable: Unreadable) -> Result<u64> {
    let mut hash = Fnv1a::default();
    hash_table(&mut hash, root, &[], unreadable)?;
    Ok(hash.finish())
}

/// A file a scene names: a mesh, an asset, a measured table.
const HASHED_FILE: FileKind = FileKind::new("scene file's asset", 16 * GIB);

/// Keys left out of the hash, by their path from the root.
const NOT_HASHED: &[&[&str]] = &[&["seed"], &["sampler", "spp"], &["film", "output"]];

fn hash_table(hash: &mut Fnv1a, table: &Table, at: &[&str], unreadable: Unreadable) -> Result<()> {
    let mut entries: Vec<_> = table.entries.iter().collect();
    entries.sort_by(|a, b| a.key.cmp(&b.key));
    let mut path = at.to_vec();
    for entry in entries {
        path.push(&entry.key);
        if !NOT_HASHED.contains(&path.as_slice()) {
            hash.write(b"k");
            hash.write_field(entry.key.as_bytes());
            hash_value(hash, &entry.node, &path, unreadable)?;
        }
        path.pop();
    }
    hash.write(b"}");
    Ok(())
}

fn hash_value(hash: &mut Fnv1a, node: &Node, at: &[&str], unreadable: Unreadable) -> Result<()> {
    match &node.value {
        Value::Bool(b) => hash.write(&[b'b', *b as u8]),
        Value::Int(i) => {
            hash.write(b"i");
            hash.write(&i.to_le_bytes());
        }
        Value::Float(f) => {
            hash.write(b"f");
            hash.write(&f.to_bits().to_le_bytes());
        }
        Value::String(s) => {
            hash.write(b"s");
            hash.write_field(s.as_bytes());
            if names_a_file(at) {
                let mut bytes = *hash;
                match bytes.write_file(&node.location.resolve(s)) {
                    Ok(()) => *hash = bytes,
                    Err(_) if unreadable == Unreadable::CountsByName => hash.write(b"?"),
                    Err(e) => {
                        return Err(Error::msg(format!(
                            "{e} (named by {} in the scene, to hash it)",
                            at.join(".")
                        )))
                    }
                }
            }
        }
        Value::Array(items) => {
            hash.write(b"a");
            hash.write(&(items.len() as u64).to_le_bytes());
            for item in items {
                hash_value(hash, item, at, unreadable)?;
            }
        }
        Value::Table(table) => {
            hash.write(b"{");
            hash_table(hash, table, at, unreadable)?;
        }
        Value::Datetime(d) => {
            hash.write(b"d");
            hash.write_field(d.as_bytes());
        }
        // Texels decoded by the importer: a scene file holds none, but a
        // table built in code may.
        Value::Image(image) => {
            hash.write(b"m");
            hash.write(&(image.width as u64).to_le_bytes());
            hash.write(&(image.height as u64).to_le_bytes());
            for texel in image.floats() {
                for c in texel.to_array() {
                    hash.write(&c.to_bits().to_le_bytes());
                }
            }
        }
    }
    Ok(())
}

/// Whether a string at this key path names a file whose bytes count: a
/// shape's, camera's or measured BSDF's `file`, an image texture's or
/// environment map's `filename`.
fn names_a_file(at: &[&str]) -> bool {
    matches!(at.last(), Some(&"file" | &"filename"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hash_of(text: &str, overrides: &[&str]) -> u64 {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("mesh.obj"), b"v 0 0 0\n").unwrap();
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        scene_hash(&path, &overrides).unwrap()
    }

    #[test]
    fn meaning_counts_and_spelling_does_not() {
        let base = hash_of(
            "seed = 1\n[sampler]\ntype = \"sobol\"\nspp = 4\n[film]\nresolution = [8, 8]\n",
            &[],
        );
        // Comments, whitespace, key order, number spelling, the seed, the
        // spp and the output path do not count.
        assert_eq!(
            base,
            hash_of("# a comment\n[film]\nresolution = [ 8, 8 ]\noutput = \"x.exr\"\n[sampler]\nspp = 64 # more\ntype = \"sobol\"\n", &[])
        );
        // Values do, also when set on the command line.
        assert_ne!(
            base,
            hash_of(
                "[sampler]\ntype = \"sobol\"\n[film]\nresolution = [8, 9]\n",
                &[]
            )
        );
        assert_ne!(
            base,
            hash_of(
                "[sampler]\ntype = \"sobol\"\n[film]\nresolution = [8, 8]\n",
                &["sampler.type=independent"]
            )
        );
        // Integer and float are different parameters.
        assert_ne!(hash_of("a = 1\n", &[]), hash_of("a = 1.0\n", &[]));
        assert_eq!(hash_of("a = 1000.0\n", &[]), hash_of("a = 1e3\n", &[]));
    }

    #[test]
    fn the_bytes_of_named_files_count() {
        let scene = "[[shape]]\ntype = \"obj\"\nfile = \"mesh.obj\"\n";
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, scene).unwrap();
        std::fs::write(dir.path().join("mesh.obj"), b"v 0 0 0\n").unwrap();
        let before = scene_hash(&path, &[]).unwrap();
        std::fs::write(dir.path().join("mesh.obj"), b"v 0 0 1\n").unwrap();
        assert_ne!(before, scene_hash(&path, &[]).unwrap());
        std::fs::remove_file(dir.path().join("mesh.obj")).unwrap();
        let err = scene_hash(&path, &[]).unwrap_err().to_string();
        assert!(
            err.contains("mesh.obj") && err.contains("shape.file"),
            "{err}"
        );
    }

    /// An environment map's or image texture's `filename` counts like a
    /// mesh's `file`.
    #[test]
    fn a_named_image_counts() {
        let scene = "[[light]]\ntype = \"envmap\"\nfilename = \"sky.exr\"\n";
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, scene).unwrap();
        std::fs::write(dir.path().join("sky.exr"), b"one sky").unwrap();
        let before = scene_hash(&path, &[]).unwrap();
        std::fs::write(dir.path().join("sky.exr"), b"another sky").unwrap();
        assert_ne!(before, scene_hash(&path, &[]).unwrap());
    }

    /// The scene file's own hash counts a file it cannot read by its name,
    /// where the render's hash refuses: an override may replace it.
    #[test]
    fn the_file_hash_counts_an_unreadable_file_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.toml");
        let scene = |file: &str| format!("[[shape]]\ntype = \"obj\"\nfile = \"{file}\"\n");
        std::fs::write(&path, scene("absent.obj")).unwrap();
        assert!(scene_hash(&path, &[]).is_err());
        let absent = scene_file_hash(&path).unwrap();
        assert_eq!(absent, scene_file_hash(&path).unwrap());
        std::fs::write(&path, scene("other.obj")).unwrap();
        assert_ne!(absent, scene_file_hash(&path).unwrap());
        std::fs::write(dir.path().join("other.obj"), b"v 0 0 0\n").unwrap();
        assert_eq!(
            scene_file_hash(&path).unwrap(),
            scene_hash(&path, &[]).unwrap()
        );
    }

    /// A path given with `--set` is hashed where the loader reads it: from
    /// the working directory, not beside the scene file.
    #[test]
    fn an_overridden_path_is_hashed_where_it_is_read() {
        let scene_dir = tempfile::tempdir().unwrap();
        let path = scene_dir.path().join("scene.toml");
        std::fs::write(&path, "[[shape]]\ntype = \"obj\"\nfile = \"x.obj\"\n").unwrap();
        std::fs::write(scene_dir.path().join("mesh.obj"), b"v 0 0 0\n").unwrap();
        let elsewhere = tempfile::tempdir().unwrap();
        let absolute = elsewhere.path().join("mesh.obj");
        std::fs::write(&absolute, b"v 0 0 1\n").unwrap();
        let set = |file: &str| vec![format!("shape.0.file=\"{file}\"")];
        // Relative: the working directory's file (there is none), not the
        // one beside the scene.
        let err = scene_hash(&path, &set("mesh.obj")).unwrap_err().to_string();
        assert!(err.contains("mesh.obj"), "{err}");
        assert!(!err.contains(&*scene_dir.path().to_string_lossy()), "{err}");
        assert!(scene_hash(&path, &set(&absolute.to_string_lossy())).is_ok());
    }
}
