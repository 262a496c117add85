//! Mutations: JSON-level edits of a glTF document (with byte edits of its `.bin`), and
//! byte-level edits of whole GLB files.

use serde_json::{json, Value};

use crate::Rng;

/// Collects JSON pointers of every value in the tree.
fn pointers(v: &Value, prefix: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{prefix}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let p = format!("{prefix}/{i}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        _ => {}
    }
}

fn interesting_number(rng: &mut Rng) -> Value {
    let choices = [
        json!(0),
        json!(1),
        json!(-1),
        json!(3),
        json!(255),
        json!(65535),
        json!(4_294_967_295u64),
        json!(1e30),
        json!(-1e30),
        json!(0.5),
        json!(i64::MAX),
    ];
    match rng.below(3) {
        0 => rng.pick(&choices).clone(),
        1 => json!(rng.below(64)),
        _ => json!(rng.below(100_000)),
    }
}

/// Sets `root[array][index][field] = value` when that object exists.
fn set(root: &mut Value, array: &str, index: usize, field: &str, value: Value) {
    if let Some(Value::Object(o)) = root.get_mut(array).and_then(|a| a.get_mut(index)) {
        o.insert(field.to_string(), value);
    }
}

/// Applies one JSON-level (or `.bin` byte-level) mutation.
pub fn mutate_json(rng: &mut Rng, root: &mut Value, bin: &mut Vec<u8>) {
    let accessors = root["accessors"].as_array().map_or(0, Vec::len);
    let views = root["bufferViews"].as_array().map_or(0, Vec::len);
    match rng.below(12) {
        0 | 1 => {
            for _ in 0..=rng.below(8) {
                if !bin.is_empty() {
                    let i = rng.below(bin.len());
                    bin[i] ^= 1 << rng.below(8);
                }
            }
        }
        2 => {
            let n = rng.below(bin.len() + 1);
            bin.truncate(n);
        }
        3 => {
            let a = rng.below(accessors);
            let field = *rng.pick(&["count", "byteOffset", "componentType", "bufferView"]);
            let value = if field == "componentType" {
                json!(*rng.pick(&[5120, 5121, 5122, 5123, 5125, 5126, 5124, 1]))
            } else {
                interesting_number(rng)
            };
            set(root, "accessors", a, field, value);
        }
        4 => {
            let a = rng.below(accessors);
            let ty = json!(*rng.pick(&["SCALAR", "VEC2", "VEC3", "VEC4", "MAT4", "MAT2"]));
            set(root, "accessors", a, "type", ty);
            if rng.below(2) == 0 {
                set(root, "accessors", a, "normalized", json!(true));
            }
        }
        5 => {
            let v = rng.below(views);
            let field = *rng.pick(&["byteOffset", "byteLength", "byteStride", "buffer"]);
            let value = interesting_number(rng);
            set(root, "bufferViews", v, field, value);
        }
        6 | 7 => {
            let mut ps = Vec::new();
            pointers(root, String::new(), &mut ps);
            let p = rng.pick(&ps).clone();
            let (parent, key) = p.rsplit_once('/').unwrap_or(("", ""));
            let replace_number = rng.below(2) == 0;
            if let Some(target) = root.pointer_mut(&p) {
                if replace_number && target.is_number() {
                    *target = interesting_number(rng);
                    return;
                }
            }
            match root.pointer_mut(parent) {
                Some(Value::Object(m)) => {
                    m.remove(key);
                }
                Some(Value::Array(a)) => {
                    if let Ok(i) = key.parse::<usize>() {
                        if i < a.len() {
                            a.remove(i);
                        }
                    }
                }
                _ => {}
            }
        }
        8 => {
            // Swap two index values inside an index buffer view, or two random bytes.
            if bin.len() >= 4 {
                let (i, j) = (rng.below(bin.len() / 2) * 2, rng.below(bin.len() / 2) * 2);
                bin.swap(i, j);
                bin.swap(i + 1, j + 1);
            }
            let a = rng.below(accessors);
            let b = rng.below(accessors);
            if let (Some(x), Some(y)) = (
                root["accessors"][a].get("bufferView").cloned(),
                root["accessors"][b].get("bufferView").cloned(),
            ) {
                set(root, "accessors", a, "bufferView", y);
                set(root, "accessors", b, "bufferView", x);
            }
        }
        9 => {
            // Replace a string with another meaningful glTF string (types, paths, modes, URIs).
            let mut ps = Vec::new();
            pointers(root, String::new(), &mut ps);
            let strings: Vec<String> = ps
                .into_iter()
                .filter(|p| root.pointer(p).is_some_and(Value::is_string))
                .collect();
            if !strings.is_empty() {
                let p = rng.pick(&strings).clone();
                let choices = [
                    "spot",
                    "point",
                    "directional",
                    "orthographic",
                    "perspective",
                    "STEP",
                    "LINEAR",
                    "CUBICSPLINE",
                    "rotation",
                    "scale",
                    "translation",
                    "weights",
                    "BLEND",
                    "MASK",
                    "image/png",
                    "image/jpeg",
                    "data:,",
                    "data:application/octet-stream;base64,AAAA",
                    "../f.bin",
                    "%FF.bin",
                    "file:///etc/passwd",
                    "",
                    "VEC4",
                    "MAT3",
                ];
                if let Some(v) = root.pointer_mut(&p) {
                    *v = json!(*rng.pick(&choices));
                }
            }
        }
        10 => {
            // Add a reference field with an arbitrary index somewhere it is meaningful.
            let (array, field) = *rng.pick(&[
                ("nodes", "mesh"),
                ("nodes", "camera"),
                ("nodes", "skin"),
                ("nodes", "children"),
                ("meshes", "weights"),
                ("materials", "emissiveTexture"),
                ("textures", "source"),
                ("textures", "sampler"),
                ("scenes", "nodes"),
            ]);
            let n = root[array].as_array().map_or(0, Vec::len);
            let i = rng.below(n);
            let value = match field {
                "children" | "nodes" | "weights" => json!([rng.below(8), rng.below(8)]),
                "emissiveTexture" => json!({"index": rng.below(4), "texCoord": rng.below(2)}),
                _ => json!(rng.below(8)),
            };
            set(root, array, i, field, value);
        }
        _ => {
            let p = *rng.pick(&[
                "/nodes/0/rotation",
                "/nodes/0/scale",
                "/nodes/1/matrix",
                "/materials/0/emissiveFactor",
                "/scenes/0/extras",
            ]);
            if let Some(v) = root.pointer_mut(p) {
                *v = json!([0, 0, 0, 0]);
            }
        }
    }
}

/// u32 values that make interesting lengths, offsets and counts.
fn interesting_u32(rng: &mut Rng, len: usize) -> u32 {
    let choices = [0, 1, 3, 4, 11, 12, 19, 20, 0x7fff_ffff, 0xffff_ffff];
    match rng.below(3) {
        0 => *rng.pick(&choices),
        1 => (len as u32)
            .wrapping_add(rng.below(9) as u32)
            .wrapping_sub(4),
        _ => rng.next_u64() as u32,
    }
}

/// Applies one byte-level mutation to a whole GLB file: bit flips, a u32 overwritten with an
/// interesting value (often in the 12-byte header or a chunk header), truncation, insertion or
/// deletion of a byte range.
pub fn mutate_bytes(rng: &mut Rng, bytes: &mut Vec<u8>) {
    let len = bytes.len();
    match rng.below(6) {
        0 => {
            for _ in 0..=rng.below(8) {
                if !bytes.is_empty() {
                    let i = rng.below(bytes.len());
                    bytes[i] ^= 1 << rng.below(8);
                }
            }
        }
        1 | 2 => {
            // Headers: GLB length at 8, JSON chunk length at 12, BIN chunk length after the JSON.
            let json_len = bytes
                .get(12..16)
                .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
            let targets = [
                8,
                12,
                16,
                20 + json_len,
                24 + json_len,
                rng.below(len.max(1)) & !3,
            ];
            let at = *rng.pick(&targets);
            let v = interesting_u32(rng, len).to_le_bytes();
            if at + 4 <= bytes.len() {
                bytes[at..at + 4].copy_from_slice(&v);
            }
        }
        3 => {
            let n = rng.below(len + 1);
            bytes.truncate(n);
        }
        4 => {
            let at = rng.below(len + 1);
            let n = 1 + rng.below(8);
            let insert: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
            bytes.splice(at..at, insert);
        }
        _ => {
            let at = rng.below(len + 1);
            let end = (at + 1 + rng.below(16)).min(len);
            bytes.drain(at..end);
        }
    }
}
