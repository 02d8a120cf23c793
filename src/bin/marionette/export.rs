//! `marionette export FILE.bvh`: global joint positions (CSV), joint angles on a model (CSV), or
//! BVH as read or mapped onto a model.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use marionette::bvh;
use marionette::humanoid::Figure;
use marionette::mapping::{effector_errors, retarget};
use marionette::skeleton::Clip;

use crate::common::{mapping_for, read_bvh};

// The command's arguments (its help text is on `Command::Export`).
#[derive(clap::Args)]
pub struct Args {
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
}

/// Runs `export`: writes the one output asked for and says what it wrote.
pub fn export(args: Args) -> Result<()> {
    let Args {
        file,
        positions,
        angles,
        bvh: bvh_out,
        model,
        mapping,
        unit_scale,
    } = args;
    let file = file.as_path();
    let b = read_bvh(file)?;
    if let Some(out) = positions {
        let clip = Clip::from_bvh(&b, unit_scale).with_context(|| file.display().to_string())?;
        let s = positions_csv(&clip);
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
        let model = Figure::by_name(model_name)?;
        let clip = Clip::from_bvh(&b, unit_scale).with_context(|| file.display().to_string())?;
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
            Some(name) => write_mapped_bvh(&b, file, &name, &mapping, unit_scale, &out)?,
        }
    } else {
        bail!("say what to export: --positions OUT.csv, --angles MODEL OUT.csv or --bvh OUT.bvh");
    }
    Ok(())
}

/// Every joint's global position at every frame of `clip` as CSV: a line per frame (its number
/// and time), three columns per joint, micrometre precision.
fn positions_csv(clip: &Clip) -> String {
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
    s
}

/// Writes the motion of `b` (read from `file`) mapped onto the model `model_name` as BVH at
/// `out`, and prints how far its end effectors land from the source's.
fn write_mapped_bvh(
    b: &bvh::Bvh,
    file: &Path,
    model_name: &str,
    mapping: &Option<PathBuf>,
    unit_scale: Option<f64>,
    out: &Path,
) -> Result<()> {
    let model = Figure::by_name(model_name)?;
    let clip = Clip::from_bvh(b, unit_scale).with_context(|| file.display().to_string())?;
    let m = mapping_for(&clip, mapping)?;
    let mapped = retarget(&clip, &m, &model)?;
    bvh::write_file(&mapped.to_clip().to_bvh(), out)?;
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
    Ok(())
}
