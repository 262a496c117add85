//! Human-readable scene summary (`radcache info scene.gltf` prints exactly this): counts of nodes,
//! meshes, triangles, materials, textures, lights by kind, animations and time range, world bounds
//! at the start time and over the animation range, the camera, the environment, then the plan.
//! Material extensions that radcache does not implement are named once each, with the number of
//! materials using them, and unused occlusion textures are mentioned once.

use std::fmt;

use glam::Vec3;

use crate::environment::Environment;
use crate::light::LightKind;
use crate::math::Aabb;
use crate::scene::Scene;

/// `x` with 3 decimals, printing values that round to zero as `0.000` (never `-0.000`).
fn f3(x: f32) -> String {
    let s = format!("{x:.3}");
    if s == "-0.000" {
        "0.000".into()
    } else {
        s
    }
}

/// `(x, y, z)` with 3 decimals.
fn v3(v: Vec3) -> String {
    format!("({}, {}, {})", f3(v.x), f3(v.y), f3(v.z))
}

fn aabb(b: &Aabb) -> String {
    if b.is_empty() {
        "empty".into()
    } else {
        format!("min {} max {}", v3(b.min), v3(b.max))
    }
}

impl Scene {
    /// The summary text (same as `Display`).
    pub fn summary(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene: {}", self.path.display())?;
        let in_scene = self.nodes.iter().filter(|n| n.in_scene).count();
        writeln!(f, "  nodes: {} ({in_scene} in scene)", self.nodes.len())?;
        writeln!(
            f,
            "  meshes: {}, instances: {}, triangles: {} ({} instanced)",
            self.meshes.len(),
            self.instances.len(),
            self.triangle_count(),
            self.instanced_triangle_count()
        )?;
        writeln!(
            f,
            "  materials: {} ({} emissive), textures: {}, images: {}",
            self.materials.len(),
            self.materials.iter().filter(|m| m.is_emissive()).count(),
            self.textures.len(),
            self.images.len()
        )?;
        let notes = &self.material_notes;
        if !notes.unsupported_extensions.is_empty() {
            let list: Vec<String> = notes
                .unsupported_extensions
                .iter()
                .map(|(name, n)| format!("{name} ({n} material{})", if *n == 1 { "" } else { "s" }))
                .collect();
            writeln!(
                f,
                "  material extensions not implemented (ignored; the core metallic-roughness model is used): {}",
                list.join(", ")
            )?;
        }
        if notes.occlusion_textures > 0 {
            writeln!(
                f,
                "  occlusion textures: not used ({} material{}; a global-illumination renderer computes occlusion itself)",
                notes.occlusion_textures,
                if notes.occlusion_textures == 1 { "" } else { "s" }
            )?;
        }
        let count = |k: fn(&LightKind) -> bool| {
            self.light_instances
                .iter()
                .filter(|l| k(&self.lights[l.light].kind))
                .count()
        };
        writeln!(
            f,
            "  lights: {} point, {} spot, {} directional",
            count(|k| *k == LightKind::Point),
            count(|k| matches!(k, LightKind::Spot { .. })),
            count(|k| *k == LightKind::Directional)
        )?;
        let channels: usize = self.animations.iter().map(|a| a.channels.len()).sum();
        match self.time_range() {
            Some((t0, t1)) => writeln!(
                f,
                "  animations: {} ({channels} channels), time range [{t0:.3}, {t1:.3}] s",
                self.animations.len()
            )?,
            None => writeln!(f, "  animations: {}", self.animations.len())?,
        }
        let t0 = self.time_range().map_or(0.0, |r| r.0);
        writeln!(f, "  bounds at t={t0:.3}: {}", aabb(&self.bounds_at(t0)))?;
        if self.time_range().is_some() {
            writeln!(
                f,
                "  bounds over range: {}",
                aabb(&self.bounds_over_range())
            )?;
        }
        let view = self.camera_at(t0);
        let p = &view.perspective;
        let aspect = p
            .aspect_ratio
            .map_or("image".to_string(), |a| format!("{a:.3}"));
        let zfar = p.zfar.map_or("inf".to_string(), |z| format!("{z:.3}"));
        writeln!(
            f,
            "  camera: {:?} ({} camera node(s)), yfov {:.2} deg, aspect {aspect}, znear {:.3}, zfar {zfar}, at {} looking {}",
            self.camera.name,
            self.camera_count,
            p.yfov.to_degrees(),
            p.znear,
            v3(view.position),
            v3(view.forward)
        )?;
        match &self.environment {
            Environment::None => writeln!(f, "  environment: none")?,
            Environment::Constant(l) => writeln!(f, "  environment: constant {}", v3(*l))?,
            Environment::Map { path, scale } => {
                writeln!(f, "  environment: map {} x {scale}", path.display())?
            }
        }
        write!(f, "{}", self.plan())
    }
}
