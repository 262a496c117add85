//! Acceleration structures: one compacted BLAS per mesh, and a TLAS of instances that is rebuilt or
//! refitted per frame.
//!
//! BLAS builds happen on the device (lavapipe has no host builds): build with `ALLOW_COMPACTION`,
//! query the compacted sizes, copy into right-sized structures, drop the originals. The TLAS keeps
//! its storage and scratch for a fixed capacity and is built with `ALLOW_UPDATE`, so a frame whose
//! instance count is unchanged can refit instead of rebuilding.

use std::sync::Arc;

use ash::vk;

use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::sync::Access;

/// An acceleration structure and the buffer holding it.
pub struct AccelerationStructure {
    shared: Arc<DeviceShared>,
    pub(crate) raw: vk::AccelerationStructureKHR,
    pub(crate) address: u64,
    // Dropped after `raw` is retired (field order): the graveyard frees both together.
    buffer: Buffer,
    pub(crate) name: String,
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
    pub(crate) fn new(
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
pub struct Blas(pub(crate) Arc<AccelerationStructure>);

impl Blas {
    /// Bytes of storage (after compaction).
    pub fn size(&self) -> u64 {
        self.0.size()
    }
}

/// Triangle geometry of one BLAS: `R32G32B32_SFLOAT` positions and `u32` indices. Both buffers
/// need `ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR | SHADER_DEVICE_ADDRESS` usage and must
/// hold the ranges described (both checked). The index values are GPU data the host does not
/// read: each must be below `vertex_count`.
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
    /// Flag the geometry `OPAQUE`: ray queries commit its hits without reporting them as
    /// candidates. False for geometry that shaders alpha-test in their traversal loop (a
    /// candidate may then be reported more than once, so the test must be deterministic).
    pub opaque: bool,
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
    let usage = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let vertex_end = (u64::from(g.vertex_count).checked_sub(1))
        .map(|last| g.vertex_offset + last * g.vertex_stride + 12)
        .unwrap_or(g.vertex_offset);
    let index_end = g.index_offset + u64::from(g.triangle_count) * 12;
    for (b, what, end) in [
        (g.vertices, "vertex", vertex_end),
        (g.indices, "index", index_end),
    ] {
        if !b.usage().contains(usage) {
            return Err(Error::Invalid(format!(
                "BLAS {:?}: {what} buffer {:?} lacks {usage:?} usage",
                g.name,
                b.name()
            )));
        }
        if end > b.size() {
            return Err(Error::Invalid(format!(
                "BLAS {:?}: the {what} data ends at byte {end}, past the end of buffer {:?} ({} \
                 bytes)",
                g.name,
                b.name(),
                b.size()
            )));
        }
    }
    let aligned = [g.index_offset, g.vertex_offset, g.vertex_stride]
        .iter()
        .all(|v| v.is_multiple_of(4));
    if !aligned || g.vertex_stride < 12 {
        return Err(Error::Invalid(format!(
            "BLAS {:?}: index offset {}, vertex offset {} and vertex stride {} must be multiples \
             of 4, the stride at least 12",
            g.name, g.index_offset, g.vertex_offset, g.vertex_stride
        )));
    }
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
        .flags(if g.opaque {
            vk::GeometryFlagsKHR::OPAQUE
        } else {
            vk::GeometryFlagsKHR::empty()
        }))
}

pub(crate) fn scratch(ctx: &Context, name: &str, size: u64) -> Result<Buffer> {
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

/// What a BLAS's sizes depend on, for an estimate before any buffer exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlasShape {
    /// Vertices the triangles index.
    pub vertex_count: u32,
    /// Triangles.
    pub triangle_count: u32,
}

/// Device bytes of one acceleration-structure build, as the driver states them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildSizes {
    /// The structure before compaction.
    pub structure: u64,
    /// Scratch for a build.
    pub scratch: u64,
    /// Scratch for an update (a refit).
    pub update_scratch: u64,
}

pub(crate) const BLAS_FLAGS: vk::BuildAccelerationStructureFlagsKHR =
    vk::BuildAccelerationStructureFlagsKHR::from_raw(
        vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE.as_raw()
            | vk::BuildAccelerationStructureFlagsKHR::ALLOW_COMPACTION.as_raw(),
    );

impl Context {
    /// `vkGetAccelerationStructureBuildSizesKHR` for a device build of `info` (its geometries
    /// with `counts` primitives each).
    pub(crate) fn build_sizes(
        &self,
        info: &vk::AccelerationStructureBuildGeometryInfoKHR<'_>,
        counts: &[u32],
    ) -> BuildSizes {
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: `info` describes valid geometry with one count per geometry (the sizes query
        // reads formats, counts and `maxVertex`, not the data); `sizes` is an output struct.
        unsafe {
            self.shared.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                info,
                counts,
                &mut sizes,
            )
        };
        BuildSizes {
            structure: sizes.acceleration_structure_size,
            scratch: sizes.build_scratch_size,
            update_scratch: sizes.update_scratch_size,
        }
    }

    /// The build sizes of BLASes of these shapes (as [`Context::build_blases`] builds them:
    /// float3 positions, 32-bit indices, fast trace, compactable), without building anything.
    pub fn blas_sizes(&self, shapes: &[BlasShape]) -> Vec<BuildSizes> {
        shapes
            .iter()
            .map(|s| {
                let tri = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                    .vertex_format(vk::Format::R32G32B32_SFLOAT)
                    .vertex_stride(12)
                    .max_vertex(s.vertex_count.saturating_sub(1))
                    .index_type(vk::IndexType::UINT32);
                let geometry = [vk::AccelerationStructureGeometryKHR::default()
                    .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                    .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: tri })
                    .flags(vk::GeometryFlagsKHR::OPAQUE)];
                let info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
                    .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
                    .flags(BLAS_FLAGS)
                    .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
                    .geometries(&geometry);
                self.build_sizes(&info, &[s.triangle_count])
            })
            .collect()
    }

    /// Builds and compacts one BLAS per geometry, waiting for the GPU.
    pub fn build_blases(&self, geoms: &[BlasGeometry<'_>]) -> Result<(Vec<Blas>, BlasBuildStats)> {
        let mut stats = BlasBuildStats::default();
        if geoms.is_empty() {
            return Ok((Vec::new(), stats));
        }
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
                .flags(BLAS_FLAGS)
                .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
                .geometries(geometry);
            let sizes = self.build_sizes(&info, &[g.triangle_count]);
            let blas = AccelerationStructure::new(
                self,
                g.name,
                vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
                sizes.structure,
            )?;
            let s = scratch(self, "accel.blas_scratch", sizes.scratch)?;
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
            // SAFETY: recording outside a rendering; inputs (usage and ranges checked by
            // `triangles`), destinations and scratch are live device-address buffers kept alive
            // until the submission is waited for below; one range per geometry.
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
