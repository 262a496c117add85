//! [`ScenePlan`]: what a scene needs from the renderer, derived once after loading.
//!
//! Later passes consult it instead of re-inspecting the scene: whether to build the emitter
//! sampling table, whether the full metallic-roughness BRDF is needed or every material is
//! Lambertian, which punctual light kinds exist, which environment is used, whether textures
//! must be bound and which texture coordinates they need, and how the scene animates (nothing, camera only, lights only, or geometry —
//! the latter needing TLAS refits) over which time range.

use std::fmt;

use radcache_shared::consts::GLOSSY_ROUGHNESS_MIN;

use crate::environment::Environment;
use crate::light::LightKind;
use crate::scene::Scene;

/// Counts of punctual light instances by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightCounts {
    /// Point lights.
    pub point: usize,
    /// Spot lights.
    pub spot: usize,
    /// Directional lights.
    pub directional: usize,
}

impl LightCounts {
    /// Total number of punctual light instances.
    pub fn total(&self) -> usize {
        self.point + self.spot + self.directional
    }
}

/// Which environment the scene uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvironmentKind {
    /// No environment light.
    None,
    /// Uniform radiance.
    Constant,
    /// Equirectangular map.
    Map,
}

/// How the scene changes over time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationKind {
    /// Nothing moves.
    None,
    /// Only the camera moves: geometry, lights and emitters are static.
    CameraOnly,
    /// Punctual lights move but no geometry does (the camera may move too).
    LightsOnly,
    /// At least one mesh instance moves (TLAS refit; emitters may move); others may move too.
    Geometry,
}

/// The animation part of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnimationPlan {
    /// Classification.
    pub kind: AnimationKind,
    /// The selected camera moves.
    pub camera: bool,
    /// Some punctual light moves.
    pub lights: bool,
    /// Some mesh instance moves.
    pub geometry: bool,
    /// Key range `[t0, t1]` in seconds, when the file has animation channels.
    pub time_range: Option<(f32, f32)>,
}

/// Most emissive triangles whose unshadowed light the cache's direct pass computes in closed
/// form ([`ScenePlan::analytic_emitters`]): each costs every pixel one horizon-clipped polygon
/// integral per sub-frame, a few dozen flops beside a shadow ray's traversal.
pub const ANALYTIC_EMITTERS_MAX: usize = 16;

/// Smallest share of the scene's bounding-box surface that its emitters must cover for the
/// cache's gathers to take their light in closed form ([`ScenePlan::closed_form_gathers`]).
/// Measured on lavapipe at 256², default preset, against 8192-spp Mitsuba references
/// (docs/cache-frame.md §4): in the furnace (emitters 100 % of it) relMSE 1.81e-5 → 9.75e-6 and
/// 8×8-block RMSE 6.37e-3 → 3.81e-3 for a frame 1.16 → 1.72 s; in the Cornell box (0.7 %)
/// relMSE only −2 % for a record pass 14 % longer: a small emitter's sampled light varies little
/// but by its visibility, which the closed form does not help.
pub const CLOSED_FORM_GATHER_MIN_EMITTER_SHARE: f32 = 0.1;

/// Fewest instanced triangles for which the cache's G-buffer is ray traced
/// ([`ScenePlan::traced_gbuffer`]). Measured on lavapipe (docs/cache-frame.md §2): at 32
/// triangles (the Cornell box) rasterization is level at 256² and 25 % faster at 1024²; from
/// 7,958 (metal_spheres) tracing is faster, 3.5× at 113,394 (the courtyard, 256²).
pub const TRACED_GBUFFER_MIN_TRIANGLES: usize = 1_000;

/// Rendering plan of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenePlan {
    /// Number of emissive triangles (world space at the start time).
    pub emissive_triangles: usize,
    /// Their total luminance-weighted power (W).
    pub emissive_power: f32,
    /// The cache's direct pass computes the emitters' unshadowed light in closed form and
    /// samples only their visibility (the ratio estimator, docs/cache-frame.md §8.2): at most
    /// [`ANALYTIC_EMITTERS_MAX`] emissive triangles, none with an emissive texture or an alpha
    /// test (the closed form takes the whole triangle). Lambert's formula gives irradiance, not
    /// a glossy lobe's integral: in a scene with specular materials only the pixels of
    /// Lambertian ones take the closed form, the others sample the emitters as before.
    pub analytic_emitters: bool,
    /// The cache's gather paths take the emitters' light at each vertex in closed form, less a
    /// one-sample estimate of its hidden part (`PATH_CLOSED_FORM_EMITTERS`,
    /// `shaders/common/path.glsl`): with [`Self::analytic_emitters`] and no specular material,
    /// where the emitters cover at least [`CLOSED_FORM_GATHER_MIN_EMITTER_SHARE`] of the bounding
    /// box's surface. False: one sampled shadow ray per vertex with MIS.
    pub closed_form_gathers: bool,
    /// Some material has a specular lobe (metallic, or a dielectric specular layer): the passes
    /// compile the full metallic-roughness BRDF (`HAS_SPECULAR`). False when every material is
    /// Lambertian ([`Material::is_lambertian`](crate::Material::is_lambertian)).
    pub specular: bool,
    /// Some material is Lambertian: the records' gather paths share a radiance grid at the
    /// vertices on such materials ([`Self::path_grid`]).
    pub lambertian: bool,
    /// Materials whose specular lobe is rough enough for the radiance records
    /// (docs/radiance-caching.md §4): not Lambertian, roughness factor at or above
    /// `GLOSSY_ROUGHNESS_MIN` (a roughness texture can only lower it; pixels below the threshold
    /// keep the per-pixel specular paths). Zero: no radiance records, nothing of them compiled.
    pub glossy_materials: usize,
    /// Some material's surface may be missing in places (alpha mode MASK or BLEND,
    /// [`Material::has_alpha`](crate::Material::has_alpha)): the passes compile the alpha test
    /// (`HAS_ALPHA`) into every ray query and the G-buffer, and the geometry of those materials is
    /// built non-opaque. False: every ray query keeps the opaque fast path.
    pub alpha: bool,
    /// Some primitive has a normal-mapped material and the tangents it needs (docs/materials.md
    /// §12): the passes compile the normal-map code (`HAS_NORMAL_MAPS`) and upload a tangent per
    /// vertex. False otherwise: no tangent memory, no normal-map code.
    pub normal_maps: bool,
    /// Some texture reference has a `KHR_texture_transform` other than the identity
    /// ([`Material::has_uv_transform`](crate::Material::has_uv_transform); docs/materials.md
    /// §13): the passes compile the transforms in (`HAS_UV_TRANSFORM`). False: every lookup
    /// takes its coordinates as they are.
    pub uv_transform: bool,
    /// Some primitive's material samples a texture through TEXCOORD_1 (its mesh keeps
    /// `Mesh::texcoords1`): the passes compile the second set in (`HAS_TEXCOORD1`) and upload it
    /// per vertex. False: no second set in memory or in the shaders.
    pub texcoord1: bool,
    /// The cache's G-buffer is ray traced, one camera ray per pixel (`passes/gbuffer.comp`):
    /// the scene has at least [`TRACED_GBUFFER_MIN_TRIANGLES`] instanced triangles, where
    /// rasterizing them all at every sub-frame costs more than a ray per pixel. False: they are
    /// rasterized (`passes/gbuffer.vert` and `.frag`).
    pub traced_gbuffer: bool,
    /// Punctual light instances by kind.
    pub lights: LightCounts,
    /// Environment kind.
    pub environment: EnvironmentKind,
    /// Number of textures used by materials.
    pub textures: usize,
    /// Animation summary.
    pub animation: AnimationPlan,
}

impl ScenePlan {
    /// Derives the plan of `scene`.
    pub fn new(scene: &Scene) -> ScenePlan {
        let time_range = scene.time_range();
        let t0 = time_range.map_or(0.0, |r| r.0);
        let emitters = scene.emitters_at(t0);
        let mut lights = LightCounts::default();
        for li in &scene.light_instances {
            match scene.lights[li.light].kind {
                LightKind::Point => lights.point += 1,
                LightKind::Spot { .. } => lights.spot += 1,
                LightKind::Directional => lights.directional += 1,
            }
        }
        let camera = scene.camera.node.is_some_and(|n| scene.dynamic[n]);
        let lights_moving = scene.light_instances.iter().any(|l| l.dynamic);
        let geometry = scene.instances.iter().any(|i| i.dynamic);
        let kind = if geometry {
            AnimationKind::Geometry
        } else if lights_moving {
            AnimationKind::LightsOnly
        } else if camera {
            AnimationKind::CameraOnly
        } else {
            AnimationKind::None
        };
        let textured_emission = scene
            .materials
            .iter()
            .any(|m| (m.emissive_texture.is_some() || m.has_alpha()) && m.is_emissive());
        let count = emitters.triangles.len();
        let specular = scene.materials.iter().any(|m| !m.is_lambertian());
        let lambertian = scene.materials.iter().any(|m| m.is_lambertian());
        let alpha = scene.materials.iter().any(|m| m.has_alpha());
        let glossy_materials = scene
            .materials
            .iter()
            .filter(|m| !m.is_lambertian() && m.roughness >= GLOSSY_ROUGHNESS_MIN)
            .count();
        let analytic_emitters = count > 0 && count <= ANALYTIC_EMITTERS_MAX && !textured_emission;
        let emitter_area: f32 = emitters.triangles.iter().map(|t| t.area).sum();
        let b = scene.bounds_at(t0);
        let e = (b.max - b.min).max(glam::Vec3::ZERO);
        let box_area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
        let closed_form_gathers = analytic_emitters
            && !specular
            && box_area > 0.0
            && emitter_area >= CLOSED_FORM_GATHER_MIN_EMITTER_SHARE * box_area;
        ScenePlan {
            glossy_materials,
            analytic_emitters,
            closed_form_gathers,
            specular,
            lambertian,
            alpha,
            normal_maps: scene.meshes.iter().any(|m| !m.tangents.is_empty()),
            uv_transform: scene.materials.iter().any(|m| m.has_uv_transform()),
            texcoord1: scene.meshes.iter().any(|m| !m.texcoords1.is_empty()),
            traced_gbuffer: scene.instanced_triangle_count() >= TRACED_GBUFFER_MIN_TRIANGLES,
            emissive_triangles: count,
            emissive_power: emitters.total_power,
            lights,
            environment: match scene.environment {
                Environment::None => EnvironmentKind::None,
                Environment::Constant(_) => EnvironmentKind::Constant,
                Environment::Map { .. } => EnvironmentKind::Map,
            },
            textures: scene.textures.len(),
            animation: AnimationPlan {
                kind,
                camera,
                lights: lights_moving,
                geometry,
                time_range,
            },
        }
    }

    /// The gathers of new records may share a radiance grid (docs/cache-frame.md §4.1;
    /// `PATH_GRID`): some material is Lambertian, and past a vertex on one the light a path
    /// finds does not depend on the direction it came from (vertices on other materials neither
    /// read nor fill the grid).
    pub fn path_grid(&self) -> bool {
        self.lambertian
    }

    /// The scene has emissive triangles.
    pub fn has_emissive(&self) -> bool {
        self.emissive_triangles > 0
    }

    /// The cache caches incoming radiance for glossy lobes ([`ScenePlan::glossy_materials`]).
    pub fn radiance_cache(&self) -> bool {
        self.glossy_materials > 0
    }

    /// The scene has punctual lights.
    pub fn has_punctual_lights(&self) -> bool {
        self.lights.total() > 0
    }
}

impl Scene {
    /// The scene's rendering plan.
    pub fn plan(&self) -> ScenePlan {
        ScenePlan::new(self)
    }
}

impl ScenePlan {
    /// Whether an animation's irradiance records stay valid from frame to frame as they are:
    /// records are world-space, so they do while nothing but the camera moves.
    pub fn keeps_records(&self) -> bool {
        matches!(
            self.animation.kind,
            AnimationKind::None | AnimationKind::CameraOnly
        )
    }

    /// Whether kept records need temporal caching (docs/temporal.md §1, §3): moving geometry or
    /// lights change the irradiance, so records follow their instances, carry temporal gradients
    /// and are refreshed in place when their lifespan ends.
    pub fn needs_lifespans(&self) -> bool {
        matches!(
            self.animation.kind,
            AnimationKind::LightsOnly | AnimationKind::Geometry
        )
    }
}

impl fmt::Display for ScenePlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "plan:")?;
        if self.has_emissive() {
            writeln!(
                f,
                "  emissive triangles: {} (power {:.4} W; cache frames: {})",
                self.emissive_triangles,
                self.emissive_power,
                match (self.analytic_emitters, self.closed_form_gathers) {
                    (true, true) => {
                        "unshadowed light in closed form, shadows sampled; in the records' \
                         gathers too"
                    }
                    (true, false) => "unshadowed light in closed form, shadows sampled",
                    _ => "sampled with MIS",
                }
            )?;
        } else {
            writeln!(f, "  emissive triangles: none")?;
        }
        let l = &self.lights;
        if self.has_punctual_lights() {
            writeln!(
                f,
                "  punctual lights: {} point, {} spot, {} directional",
                l.point, l.spot, l.directional
            )?;
        } else {
            writeln!(f, "  punctual lights: none")?;
        }
        let env = match self.environment {
            EnvironmentKind::None => "none",
            EnvironmentKind::Constant => {
                "constant (cache frames: its light gathered by the records, unless `--set sky=direct`)"
            }
            EnvironmentKind::Map => "map",
        };
        writeln!(f, "  environment: {env}")?;
        writeln!(
            f,
            "  materials: {}",
            if self.specular {
                "metallic-roughness BRDF (specular lobes compiled in)"
            } else {
                "lambertian only (no specular code compiled)"
            }
        )?;
        writeln!(
            f,
            "  gather paths: {}",
            match (self.path_grid(), self.specular) {
                (true, false) => {
                    "radiance grid (a path ends where its cell holds enough continuations)"
                }
                (true, true) => {
                    "radiance grid at Lambertian vertices (a path ends where its cell holds \
                     enough continuations)"
                }
                _ => "to their end (no Lambertian material: no radiance grid)",
            }
        )?;
        if self.specular {
            if self.radiance_cache() {
                writeln!(
                    f,
                    "  glossy lobes: radiance records for roughness ≥ {GLOSSY_ROUGHNESS_MIN} \
                     ({} material{}; sharper lobes path traced per pixel, the paths pooled over \
                     each pixel's 3×3 neighbourhood)",
                    self.glossy_materials,
                    if self.glossy_materials == 1 { "" } else { "s" }
                )?;
            } else {
                writeln!(
                    f,
                    "  glossy lobes: none at roughness ≥ {GLOSSY_ROUGHNESS_MIN} (specular light \
                     path traced per pixel, the paths pooled over each pixel's 3×3 neighbourhood; \
                     no radiance records)"
                )?;
            }
        }
        writeln!(
            f,
            "  G-buffer: {}",
            if self.traced_gbuffer {
                "ray traced (a camera ray per pixel)"
            } else {
                "rasterized (few triangles)"
            }
        )?;
        writeln!(
            f,
            "  normal maps: {}",
            if self.normal_maps {
                "yes (a tangent per vertex)"
            } else {
                "none"
            }
        )?;
        writeln!(
            f,
            "  textures: {}",
            if self.textures > 0 { "yes" } else { "no" }
        )?;
        writeln!(
            f,
            "  texture coordinates: {}, {}",
            if self.texcoord1 {
                "TEXCOORD_0 and TEXCOORD_1 (a second set per vertex)"
            } else {
                "TEXCOORD_0"
            },
            if self.uv_transform {
                "KHR_texture_transform applied"
            } else {
                "no transforms"
            }
        )?;
        writeln!(
            f,
            "  alpha: {}",
            if self.alpha {
                "masked or blended materials (alpha-tested ray queries and G-buffer)"
            } else {
                "none (opaque ray queries)"
            }
        )?;
        let a = &self.animation;
        let kind = match a.kind {
            AnimationKind::None => "none",
            AnimationKind::CameraOnly => "camera only",
            AnimationKind::LightsOnly => "lights only",
            AnimationKind::Geometry => "geometry",
        };
        write!(f, "  animation: {kind}")?;
        if a.kind != AnimationKind::None {
            let yn = |b: bool| if b { "yes" } else { "no" };
            write!(
                f,
                " (camera {}, lights {}, geometry {})",
                yn(a.camera),
                yn(a.lights),
                yn(a.geometry)
            )?;
        }
        if let Some((t0, t1)) = a.time_range {
            write!(f, ", time range [{t0:.3}, {t1:.3}] s")?;
        }
        writeln!(f)?;
        let cache = if self.keeps_records() {
            "records kept from frame to frame (holes filled where the view uncovers new surfaces)"
        } else {
            "records kept with lifespans (moving geometry or lights: records follow their \
             instances, are extrapolated in time and refreshed in place when they expire)"
        };
        writeln!(f, "  cache across frames: {cache}")?;
        if !self.keeps_records() && self.path_grid() {
            writeln!(
                f,
                "  radiance grid across frames: kept with the records, each cell at most the \
                 records' longest life old"
            )?;
        }
        Ok(())
    }
}
