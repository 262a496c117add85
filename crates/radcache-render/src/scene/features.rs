//! What of a scene's plan reaches the shaders: the features that set their defines, and the
//! shader modules a pass compiles. Every pass lists its modules from these and its variant, and
//! compiles exactly that list; `cargo xtask shaders` compiles and validates the same lists for
//! every variant ([`crate::passes::every_shader_module`]).

use std::sync::Arc;

use radcache_scene::ScenePlan;
use radcache_vk::ShaderCompiler;

use crate::error::Result;

/// One shader module as a pass compiles it: its path under `shaders/` and its defines.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ShaderModule {
    /// The path under `shaders/`.
    pub path: &'static str,
    /// The defines, in the order the pass passes them.
    pub defines: Vec<(&'static str, &'static str)>,
}

impl ShaderModule {
    /// `path` compiled with `defines`.
    pub fn new(path: &'static str, defines: Vec<(&'static str, &'static str)>) -> ShaderModule {
        ShaderModule { path, defines }
    }

    /// `path` compiled without defines.
    pub fn plain(path: &'static str) -> ShaderModule {
        ShaderModule::new(path, Vec::new())
    }

    /// The module's SPIR-V, compiled by `shaders`.
    pub fn compile(&self, shaders: &ShaderCompiler) -> Result<Arc<Vec<u32>>> {
        Ok(shaders.compile(self.path, &self.defines)?)
    }
}

/// The scene's features that set shader defines: the plan's, and which environment it has.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    /// Some material has a specular lobe (`HAS_SPECULAR`, [`ScenePlan::specular`]).
    pub specular: bool,
    /// Some material is alpha-tested (`HAS_ALPHA`, [`ScenePlan::alpha`]).
    pub alpha: bool,
    /// Some primitive has a normal map (`HAS_NORMAL_MAPS`, [`ScenePlan::normal_maps`]).
    pub normal_maps: bool,
    /// Some texture reference has a transform (`HAS_UV_TRANSFORM`, [`ScenePlan::uv_transform`]).
    pub uv_transform: bool,
    /// Some material samples TEXCOORD_1 (`HAS_TEXCOORD1`, [`ScenePlan::texcoord1`]).
    pub texcoord1: bool,
    /// The scene has emissive triangles (`HAS_EMITTERS`).
    pub emitters: bool,
    /// It has punctual lights (`HAS_LIGHTS`).
    pub lights: bool,
    /// It has a constant environment that emits (`HAS_ENV_CONSTANT`).
    pub env_constant: bool,
    /// It has an environment map (`HAS_ENV_MAP`).
    pub env_map: bool,
    /// The plan allows the emitters' light in closed form ([`ScenePlan::analytic_emitters`]).
    pub analytic_emitters: bool,
    /// The gathers may take the emitters' light in closed form
    /// ([`ScenePlan::closed_form_gathers`]).
    pub closed_form_gathers: bool,
    /// The gathers may share a radiance grid ([`ScenePlan::path_grid`]).
    pub path_grid: bool,
    /// The scene has glossy materials for the radiance records
    /// ([`ScenePlan::radiance_cache`]; some material is then specular): without them no pass
    /// is made with radiance (`HAS_RADIANCE_CACHE`). Sets no define itself.
    pub radiance_cache: bool,
}

impl SceneFeatures {
    /// The features of a scene planned as `plan`, with (`env_constant`) or without a constant
    /// environment and with (`env_map`) or without an environment map.
    pub fn new(plan: &ScenePlan, env_constant: bool, env_map: bool) -> SceneFeatures {
        SceneFeatures {
            specular: plan.specular,
            alpha: plan.alpha,
            normal_maps: plan.normal_maps,
            uv_transform: plan.uv_transform,
            texcoord1: plan.texcoord1,
            emitters: plan.has_emissive(),
            lights: plan.has_punctual_lights(),
            env_constant,
            env_map,
            analytic_emitters: plan.analytic_emitters,
            closed_form_gathers: plan.closed_form_gathers,
            path_grid: plan.path_grid(),
            radiance_cache: plan.radiance_cache(),
        }
    }

    /// Shader defines of the scene's materials: `HAS_SPECULAR` compiles in the full
    /// metallic-roughness BRDF; `HAS_ALPHA` the alpha test into every ray query and the
    /// G-buffer; `HAS_NORMAL_MAPS` the tangent binding and the normal-map code;
    /// `HAS_UV_TRANSFORM` and `HAS_TEXCOORD1` the texture transforms and the second set of
    /// coordinates (its binding, its interpolation and the choice of set per reference).
    pub fn material_defines(&self) -> Vec<(&'static str, &'static str)> {
        [
            (self.specular, "HAS_SPECULAR"),
            (self.alpha, "HAS_ALPHA"),
            (self.normal_maps, "HAS_NORMAL_MAPS"),
            (self.uv_transform, "HAS_UV_TRANSFORM"),
            (self.texcoord1, "HAS_TEXCOORD1"),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some((name, "1")))
        .collect()
    }

    /// Shader defines that compile in only the light sources and material features the scene
    /// has: the material defines and `HAS_EMITTERS`, `HAS_LIGHTS`, `HAS_ENV_CONSTANT`,
    /// `HAS_ENV_MAP`.
    pub fn defines(&self) -> Vec<(&'static str, &'static str)> {
        let mut d = self.material_defines();
        d.extend(
            [
                (self.emitters, "HAS_EMITTERS"),
                (self.lights, "HAS_LIGHTS"),
                (self.env_constant, "HAS_ENV_CONSTANT"),
                (self.env_map, "HAS_ENV_MAP"),
            ]
            .into_iter()
            .filter_map(|(on, name)| on.then_some((name, "1"))),
        );
        d
    }

    /// Feature sets whose defines cover every scene the planner can see, for compiling every
    /// variant: none; each feature alone (with what the plan requires of it: closed-form
    /// emitters need emitters, closed-form gathers closed-form emitters and no specular
    /// material, glossy materials a specular one); and every feature at once, once with each
    /// kind of environment.
    pub fn coverage() -> Vec<SceneFeatures> {
        let none = SceneFeatures::default();
        let emitters = SceneFeatures {
            emitters: true,
            ..none
        };
        let analytic = SceneFeatures {
            analytic_emitters: true,
            ..emitters
        };
        let all = SceneFeatures {
            specular: true,
            alpha: true,
            normal_maps: true,
            uv_transform: true,
            texcoord1: true,
            emitters: true,
            lights: true,
            env_constant: true,
            env_map: false,
            analytic_emitters: true,
            closed_form_gathers: false,
            path_grid: true,
            radiance_cache: true,
        };
        vec![
            none,
            SceneFeatures {
                specular: true,
                ..none
            },
            SceneFeatures {
                alpha: true,
                ..none
            },
            SceneFeatures {
                normal_maps: true,
                ..none
            },
            SceneFeatures {
                uv_transform: true,
                ..none
            },
            SceneFeatures {
                texcoord1: true,
                ..none
            },
            emitters,
            analytic,
            SceneFeatures {
                closed_form_gathers: true,
                path_grid: true,
                ..analytic
            },
            SceneFeatures {
                lights: true,
                ..none
            },
            SceneFeatures {
                env_constant: true,
                ..none
            },
            SceneFeatures {
                env_map: true,
                ..none
            },
            SceneFeatures {
                path_grid: true,
                ..none
            },
            all,
            SceneFeatures {
                env_constant: false,
                env_map: true,
                ..all
            },
        ]
    }
}
