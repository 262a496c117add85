//! Seeded mutation test of the loader (a bounded stand-in for a fuzzer): take each valid asset's
//! JSON and binary buffer, apply random mutations (byte flips and truncation of the buffer,
//! accessor count/offset/componentType/type changes, buffer-view edits, deleted fields, replaced
//! numbers, swapped indices), load, and require only that loading returns (Ok or Err) without
//! panicking. A panic fails the test; the seed and iteration are printed first so it can be replayed.
//!
//! `RADCACHE_FUZZ_ITERS` sets the number of mutated files per asset (default 500);
//! `RADCACHE_FUZZ_SEED` the base seed.

mod common;

use radcache_scene::assets::{animated_builder, cornell_builder, furnace_builder};
use radcache_scene::writer::{write_files, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{LoadOptions, Scene};
use serde_json::{json, Value};

/// splitmix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
    fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
}

/// A small textured scene so that image decoding is exercised too.
fn textured_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let pixels: Vec<u8> = (0..4 * 4 * 4).map(|i| (i * 37 % 256) as u8).collect();
    let tex = b.add_texture_rgba8(4, 4, &pixels, 10497).unwrap();
    let mut m = MaterialDesc::emitter("t", [1.0; 3], [2.0; 3]);
    m.base_color_texture = Some(tex);
    m.emissive_texture = Some(tex);
    let mat = b.add_material(&m);
    let mut prim = PrimitiveDesc::triangles(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        vec![0, 1, 2],
        Some(mat),
    );
    prim.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let mesh = b.add_mesh("m", &[prim]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    b
}

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

fn mutate(rng: &mut Rng, root: &mut Value, bin: &mut Vec<u8>) {
    let accessors = root["accessors"].as_array().map_or(0, Vec::len);
    let views = root["bufferViews"].as_array().map_or(0, Vec::len);
    match rng.below(10) {
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

#[test]
fn mutated_assets_never_panic() {
    let iters: usize = std::env::var("RADCACHE_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(500);
    let seed: u64 = std::env::var("RADCACHE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5eed);
    let dir = common::temp_dir("fuzz");
    let sources = [
        ("cornell", cornell_builder()),
        ("furnace", furnace_builder(0.5, 1.0)),
        ("animated", animated_builder()),
        ("textured", textured_builder()),
    ];
    let (mut ok, mut err) = (0usize, 0usize);
    for (si, (name, builder)) in sources.iter().enumerate() {
        let (root, bin) = builder.to_json(Some("f.bin"));
        for it in 0..iters {
            let mut rng = Rng(seed.wrapping_mul(0x2545_f491_4f6c_dd1d)
                ^ ((si as u64) << 48)
                ^ (it as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            let (mut r, mut b) = (root.clone(), bin.clone());
            for _ in 0..=rng.below(3) {
                mutate(&mut rng, &mut r, &mut b);
            }
            let path = dir.join("f.gltf");
            write_files(&path, &r, Some(("f.bin", &b))).unwrap();
            eprintln!("fuzz {name} iteration {it} (RADCACHE_FUZZ_SEED={seed})");
            let opts = LoadOptions::default();
            match Scene::load(&path, &opts) {
                Ok((scene, _)) => {
                    // Exercise the time-dependent queries too.
                    let t = scene.time_range().map_or(0.0, |r| r.1 * 0.5);
                    let _ = scene.summary();
                    let _ = scene.emitters_at(t);
                    let _ = scene.camera_at(t);
                    ok += 1;
                }
                Err(e) => {
                    assert!(
                        e.to_string().contains("f.gltf"),
                        "error does not name the file: {e}"
                    );
                    err += 1;
                }
            }
        }
    }
    println!("fuzz: {ok} loaded, {err} rejected");
    assert!(ok > 0 && err > 0);
}
