//! `marionette body fall21 --urdf OUT.urdf --mjcf OUT.xml`: the articulated fall21 body (links,
//! joints, axes, ranges, masses, centres of mass, inertias, contact boxes) for a subject of the
//! given age group, height and mass, as URDF and/or MJCF.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use marionette::humanoid::fall21_body;
use marionette::humanoid::strength::torque_limits;
use marionette::humanoid::{AgeGroup, RangeTable};
use marionette::humanoid::{to_mjcf, to_urdf};

// The command's arguments (its help text is on `Command::Body`).
#[derive(clap::Args)]
pub struct Args {
    /// The model (only fall21 is articulated).
    model: String,
    /// Write URDF (Pinocchio, ROS tools).
    #[arg(long, value_name = "OUT.urdf")]
    urdf: Option<PathBuf>,
    /// Write MJCF (MuJoCo).
    #[arg(long, value_name = "OUT.xml")]
    mjcf: Option<PathBuf>,
    /// Age group of the joint ranges and strength: elderly or adult.
    #[arg(long, default_value = "elderly")]
    age_group: String,
    /// Standing height (m).
    #[arg(long, default_value_t = 1.70)]
    height_m: f64,
    /// Body mass (kg).
    #[arg(long, default_value_t = 65.0)]
    mass_kg: f64,
    /// Gravity magnitude (m/s², along −Y), written into the MJCF.
    #[arg(long, default_value_t = 9.81)]
    gravity: f64,
}

/// Runs the command.
pub fn body(a: Args) -> Result<()> {
    if a.model != "fall21" {
        bail!("model '{}': only fall21 is an articulated body", a.model);
    }
    if a.urdf.is_none() && a.mjcf.is_none() {
        bail!("nothing to write: give --urdf OUT.urdf and/or --mjcf OUT.xml");
    }
    let group = match a.age_group.as_str() {
        "elderly" => AgeGroup::Elderly,
        "adult" => AgeGroup::Adult,
        other => bail!("--age-group '{other}': expected elderly or adult"),
    };
    let body = fall21_body(a.height_m, a.mass_kg, a.gravity)?;
    let ranges = RangeTable::builtin(group).for_figure(&body.figure)?;
    if let Some(p) = &a.urdf {
        std::fs::write(p, to_urdf(&body, &ranges, &torque_limits(group)))
            .with_context(|| format!("writing {}", p.display()))?;
        println!("wrote {}", p.display());
    }
    if let Some(p) = &a.mjcf {
        std::fs::write(p, to_mjcf(&body, &ranges, a.gravity))
            .with_context(|| format!("writing {}", p.display()))?;
        println!("wrote {}", p.display());
    }
    Ok(())
}
