//! 2D images with one view (RAII over gpu-allocator), their tracked layout, and samplers.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::hazard::Target;

/// What to create.
#[derive(Debug, Clone)]
pub struct ImageDesc<'a> {
    /// Debug and allocation name.
    pub name: &'a str,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixel format.
    pub format: vk::Format,
    /// Usage flags (`TRANSFER_SRC | TRANSFER_DST` are always added).
    pub usage: vk::ImageUsageFlags,
}

/// A device-local 2D image with a full view. Destroyed after the GPU is done with it.
pub struct Image {
    shared: Arc<DeviceShared>,
    raw: vk::Image,
    view: vk::ImageView,
    allocation: Option<Allocation>,
    format: vk::Format,
    extent: vk::Extent2D,
    aspect: vk::ImageAspectFlags,
    /// The usage it was created with (`TRANSFER_SRC | TRANSFER_DST` included).
    usage: vk::ImageUsageFlags,
    /// Its track: its layout and last use, from which the barrier of its next use is derived
    /// (`hazard.rs`).
    pub(crate) target: Target,
    name: String,
    alloc_id: u64,
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Image")
            .field("name", &self.name)
            .field("extent", &self.extent)
            .field("format", &self.format)
            .finish()
    }
}

/// The one mip level and layer of an image with `aspect`.
fn full_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

fn is_depth(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32
    )
}

impl Image {
    /// Creates the image and its view; the layout starts `UNDEFINED`.
    pub fn new(ctx: &Context, desc: &ImageDesc<'_>) -> Result<Self> {
        let shared = &ctx.shared;
        if desc.width == 0 || desc.height == 0 {
            return Err(Error::Invalid(format!(
                "image {:?} has a zero extent",
                desc.name
            )));
        }
        let aspect = if is_depth(desc.format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        };
        let usage =
            desc.usage | vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.width,
                height: desc.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: the device is live; `info` is valid for the call.
        let raw = unsafe { shared.device.create_image(&info, None) }.call("vkCreateImage")?;
        // SAFETY: `raw` was just created from this device.
        let requirements = unsafe { shared.device.get_image_memory_requirements(raw) };
        let allocation = shared.lock_allocator().as_mut().map(|a| {
            a.allocate(&AllocationCreateDesc {
                name: desc.name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
        });
        let allocation = match allocation {
            Some(Ok(a)) => a,
            other => {
                // SAFETY: `raw` is unused and unbound.
                unsafe { shared.device.destroy_image(raw, None) };
                return Err(match other {
                    Some(Err(source)) => Error::Alloc {
                        name: desc.name.to_string(),
                        source,
                    },
                    _ => Error::Invalid("allocator already shut down".into()),
                });
            }
        };
        let alloc_id = shared.register(desc.name);
        let mut image = Image {
            shared: shared.clone(),
            raw,
            view: vk::ImageView::null(),
            allocation: Some(allocation),
            format: desc.format,
            extent: vk::Extent2D {
                width: desc.width,
                height: desc.height,
            },
            aspect,
            usage,
            target: Target::new(desc.name, Some((raw, full_range(aspect)))),
            name: desc.name.to_string(),
            alloc_id,
        };
        if let Some(a) = image.allocation.as_ref() {
            // SAFETY: memory and offset come from an allocation made for this image's
            // requirements; the memory outlives the image (both are retired together).
            unsafe { shared.device.bind_image_memory(raw, a.memory(), a.offset()) }
                .call("vkBindImageMemory")?;
        }
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(image.subresource_range());
        // SAFETY: `raw` is bound to memory; `view_info` is valid for the call.
        image.view = unsafe { shared.device.create_image_view(&view_info, None) }
            .call("vkCreateImageView")?;
        shared.set_name(raw, desc.name);
        shared.set_name(image.view, desc.name);
        Ok(image)
    }

    pub(crate) fn raw(&self) -> vk::Image {
        self.raw
    }

    pub(crate) fn view(&self) -> vk::ImageView {
        self.view
    }

    pub(crate) fn subresource_range(&self) -> vk::ImageSubresourceRange {
        full_range(self.aspect)
    }

    pub(crate) fn aspect(&self) -> vk::ImageAspectFlags {
        self.aspect
    }

    /// Whether this is a depth image.
    pub fn is_depth(&self) -> bool {
        self.aspect == vk::ImageAspectFlags::DEPTH
    }

    /// The usage flags it was created with (`TRANSFER_SRC | TRANSFER_DST` always included).
    pub fn usage(&self) -> vk::ImageUsageFlags {
        self.usage
    }

    /// Pixel format.
    pub fn format(&self) -> vk::Format {
        self.format
    }

    /// Width and height.
    pub fn extent(&self) -> (u32, u32) {
        (self.extent.width, self.extent.height)
    }

    /// The allocation name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        self.shared.unregister(self.alloc_id);
        if let Some(a) = self.allocation.take() {
            self.shared.retire(Garbage::Image(self.raw, self.view, a));
        }
    }
}

/// A texture sampler.
pub struct Sampler {
    shared: Arc<DeviceShared>,
    raw: vk::Sampler,
}

impl std::fmt::Debug for Sampler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sampler").finish()
    }
}

impl Sampler {
    /// A sampler with the given filter and address mode (U and V alike or separately).
    pub fn new(
        ctx: &Context,
        name: &str,
        filter: vk::Filter,
        address_u: vk::SamplerAddressMode,
        address_v: vk::SamplerAddressMode,
    ) -> Result<Self> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(address_u)
            .address_mode_v(address_v)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        // SAFETY: the device is live; `info` is valid for the call.
        let raw =
            unsafe { ctx.shared.device.create_sampler(&info, None) }.call("vkCreateSampler")?;
        ctx.shared.set_name(raw, name);
        Ok(Sampler {
            shared: ctx.shared.clone(),
            raw,
        })
    }

    pub(crate) fn raw(&self) -> vk::Sampler {
        self.raw
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        self.shared.retire(Garbage::Sampler(self.raw));
    }
}
