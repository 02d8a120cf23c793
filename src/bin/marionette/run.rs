//! `marionette run SCENE.ron…`: each scene run into its output folder, its headline printed.

use std::path::{Path, PathBuf};

use anyhow::Result;

use marionette::scene::{self, Scene};

// The command's arguments (its help text is on `Command::Run`).
#[derive(clap::Args)]
pub struct Args {
    /// The scenes (RON), run one after the other, each into its own folder.
    #[arg(required = true, num_args = 1..)]
    scenes: Vec<PathBuf>,
    /// Output folder; with several scenes, the folder holding each scene's folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override a scene field: --set field.path=value (repeatable; one scene only).
    #[arg(long = "set", value_name = "FIELD=VALUE")]
    set: Vec<String>,
    /// Continue an interrupted evolution from the checkpoint in DIR (one EvolveFall scene).
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
}

/// Runs `run`: each scene into its folder, then prints its headline and where its outputs are.
pub fn run(args: Args) -> Result<()> {
    let Args {
        scenes,
        out,
        set,
        resume,
    } = args;
    if scenes.len() > 1 && (!set.is_empty() || resume.is_some()) {
        anyhow::bail!(
            "--set and --resume apply to one scene; {} were given",
            scenes.len()
        );
    }
    let many = scenes.len() > 1;
    let mut pages = Vec::new();
    for path in &scenes {
        pages.push(run_one(
            path,
            out.as_deref(),
            many,
            set.clone(),
            resume.clone(),
        )?);
    }
    // The last line: the results page of the one scene, or with several a page linking each
    // scene's page, in the folder holding their folders.
    let page = match pages.as_slice() {
        [one] => one.page.clone(),
        _ => {
            let dir = out.unwrap_or_else(|| PathBuf::from("out"));
            scene::write_run_index(&pages, &dir)?
        }
    };
    println!("page: {}", page.display());
    Ok(())
}

/// One scene: loaded, overridden, run, and summed up in a few lines (with several scenes, the
/// last names its results page). Returns what the run's index page says of it.
fn run_one(
    path: &Path,
    out: Option<&Path>,
    many: bool,
    mut set: Vec<String>,
    resume: Option<PathBuf>,
) -> Result<scene::RunPage> {
    let scene = Scene::load(path)?;
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
    let out = match out {
        Some(dir) if many => dir.join(scene.name()),
        Some(dir) => dir.to_path_buf(),
        None => scene::default_out_dir(&scene),
    };
    let base = path.parent().unwrap_or(Path::new("."));
    let report = scene::run(&scene, base, &out)?;
    let wall = report.get("wall_time_s").and_then(|v| v.as_f64());
    println!(
        "scene '{}' done in {:.1} s: outputs in {}",
        scene.name(),
        wall.unwrap_or(f64::NAN),
        out.display()
    );
    let headline = scene::headline(&scene, &report);
    for line in &headline {
        println!("  {line}");
    }
    println!("  pictures: {}", pictures(&out)?.join(" "));
    println!("  report: {}", out.join("report.json").display());
    let page = out.join(scene::PAGE_FILE);
    if many {
        println!("  page: {}", page.display());
    }
    Ok(scene::RunPage {
        name: scene.name().to_string(),
        page,
        headline,
    })
}

/// The PNG and GIF files of an output folder, sorted by name.
fn pictures(dir: &Path) -> Result<Vec<String>> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let name = entry?.file_name().to_string_lossy().into_owned();
        if name.ends_with(".png") || name.ends_with(".gif") {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}
