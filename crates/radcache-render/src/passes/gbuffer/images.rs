//! The irradiance cache's G-buffer: the images every IC pass reads (layout in
//! `shaders/common/gbuffer.glsl`), bound at `PASS_BASE + 0..5`.

use radcache_vk::{
    vk, BindingLayout, Buffer, BufferDesc, Context, Image, ImageDesc, MemoryLocation, Resource,
};

use crate::bindings::{gbuffer as b, GBUFFER};
use crate::error::Result;

/// Format of every G-buffer colour image.
pub const GBUFFER_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Format of the depth attachment (reversed Z: 1 at the near plane, cleared to 0).
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Number of bindings the G-buffer occupies from `PASS_BASE` (the last is the direct light).
pub const GBUFFER_BINDINGS: u32 = GBUFFER.len() as u32;

/// The G-buffer images of one image size.
pub struct GBuffer {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// World position (xyz), 1 on surfaces / 0 on the background (w).
    pub position: Image,
    /// Shading normal toward the camera (xyz), pixel footprint (w).
    pub normal: Image,
    /// Geometric normal toward the camera (xyz), material index (w).
    pub geometric: Image,
    /// Diffuse albedo (rgb), mesh instance (w, its custom index as a float).
    pub albedo: Image,
    /// Emitted radiance toward the camera (rgb).
    pub emission: Image,
    /// Direct light reflected toward the camera (rgb), written by the direct pass.
    pub direct: Image,
    /// Depth attachment of the rasterization.
    pub depth: Image,
    /// One `uint` a pixel, host-visible: 1 where the next sub-frames shade the pixel, 0 where
    /// per-pixel adaptive anti-aliasing has stopped it (docs/cache-frame.md §7.2). The G-buffer
    /// pass marks a stopped pixel's position with w = −1 instead of finding its surface, and
    /// the direct and composite passes leave it alone. All 1 unless [`GBuffer::set_active`]
    /// says otherwise.
    active: Buffer,
    /// Whether `active` holds a 0 somewhere.
    partly_active: bool,
}

impl std::fmt::Debug for GBuffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GBuffer")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl GBuffer {
    /// Allocates the images for `width × height`.
    pub fn new(ctx: &Context, width: u32, height: u32) -> Result<GBuffer> {
        let color = |name| {
            Image::new(
                ctx,
                &ImageDesc {
                    name,
                    width,
                    height,
                    format: GBUFFER_FORMAT,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE,
                },
            )
        };
        Ok(GBuffer {
            width,
            height,
            position: color("gbuffer.position")?,
            normal: color("gbuffer.normal")?,
            geometric: color("gbuffer.geometric")?,
            albedo: color("gbuffer.albedo")?,
            emission: color("gbuffer.emission")?,
            direct: color("gbuffer.direct")?,
            depth: Image::new(
                ctx,
                &ImageDesc {
                    name: "gbuffer.depth",
                    width,
                    height,
                    format: DEPTH_FORMAT,
                    usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                },
            )?,
            active: {
                let mut active = Buffer::new(
                    ctx,
                    &BufferDesc {
                        name: "gbuffer.active",
                        size: 4 * u64::from(width) * u64::from(height),
                        usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                        location: MemoryLocation::CpuToGpu,
                        alignment: 0,
                    },
                )?;
                active.write(0, &vec![1u32; (width * height) as usize])?;
                active
            },
            partly_active: false,
        })
    }

    /// Which pixels the following sub-frames shade: `mask[i]` non-zero for pixel i (row-major),
    /// `None` for all of them. No submission that uses the G-buffer may be in flight.
    pub fn set_active(&mut self, mask: Option<&[u32]>) -> Result<()> {
        match mask {
            Some(mask) => {
                if mask.len() != (self.width * self.height) as usize {
                    return Err(crate::error::Error::Invalid(format!(
                        "an activity mask of {} pixels for a {}x{} G-buffer",
                        mask.len(),
                        self.width,
                        self.height
                    )));
                }
                self.active.write(0, mask)?;
                self.partly_active = mask.contains(&0);
            }
            None if self.partly_active => {
                self.active
                    .write(0, &vec![1u32; (self.width * self.height) as usize])?;
                self.partly_active = false;
            }
            None => {}
        }
        Ok(())
    }

    /// The activity mask's binding for the G-buffer pass (`gbuffer_pass::ACTIVE`).
    pub fn active_binding(&self) -> (u32, Resource<'_>) {
        (
            crate::bindings::gbuffer_pass::ACTIVE,
            Resource::Buffer(&self.active),
        )
    }

    /// The binding layout of the G-buffer images (storage images at `PASS_BASE + 0..5`).
    pub fn layout() -> [BindingLayout; GBUFFER_BINDINGS as usize] {
        GBUFFER
    }

    /// The images to push at `PASS_BASE + 0..5` (as storage images: each dispatch or draw that
    /// pushes them transitions them to `GENERAL`).
    pub fn bindings(&self) -> [(u32, Resource<'_>); GBUFFER_BINDINGS as usize] {
        [
            (b::POSITION, Resource::StorageImage(&self.position)),
            (b::NORMAL, Resource::StorageImage(&self.normal)),
            (b::GEOMETRIC, Resource::StorageImage(&self.geometric)),
            (b::ALBEDO, Resource::StorageImage(&self.albedo)),
            (b::EMISSION, Resource::StorageImage(&self.emission)),
            (b::DIRECT, Resource::StorageImage(&self.direct)),
        ]
    }

    /// The colour images in attachment order (position, normal, geometric, albedo, emission).
    pub fn attachments(&self) -> [&Image; 5] {
        [
            &self.position,
            &self.normal,
            &self.geometric,
            &self.albedo,
            &self.emission,
        ]
    }

    /// Every colour image, the direct-light image included.
    pub fn images(&self) -> [&Image; 6] {
        [
            &self.position,
            &self.normal,
            &self.geometric,
            &self.albedo,
            &self.emission,
            &self.direct,
        ]
    }
}
