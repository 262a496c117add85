//! The top-level acceleration structure: instances of BLASes with transforms, kept at a fixed
//! capacity and built with `ALLOW_UPDATE`, so a frame whose instance count is unchanged can refit
//! instead of rebuilding.

use ash::vk;
use bytemuck::{Pod, Zeroable};

use crate::accel::{scratch, AccelerationStructure, Blas, BuildSizes};
use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::commands::Recorder;
use crate::context::Context;
use crate::error::{Error, Result};
use crate::sync::Access;

/// One instance of a TLAS.
#[derive(Debug, Clone, Copy)]
pub struct TlasInstance<'a> {
    /// The instanced BLAS.
    pub blas: &'a Blas,
    /// Object-to-world transform, row-major 3×4 (the upper three rows of the 4×4 matrix).
    pub transform: [f32; 12],
    /// `gl_InstanceCustomIndexEXT` / `rayQueryGetIntersectionInstanceCustomIndexEXT` (24 bits).
    pub custom_index: u32,
    /// Visibility mask (8 bits).
    pub mask: u8,
}

/// The 64-byte `VkAccelerationStructureInstanceKHR`, as plain data.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct RawInstance {
    transform: [f32; 12],
    custom_index_and_mask: u32,
    sbt_offset_and_flags: u32,
    blas_address: u64,
}
const _: () = assert!(
    std::mem::size_of::<RawInstance>()
        == std::mem::size_of::<vk::AccelerationStructureInstanceKHR>()
);

/// How to bring a TLAS up to date.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TlasUpdate {
    /// Full rebuild.
    Rebuild,
    /// Refit (update) when the instance count is unchanged; rebuild otherwise.
    Refit,
}

/// A top-level acceleration structure with storage for a fixed number of instances.
pub struct Tlas {
    structure: AccelerationStructure,
    instances: Buffer,
    scratch: Buffer,
    capacity: u32,
    count: Option<u32>,
    /// The BLASes referenced by the last build, kept alive with it.
    blases: Vec<Blas>,
}

impl std::fmt::Debug for Tlas {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tlas")
            .field("name", &self.structure.name)
            .field("capacity", &self.capacity)
            .finish()
    }
}

const TLAS_FLAGS: vk::BuildAccelerationStructureFlagsKHR =
    vk::BuildAccelerationStructureFlagsKHR::from_raw(
        vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE.as_raw()
            | vk::BuildAccelerationStructureFlagsKHR::ALLOW_UPDATE.as_raw(),
    );

fn instance_geometry<'a>(address: u64) -> vk::AccelerationStructureGeometryKHR<'a> {
    let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR {
            device_address: address,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data })
}

impl Tlas {
    /// The device bytes of a TLAS for `capacity` instances: its structure and the scratch it
    /// keeps (its instance buffer holds 64 bytes an instance on top).
    pub fn sizes(ctx: &Context, capacity: u32) -> BuildSizes {
        let geometry = [instance_geometry(0)];
        let info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
            .flags(TLAS_FLAGS)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometry);
        ctx.build_sizes(&info, &[capacity.max(1)])
    }

    /// Allocates a TLAS for up to `capacity` instances (not built yet).
    pub fn new(ctx: &Context, name: &str, capacity: u32) -> Result<Self> {
        let capacity = capacity.max(1);
        let instances = Buffer::new(
            ctx,
            &BufferDesc {
                name: "accel.tlas_instances",
                size: u64::from(capacity) * 64,
                usage: vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                    | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                location: MemoryLocation::GpuOnly,
                alignment: 16,
            },
        )?;
        let sizes = Self::sizes(ctx, capacity);
        let structure = AccelerationStructure::new(
            ctx,
            name,
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            sizes.structure,
        )?;
        let scratch = scratch(
            ctx,
            "accel.tlas_scratch",
            sizes.scratch.max(sizes.update_scratch),
        )?;
        Ok(Tlas {
            structure,
            instances,
            scratch,
            capacity,
            count: None,
            blases: Vec::new(),
        })
    }

    pub(crate) fn raw(&self) -> vk::AccelerationStructureKHR {
        self.structure.raw
    }

    /// Instances of the last build.
    pub fn instance_count(&self) -> u32 {
        self.count.unwrap_or(0)
    }

    /// Whether a build was recorded (ray queries on a never-built TLAS are undefined).
    pub(crate) fn is_built(&self) -> bool {
        self.count.is_some()
    }

    /// The TLAS's name.
    pub fn name(&self) -> &str {
        &self.structure.name
    }
}

impl Recorder {
    /// Uploads `instances` and builds or refits `tlas`, followed by a barrier that makes it
    /// visible to ray queries in compute and fragment shaders.
    pub fn build_tlas(
        &mut self,
        ctx: &Context,
        tlas: &mut Tlas,
        instances: &[TlasInstance<'_>],
        update: TlasUpdate,
    ) -> Result<()> {
        self.check_outside_rendering("build_tlas");
        let n = instances.len() as u32;
        if n > tlas.capacity {
            return Err(Error::Invalid(format!(
                "TLAS {:?} holds {} instances, {n} given",
                tlas.structure.name, tlas.capacity
            )));
        }
        let raw: Vec<RawInstance> = instances
            .iter()
            .map(|i| RawInstance {
                transform: i.transform,
                custom_index_and_mask: (i.custom_index & 0x00ff_ffff) | (u32::from(i.mask) << 24),
                sbt_offset_and_flags: vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE
                    .as_raw()
                    << 24,
                blas_address: i.blas.0.address,
            })
            .collect();
        let mut staging = Buffer::new(
            ctx,
            &BufferDesc {
                name: "staging.tlas_instances",
                size: (raw.len() * 64) as u64,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
                alignment: 0,
            },
        )?;
        staging.write(0, &raw)?;
        let refit = update == TlasUpdate::Refit && tlas.count == Some(n);
        self.pass("accel.tlas_build", |rec| {
            rec.barrier(
                Access::AS_BUILD_READ.union(Access::RAY_QUERY),
                Access::TRANSFER_WRITE,
            );
            rec.copy_buffer(&staging, 0, &tlas.instances, 0, (raw.len() * 64) as u64);
            rec.barrier(Access::TRANSFER_WRITE, Access::AS_BUILD_READ);
            let geometry = [instance_geometry(tlas.instances.device_address()?)];
            let mut info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
                .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
                .flags(TLAS_FLAGS)
                .mode(if refit {
                    vk::BuildAccelerationStructureModeKHR::UPDATE
                } else {
                    vk::BuildAccelerationStructureModeKHR::BUILD
                })
                .dst_acceleration_structure(tlas.structure.raw)
                .geometries(&geometry)
                .scratch_data(vk::DeviceOrHostAddressKHR {
                    device_address: tlas.scratch.device_address()?,
                });
            if refit {
                info = info.src_acceleration_structure(tlas.structure.raw);
            }
            let range = [vk::AccelerationStructureBuildRangeInfoKHR {
                primitive_count: n,
                ..Default::default()
            }];
            tlas.scratch.used_by(rec.index);
            // SAFETY: recording outside a rendering (checked above); instance data was copied
            // above (barrier), the storage and scratch were sized for `capacity` ≥ n, refit only
            // happens with an unchanged count, and every BLAS referenced is kept alive by `tlas`.
            unsafe {
                rec.shared
                    .accel
                    .cmd_build_acceleration_structures(rec.cmd, &[info], &[&range])
            };
            rec.barrier(
                Access::AS_BUILD_WRITE,
                Access::RAY_QUERY.union(Access::AS_BUILD_READ),
            );
            Ok::<(), Error>(())
        })?;
        tlas.count = Some(n);
        tlas.blases = instances.iter().map(|i| i.blas.clone()).collect();
        Ok(())
    }
}
