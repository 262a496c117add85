//! `radcache info SCENE`: the scene summary and its plan.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use radcache_scene::{LoadOptions, Scene};

use crate::args::EnvArgs;

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The glTF scene (.gltf or .glb).
    scene: PathBuf,
    /// Use the camera with this name instead of the scene's first.
    #[arg(long)]
    camera: Option<String>,
    #[command(flatten)]
    env: EnvArgs,
}

pub fn run(args: &InfoArgs) -> Result<ExitCode> {
    let opts = LoadOptions {
        camera_name: args.camera.clone(),
        env: args.env.to_override()?,
    };
    // The loader logs its warnings on stderr as it finds them; stdout has the summary only.
    let (scene, _warnings) = Scene::load(&args.scene, &opts)?;
    crate::output::emit(&scene.to_string())?;
    Ok(ExitCode::SUCCESS)
}
