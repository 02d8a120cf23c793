//! Helpers shared by the commands.

use std::path::{Path, PathBuf};

use anyhow::Result;

use marionette::bvh;
use marionette::mapping::Mapping;
use marionette::skeleton::Clip;

/// Reads a BVH file, printing its warnings (file and line) to stderr.
pub fn read_bvh(file: &Path) -> Result<bvh::Bvh> {
    let (b, warnings) = bvh::parse_file(file)?;
    for w in warnings {
        eprintln!("warning: {}:{}: {}", file.display(), w.line, w.message);
    }
    Ok(b)
}

/// The mapping file given, else the built-in mapping detected from the clip's joint names, else
/// the automatic one.
pub fn mapping_for(clip: &Clip, mapping: &Option<PathBuf>) -> Result<Mapping> {
    Ok(match mapping {
        Some(p) => Mapping::load(p)?,
        None => Mapping::detect_clip(clip)?,
    })
}
