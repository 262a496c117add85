//! Synchronization2 access descriptions and image uses.
//!
//! Passes state what they did and what comes next (`rec.barrier(Access::COMPUTE_WRITE,
//! Access::FRAGMENT_READ)`); images carry their current layout and last access, so
//! `rec.use_image(&img, ImageUse::ColorAttachment)` derives the layout transition and the memory
//! dependency from the tracked state.

use ash::vk;

type S = vk::PipelineStageFlags2;
type A = vk::AccessFlags2;

/// A pipeline stage set and the memory accesses made there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Access {
    /// Pipeline stages.
    pub stage: vk::PipelineStageFlags2,
    /// Memory accesses.
    pub access: vk::AccessFlags2,
}

const SHADER_READS: A = A::from_raw(
    A::SHADER_STORAGE_READ.as_raw() | A::SHADER_SAMPLED_READ.as_raw() | A::UNIFORM_READ.as_raw(),
);
const RASTER: S = S::from_raw(S::VERTEX_SHADER.as_raw() | S::FRAGMENT_SHADER.as_raw());

impl Access {
    /// Nothing (the start of a command buffer, or an undefined image).
    pub const NONE: Access = Access::new(S::NONE, A::NONE);
    /// Compute shaders reading buffers, images, uniforms.
    pub const COMPUTE_READ: Access = Access::new(S::COMPUTE_SHADER, SHADER_READS);
    /// Compute shaders writing storage buffers/images.
    pub const COMPUTE_WRITE: Access = Access::new(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE);
    /// Compute shaders reading and writing.
    pub const COMPUTE_READ_WRITE: Access = Access::COMPUTE_READ.union(Access::COMPUTE_WRITE);
    /// Vertex and fragment shaders reading buffers and images.
    pub const RASTER_READ: Access = Access::new(RASTER, SHADER_READS);
    /// Fragment shaders writing storage buffers/images.
    pub const FRAGMENT_WRITE: Access = Access::new(S::FRAGMENT_SHADER, A::SHADER_STORAGE_WRITE);
    /// Indirect dispatch/draw arguments.
    pub const INDIRECT: Access = Access::new(S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ);
    /// Index buffer reads.
    pub const INDEX_READ: Access = Access::new(S::INDEX_INPUT, A::INDEX_READ);
    /// Transfer reads.
    pub const TRANSFER_READ: Access = Access::new(S::ALL_TRANSFER, A::TRANSFER_READ);
    /// Transfer writes (copies, fills, clears).
    pub const TRANSFER_WRITE: Access = Access::new(S::ALL_TRANSFER, A::TRANSFER_WRITE);
    /// Host reads after a readback.
    pub const HOST_READ: Access = Access::new(S::HOST, A::HOST_READ);
    /// Acceleration structure build reading its inputs and source structures.
    pub const AS_BUILD_READ: Access = Access::new(
        S::ACCELERATION_STRUCTURE_BUILD_KHR,
        A::from_raw(A::SHADER_READ.as_raw() | A::ACCELERATION_STRUCTURE_READ_KHR.as_raw()),
    );
    /// Acceleration structure build writing the structure and scratch.
    pub const AS_BUILD_WRITE: Access = Access::new(
        S::ACCELERATION_STRUCTURE_BUILD_KHR,
        A::from_raw(
            A::ACCELERATION_STRUCTURE_WRITE_KHR.as_raw()
                | A::ACCELERATION_STRUCTURE_READ_KHR.as_raw(),
        ),
    );
    /// Ray queries in compute or fragment shaders.
    pub const RAY_QUERY: Access = Access::new(
        S::from_raw(S::COMPUTE_SHADER.as_raw() | S::FRAGMENT_SHADER.as_raw()),
        A::ACCELERATION_STRUCTURE_READ_KHR,
    );
    /// Colour attachment output (load, blend, store).
    pub const COLOR_ATTACHMENT: Access = Access::new(
        S::COLOR_ATTACHMENT_OUTPUT,
        A::from_raw(A::COLOR_ATTACHMENT_READ.as_raw() | A::COLOR_ATTACHMENT_WRITE.as_raw()),
    );
    /// Depth attachment tests and writes.
    pub const DEPTH_ATTACHMENT: Access = Access::new(
        S::from_raw(S::EARLY_FRAGMENT_TESTS.as_raw() | S::LATE_FRAGMENT_TESTS.as_raw()),
        A::from_raw(
            A::DEPTH_STENCIL_ATTACHMENT_READ.as_raw() | A::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
        ),
    );
    /// Every write of every stage (a conservative source).
    pub const ALL_WRITES: Access = Access::new(S::ALL_COMMANDS, A::MEMORY_WRITE);
    /// Every access of every stage (a conservative destination).
    pub const ALL: Access = Access::new(
        S::ALL_COMMANDS,
        A::from_raw(A::MEMORY_READ.as_raw() | A::MEMORY_WRITE.as_raw()),
    );

    /// An access from raw flags.
    pub const fn new(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2) -> Self {
        Access { stage, access }
    }

    /// Both accesses.
    pub const fn union(self, other: Access) -> Access {
        Access {
            stage: S::from_raw(self.stage.as_raw() | other.stage.as_raw()),
            access: A::from_raw(self.access.as_raw() | other.access.as_raw()),
        }
    }
}

/// How an image is about to be used; decides its layout and access.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageUse {
    /// Colour attachment (rendering, blending).
    ColorAttachment,
    /// Depth attachment (test and write).
    DepthAttachment,
    /// Storage image read/written by compute shaders.
    ComputeStorage,
    /// Storage image read/written by fragment shaders.
    FragmentStorage,
    /// Sampled by compute shaders.
    ComputeSampled,
    /// Sampled by vertex/fragment shaders.
    RasterSampled,
    /// Source of a copy.
    TransferSrc,
    /// Destination of a copy or clear.
    TransferDst,
}

impl ImageUse {
    pub(crate) fn layout_and_access(self, depth: bool) -> (vk::ImageLayout, Access) {
        use vk::ImageLayout as L;
        match self {
            ImageUse::ColorAttachment => (L::COLOR_ATTACHMENT_OPTIMAL, Access::COLOR_ATTACHMENT),
            ImageUse::DepthAttachment => (L::DEPTH_ATTACHMENT_OPTIMAL, Access::DEPTH_ATTACHMENT),
            ImageUse::ComputeStorage => (L::GENERAL, Access::COMPUTE_READ_WRITE),
            ImageUse::FragmentStorage => (
                L::GENERAL,
                Access::new(
                    S::FRAGMENT_SHADER,
                    A::from_raw(A::SHADER_STORAGE_READ.as_raw() | A::SHADER_STORAGE_WRITE.as_raw()),
                ),
            ),
            ImageUse::ComputeSampled => (
                if depth {
                    L::DEPTH_READ_ONLY_OPTIMAL
                } else {
                    L::SHADER_READ_ONLY_OPTIMAL
                },
                Access::COMPUTE_READ,
            ),
            ImageUse::RasterSampled => (
                if depth {
                    L::DEPTH_READ_ONLY_OPTIMAL
                } else {
                    L::SHADER_READ_ONLY_OPTIMAL
                },
                Access::RASTER_READ,
            ),
            ImageUse::TransferSrc => (L::TRANSFER_SRC_OPTIMAL, Access::TRANSFER_READ),
            ImageUse::TransferDst => (L::TRANSFER_DST_OPTIMAL, Access::TRANSFER_WRITE),
        }
    }
}
