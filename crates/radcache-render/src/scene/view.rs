//! The per-frame side of [`GpuScene`]: frame constants for a view, shader defines of the plan, and
//! the binding table every scene-reading pass pushes.

use radcache_scene::CameraView;
use radcache_shared::gpu::FrameConstants;
use radcache_vk::Resource;

use super::GpuScene;
use crate::bindings as b;
use crate::error::Result;
use crate::scene::features::SceneFeatures;
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

    /// The features of the scene that set shader defines.
    pub fn features(&self) -> SceneFeatures {
        SceneFeatures::new(
            &self.plan,
            self.has_constant_environment(),
            self.env_size.0 > 0,
        )
    }

    /// Shader defines of the scene's materials ([`SceneFeatures::material_defines`]).
    pub fn material_defines(&self) -> Vec<(&'static str, &'static str)> {
        self.features().material_defines()
    }

    /// Shader defines that compile in only the light sources and material features the scene
    /// has ([`SceneFeatures::defines`]).
    pub fn defines(&self) -> Vec<(&'static str, &'static str)> {
        self.features().defines()
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
