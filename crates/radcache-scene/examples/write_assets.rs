//! Writes the bundled assets: `cargo run -p radcache-scene --example write_assets -- <dir>`
//! (default `assets`). `cargo xtask assets` does the same through
//! `radcache_scene::assets::write_bundled_assets`.

fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "assets".into());
    match radcache_scene::assets::write_bundled_assets(std::path::Path::new(&dir)) {
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
