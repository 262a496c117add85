//! Physical device choice: what radcache requires, what each device offers, and the report that
//! explains a refusal.
//!
//! The check is a pure function over [`DeviceCaps`] so that the refusal path can be tested on any
//! machine (`missing_capabilities`), and the report lists every device seen with what it lacks.

use std::fmt;

/// Device extensions radcache cannot run without.
pub const REQUIRED_EXTENSIONS: &[&str] = &[
    "VK_KHR_acceleration_structure",
    "VK_KHR_ray_query",
    "VK_KHR_deferred_host_operations",
    "VK_KHR_push_descriptor",
];

/// Device features radcache enables (names as in the Vulkan spec's feature structs).
pub const REQUIRED_FEATURES: &[&str] = &[
    "bufferDeviceAddress",
    "scalarBlockLayout",
    "runtimeDescriptorArray",
    "descriptorBindingPartiallyBound",
    "shaderSampledImageArrayNonUniformIndexing",
    "dynamicRendering",
    "synchronization2",
    "maintenance4",
    "shaderDemoteToHelperInvocation",
    "accelerationStructure",
    "rayQuery",
    "fragmentStoresAndAtomics",
    "shaderInt64",
    "shaderBufferInt64Atomics",
    "drawIndirectFirstInstance",
    "timestampComputeAndGraphics",
];

/// The Vulkan version radcache asks for (dynamic rendering and synchronization2 are core there).
pub const REQUIRED_API: (u32, u32) = (1, 3);

/// What one physical device offers, as far as radcache cares.
#[derive(Debug, Clone, Default)]
pub struct DeviceCaps {
    /// `deviceName`.
    pub name: String,
    /// Kind of device (`discrete`, `integrated`, `virtual`, `cpu`, `other`).
    pub kind: DeviceKind,
    /// Vulkan version (major, minor).
    pub api: (u32, u32),
    /// Supported device extensions.
    pub extensions: Vec<String>,
    /// Feature names that are supported (true) on this device.
    pub features: Vec<&'static str>,
    /// Whether a queue family supports graphics + compute with valid timestamps.
    pub has_universal_queue: bool,
}

/// Kind of physical device, ordered by preference (best first).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum DeviceKind {
    /// A discrete GPU.
    Discrete,
    /// An integrated GPU.
    Integrated,
    /// A virtual GPU.
    Virtual,
    /// A CPU implementation (lavapipe, SwiftShader).
    Cpu,
    /// Anything else.
    #[default]
    Other,
}

impl fmt::Display for DeviceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            DeviceKind::Discrete => "discrete GPU",
            DeviceKind::Integrated => "integrated GPU",
            DeviceKind::Virtual => "virtual GPU",
            DeviceKind::Cpu => "CPU",
            DeviceKind::Other => "other",
        };
        f.write_str(s)
    }
}

/// Lists what `caps` lacks for radcache plus `extra_extensions`; empty means usable.
pub fn missing_capabilities(caps: &DeviceCaps, extra_extensions: &[String]) -> Vec<String> {
    let mut missing = Vec::new();
    if caps.api < REQUIRED_API {
        missing.push(format!(
            "Vulkan {}.{} (device has {}.{})",
            REQUIRED_API.0, REQUIRED_API.1, caps.api.0, caps.api.1
        ));
    }
    let required = REQUIRED_EXTENSIONS.iter().map(|s| s.to_string());
    for ext in required.chain(extra_extensions.iter().cloned()) {
        if !caps.extensions.contains(&ext) {
            missing.push(ext);
        }
    }
    for feat in REQUIRED_FEATURES {
        if !caps.features.contains(feat) {
            missing.push(format!("feature {feat}"));
        }
    }
    if !caps.has_universal_queue {
        missing.push("a graphics+compute queue with timestamps".to_string());
    }
    missing
}

/// One device as seen during selection.
#[derive(Debug, Clone)]
pub struct SeenDevice {
    /// Device name.
    pub name: String,
    /// Device kind.
    pub kind: DeviceKind,
    /// What it lacks (empty if usable).
    pub missing: Vec<String>,
    /// Whether `RADCACHE_DEVICE` excluded it.
    pub filtered_out: bool,
}

/// Why no device was chosen: every device seen, with what it lacks.
#[derive(Debug, Clone, Default)]
pub struct DeviceReport {
    /// The devices, in enumeration order.
    pub devices: Vec<SeenDevice>,
    /// The `RADCACHE_DEVICE` filter in force, if any.
    pub filter: Option<String>,
}

impl fmt::Display for DeviceReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.devices.is_empty() {
            return write!(
                f,
                "no Vulkan device found; on Debian 12 install mesa-vulkan-drivers from \
                 bookworm-backports (scripts/setup.sh) for lavapipe with ray queries"
            );
        }
        write!(f, "no Vulkan device has what radcache needs")?;
        if let Some(filter) = &self.filter {
            write!(f, " (RADCACHE_DEVICE={filter:?})")?;
        }
        writeln!(f, "; devices seen:")?;
        for d in &self.devices {
            if d.filtered_out {
                writeln!(
                    f,
                    "  - {} ({}): excluded by RADCACHE_DEVICE",
                    d.name, d.kind
                )?;
            } else {
                writeln!(
                    f,
                    "  - {} ({}): missing {}",
                    d.name,
                    d.kind,
                    d.missing.join(", ")
                )?;
            }
        }
        Ok(())
    }
}

/// Picks the preferred usable device: discrete > integrated > virtual > CPU, first seen on ties.
/// `filter` (from `RADCACHE_DEVICE`) keeps only names containing it (case-insensitive).
pub fn choose(
    caps: &[DeviceCaps],
    extra_extensions: &[String],
    filter: Option<&str>,
) -> Result<usize, DeviceReport> {
    let mut report = DeviceReport {
        devices: Vec::new(),
        filter: filter.map(str::to_string),
    };
    let mut best: Option<usize> = None;
    for (i, c) in caps.iter().enumerate() {
        let filtered_out =
            filter.is_some_and(|f| !c.name.to_lowercase().contains(&f.to_lowercase()));
        let missing = missing_capabilities(c, extra_extensions);
        let usable = !filtered_out && missing.is_empty();
        if usable && best.is_none_or(|b| c.kind < caps[b].kind) {
            best = Some(i);
        }
        report.devices.push(SeenDevice {
            name: c.name.clone(),
            kind: c.kind,
            missing,
            filtered_out,
        });
    }
    best.ok_or(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn full(name: &str, kind: DeviceKind) -> DeviceCaps {
        DeviceCaps {
            name: name.into(),
            kind,
            api: (1, 3),
            extensions: REQUIRED_EXTENSIONS.iter().map(|s| s.to_string()).collect(),
            features: REQUIRED_FEATURES.to_vec(),
            has_universal_queue: true,
        }
    }

    #[test]
    fn prefers_discrete_then_integrated() {
        let devs = [
            full("cpu", DeviceKind::Cpu),
            full("igpu", DeviceKind::Integrated),
            full("dgpu", DeviceKind::Discrete),
        ];
        assert_eq!(choose(&devs, &[], None).unwrap(), 2);
        assert_eq!(choose(&devs[..2], &[], None).unwrap(), 1);
    }

    #[test]
    fn filter_and_missing_are_reported() {
        let mut no_rq = full("old gpu", DeviceKind::Discrete);
        no_rq.extensions.retain(|e| e != "VK_KHR_ray_query");
        no_rq.features.retain(|f| *f != "rayQuery");
        let devs = [no_rq, full("llvmpipe", DeviceKind::Cpu)];
        assert_eq!(choose(&devs, &[], None).unwrap(), 1);
        let err = choose(&devs, &[], Some("nvidia")).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("RADCACHE_DEVICE=\"nvidia\""), "{text}");
        assert!(text.contains("old gpu"), "{text}");
        assert!(text.contains("excluded by RADCACHE_DEVICE"), "{text}");
        let err = choose(&devs[..1], &[], None).unwrap_err().to_string();
        assert!(
            err.contains("VK_KHR_ray_query") && err.contains("feature rayQuery"),
            "{err}"
        );
    }

    #[test]
    fn empty_list_explains_setup() {
        let err = choose(&[], &[], None).unwrap_err().to_string();
        assert!(err.contains("bookworm-backports"), "{err}");
    }
}
