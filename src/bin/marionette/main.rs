//! The `marionette` command: inspect, export and render motion files, and run scene files.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

use marionette::analysis::clip_contacts;
use marionette::bvh;
use marionette::humanoid::Model;
use marionette::mapping::{Mapping, effector_errors, retarget};
use marionette::render::{Track, animation_gif, filmstrip_png};
use marionette::scene::{self, ClipSource, Scene, load_motion};
use marionette::skeleton::Clip;

/// marionette: human character motion — motor primitives, choreography, evolved falls.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a BVH file's skeleton, channels, frames, rate, duration, size, ground contact and
    /// flight phases.
    Inspect {
        /// The BVH file.
        file: PathBuf,
        /// Metres per file unit (estimated from the standing height when absent).
        #[arg(long)]
        unit_scale: Option<f64>,
    },
    /// Export a BVH file's motion: global joint positions, joint angles on a model, or BVH.
    Export {
        /// The BVH file.
        file: PathBuf,
        /// Write global joint positions (metres) as CSV: frame,time_s,<joint>.x,.y,.z,…
        #[arg(long, value_name = "OUT.csv", group = "what")]
        positions: Option<PathBuf>,
        /// Write the clip mapped onto MODEL (humanoid24 or fall21) as angles in degrees:
        /// frame,time_s,<dof>,…
        #[arg(long, num_args = 2, value_names = ["MODEL", "OUT.csv"], group = "what")]
        angles: Option<Vec<String>>,
        /// Write BVH: the file as it is, or with --model the clip mapped onto that model.
        #[arg(long, value_name = "OUT.bvh", group = "what")]
        bvh: Option<PathBuf>,
        /// With --bvh: the model to map onto (humanoid24 or fall21).
        #[arg(long, requires = "bvh")]
        model: Option<String>,
        /// A mapping file for the skeleton (default: detected among src/mapping/builtin/*.ron).
        #[arg(long)]
        mapping: Option<PathBuf>,
        /// Metres per file unit (estimated from the standing height when absent).
        #[arg(long)]
        unit_scale: Option<f64>,
    },
    /// Draw a motion (BVH or keyframed .ron clip) as a filmstrip PNG or an animated GIF.
    Render {
        /// The motion file.
        file: PathBuf,
        /// OUT.png (filmstrip) or OUT.gif (animation).
        #[arg(long)]
        out: PathBuf,
        /// Map onto this model first (humanoid24 or fall21).
        #[arg(long)]
        model: Option<String>,
        /// Frames in a filmstrip.
        #[arg(long, default_value_t = 8)]
        frames: usize,
    },
    /// Run a scene file; outputs go to one folder (default out/<scene name>/) with report.json.
    Run {
        /// The scene (RON).
        scene: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene field: --set field.path=value (repeatable).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        set: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Inspect { file, unit_scale } => inspect(&file, unit_scale),
        Command::Export {
            file,
            positions,
            angles,
            bvh,
            model,
            mapping,
            unit_scale,
        } => export(&file, positions, angles, bvh, model, mapping, unit_scale),
        Command::Render {
            file,
            out,
            model,
            frames,
        } => render(&file, &out, model, frames),
        Command::Run { scene, out, set } => run(&scene, out, &set),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", format_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line.
fn format_chain(e: &anyhow::Error) -> String {
    e.chain()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(": ")
}

fn read_bvh(file: &Path) -> Result<bvh::Bvh> {
    let (b, warnings) = bvh::parse_file(file)?;
    for w in warnings {
        eprintln!("warning: {}:{}: {}", file.display(), w.line, w.message);
    }
    Ok(b)
}

fn inspect(file: &Path, unit_scale: Option<f64>) -> Result<()> {
    let b = read_bvh(file)?;
    let size = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
    let clip = Clip::from_bvh(&b, unit_scale)?;
    let scale = clip
        .skeleton
        .joints
        .iter()
        .zip(&b.joints)
        .find_map(|(c, j)| {
            (j.offset.length() > 1e-9).then(|| c.offset.length() / j.offset.length())
        });
    println!("file        {}", file.display());
    println!("size        {} bytes ({:.2} MB)", size, size as f64 / 1e6);
    println!(
        "joints      {} ({} channels per frame)",
        b.joints.len(),
        b.channel_count
    );
    println!("frames      {}", b.frame_count());
    println!("frame time  {} s ({:.3} fps)", b.frame_time, b.fps());
    println!("duration    {:.3} s", b.duration());
    if let Some(s) = scale {
        println!(
            "unit scale  {s:.6} m per file unit{}",
            if unit_scale.is_some() {
                ""
            } else {
                " (estimated)"
            }
        );
    }
    println!(
        "height      {:.3} m (median vertical extent)",
        clip.median_vertical_extent()
    );
    println!("skeleton:");
    for (i, j) in b.joints.iter().enumerate() {
        let mut depth = 0;
        let mut p = j.parent;
        while let Some(q) = p {
            depth += 1;
            p = b.joints[q].parent;
        }
        let ch: Vec<&str> = j.channels.iter().map(|c| c.name()).collect();
        let end = j.end_site.map(|_| "  + End Site").unwrap_or("");
        println!(
            "  {:>3} {}{}  [{}]{}",
            i,
            "  ".repeat(depth),
            j.name,
            ch.join(" "),
            end
        );
    }
    // Ground contact and flight from the feet: the mapping's ankles and toes, else by name.
    let Some(c) = clip_contacts(&clip, 0.03, 0.1) else {
        println!("contact     (no feet found: no joint named foot/toe/ankle on each side)");
        return Ok(());
    };
    let spans = |s: &[marionette::analysis::Span]| -> String {
        s.iter()
            .map(|x| format!("{:.2}-{:.2}", x.start_s, x.end_s))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "floor       y = {:.3} m (contact within {:.0} cm)",
        c.floor_y_m,
        c.threshold_m * 100.0
    );
    println!(
        "left foot   {} contact spans: {}",
        c.left.len(),
        spans(&c.left)
    );
    println!(
        "right foot  {} contact spans: {}",
        c.right.len(),
        spans(&c.right)
    );
    println!("flights     {}", c.flights.len());
    for (i, f) in c.flights.iter().enumerate() {
        println!(
            "  {:>2}  {:7.3} s .. {:7.3} s  ({:.3} s)",
            i + 1,
            f.start_s,
            f.end_s,
            f.duration()
        );
    }
    Ok(())
}

fn mapping_for(clip: &Clip, mapping: &Option<PathBuf>) -> Result<Mapping> {
    Ok(match mapping {
        Some(p) => Mapping::load(p)?,
        None => Mapping::detect(&clip.skeleton)?,
    })
}

fn export(
    file: &Path,
    positions: Option<PathBuf>,
    angles: Option<Vec<String>>,
    bvh_out: Option<PathBuf>,
    model: Option<String>,
    mapping: Option<PathBuf>,
    unit_scale: Option<f64>,
) -> Result<()> {
    let b = read_bvh(file)?;
    if let Some(out) = positions {
        let clip = Clip::from_bvh(&b, unit_scale)?;
        let mut s = String::from("frame,time_s");
        for j in &clip.skeleton.joints {
            s.push_str(&format!(",{0}.x,{0}.y,{0}.z", j.name));
        }
        s.push('\n');
        let mut g = vec![];
        for f in 0..clip.frame_count() {
            clip.globals(f, &mut g);
            s.push_str(&format!("{f},{:.6}", f as f64 * clip.frame_time));
            for t in &g {
                let p = t.translation;
                s.push_str(&format!(",{:.6},{:.6},{:.6}", p.x, p.y, p.z));
            }
            s.push('\n');
        }
        marionette::io::write_atomic(&out, s.as_bytes())
            .with_context(|| out.display().to_string())?;
        println!(
            "wrote {} ({} frames, {} joints)",
            out.display(),
            clip.frame_count(),
            clip.joint_count()
        );
    } else if let Some(a) = angles {
        let (model_name, out) = (&a[0], PathBuf::from(&a[1]));
        let model = Model::by_name(model_name)?;
        let clip = Clip::from_bvh(&b, unit_scale)?;
        let m = mapping_for(&clip, &mapping)?;
        let mapped = retarget(&clip, &m, &model)?;
        marionette::io::write_atomic(&out, mapped.angles_csv().as_bytes())
            .with_context(|| out.display().to_string())?;
        println!(
            "wrote {} ({} frames, {} DOFs of {}, mapping {})",
            out.display(),
            mapped.frame_count(),
            mapped.dof_count(),
            model.name,
            m.name
        );
    } else if let Some(out) = bvh_out {
        match model {
            None => {
                bvh::write_file(&b, &out)?;
                println!("wrote {} (as read)", out.display());
            }
            Some(name) => {
                let model = Model::by_name(&name)?;
                let clip = Clip::from_bvh(&b, unit_scale)?;
                let m = mapping_for(&clip, &mapping)?;
                let mapped = retarget(&clip, &m, &model)?;
                bvh::write_file(&mapped.to_clip().to_bvh(), &out)?;
                println!(
                    "wrote {} ({} on {}, mapping {}, metres)",
                    out.display(),
                    file.display(),
                    model.name,
                    m.name
                );
                println!("end effector distance to the source (mean / worst):");
                for e in effector_errors(&clip, &m, &mapped)? {
                    println!(
                        "  {:<11} {:6.1} mm / {:6.1} mm",
                        e.effector,
                        e.mean_m * 1e3,
                        e.max_m * 1e3
                    );
                }
            }
        }
    } else {
        bail!("say what to export: --positions OUT.csv, --angles MODEL OUT.csv or --bvh OUT.bvh");
    }
    Ok(())
}

fn render(file: &Path, out: &Path, model: Option<String>, frames: usize) -> Result<()> {
    let base = Path::new(".");
    let src = ClipSource {
        file: file.display().to_string(),
        start_s: None,
        end_s: None,
        unit_scale: None,
        mapping: None,
    };
    let motion = load_motion(&src, base)?;
    let clip = match &model {
        Some(name) => motion.on_model(&Model::by_name(name)?)?.to_clip(),
        None => motion.clip(),
    };
    let figure = clip.skeleton.figure();
    let points = clip.point_frames();
    let label = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let track = Track {
        figure: &figure,
        frames: &points,
        label,
        frame_time: clip.frame_time,
    };
    match out
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("png") => filmstrip_png(&[track], frames.max(1), out)?,
        Some("gif") => animation_gif(&[track], 25.0, out)?,
        _ => bail!(
            "--out {}: expected a .png (filmstrip) or .gif (animation) file",
            out.display()
        ),
    }
    println!("wrote {}", out.display());
    Ok(())
}

fn run(path: &Path, out: Option<PathBuf>, set: &[String]) -> Result<()> {
    let scene = Scene::load(path)?;
    let scene = scene::apply_overrides(&scene, set)?;
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
