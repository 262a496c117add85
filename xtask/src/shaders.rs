//! `cargo xtask shaders`: compile every shader with the run-time options, validate with spirv-val.

use anyhow::{bail, Result};
use radcache_tests::shader_check::{check_all, has_spirv_val};

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
    let results = check_all(&root.join("shaders"), &out, validate)?;
    let mut failed = 0;
    for r in &results {
        match &r.error {
            None => println!("ok    {:<40} {:>7} words", r.path, r.words),
            Some(e) => {
                failed += 1;
                println!("FAIL  {}\n{e}", r.path);
            }
        }
    }
    println!(
        "{} shaders, {failed} failed; SPIR-V in {}",
        results.len(),
        out.display()
    );
    if failed > 0 {
        bail!("{failed} shader(s) failed");
    }
    Ok(())
}
