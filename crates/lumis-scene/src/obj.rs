//! Wavefront OBJ files to one triangle mesh (faces triangulated, every
//! object merged).
//!
//! `tobj` parses; lumis reads the file itself (bounded, with the OS's
//! reason on failure) and counts the lines `tobj` consumes, so a parse
//! error names its line. Materials (`mtllib`) are not read: the scene's
//! `bsdf` shades the mesh.

use std::io::{BufRead, Read};
use std::path::Path;

use lumis_core::Vec3;
use lumis_files::{read_bounded, FileKind, GIB};

use crate::triangle_mesh::TriangleMesh;

/// Far above the 100-million-triangle meshes lumis is meant to render.
const OBJ_FILE: FileKind = FileKind::new("OBJ mesh", 16 * GIB);

/// Reads `path`. Errors say what is wrong with the file and where (the
/// caller says which shape and key named it).
pub(crate) fn import(path: &Path) -> Result<TriangleMesh, String> {
    let bytes = read_bounded(path, OBJ_FILE)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    check_face_indices(&bytes).map_err(|e| format!("'{}' {e}", path.display()))?;
    let mut reader = LineCounter::new(&bytes);
    let no_materials = |_: &Path| Ok(Default::default());
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, no_materials).map_err(|e| {
        // The bytes are in memory, so a read error is a line that is not
        // UTF-8.
        let what = match e {
            tobj::LoadError::ReadError => "not UTF-8 text".to_string(),
            e => e.to_string(),
        };
        format!("'{}' line {}: {what}", path.display(), reader.line())
    })?;
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut normals = Vec::new();
    let mut all_have_normals = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as u32;
        let count = mesh.positions.len() / 3;
        for (what, values) in [
            ("vertex position", &mesh.positions),
            ("normal", &mesh.normals),
        ] {
            if let Some(bad) = values
                .chunks_exact(3)
                .find(|v| !v.iter().all(|c| c.is_finite()))
            {
                return Err(format!(
                    "'{}': {what} {bad:?} is not finite (NaN, or beyond the range of a 32-bit float)",
                    path.display()
                ));
            }
        }
        positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if mesh.normals.len() == mesh.positions.len() {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_have_normals = false;
        }
        for t in mesh.indices.chunks_exact(3) {
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= count) {
                return Err(format!(
                    "'{}': face index {bad} out of range for {count} vertices",
                    path.display()
                ));
            }
            indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if indices.is_empty() {
        return Err(format!("'{}' contains no triangles", path.display()));
    }
    Ok(TriangleMesh {
        positions,
        indices,
        normals: all_have_normals
            .then_some(normals)
            .filter(|n| !n.is_empty()),
    })
}

/// A reader over the file's bytes that counts the lines handed out.
struct LineCounter<'a> {
    rest: &'a [u8],
    /// Newlines consumed.
    newlines: usize,
    /// Whether bytes after the last newline were consumed.
    mid_line: bool,
}

impl<'a> LineCounter<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self {
            rest: bytes,
            newlines: 0,
            mid_line: false,
        }
    }

    /// The 1-based number of the line consumed last.
    fn line(&self) -> usize {
        self.newlines + usize::from(self.mid_line)
    }
}

impl Read for LineCounter<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let n = self.fill_buf()?.len().min(out.len());
        out[..n].copy_from_slice(&self.rest[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineCounter<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        Ok(self.rest)
    }

    fn consume(&mut self, n: usize) {
        let (taken, rest) = self.rest.split_at(n);
        if !taken.is_empty() {
            let newlines = taken.iter().filter(|&&b| b == b'\n').count();
            self.newlines += newlines;
            self.mid_line = if newlines == 0 {
                self.mid_line || !taken.is_empty()
            } else {
                taken.last() != Some(&b'\n')
            };
        }
        self.rest = rest;
    }
}

/// Checks that every face index names an element the file has: a
/// positive index one of the file's elements of its kind, a negative one
/// (counting back) one read before it.
///
/// `tobj` finds a bad index only when the object ends, so not its line,
/// and computes with extreme ones in arithmetic that overflows.
fn check_face_indices(bytes: &[u8]) -> Result<(), String> {
    const KINDS: [(&str, &str); 3] = [
        ("v", "vertex"),
        ("vt", "texture coordinate"),
        ("vn", "normal"),
    ];
    let text = String::from_utf8_lossy(bytes);
    let mut total = [0i64; 3];
    for line in text.lines() {
        if let Some(k) = KINDS
            .iter()
            .position(|(tag, _)| line.split_whitespace().next() == Some(tag))
        {
            total[k] += 1;
        }
    }
    let mut seen = [0i64; 3];
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(tag) = words.next() else { continue };
        if let Some(k) = KINDS.iter().position(|(t, _)| *t == tag) {
            seen[k] += 1;
            continue;
        }
        if tag != "f" {
            continue;
        }
        for word in words {
            for (k, index) in word.split('/').enumerate().take(3) {
                // Empty fields (`1//2`) and malformed ones are tobj's to judge.
                let Ok(index) = index.parse::<i64>() else {
                    continue;
                };
                let names_one = match index {
                    i if i > 0 => i <= total[k],
                    i if i < 0 => seen[k].checked_add(i).is_some_and(|at| at >= 0),
                    _ => true,
                };
                if !names_one {
                    return Err(format!(
                        "line {}: face index {index} names no {} (the file has {}, {} before this line)",
                        n + 1,
                        KINDS[k].1,
                        total[k],
                        seen[k]
                    ));
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error_of(text: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(&path, text).unwrap();
        import(&path).map(|_| ()).unwrap_err()
    }

    #[test]
    fn parse_errors_name_their_line() {
        let err = error_of(b"v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
        assert!(err.contains("line 3: position parse error"), "{err}");
        let err = error_of(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\nv 0 0 1");
        assert!(
            err.contains("line 5: face index 9 names no vertex"),
            "{err}"
        );
        let err = error_of(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//-2 3//1\n");
        assert!(
            err.contains("line 5: face index -2 names no normal"),
            "{err}"
        );
        let err = error_of(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9223372036854775808\n");
        assert!(
            err.contains("line 4: face index -9223372036854775808"),
            "{err}"
        );
        let err = error_of(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nvn 0 0");
        assert!(err.contains("line 5: normal parse error"), "{err}");
        let err = error_of(b"v 0 0 0\nv 1 \xff 0\n");
        assert!(err.contains("line 2: not UTF-8 text"), "{err}");
    }

    #[test]
    fn materials_are_not_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(
            &path,
            "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(import(&path).unwrap().indices.len(), 1);
    }

    #[test]
    fn devices_are_refused() {
        let err = import(Path::new("/dev/zero")).map(|_| ()).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
    }
}
