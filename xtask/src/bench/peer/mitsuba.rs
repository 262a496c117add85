//! Mitsuba 3 as the peer of `bench peer`: the scene export (binary PLY meshes and an XML scene,
//! written from the loaded [`Scene`], i.e. the data radcache renders) and the renderer (the
//! `llvm_ad_rgb` variant, run through `render.py` with the Python of the virtual environment that
//! `scripts/setup-peer.sh` creates).
//!
//! The export at scene time `t`, in radcache's conventions:
//! - geometry: every instance's triangles in world space (`instance_transforms(t)`), one PLY per
//!   (instance, material), with the scene's per-vertex normals (transformed by the inverse
//!   transpose) on non-emissive groups; the winding is reversed under a mirroring transform so that
//!   the counter-clockwise side stays the front, as radcache keeps it;
//! - materials: Lambertian ones as `diffuse` with their albedo, white metals as GGX
//!   `roughconductor` (see [`bsdf`]; other specular materials are refused), reflecting on both
//!   sides (`twosided`) as radcache's surfaces do;
//! - emission: an `area` emitter on the emissive groups, which are written without vertex normals
//!   so that Mitsuba's front side is the geometric normal's, the side radcache emits from (front face
//!   only);
//! - the constant environment as a `constant` emitter, directional lights as `directional`
//!   (irradiance = colour × lux), point lights as `point` (intensity = colour × cd);
//! - the camera: `perspective` with the vertical field of view, a `lookat` of its frame, a `box`
//!   reconstruction filter (radcache averages jittered sub-frames: a box over the pixel);
//! - the integrator: `path` with unbounded depth (`max_depth = −1`; radcache's path tracer ends
//!   paths by Russian roulette only) and Mitsuba's own Russian roulette.
//!
//! What the bundled scenes do not use is refused with a clear error rather than approximated:
//! textures, environment maps, double-sided emitters, spot lights and lights with a range.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context as _, Result};
use glam::{Mat3, Vec3};
use radcache_image::Image;
use radcache_scene::{Environment, Fnv1a, LightKind, Scene};

/// The driver run by the peer's Python.
const DRIVER: &str = include_str!("render.py");

/// What to run when Mitsuba is missing.
const SETUP_HINT: &str = "run `scripts/setup-peer.sh` (installs libllvm19 and a Python venv with \
     `pip install mitsuba` under ~/.cache/radcache/peer-venv; RADCACHE_PEER_VENV overrides the path)";

/// Candidate locations of Debian's LLVM 19 (`libllvm19`).
const LLVM_PATHS: [&str; 2] = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
    "/usr/lib/x86_64-linux-gnu/libLLVM-19.so.1",
];

/// The cache folder of the peer: `$XDG_CACHE_HOME/radcache/peer`, else `~/.cache/radcache/peer`.
pub fn cache_root() -> Result<PathBuf> {
    let var = |n: &str| {
        std::env::var_os(n)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    let base = var("XDG_CACHE_HOME")
        .filter(|p| p.is_absolute())
        .or_else(|| var("HOME").map(|h| h.join(".cache")))
        .context("bench peer: neither XDG_CACHE_HOME nor HOME is set (no cache folder)")?;
    Ok(base.join("radcache"))
}

/// An installed Mitsuba 3: the venv's Python and the LLVM library its JIT needs.
pub struct Mitsuba {
    python: PathBuf,
    llvm: PathBuf,
    version: String,
}

/// A finished Mitsuba render.
pub struct PeerRender {
    pub image: Image,
    pub spp: u32,
    /// Wall time of the timed passes (kernel compilation, in the warm-up pass, excluded).
    pub time_s: f64,
    /// The warm-up pass (JIT compilation included).
    pub warmup_s: f64,
}

/// How much a render may spend.
#[derive(Clone, Copy, Debug)]
pub enum PeerBudget {
    Spp(u32),
    Seconds(f64),
}

impl Mitsuba {
    /// Finds the venv and LLVM 19; one error saying what to run when either is missing.
    pub fn find() -> Result<Mitsuba> {
        let venv = match std::env::var_os("RADCACHE_PEER_VENV") {
            Some(v) => PathBuf::from(v),
            None => cache_root()?.join("peer-venv"),
        };
        let python = venv.join("bin/python");
        let llvm = match std::env::var_os("DRJIT_LIBLLVM_PATH") {
            Some(p) => Some(PathBuf::from(p)),
            None => LLVM_PATHS.iter().map(PathBuf::from).find(|p| p.exists()),
        };
        let Some(llvm) = llvm.filter(|p| p.exists()) else {
            bail!("bench peer: LLVM 19 (Debian's libllvm19) not found; {SETUP_HINT}");
        };
        let out = Command::new(&python)
            .args(["-c", "import mitsuba; print(mitsuba.__version__)"])
            .env("DRJIT_LIBLLVM_PATH", &llvm)
            .output();
        match out {
            Ok(o) if o.status.success() => Ok(Mitsuba {
                python,
                llvm,
                version: String::from_utf8_lossy(&o.stdout).trim().to_string(),
            }),
            _ => bail!(
                "bench peer: Mitsuba 3 not found (no `import mitsuba` with {}); {SETUP_HINT}",
                python.display()
            ),
        }
    }

    pub fn version(&self) -> &str {
        &self.version
    }

    /// Renders `scene_xml` (from [`export`]) in passes of `pass_spp` samples per pixel.
    pub fn render(
        &self,
        scene_xml: &Path,
        budget: PeerBudget,
        pass_spp: u32,
    ) -> Result<PeerRender> {
        let dir = scene_xml.parent().unwrap_or(Path::new("."));
        let driver = dir.join("render.py");
        std::fs::write(&driver, DRIVER).with_context(|| format!("writing {}", driver.display()))?;
        let out = dir.join(format!("out-{}.f32", std::process::id()));
        let (mode, value) = match budget {
            PeerBudget::Spp(n) => ("spp", f64::from(n)),
            PeerBudget::Seconds(s) => ("time", s),
        };
        let run = Command::new(&self.python)
            .arg(&driver)
            .arg(scene_xml)
            .arg(&out)
            .args([mode, &value.to_string(), &pass_spp.to_string()])
            .env("DRJIT_LIBLLVM_PATH", &self.llvm)
            .output()
            .with_context(|| format!("running {}", self.python.display()))?;
        let stdout = String::from_utf8_lossy(&run.stdout);
        if !run.status.success() {
            bail!(
                "bench peer: Mitsuba failed on {} ({}):\n{}{}",
                scene_xml.display(),
                run.status,
                stdout,
                String::from_utf8_lossy(&run.stderr)
            );
        }
        let line = stdout
            .lines()
            .find(|l| l.starts_with("radcache-peer "))
            .with_context(|| format!("bench peer: no result line from render.py:\n{stdout}"))?;
        let field = |name: &str| -> Result<f64> {
            line.split_whitespace()
                .find_map(|kv| kv.strip_prefix(name)?.strip_prefix('='))
                .and_then(|v| v.parse().ok())
                .with_context(|| format!("bench peer: no {name} in `{line}`"))
        };
        let (width, height) = (field("width")? as u32, field("height")? as u32);
        let bytes = std::fs::read(&out).with_context(|| format!("reading {}", out.display()))?;
        std::fs::remove_file(&out).ok();
        let rgb: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok(PeerRender {
            image: Image::from_rgb(width, height, rgb)?,
            spp: field("spp")? as u32,
            time_s: field("time_s")?,
            warmup_s: field("warmup_s")?,
        })
    }
}

/// Exports `scene` at time `t` for a `width × height` film into a folder under `root` named by the
/// export's hash (scene content, time, and the XML, which holds the camera, lights and film), and
/// returns the XML's path. An existing complete export is reused.
pub fn export(scene: &Scene, t: f32, width: u32, height: u32, root: &Path) -> Result<PathBuf> {
    let (xml, meshes) = build(scene, t, width, height)?;
    let mut h = Fnv1a::default();
    h.bytes(b"radcache peer export 1");
    h.bytes(&scene.content_hash().to_le_bytes());
    h.f32(t);
    h.bytes(xml.as_bytes());
    let dir = root.join(format!("{:016x}", h.finish()));
    let path = dir.join("scene.xml");
    if path.exists() {
        return Ok(path);
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    for (name, mesh) in &meshes {
        let file = dir.join(name);
        std::fs::write(&file, mesh.ply()).with_context(|| format!("writing {}", file.display()))?;
    }
    // The XML last: its presence marks a complete export.
    let tmp = dir.join("scene.xml.tmp");
    std::fs::write(&tmp, &xml).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, &path).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// One exported mesh: world-space vertices (normals optional) and triangles.
#[derive(Default)]
struct PlyMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl PlyMesh {
    /// Binary little-endian PLY.
    fn ply(&self) -> Vec<u8> {
        let normals = !self.normals.is_empty();
        let mut out = Vec::new();
        let _ = write!(
            out,
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\n",
            self.positions.len()
        );
        if normals {
            let _ = write!(
                out,
                "property float nx\nproperty float ny\nproperty float nz\n"
            );
        }
        let _ = write!(
            out,
            "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            self.triangles.len()
        );
        for (i, p) in self.positions.iter().enumerate() {
            let n = normals.then(|| self.normals[i]);
            for v in p
                .to_array()
                .into_iter()
                .chain(n.into_iter().flat_map(|n| n.to_array()))
            {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        for tri in &self.triangles {
            out.push(3);
            tri.iter()
                .for_each(|i| out.extend_from_slice(&i.to_le_bytes()));
        }
        out
    }
}

/// `"x, y, z"` for an XML attribute.
fn v3(v: Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

/// The XML scene and its meshes (file name, mesh).
/// The Mitsuba BSDF of a material: `diffuse` for a Lambertian one; for a white metal (metallic
/// 1, base colour 1, untextured) `roughconductor` with the GGX distribution, α = roughness²
/// (floored at the BRDF's `ALPHA_MIN`), `material="none"` (Fresnel 1, as Schlick's with F0 = 1)
/// and visible-normal sampling. Mitsuba's microfacet model uses the separable Smith term
/// G1(v)·G1(l), glTF's the height-correlated one, which is larger: a white glTF metal reflects a
/// little more (docs/materials.md §10). Anything else (a dielectric's specular layer, a coloured
/// or partly metallic one) has no equivalent there and is refused.
fn bsdf(m: &radcache_scene::Material) -> Result<String> {
    if m.is_lambertian() {
        return Ok(format!(
            "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf>",
            v3(m.diffuse_albedo())
        ));
    }
    let white = m.base_color.truncate() == Vec3::ONE;
    if m.metallic == 1.0 && white && m.metallic_roughness_texture.is_none() {
        let alpha = (m.roughness * m.roughness).max(radcache_shared::consts::ALPHA_MIN);
        return Ok(format!(
            "<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/><float \
             name=\"alpha\" value=\"{alpha}\"/><string name=\"material\" value=\"none\"/><boolean \
             name=\"sample_visible\" value=\"true\"/></bsdf>"
        ));
    }
    bail!(
        "not Lambertian and not a white untextured metal (metallic {}, base colour {}, specular \
         factor {}); the Mitsuba export has no equivalent BSDF",
        m.metallic,
        v3(m.base_color.truncate()),
        m.specular_factor
    )
}

fn build(
    scene: &Scene,
    t: f32,
    width: u32,
    height: u32,
) -> Result<(String, Vec<(String, PlyMesh)>)> {
    let name = scene.path.display();
    let mut x = String::from("<scene version=\"3.0.0\">\n");
    x += "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"-1\"/></integrator>\n";
    let view = scene.camera_at(t);
    x += &format!(
        "  <sensor type=\"perspective\">\n    <string name=\"fov_axis\" value=\"y\"/>\n    \
         <float name=\"fov\" value=\"{}\"/>\n    <float name=\"near_clip\" value=\"0.001\"/>\n    \
         <float name=\"far_clip\" value=\"100000\"/>\n    <transform name=\"to_world\"><lookat \
         origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\n    <sampler type=\"independent\"/>\n    \
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"{width}\"/><integer name=\"height\" \
         value=\"{height}\"/><string name=\"pixel_format\" value=\"rgb\"/><rfilter type=\"box\"/></film>\n  \
         </sensor>\n",
        view.perspective.yfov.to_degrees(),
        v3(view.position),
        v3(view.position + view.forward),
        v3(view.up)
    );
    for (i, m) in scene.materials.iter().enumerate() {
        if m.base_color_texture.is_some() || m.emissive_texture.is_some() {
            bail!(
                "bench peer: {name}: material {i} is textured; the Mitsuba export has no textures"
            );
        }
        if m.is_emissive() && m.double_sided {
            bail!("bench peer: {name}: material {i} is a double-sided emitter; the export has only one-sided area lights");
        }
        x += &format!(
            "  <bsdf type=\"twosided\" id=\"m{i}\">{}</bsdf>\n",
            bsdf(m).with_context(|| format!("bench peer: {name}: material {i}"))?
        );
    }
    match &scene.environment {
        Environment::None => {}
        Environment::Constant(l) => {
            x += &format!(
                "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>\n",
                v3(*l)
            );
        }
        Environment::Map { path, .. } => {
            bail!(
                "bench peer: {name}: environment map {} is not exported",
                path.display()
            )
        }
    }
    for (i, l) in scene.lights_at(t).iter().enumerate() {
        if l.range.is_some() {
            bail!("bench peer: {name}: light {i} has a range; the export has no range window");
        }
        let power = v3(l.color * l.intensity);
        x += &match l.kind {
            LightKind::Point => format!(
                "  <emitter type=\"point\"><point name=\"position\" value=\"{}\"/><rgb \
                 name=\"intensity\" value=\"{power}\"/></emitter>\n",
                v3(l.position)
            ),
            LightKind::Directional => format!(
                "  <emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/><rgb \
                 name=\"irradiance\" value=\"{power}\"/></emitter>\n",
                v3(l.direction)
            ),
            LightKind::Spot { .. } => {
                bail!("bench peer: {name}: light {i} is a spot light; its glTF falloff is not exported")
            }
        };
    }
    let mut meshes = Vec::new();
    for (i, (inst, m)) in scene
        .instances
        .iter()
        .zip(scene.instance_transforms(t))
        .enumerate()
    {
        let mesh = &scene.meshes[inst.mesh];
        let linear = Mat3::from_mat4(m);
        let normal_m = linear.inverse().transpose();
        let mirror = linear.determinant() < 0.0;
        let mut used: Vec<u32> = mesh.triangle_materials.clone();
        used.sort_unstable();
        used.dedup();
        for mat in used {
            let material = scene.materials.get(mat as usize).with_context(|| {
                format!(
                    "bench peer: {name}: mesh {} names material {mat}",
                    inst.mesh
                )
            })?;
            let emissive = material.is_emissive();
            let mut out = PlyMesh::default();
            let mut remap = vec![u32::MAX; mesh.positions.len()];
            for (tri, _) in mesh
                .triangle_materials
                .iter()
                .enumerate()
                .filter(|(_, &tm)| tm == mat)
            {
                let mut idx = [0u32; 3];
                for (k, slot) in idx.iter_mut().enumerate() {
                    let v = mesh.indices[3 * tri + k] as usize;
                    if remap[v] == u32::MAX {
                        remap[v] = out.positions.len() as u32;
                        out.positions.push(m.transform_point3(mesh.positions[v]));
                        if !emissive {
                            let n = mesh.normals.get(v).copied().unwrap_or(Vec3::ZERO);
                            out.normals.push((normal_m * n).normalize_or_zero());
                        }
                    }
                    *slot = remap[v];
                }
                if mirror {
                    idx.swap(1, 2);
                }
                out.triangles.push(idx);
            }
            // Vertex normals only where the scene has them all (else Mitsuba's face normals).
            if out.normals.contains(&Vec3::ZERO) {
                out.normals.clear();
            }
            let file = format!("i{i}_m{mat}.ply");
            x += &format!(
                "  <shape type=\"ply\"><string name=\"filename\" value=\"{file}\"/><ref id=\"m{mat}\"/>"
            );
            if emissive {
                x += &format!(
                    "<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                    v3(material.emissive)
                );
            }
            x += "</shape>\n";
            meshes.push((file, out));
        }
    }
    x += "</scene>\n";
    Ok((x, meshes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radcache_scene::LoadOptions;

    fn cornell() -> Scene {
        let path = crate::root().join("assets/cornell/cornell.gltf");
        Scene::load(&path, &LoadOptions::default()).unwrap().0
    }

    #[test]
    fn cornell_export_keeps_every_triangle_and_a_downward_light() {
        let scene = cornell();
        let (xml, meshes) = build(&scene, 0.0, 256, 256).unwrap();
        let total: usize = meshes.iter().map(|(_, m)| m.triangles.len()).sum();
        assert_eq!(total, scene.instanced_triangle_count());
        assert_eq!(xml.matches("<shape ").count(), meshes.len());
        assert_eq!(xml.matches("type=\"area\"").count(), 1);
        // The light's group carries no vertex normals, and its winding's normal points down (−Y),
        // the side radcache emits from.
        let light = scene
            .materials
            .iter()
            .position(|m| m.is_emissive())
            .unwrap();
        let (_, mesh) = meshes
            .iter()
            .find(|(n, _)| n.ends_with(&format!("_m{light}.ply")))
            .unwrap();
        assert!(mesh.normals.is_empty());
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            assert!(n.y < -0.99, "light normal {n}");
        }
        // Non-emissive groups carry one unit normal per vertex.
        for (_, m) in meshes.iter().filter(|(_, m)| !m.normals.is_empty()) {
            assert_eq!(m.normals.len(), m.positions.len());
            assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        }
    }

    #[test]
    fn white_metals_become_ggx_conductors_and_dielectrics_are_refused() {
        let mut m = cornell().materials[0].clone();
        assert!(m.is_lambertian());
        assert!(bsdf(&m).unwrap().contains("type=\"diffuse\""));
        m.metallic = 1.0;
        m.base_color = glam::Vec4::ONE;
        m.roughness = 0.5;
        let x = bsdf(&m).unwrap();
        assert!(
            x.contains("roughconductor") && x.contains("value=\"0.25\""),
            "{x}"
        );
        m.roughness = 0.0;
        assert!(bsdf(&m).unwrap().contains("value=\"0.001\""));
        m.base_color = glam::Vec4::new(0.9, 0.6, 0.3, 1.0);
        assert!(
            bsdf(&m).is_err(),
            "a coloured metal's Schlick Fresnel has no Mitsuba twin"
        );
        m.base_color = glam::Vec4::ONE;
        m.metallic = 0.0;
        m.specular_factor = 1.0;
        assert!(
            bsdf(&m).is_err(),
            "a dielectric's specular layer has no Mitsuba twin"
        );
    }

    #[test]
    fn ply_header_matches_its_binary_body() {
        let mesh = PlyMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            triangles: vec![[0, 1, 2]],
        };
        let bytes = mesh.ply();
        let header_end = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let header = std::str::from_utf8(&bytes[..header_end]).unwrap();
        assert!(header.contains("element vertex 3\n") && header.contains("property float nz\n"));
        assert!(header.contains("element face 1\n"));
        // 3 vertices × 6 floats, then one face: a count byte and 3 u32 indices.
        assert_eq!(bytes.len() - header_end, 3 * 6 * 4 + 1 + 3 * 4);
        let body = &bytes[header_end..];
        assert_eq!(f32::from_le_bytes(body[24..28].try_into().unwrap()), 1.0); // vertex 1's x
        assert_eq!(body[72], 3);
    }
}
