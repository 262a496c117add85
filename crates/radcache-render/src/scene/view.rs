//! The per-frame side of [`GpuScene`]: frame constants for a view, shader defines of the plan, and
//! the binding table every scene-reading pass pushes.

use radcache_scene::CameraView;
use radcache_shared::gpu::FrameConstants;
use radcache_vk::Resource;

use super::GpuScene;
use crate::bindings as b;
use crate::error::Result;
use crate::scene::upload::{cols, vulkan_clip_from_view};

impl GpuScene {
    /// Writes the frame constants for `view` at `width × height`.
    pub fn set_view(
        &mut self,
        view: &CameraView,
        width: u32,
        height: u32,
        frame: u32,
        seed: u32,
    ) -> Result<()> {
        let aspect = width as f32 / height.max(1) as f32;
        let clip_from_world =
            vulkan_clip_from_view(view.perspective.yfov, aspect, view.perspective.znear)
                * view.view_from_world();
        let world_from_clip = clip_from_world.inverse();
        let p = view.position;
        self.constants = FrameConstants {
            clip_from_world: cols(clip_from_world),
            world_from_clip: cols(world_from_clip),
            camera_position: [p.x, p.y, p.z, self.scene_scale],
            environment: [
                self.env_constant.x,
                self.env_constant.y,
                self.env_constant.z,
                self.env_scale,
            ],
            resolution: [width, height, frame, seed],
            counts: [
                self.emitter_count,
                self.light_count,
                self.transforms.len() as u32,
                self.env_size.0,
            ],
            totals: [self.emitter_power, self.env_size.1 as f32, 0.0, 0.0],
        };
        self.frame.write(0, std::slice::from_ref(&self.constants))?;
        Ok(())
    }

    /// The frame constants last written.
    pub fn constants(&self) -> &FrameConstants {
        &self.constants
    }

    /// Shader defines of the scene's materials: `HAS_SPECULAR` when some material is not
    /// Lambertian (`ScenePlan::specular`), which compiles in the full metallic-roughness BRDF;
    /// `HAS_ALPHA` when some material is alpha-tested (`ScenePlan::alpha`), which compiles the
    /// alpha test into every ray query and the G-buffer; `HAS_NORMAL_MAPS` when some primitive
    /// has a normal map (`ScenePlan::normal_maps`), which compiles in the tangent binding and the
    /// normal-map code; `HAS_UV_TRANSFORM` when some texture reference has a
    /// `KHR_texture_transform` (`ScenePlan::uv_transform`) and `HAS_TEXCOORD1` when some samples
    /// TEXCOORD_1 (`ScenePlan::texcoord1`), which compile in the transforms and the second set
    /// (its binding, its interpolation and the choice of set per reference).
    pub fn material_defines(&self) -> Vec<(&'static str, &'static str)> {
        let mut d = Vec::new();
        if self.plan.specular {
            d.push(("HAS_SPECULAR", "1"));
        }
        if self.plan.alpha {
            d.push(("HAS_ALPHA", "1"));
        }
        if self.plan.normal_maps {
            d.push(("HAS_NORMAL_MAPS", "1"));
        }
        if self.plan.uv_transform {
            d.push(("HAS_UV_TRANSFORM", "1"));
        }
        if self.plan.texcoord1 {
            d.push(("HAS_TEXCOORD1", "1"));
        }
        d
    }

    /// Shader defines that compile in only the light sources and material features the scene
    /// has.
    pub fn defines(&self) -> Vec<(&'static str, &'static str)> {
        let mut d = self.material_defines();
        if self.plan.has_emissive() {
            d.push(("HAS_EMITTERS", "1"));
        }
        if self.plan.has_punctual_lights() {
            d.push(("HAS_LIGHTS", "1"));
        }
        if self.has_constant_environment() {
            d.push(("HAS_ENV_CONSTANT", "1"));
        }
        if self.env_size.0 > 0 {
            d.push(("HAS_ENV_MAP", "1"));
        }
        d
    }

    /// The scene's binding table (bindings 0–15), to prefix a pass's own bindings.
    pub fn bindings(&self) -> Vec<(u32, Resource<'_>)> {
        vec![
            (b::FRAME, Resource::Buffer(&self.frame)),
            (b::TLAS, Resource::Tlas(&self.tlas)),
            (b::VERTICES, Resource::Buffer(&self.vertices)),
            (b::INDICES, Resource::Buffer(&self.indices)),
            (b::INSTANCES, Resource::Buffer(&self.instances)),
            (b::TRI_MATERIALS, Resource::Buffer(&self.tri_materials)),
            (b::MATERIALS, Resource::Buffer(&self.materials)),
            (b::TEXTURES, Resource::Buffer(&self.textures)),
            (b::TEXELS, Resource::Buffer(&self.texels)),
            (b::EMITTERS, Resource::Buffer(&self.emitters)),
            (b::EMITTER_ALIAS, Resource::Buffer(&self.emitter_alias)),
            (b::LIGHTS, Resource::Buffer(&self.lights)),
            (b::ENV_TEXELS, Resource::Buffer(&self.env_texels)),
            (b::ENV_ALIAS, Resource::Buffer(&self.env_alias)),
            (b::TANGENTS, Resource::Buffer(&self.tangents)),
            (b::TEXCOORDS1, Resource::Buffer(&self.texcoords1)),
        ]
    }
}
