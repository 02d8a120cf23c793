//! `marionette mapping FILE.bvh --out my.ron`: the landmark mapping of a skeleton, found
//! automatically (names and structure), written as an editable mapping file.

use std::path::PathBuf;

use anyhow::{Context, Result};

use marionette::mapping::{Mapping, Synonyms};
use marionette::skeleton::Clip;

use crate::common::read_bvh;

// The command's arguments (its help text is on `Command::Mapping`).
#[derive(clap::Args)]
pub struct Args {
    /// The BVH file.
    file: PathBuf,
    /// The mapping file to write (RON; pass it to export and render with --mapping).
    #[arg(long, value_name = "OUT.ron")]
    out: PathBuf,
    /// More synonyms (a RON file like src/mapping/builtin/synonyms.ron), added to the built-in
    /// ones.
    #[arg(long, value_name = "SYNONYMS.ron")]
    synonyms: Option<PathBuf>,
    /// Metres per file unit (estimated from the standing height when absent).
    #[arg(long)]
    unit_scale: Option<f64>,
}

/// Runs `mapping`: finds the mapping, writes it, and says how it was found.
pub fn mapping(args: Args) -> Result<()> {
    let b = read_bvh(&args.file)?;
    let clip = Clip::from_bvh(&b, args.unit_scale)?;
    let synonyms = match &args.synonyms {
        Some(p) => Synonyms::builtin().extended(&Synonyms::load(p)?),
        None => Synonyms::builtin().clone(),
    };
    let auto = Mapping::automatic(&clip, &synonyms)?;
    let title = args
        .file
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let text = auto.to_ron(&title);
    // What is written must read back as exactly this mapping.
    let back = Mapping::parse(&text, &args.out.display().to_string())?;
    anyhow::ensure!(
        back == auto.mapping,
        "the mapping written does not read back the same"
    );
    marionette::io::write_atomic(&args.out, text.as_bytes())
        .with_context(|| args.out.display().to_string())?;
    let by_name = auto
        .findings
        .iter()
        .filter(|f| f.reason.starts_with("name"))
        .count();
    let low = auto
        .findings
        .iter()
        .filter(|f| f.confidence < 0.75)
        .map(|f| f.landmark.as_str())
        .collect::<Vec<_>>();
    println!(
        "wrote {} ({} landmarks: {} by name, {} by structure alone{})",
        args.out.display(),
        auto.findings.len(),
        by_name,
        auto.findings.len() - by_name,
        if low.is_empty() {
            String::new()
        } else {
            format!("; check {}", low.join(", "))
        }
    );
    if let Some(m) = Mapping::builtin_for(&clip.skeleton) {
        let same = m
            .landmarks
            .iter()
            .filter(|(k, v)| auto.mapping.landmarks.get(*k) == Some(v))
            .count();
        println!(
            "note: the built-in mapping '{}' also fits this skeleton and is used without --mapping; \
             it names the same point for {same} of {} landmarks",
            m.name,
            m.landmarks.len()
        );
    }
    Ok(())
}
