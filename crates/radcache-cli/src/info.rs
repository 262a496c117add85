//! `radcache info SCENE`: the scene summary and its plan.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;
use radcache_scene::{LoadOptions, Scene};

use crate::render::EnvArgs;

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
    let (scene, warnings) = Scene::load(&args.scene, &opts)?;
    let mut text = String::new();
    for w in &warnings {
        text.push_str(&format!("warning: {w}\n"));
    }
    text.push_str(&scene.to_string());
    crate::emit(&text)?;
    Ok(ExitCode::SUCCESS)
}
