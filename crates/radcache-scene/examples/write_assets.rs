//! Writes the bundled assets: `cargo run -p radcache-scene --example write_assets [-- <dir>]`
//! (default: the repository's `assets/`, whatever the working directory). `cargo xtask assets`
//! does the same through `radcache_scene::assets::write_bundled_assets`.

use std::path::PathBuf;

fn main() {
    let dir = std::env::args().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets"),
        PathBuf::from,
    );
    match radcache_scene::assets::write_bundled_assets(&dir) {
        Ok(paths) => {
            for p in paths {
                println!("wrote {}", p.display());
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
