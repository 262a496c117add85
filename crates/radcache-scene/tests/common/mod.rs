//! Shared helpers of the integration tests: temporary directories, loading, small scenes.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use radcache_scene::writer::{BufferLayout, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{LoadOptions, Scene, Warning, WarningKind};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A fresh, empty directory under the system temp dir.
pub fn temp_dir(tag: &str) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::SeqCst);
    let dir = std::env::temp_dir().join(format!("radcache-scene-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Loads with default options, panicking with the error message on failure.
pub fn load(path: &Path) -> (Scene, Vec<Warning>) {
    match Scene::load(path, &LoadOptions::default()) {
        Ok(r) => r,
        Err(e) => panic!("loading {} failed: {e}", path.display()),
    }
}

/// Number of warnings of `kind`, and the sum of their counts.
pub fn warnings_of(warnings: &[Warning], kind: WarningKind) -> (usize, usize) {
    let w: Vec<&Warning> = warnings.iter().filter(|w| w.kind == kind).collect();
    (w.len(), w.iter().map(|w| w.count).sum())
}

/// Writes `b` as `dir/name.gltf` (+ `.bin`) and returns the path.
pub fn write(b: &GltfBuilder, dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(format!("{name}.gltf"));
    b.write(&path, BufferLayout::External).unwrap();
    path
}

/// A unit right triangle in the XY plane (normal +Z) and a camera at z = 2, as a builder
/// whose single primitive can be customised by `f`.
pub fn triangle_scene(
    material: Option<MaterialDesc>,
    f: impl FnOnce(&mut PrimitiveDesc),
) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mat = material.map(|m| b.add_material(&m));
    let mut prim = PrimitiveDesc::triangles(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        Some(vec![[0.0, 0.0, 1.0]; 3]),
        vec![0, 1, 2],
        mat,
    );
    f(&mut prim);
    let mesh = b.add_mesh("tri", &[prim]);
    let node = b.add_node(&NodeDesc {
        name: Some("tri".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let cam = b.add_perspective_camera("cam", 1.0, None, 0.1, None);
    let cam_node = b.add_node(&NodeDesc {
        name: Some("cam".into()),
        translation: Some([0.0, 0.0, 2.0]),
        camera: Some(cam),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node, cam_node], None);
    b
}

/// Asserts two floats are within `tol`.
#[track_caller]
pub fn close(a: f32, b: f32, tol: f32) {
    assert!((a - b).abs() <= tol, "{a} != {b} (tol {tol})");
}

/// Asserts two vectors are within `tol` (Euclidean).
#[track_caller]
pub fn close3(a: glam::Vec3, b: glam::Vec3, tol: f32) {
    assert!((a - b).length() <= tol, "{a} != {b} (tol {tol})");
}

/// A GLB file (header, space-padded JSON chunk, zero-padded BIN chunk) of `root` and `bin`; the
/// first buffer loses its `uri` so that it refers to the BIN chunk.
pub fn glb_bytes(root: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut root = root.clone();
    if let Some(b) = root
        .pointer_mut("/buffers/0")
        .and_then(|b| b.as_object_mut())
    {
        b.remove("uri");
    }
    let mut text = serde_json::to_vec(&root).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut glb = Vec::with_capacity(total);
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&(total as u32).to_le_bytes());
    glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&text);
    if !bin.is_empty() {
        glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"BIN\0");
        glb.extend_from_slice(&bin);
    }
    glb
}

/// `shared/models/<rel>`: the Khronos sample models kept beside the checkout (CI has `shared/`
/// next to the clone, i.e. `../shared/models` from the repository root; a git worktree finds it
/// in a folder further up). Panics, naming where it looked, when the file is absent.
pub fn shared_model(rel: &str) -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let repo = repo.canonicalize().unwrap_or(repo);
    let candidates: Vec<PathBuf> = repo
        .ancestors()
        .map(|dir| dir.join("shared/models").join(rel))
        .collect();
    match candidates.iter().find(|p| p.is_file()) {
        Some(p) => p.clone(),
        None => panic!("shared model {rel} not found; looked for {candidates:?}"),
    }
}
