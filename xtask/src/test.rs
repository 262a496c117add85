//! `cargo xtask test`: the whole suite on lavapipe with the validation layer and its
//! synchronization validation (every derived barrier checked: a hazard is a validation error,
//! which fails the test), as CI runs it.

use std::process::Command;

use anyhow::{bail, Context, Result};

/// lavapipe's ICD manifest on Debian.
pub const LVP_ICD: &str = "/usr/share/vulkan/icd.d/lvp_icd.json";

pub fn run(extra: &[&str]) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(crate::root())
        .args(["test", "--workspace", "--no-fail-fast"])
        .args(extra)
        .env("RADCACHE_VALIDATION", "sync");
    if std::env::var_os("VK_DRIVER_FILES").is_none() && std::path::Path::new(LVP_ICD).exists() {
        cmd.env("VK_DRIVER_FILES", LVP_ICD);
    }
    let status = cmd.status().context("running cargo test")?;
    if !status.success() {
        bail!("tests failed");
    }
    Ok(())
}
