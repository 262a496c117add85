//! Synchronization2 access descriptions: the stages and accesses of a use, from which `hazard.rs`
//! derives each barrier.

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

impl Access {
    /// Nothing (the start of a command buffer, or an undefined image).
    pub const NONE: Access = Access::new(S::NONE, A::NONE);
    /// Indirect dispatch/draw arguments.
    pub const INDIRECT: Access = Access::new(S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ);
    /// Index buffer reads.
    pub const INDEX_READ: Access = Access::new(S::INDEX_INPUT, A::INDEX_READ);
    /// Transfer reads.
    pub const TRANSFER_READ: Access = Access::new(S::ALL_TRANSFER, A::TRANSFER_READ);
    /// Transfer writes (copies, fills, clears).
    pub const TRANSFER_WRITE: Access = Access::new(S::ALL_TRANSFER, A::TRANSFER_WRITE);
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
