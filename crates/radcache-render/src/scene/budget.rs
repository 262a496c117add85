//! The device memory a scene needs, known before anything is uploaded: the packed buffers' sizes
//! and the driver's build sizes of every acceleration structure. A scene that does not fit the
//! device (or `RADCACHE_DEVICE_MEMORY`) is refused with its parts named, never by an allocation
//! failure halfway through the upload or a frame.

use std::path::Path;

use radcache_vk::{BuildSizes, DeviceInfo};

use crate::error::{Error, Result};

/// Device bytes of a scene's parts, at the peak of its upload (while the BLASes are built: each
/// uncompacted structure, its scratch and its compacted copy live at once).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryNeed {
    /// Vertices, indices, per-triangle materials, tangents, second texture coordinates.
    pub geometry: u64,
    /// Materials, texture descriptors and texels.
    pub textures: u64,
    /// The environment map's texels and alias table.
    pub environment: u64,
    /// Per-instance data, the TLAS's instance records, the emissive triangles' emitter records and
    /// alias table, and the lights.
    pub instances: u64,
    /// BLASes (twice their uncompacted size: the compacted copies are made before the originals
    /// go), their build scratch, and the TLAS with its scratch.
    pub acceleration: u64,
}

impl MemoryNeed {
    /// The acceleration part from the driver's sizes of each BLAS and of the TLAS.
    pub fn acceleration(blases: &[BuildSizes], tlas: BuildSizes) -> u64 {
        let blas: u64 = blases.iter().map(|s| 2 * s.structure + s.scratch).sum();
        blas + tlas.structure + tlas.scratch.max(tlas.update_scratch)
    }

    /// Every part together.
    pub fn total(&self) -> u64 {
        self.geometry + self.textures + self.environment + self.instances + self.acceleration
    }

    /// Refuses the scene of file `path` where it needs more than the device's usable memory,
    /// naming the file, the parts and the sizes.
    pub fn check(&self, device: &DeviceInfo, path: &Path) -> Result<()> {
        let available = device.usable_memory();
        if self.total() <= available {
            return Ok(());
        }
        let parts = [
            ("geometry", self.geometry),
            ("textures", self.textures),
            ("environment", self.environment),
            ("instances, emitters and lights", self.instances),
            ("acceleration structures", self.acceleration),
        ]
        .iter()
        .filter(|(_, b)| *b > 0)
        .map(|(what, b)| format!("{what} {}", size_text(*b)))
        .collect::<Vec<_>>()
        .join(", ");
        let limit = match device.memory_limit {
            Some(l) if l < device.memory_bytes => format!(
                " (RADCACHE_DEVICE_MEMORY={} of its {})",
                size_text(l),
                size_text(device.memory_bytes)
            ),
            _ => String::new(),
        };
        Err(Error::SceneTooLarge(format!(
            "{}: the scene needs {} of device memory at the peak of its upload ({parts}), but \
             {} has {}{limit}",
            path.display(),
            size_text(self.total()),
            device.name,
            size_text(available)
        )))
    }
}

/// Bytes in binary units with three significant digits (`512 B`, `14.2 KiB`, `3.05 GiB`).
pub fn size_text(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    match unit {
        0 => format!("{bytes} B"),
        _ if v >= 100.0 => format!("{v:.0} {}", UNITS[unit]),
        _ if v >= 10.0 => format!("{v:.1} {}", UNITS[unit]),
        _ => format!("{v:.2} {}", UNITS[unit]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_in_binary_units() {
        assert_eq!(size_text(512), "512 B");
        assert_eq!(size_text(14 * 1024 + 205), "14.2 KiB");
        assert_eq!(size_text(3_275_000_000), "3.05 GiB");
        assert_eq!(size_text(300 << 20), "300 MiB");
    }

    #[test]
    fn the_acceleration_part_counts_the_compacted_copies_and_the_scratch() {
        let blas = BuildSizes {
            structure: 100,
            scratch: 30,
            update_scratch: 0,
        };
        let tlas = BuildSizes {
            structure: 50,
            scratch: 10,
            update_scratch: 20,
        };
        assert_eq!(MemoryNeed::acceleration(&[blas, blas], tlas), 2 * 230 + 70);
    }
}
