//! Mutators: small random edits of a valid file, each the kind of damage
//! real files suffer (truncation, a flipped byte, a deleted line, a number
//! replaced by an extreme) or that a hostile file carries.

use serde_json::Value;

/// SplitMix64 (Steele et al. 2014): a seeded stream that makes every
/// mutant reproducible from its seed alone.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Numbers at the edges of every type a parser converts to.
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "-0.0",
    "1e-45",
    "1e30",
    "-1e30",
    "1e39",
    "1e309",
    "nan",
    "inf",
    "-inf",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "0.5",
    "3",
];

/// Edits of text: lines and tokens.
pub fn text(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + rng.below(3) {
        out = match rng.below(8) {
            0 => truncate(rng, &out),
            1 => flip_byte(rng, &out),
            2..=4 => replace_number(rng, &out),
            5 => delete_line(rng, &out),
            6 => duplicate_line(rng, &out),
            _ => swap_lines(rng, &out),
        };
    }
    out
}

/// Edits of binary data: bytes, lengths and little-endian integers.
pub fn binary(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + rng.below(3) {
        match rng.below(4) {
            0 => out = truncate(rng, &out),
            1 => out = flip_byte(rng, &out),
            2 if out.len() >= 4 => {
                let at = rng.below(out.len() / 4) * 4;
                let value = *rng.pick(&[0u32, 1, 0x7fff_ffff, 0x8000_0000, u32::MAX]);
                out[at..at + 4].copy_from_slice(&value.to_le_bytes());
            }
            _ => out.extend((0..rng.below(64)).map(|_| rng.next_u64() as u8)),
        }
    }
    out
}

/// Edits of a JSON document's tree: values replaced by extremes or by the
/// wrong type, keys and array elements removed or duplicated, indices
/// pushed out of range.
pub fn json(rng: &mut Rng, doc: &Value) -> Value {
    let mut out = doc.clone();
    for _ in 0..1 + rng.below(3) {
        let mut nodes = Vec::new();
        collect_paths(&out, &mut Vec::new(), &mut nodes);
        // Half the edits go to integers: the indices, counts, offsets and
        // lengths that tie a glTF document together.
        let integers: Vec<_> = nodes
            .iter()
            .filter(|p| node_at(&mut out, p).is_some_and(|v| v.is_u64()))
            .cloned()
            .collect();
        let pool = if integers.is_empty() || rng.below(2) == 0 {
            &nodes
        } else {
            &integers
        };
        let path = rng.pick(pool).clone();
        let Some(node) = node_at(&mut out, &path) else {
            continue;
        };
        match rng.below(6) {
            0 => *node = extreme_json(rng),
            1 => {
                *node = rng
                    .pick(&[
                        Value::Null,
                        Value::Bool(true),
                        Value::String("x".into()),
                        Value::Array(Vec::new()),
                        Value::Object(Default::default()),
                    ])
                    .clone()
            }
            2 => match node {
                Value::Object(map) if !map.is_empty() => {
                    let key = map.keys().nth(rng.below(map.len())).cloned().unwrap();
                    map.remove(&key);
                }
                Value::Array(items) if !items.is_empty() => {
                    items.remove(rng.below(items.len()));
                }
                _ => *node = Value::Null,
            },
            3 => {
                if let Value::Array(items) = node {
                    if !items.is_empty() {
                        let copy = items[rng.below(items.len())].clone();
                        items.push(copy);
                    }
                }
            }
            4 => {
                if let Some(n) = node.as_u64() {
                    *node = Value::from(n + 1 + rng.below(3) as u64);
                } else {
                    *node = extreme_json(rng);
                }
            }
            _ => {
                if let Some(n) = node.as_u64() {
                    *node = Value::from(n.saturating_mul(1 << 20));
                }
            }
        }
    }
    out
}

fn extreme_json(rng: &mut Rng) -> Value {
    match rng.below(7) {
        0 => Value::from(u64::MAX),
        1 => Value::from(u64::MAX - 3),
        2 => Value::from(-1),
        3 => Value::from(1u64 << 32),
        4 => Value::from(1e300),
        5 => Value::from(0),
        _ => Value::from(1u64 << 62),
    }
}

fn collect_paths(value: &Value, path: &mut Vec<PathStep>, out: &mut Vec<Vec<PathStep>>) {
    out.push(path.clone());
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                path.push(PathStep::Key(key.clone()));
                collect_paths(child, path, out);
                path.pop();
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                path.push(PathStep::Index(i));
                collect_paths(child, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

#[derive(Clone)]
enum PathStep {
    Key(String),
    Index(usize),
}

fn node_at<'a>(value: &'a mut Value, path: &[PathStep]) -> Option<&'a mut Value> {
    path.iter().try_fold(value, |node, step| match step {
        PathStep::Key(key) => node.get_mut(key.as_str()),
        PathStep::Index(i) => node.get_mut(*i),
    })
}

fn truncate(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    bytes[..rng.below(bytes.len() + 1)].to_vec()
}

fn flip_byte(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    if !out.is_empty() {
        let at = rng.below(out.len());
        out[at] ^= 1 << rng.below(8);
    }
    out
}

/// Replaces one run of digits (with its sign and fraction) by an extreme.
fn replace_number(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let starts: Vec<usize> = (0..bytes.len())
        .filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_digit()))
        .collect();
    if starts.is_empty() {
        return bytes.to_vec();
    }
    let start = *rng.pick(&starts);
    let start = if start > 0 && bytes[start - 1] == b'-' {
        start - 1
    } else {
        start
    };
    let end = (start + 1..=bytes.len())
        .find(|&i| {
            i == bytes.len() || !(bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e'))
        })
        .unwrap_or(bytes.len());
    let mut out = bytes[..start].to_vec();
    out.extend_from_slice(rng.pick(EXTREME_NUMBERS).as_bytes());
    out.extend_from_slice(&bytes[end..]);
    out
}

fn lines(bytes: &[u8]) -> Vec<&[u8]> {
    bytes.split_inclusive(|&b| b == b'\n').collect()
}

fn delete_line(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut l = lines(bytes);
    if !l.is_empty() {
        l.remove(rng.below(l.len()));
    }
    l.concat()
}

fn duplicate_line(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut l = lines(bytes);
    if !l.is_empty() {
        let i = rng.below(l.len());
        l.insert(rng.below(l.len() + 1), l[i]);
    }
    l.concat()
}

fn swap_lines(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut l = lines(bytes);
    if !l.is_empty() {
        let (a, b) = (rng.below(l.len()), rng.below(l.len()));
        l.swap(a, b);
    }
    l.concat()
}

/// Sizes an image header may claim: small, at the pixel limit's edges,
/// and the largest each format's fields hold.
const CLAIMED_SIZES: &[u32] = &[1, 8, 16_384, 16_385, 65_535, 100_000, 1 << 30, u32::MAX];

/// An image whose header claims another size, its pixels left as they
/// are: a PNG's IHDR (with its CRC made right again, so the decoder reads
/// the claim) or a JPEG's frame header.
pub fn image_claim(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let (w, h) = (*rng.pick(CLAIMED_SIZES), *rng.pick(CLAIMED_SIZES));
    if out.starts_with(b"\x89PNG\r\n\x1a\n") && out.len() >= 33 {
        // Signature, IHDR length and type, then width and height.
        out[16..20].copy_from_slice(&w.to_be_bytes());
        out[20..24].copy_from_slice(&h.to_be_bytes());
        let crc = crc32fast::hash(&out[12..29]);
        out[29..33].copy_from_slice(&crc.to_be_bytes());
    } else if let Some(sof) = out
        .windows(2)
        .position(|m| m == [0xff, 0xc0] || m == [0xff, 0xc2])
    {
        // Marker, length, precision, then lines and samples per line.
        if out.len() >= sof + 9 {
            out[sof + 5..sof + 7].copy_from_slice(&(h.min(65_535) as u16).to_be_bytes());
            out[sof + 7..sof + 9].copy_from_slice(&(w.min(65_535) as u16).to_be_bytes());
        }
    }
    out
}

/// Values a node transform may hold that do not make one, or make one
/// that places its mesh nowhere or out of range.
const EXTREME_TRANSFORMS: &[(&str, &str)] = &[
    ("rotation", "[1e30, 0, 0, 0]"),
    ("rotation", "[0, 0, 0, 0]"),
    ("rotation", "[1e-30, 0, 0, 1e-30]"),
    ("scale", "[0, 1, 1]"),
    ("scale", "[1e20, 1e20, 1e20]"),
    ("scale", "[1e-30, 1e-30, 1e-30]"),
    ("scale", "[-1, 1, 1]"),
    ("translation", "[3.4e38, 0, 0]"),
    ("translation", "[1e19, 0, 0]"),
    ("matrix", "[0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]"),
    (
        "matrix",
        "[1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]",
    ),
    (
        "matrix",
        "[1e30, 0, 0, 0, 0, 1e30, 0, 0, 0, 0, 1e30, 0, 0, 0, 0, 1]",
    ),
];

/// A glTF document with one node's transform replaced by an extreme one
/// (a matrix replaces the node's TRS, and TRS its matrix, as glTF allows
/// only one of the two).
pub fn node_transform(rng: &mut Rng, doc: &Value) -> Value {
    let mut doc = doc.clone();
    let Some(nodes) = doc.get_mut("nodes").and_then(Value::as_array_mut) else {
        return doc;
    };
    if nodes.is_empty() {
        return doc;
    }
    let i = rng.below(nodes.len());
    let (key, value) = *rng.pick(EXTREME_TRANSFORMS);
    if let Some(node) = nodes[i].as_object_mut() {
        let trs = ["translation", "rotation", "scale"];
        if key == "matrix" {
            trs.iter().for_each(|k| {
                node.remove(*k);
            });
        } else {
            node.remove("matrix");
        }
        node.insert(key.into(), serde_json::from_str(value).unwrap());
    }
    doc
}
