//! Acceleration structures: one compacted BLAS per mesh, and a TLAS of instances that is rebuilt or
//! refitted per frame.
//!
//! BLAS builds happen on the device (lavapipe has no host builds): build with `ALLOW_COMPACTION`,
//! query the compacted sizes, copy into right-sized structures, drop the originals. The TLAS keeps
//! its storage and scratch for a fixed capacity and is built with `ALLOW_UPDATE`, so a frame whose
//! instance count is unchanged can refit instead of rebuilding.

use std::sync::Arc;

use ash::vk;
use bytemuck::{Pod, Zeroable};

use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::commands::Recorder;
use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::sync::Access;

/// An acceleration structure and the buffer holding it.
pub struct AccelerationStructure {
    shared: Arc<DeviceShared>,
    raw: vk::AccelerationStructureKHR,
    address: u64,
    // Dropped after `raw` is retired (field order): the graveyard frees both together.
    buffer: Buffer,
    name: String,
}

impl std::fmt::Debug for AccelerationStructure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AccelerationStructure")
            .field("name", &self.name)
            .field("bytes", &self.buffer.size())
            .finish()
    }
}

impl AccelerationStructure {
    fn new(
        ctx: &Context,
        name: &str,
        ty: vk::AccelerationStructureTypeKHR,
        size: u64,
    ) -> Result<Self> {
        let buffer = Buffer::new(
            ctx,
            &BufferDesc {
                name,
                size,
                usage: vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                    | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                location: MemoryLocation::GpuOnly,
                alignment: 256,
            },
        )?;
        let info = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(buffer.raw())
            .offset(0)
            .size(size)
            .ty(ty);
        let shared = ctx.shared.clone();
        // SAFETY: the buffer has AS storage usage, is bound, and is at least `size` bytes.
        let raw = unsafe { shared.accel.create_acceleration_structure(&info, None) }
            .call("vkCreateAccelerationStructureKHR")?;
        let addr_info =
            vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(raw);
        // SAFETY: `raw` is a live acceleration structure of this device.
        let address = unsafe {
            shared
                .accel
                .get_acceleration_structure_device_address(&addr_info)
        };
        shared.set_name(raw, name);
        Ok(AccelerationStructure {
            shared,
            raw,
            address,
            buffer,
            name: name.to_string(),
        })
    }

    /// Bytes of storage.
    pub fn size(&self) -> u64 {
        self.buffer.size()
    }
}

impl Drop for AccelerationStructure {
    fn drop(&mut self) {
        self.shared.retire(Garbage::AccelerationStructure(self.raw));
    }
}

/// A bottom-level acceleration structure (cheap to clone; shared by the TLAS that uses it).
#[derive(Debug, Clone)]
pub struct Blas(Arc<AccelerationStructure>);

impl Blas {
    /// Bytes of storage (after compaction).
    pub fn size(&self) -> u64 {
        self.0.size()
    }
}

/// Triangle geometry of one BLAS: `R32G32B32_SFLOAT` positions and `u32` indices. Both buffers
/// need `ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR | SHADER_DEVICE_ADDRESS` usage.
#[derive(Debug, Clone, Copy)]
pub struct BlasGeometry<'a> {
    /// Name of the BLAS.
    pub name: &'a str,
    /// Vertex buffer; positions are the first 12 bytes of each vertex.
    pub vertices: &'a Buffer,
    /// Byte offset of vertex 0.
    pub vertex_offset: u64,
    /// Bytes between vertices.
    pub vertex_stride: u64,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Index buffer (`u32`).
    pub indices: &'a Buffer,
    /// Byte offset of index 0 (multiple of 4).
    pub index_offset: u64,
    /// Number of triangles.
    pub triangle_count: u32,
}

/// Figures of a BLAS build.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BlasBuildStats {
    /// GPU time of the builds, ms.
    pub build_ms: f64,
    /// GPU time of the compaction copies, ms.
    pub compact_ms: f64,
    /// Bytes before compaction.
    pub bytes_built: u64,
    /// Bytes after compaction.
    pub bytes_compacted: u64,
}

fn triangles<'a>(g: &BlasGeometry<'_>) -> Result<vk::AccelerationStructureGeometryKHR<'a>> {
    let tri = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
        .vertex_format(vk::Format::R32G32B32_SFLOAT)
        .vertex_data(vk::DeviceOrHostAddressConstKHR {
            device_address: g.vertices.device_address()? + g.vertex_offset,
        })
        .vertex_stride(g.vertex_stride)
        .max_vertex(g.vertex_count.saturating_sub(1))
        .index_type(vk::IndexType::UINT32)
        .index_data(vk::DeviceOrHostAddressConstKHR {
            device_address: g.indices.device_address()? + g.index_offset,
        });
    Ok(vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: tri })
        .flags(vk::GeometryFlagsKHR::OPAQUE))
}

fn scratch(ctx: &Context, name: &str, size: u64) -> Result<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            location: MemoryLocation::GpuOnly,
            alignment: u64::from(ctx.info().min_scratch_alignment.max(1)),
        },
    )
}

impl Context {
    /// Builds and compacts one BLAS per geometry, waiting for the GPU.
    pub fn build_blases(&self, geoms: &[BlasGeometry<'_>]) -> Result<(Vec<Blas>, BlasBuildStats)> {
        let mut stats = BlasBuildStats::default();
        if geoms.is_empty() {
            return Ok((Vec::new(), stats));
        }
        let flags = vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE
            | vk::BuildAccelerationStructureFlagsKHR::ALLOW_COMPACTION;
        let geometries: Vec<[vk::AccelerationStructureGeometryKHR<'_>; 1]> = geoms
            .iter()
            .map(|g| triangles(g).map(|t| [t]))
            .collect::<Result<_>>()?;
        let mut built = Vec::with_capacity(geoms.len());
        let mut scratches = Vec::with_capacity(geoms.len());
        let mut infos = Vec::with_capacity(geoms.len());
        for (g, geometry) in geoms.iter().zip(&geometries) {
            let mut info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
                .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
                .flags(flags)
                .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
                .geometries(geometry);
            let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
            // SAFETY: `info` describes valid geometry; sizes is an output struct.
            unsafe {
                self.shared.accel.get_acceleration_structure_build_sizes(
                    vk::AccelerationStructureBuildTypeKHR::DEVICE,
                    &info,
                    &[g.triangle_count],
                    &mut sizes,
                )
            };
            let blas = AccelerationStructure::new(
                self,
                g.name,
                vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
                sizes.acceleration_structure_size,
            )?;
            let s = scratch(self, "accel.blas_scratch", sizes.build_scratch_size)?;
            info = info.dst_acceleration_structure(blas.raw).scratch_data(
                vk::DeviceOrHostAddressKHR {
                    device_address: s.device_address()?,
                },
            );
            stats.bytes_built += blas.size();
            infos.push(info);
            built.push(blas);
            scratches.push(s);
        }
        let ranges: Vec<[vk::AccelerationStructureBuildRangeInfoKHR; 1]> = geoms
            .iter()
            .map(|g| {
                [vk::AccelerationStructureBuildRangeInfoKHR {
                    primitive_count: g.triangle_count,
                    ..Default::default()
                }]
            })
            .collect();
        let range_refs: Vec<&[vk::AccelerationStructureBuildRangeInfoKHR]> =
            ranges.iter().map(|r| &r[..]).collect();
        let query_info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR)
            .query_count(geoms.len() as u32);
        // SAFETY: the device is live; `query_info` is valid.
        let pool = unsafe { self.shared.device.create_query_pool(&query_info, None) }
            .call("vkCreateQueryPool")?;
        let handles: Vec<_> = built.iter().map(|b| b.raw).collect();
        let mut rec = self.begin("accel.blas_build")?;
        rec.barrier(Access::ALL_WRITES, Access::AS_BUILD_READ);
        rec.pass("accel.blas_build", |rec| {
            // SAFETY: recording; inputs, destinations and scratch are live device-address buffers
            // kept alive until the submission is waited for below; one range per geometry.
            unsafe {
                rec.shared
                    .device
                    .cmd_reset_query_pool(rec.cmd, pool, 0, handles.len() as u32);
                rec.shared
                    .accel
                    .cmd_build_acceleration_structures(rec.cmd, &infos, &range_refs);
            }
        });
        rec.barrier(Access::AS_BUILD_WRITE, Access::AS_BUILD_READ);
        // SAFETY: recording; the builds above completed (barrier) and the queries were reset.
        unsafe {
            rec.shared
                .accel
                .cmd_write_acceleration_structures_properties(
                    rec.cmd,
                    &handles,
                    vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                    pool,
                    0,
                )
        };
        let timings = self.submit(rec)?.wait();
        let mut compact_sizes = vec![0u64; handles.len()];
        // SAFETY: the queries were written by the completed submission.
        let read = unsafe {
            self.shared.device.get_query_pool_results(
                pool,
                0,
                &mut compact_sizes,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        };
        self.shared.retire(Garbage::QueryPool(pool));
        stats.build_ms = timings?.iter().map(|t| t.duration_ms).sum();
        read.call("vkGetQueryPoolResults")?;
        drop(scratches);

        let mut compacted = Vec::with_capacity(built.len());
        let mut rec = self.begin("accel.blas_compact")?;
        let result = rec.pass("accel.blas_compact", |rec| -> Result<()> {
            for ((src, &size), g) in built.iter().zip(&compact_sizes).zip(geoms) {
                let dst = AccelerationStructure::new(
                    self,
                    g.name,
                    vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
                    size.max(256),
                )?;
                let info = vk::CopyAccelerationStructureInfoKHR::default()
                    .src(src.raw)
                    .dst(dst.raw)
                    .mode(vk::CopyAccelerationStructureModeKHR::COMPACT);
                // SAFETY: recording; `src` was built with ALLOW_COMPACTION, `dst` is at least the
                // queried compacted size; both outlive the submission.
                unsafe {
                    rec.shared
                        .accel
                        .cmd_copy_acceleration_structure(rec.cmd, &info)
                };
                stats.bytes_compacted += dst.size();
                compacted.push(Blas(Arc::new(dst)));
            }
            Ok(())
        });
        rec.barrier(
            Access::AS_BUILD_WRITE,
            Access::RAY_QUERY.union(Access::AS_BUILD_READ),
        );
        result?;
        stats.compact_ms = self
            .submit(rec)?
            .wait()?
            .iter()
            .map(|t| t.duration_ms)
            .sum();
        Ok((compacted, stats))
    }
}

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
        let geometry = [instance_geometry(instances.device_address()?)];
        let info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
            .flags(TLAS_FLAGS)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometry);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: `info` describes an instance geometry; sizes is an output struct.
        unsafe {
            ctx.shared.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &info,
                &[capacity],
                &mut sizes,
            )
        };
        let structure = AccelerationStructure::new(
            ctx,
            name,
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            sizes.acceleration_structure_size,
        )?;
        let scratch = scratch(
            ctx,
            "accel.tlas_scratch",
            sizes.build_scratch_size.max(sizes.update_scratch_size),
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
            // SAFETY: recording; instance data was copied above (barrier), the storage and scratch
            // were sized for `capacity` ≥ n, and refit only happens with an unchanged count.
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
