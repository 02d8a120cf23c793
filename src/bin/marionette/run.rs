//! `marionette run SCENE.ron`: a scene run into its output folder, its report printed.

use std::path::{Path, PathBuf};

use anyhow::Result;

use marionette::scene::{self, Scene};

// The command's arguments (its help text is on `Command::Run`).
#[derive(clap::Args)]
pub struct Args {
    /// The scene (RON).
    scene: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override a scene field: --set field.path=value (repeatable).
    #[arg(long = "set", value_name = "FIELD=VALUE")]
    set: Vec<String>,
    /// Continue an interrupted evolution from the checkpoint in DIR (EvolveFall scenes).
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
}

/// Runs `run`: the scene into its folder, then prints where and the report.
pub fn run(args: Args) -> Result<()> {
    let Args {
        scene: path,
        out,
        mut set,
        resume,
    } = args;
    let scene = Scene::load(&path)?;
    if let Some(dir) = resume {
        if !matches!(scene, Scene::EvolveFall(_)) {
            anyhow::bail!("--resume: {} is not an EvolveFall scene", path.display());
        }
        set.push(format!(
            "resume={}",
            serde_json::to_string(&dir.display().to_string())?
        ));
    }
    let scene = scene::apply_overrides(&scene, &set)?;
    let out = out.unwrap_or_else(|| scene::default_out_dir(&scene));
    let base = path.parent().unwrap_or(Path::new("."));
    let report = scene::run(&scene, base, &out)?;
    println!(
        "scene '{}' done: outputs in {}",
        scene.name(),
        out.display()
    );
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
