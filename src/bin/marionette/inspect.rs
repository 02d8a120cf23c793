//! `marionette inspect FILE.bvh`: skeleton, channels, frames, rate, duration, size, unit scale,
//! ground contact and flight spans.

use std::path::PathBuf;

use anyhow::{Context, Result};

use marionette::analysis::{ContactConfig, clip_contacts};
use marionette::bvh::Bvh;
use marionette::skeleton::Clip;

use crate::common::read_bvh;

// The command's arguments (its help text is on `Command::Inspect`).
#[derive(clap::Args)]
pub struct Args {
    /// The BVH file.
    file: PathBuf,
    /// Metres per file unit (estimated from the standing height when absent).
    #[arg(long)]
    unit_scale: Option<f64>,
}

/// Runs `inspect`: prints the report to stdout.
pub fn inspect(args: Args) -> Result<()> {
    let (file, unit_scale) = (args.file.as_path(), args.unit_scale);
    let b = read_bvh(file)?;
    let size = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
    let clip = Clip::from_bvh(&b, unit_scale).with_context(|| file.display().to_string())?;
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
    print_skeleton(&b);
    print_mapping(&clip);
    print_contacts(&clip);
    Ok(())
}

/// Prints the skeleton: each joint indented by its depth, its channels, and whether it has an
/// End Site.
fn print_skeleton(b: &Bvh) {
    println!("skeleton:");
    // Depths in one pass (parents come first); indentation stops at INDENT_MAX levels.
    const INDENT_MAX: usize = 16;
    let mut depths: Vec<usize> = Vec::with_capacity(b.joints.len());
    for (i, j) in b.joints.iter().enumerate() {
        let depth = j.parent.map_or(0, |p| depths[p] + 1);
        depths.push(depth);
        let ch: Vec<&str> = j.channels.iter().map(|c| c.name()).collect();
        let end = j.end_site.map(|_| "  + End Site").unwrap_or("");
        let deep = if depth > INDENT_MAX {
            format!("({depth} deep) ")
        } else {
            String::new()
        };
        println!(
            "  {:>3} {}{}{}  [{}]{}",
            i,
            "  ".repeat(depth.min(INDENT_MAX)),
            deep,
            j.name,
            ch.join(" "),
            end
        );
    }
}

/// Prints the ground contact and flight spans from the feet (the mapping's ankles and toes,
/// else found by name).
fn print_contacts(clip: &Clip) {
    // Ground contact and flight from the feet: the mapping's ankles and toes, else by name.
    let Some(c) = clip_contacts(clip, 0.03, 0.1) else {
        println!("contact     (no feet found: no joint named foot/toe/ankle on each side)");
        return;
    };
    let spans = |s: &[marionette::analysis::Span]| -> String {
        s.iter()
            .map(|x| format!("{:.2}-{:.2}", x.start_s, x.end_s))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "floor       y = {:.3} m (a foot point touches within {:.0} cm of its rest height)",
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
    println!(
        "body        {} spans on the floor (a joint other than the feet within {:.0} cm){}{}",
        c.body.len(),
        ContactConfig::default().body_threshold_m * 100.0,
        if c.body.is_empty() { "" } else { ": " },
        spans(&c.body)
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
}

// ---- The mapping section (landmarks onto the models) ----

/// Prints the landmark mapping `export`/`render` would use without `--mapping` (the built-in
/// file that fits, else the automatic one) and how each landmark was found.
fn print_mapping(clip: &Clip) {
    use marionette::mapping::{Mapping, Synonyms};
    let builtin = Mapping::builtin_for(&clip.skeleton);
    let auto = Mapping::automatic(clip, Synonyms::builtin());
    match (builtin, &auto) {
        (Some(m), _) => println!(
            "mapping     built-in '{}' (its joints {} are all present; --mapping FILE overrides)",
            m.name,
            m.detect.join(", ")
        ),
        (None, Ok(_)) => println!(
            "mapping     automatic, from the names and the structure of the first frame (no \
             built-in mapping fits; `marionette mapping FILE --out my.ron` writes it to edit)"
        ),
        (None, Err(e)) => {
            println!("mapping     none: {e}");
            return;
        }
    }
    match &auto {
        Ok(a) => {
            println!(
                "  {:<15} {:<22} {:>4}  how (automatic detection)",
                "landmark", "source", "conf"
            );
            for f in &a.findings {
                let used = builtin.map(|m| m.landmarks[&f.landmark].as_str());
                let source = match used {
                    Some(u) if u != f.source => format!("{u} (auto: {})", f.source),
                    Some(u) => u.to_string(),
                    None => f.source.clone(),
                };
                println!(
                    "  {:<15} {:<22} {:>4.2}  {}",
                    f.landmark, source, f.confidence, f.reason
                );
            }
            for n in &a.notes {
                println!("  note: {n}");
            }
        }
        Err(e) => {
            println!("  automatic detection: {e}");
            if let Some(m) = builtin {
                for (l, src) in &m.landmarks {
                    println!("  {l:<15} {src}");
                }
            }
        }
    }
}
