//! `cargo xtask shaders`: compile every shader with the run-time options, validate with spirv-val:
//! each entry shader without defines, then every module each pass compiles for each variant it
//! can be made with, in scenes of every feature set
//! ([`radcache_render::passes::every_shader_module`]).

use anyhow::{bail, Result};
use radcache_render::passes::every_shader_module;
use radcache_tests::shader_check::{check_all, check_modules, has_spirv_val};

pub fn run() -> Result<()> {
    let root = crate::root();
    let validate = has_spirv_val();
    if !validate {
        eprintln!("warning: spirv-val not found (install spirv-tools); compiling only");
    }
    let out = std::env::var_os("CARGO_TARGET_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("shaders");
    let report = |r: &radcache_tests::shader_check::ShaderCheck| match &r.error {
        None => println!("ok    {:<40} {:>7} words", r.path, r.words),
        Some(e) => println!("FAIL  {}\n{e}", r.path),
    };
    let results = check_all(&root.join("shaders"), &out, validate)?;
    results.iter().for_each(report);
    let modules = every_shader_module();
    let started = std::time::Instant::now();
    let variants = check_modules(
        &root.join("shaders"),
        &out.join("variants"),
        validate,
        &modules,
        report,
    )?;
    let failed = |r: &[radcache_tests::shader_check::ShaderCheck]| {
        r.iter().filter(|r| r.error.is_some()).count()
    };
    let (failed_plain, failed_variants) = (failed(&results), failed(&variants));
    println!(
        "{} shaders without defines, {failed_plain} failed; {} pass modules (every variant), \
         {failed_variants} failed, in {:.0} s; SPIR-V in {}",
        results.len(),
        variants.len(),
        started.elapsed().as_secs_f64(),
        out.display()
    );
    if failed_plain + failed_variants > 0 {
        bail!("{} shader module(s) failed", failed_plain + failed_variants);
    }
    Ok(())
}
