//! Seeded mutation test of the loader (a bounded stand-in for a fuzzer).
//!
//! Sources: the three bundled assets, a small textured scene, a "kitchen sink" document
//! (`sources.rs`), and two gltfpack files of `tests/data/` (meshopt's triangle and attribute
//! codecs with all three filters; `EXT_mesh_gpu_instancing`). Each iteration takes one source and either
//! - writes it as `.gltf` + `.bin` after 1–3 JSON-level mutations (accessor/view fields, deleted
//!   members, replaced numbers and strings, new references, byte flips and truncation of the
//!   `.bin`), or
//! - writes it as a `.glb` (optionally JSON-mutated first) after 1–3 byte-level mutations of the
//!   whole file (bit flips, header and chunk lengths overwritten, truncation, insertion, deletion),
//!
//! then loads it inside `std::panic::catch_unwind` and runs the time-dependent queries on a
//! successful load. The test fails if anything panics (the offending file is kept and named) or if
//! an error does not name the file. It also requires that some files load and some are rejected,
//! so that a mutator that stopped mutating, or a loader that rejects everything, is noticed.
//!
//! `RADCACHE_FUZZ_ITERS` sets the iterations per source (default 200; CI uses 400) and
//! `RADCACHE_FUZZ_SEED` the base seed (default 0x5eed); every iteration's seed derives from
//! these, so a failure report replays exactly.

#[path = "../common/mod.rs"]
mod common;
mod mutate;
mod sources;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use radcache_scene::assets::{animated_builder, cornell_builder, furnace_builder};
use radcache_scene::writer::write_files;
use radcache_scene::{LoadOptions, Scene};
use serde_json::Value;

/// splitmix64.
#[derive(Debug)]
pub struct Rng(u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// A uniformly chosen element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Writes one mutated file for iteration `rng` of source `(root, bin)`; returns the path to load.
fn mutated_file(rng: &mut Rng, dir: &Path, root: &Value, bin: &[u8]) -> PathBuf {
    let (mut r, mut b) = (root.clone(), bin.to_vec());
    let glb = rng.below(2) == 0;
    if !glb || rng.below(2) == 0 {
        for _ in 0..=rng.below(3) {
            mutate::mutate_json(rng, &mut r, &mut b);
        }
    }
    if glb {
        let mut bytes = common::glb_bytes(&r, &b);
        for _ in 0..=rng.below(3) {
            mutate::mutate_bytes(rng, &mut bytes);
        }
        let path = dir.join("f.glb");
        std::fs::write(&path, bytes).unwrap();
        path
    } else {
        let path = dir.join("f.gltf");
        write_files(&path, &r, Some(("f.bin", &b))).unwrap();
        path
    }
}

/// Loads `path` and exercises the queries; `Ok(true)` loaded, `Ok(false)` rejected with an error
/// that names the file, `Err` for an error message that does not.
fn exercise(path: &Path) -> Result<bool, String> {
    match Scene::load(path, &LoadOptions::default()) {
        Ok((scene, _)) => {
            let (t0, t1) = scene.time_range().unwrap_or((0.0, 0.0));
            for t in [t0 - 1.0, 0.5 * (t0 + t1), t1 + 1.0] {
                let _ = scene.instance_transforms(t);
                let _ = scene.emitters_at(t);
                let _ = scene.lights_at(t);
                let view = scene.camera_at(t);
                let _ = view.project(view.position + view.forward, 1.5);
            }
            let _ = scene.bounds_over_range();
            let _ = scene.summary();
            Ok(true)
        }
        Err(e) => {
            let text = e.to_string();
            let name = path.file_name().unwrap().to_string_lossy();
            if text.contains(name.as_ref()) {
                Ok(false)
            } else {
                Err(format!("error does not name the file: {text}"))
            }
        }
    }
}

#[test]
fn mutated_files_never_panic() {
    let iters: usize = env_or("RADCACHE_FUZZ_ITERS", 200);
    let seed: u64 = env_or("RADCACHE_FUZZ_SEED", 0x5eed);
    let dir = common::temp_dir("fuzz");
    let keep = std::env::temp_dir().join(format!(
        "radcache-scene-fuzz-failures-{}",
        std::process::id()
    ));
    let sources = [
        ("cornell", cornell_builder().to_json(Some("f.bin"))),
        ("furnace", furnace_builder(0.5, 1.0).to_json(Some("f.bin"))),
        ("animated", animated_builder().to_json(Some("f.bin"))),
        ("textured", sources::textured()),
        ("kitchen_sink", sources::kitchen_sink()),
        ("meshopt_filters", sources::glb("animated-cc.glb")),
        (
            "meshopt_instancing",
            sources::glb("cornell-instanced-cc.glb"),
        ),
    ];
    let (mut loaded, mut rejected) = (0usize, 0usize);
    let mut failures = Vec::new();
    for (si, (name, (root, bin))) in sources.iter().enumerate() {
        // Each unmutated source must load: the mutations start from valid files.
        let clean = dir.join("clean.gltf");
        write_files(&clean, root, Some(("f.bin", bin))).unwrap();
        assert_eq!(exercise(&clean), Ok(true), "{name} does not load unmutated");
        for it in 0..iters {
            let mut rng = Rng(seed.wrapping_mul(0x2545_f491_4f6c_dd1d)
                ^ ((si as u64) << 48)
                ^ (it as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            let path = mutated_file(&mut rng, &dir, root, bin);
            let what = format!("{name} iteration {it} (RADCACHE_FUZZ_SEED={seed})");
            match catch_unwind(AssertUnwindSafe(|| exercise(&path))) {
                Ok(Ok(true)) => loaded += 1,
                Ok(Ok(false)) => rejected += 1,
                Ok(Err(message)) => failures.push(format!("{what}: {message}")),
                Err(_) => {
                    let ext = path.extension().unwrap().to_string_lossy().into_owned();
                    std::fs::create_dir_all(&keep).unwrap();
                    let kept = keep.join(format!("{name}-{it}.{ext}"));
                    std::fs::copy(&path, &kept).unwrap();
                    if ext == "gltf" {
                        std::fs::copy(dir.join("f.bin"), keep.join("f.bin")).unwrap();
                    }
                    failures.push(format!(
                        "{what}: panicked; input kept as {}",
                        kept.display()
                    ));
                }
            }
        }
    }
    println!(
        "fuzz: {loaded} loaded, {rejected} rejected, {} failures",
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(
        loaded > 0 && rejected > 0,
        "{loaded} loaded, {rejected} rejected"
    );
}
