//! `marionette view FILE.bvh|FOLDER`: the results page (one self-contained HTML file) for a
//! motion file or a scene's output folder.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use marionette::humanoid::Figure;
use marionette::render::{
    Page, PageMotion, PagePlot, PageSong, Plot, Series, Track, stand_upright, write_page,
};
use marionette::scene::{ClipSource, load_motion};

// The command's arguments (its help text is on `Command::View`).
#[derive(clap::Args)]
pub struct Args {
    /// A motion file (.bvh, or .ron for a keyframed clip) or a scene's output folder (its BVH
    /// files, report.json and song.wav).
    input: PathBuf,
    /// Map a motion file onto this model first (humanoid24 or fall21); without it the skeleton
    /// is drawn as it is, whatever its joints.
    #[arg(long)]
    model: Option<String>,
    /// With --model: a mapping file for the skeleton (default: detected among the built-ins).
    #[arg(long, requires = "model")]
    mapping: Option<PathBuf>,
    /// Metres per file unit of a BVH (estimated from the standing height when absent).
    #[arg(long)]
    unit_scale: Option<f64>,
    /// The page to write (default: out/view/<name>.html).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// A loaded motion as a page motion (capsules from its bone lengths).
fn motion(
    file: &Path,
    model: Option<&str>,
    mapping: Option<&Path>,
    unit_scale: Option<f64>,
) -> Result<PageMotion> {
    let src = ClipSource {
        file: file.display().to_string(),
        start_s: None,
        end_s: None,
        unit_scale,
        mapping: mapping.map(|m| m.display().to_string()),
    };
    let loaded = load_motion(&src, Path::new("."))?;
    let clip = match model {
        Some(name) => loaded.on_figure(&Figure::by_name(name)?)?.to_clip(),
        None => loaded.clip(),
    };
    let figure = marionette::render::StickFigure::of(&clip.skeleton);
    let frames = clip.point_frames();
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let label = match model {
        Some(m) => format!("{stem} on {m}"),
        None => stem,
    };
    Ok(PageMotion::from_track(&Track {
        figure: &figure,
        frames: &frames,
        label,
        frame_time: clip.frame_time,
    }))
}

/// The report's top-level figures (numbers, yes/no, short texts), one line each.
fn headline(report: &serde_json::Value) -> Vec<String> {
    let Some(o) = report.as_object() else {
        return vec![];
    };
    o.iter()
        .filter_map(|(k, v)| {
            let words = k.replace('_', " ");
            match v {
                serde_json::Value::Number(n) => {
                    let x = n.as_f64()?;
                    Some(format!(
                        "{words}: {}",
                        if x.fract() == 0.0 {
                            format!("{x}")
                        } else {
                            format!("{x:.4}")
                        }
                    ))
                }
                serde_json::Value::Bool(b) => {
                    Some(format!("{words}: {}", if *b { "yes" } else { "no" }))
                }
                serde_json::Value::String(s) if s.len() <= 120 => Some(format!("{words}: {s}")),
                _ => None,
            }
        })
        .collect()
}

/// Runs `view`: writes the page and prints its path.
pub fn view(args: Args) -> Result<()> {
    let Args {
        input,
        model,
        mapping,
        unit_scale,
        out,
    } = args;
    // The file's stem, or the folder's name (also for `.`).
    let name = input
        .canonicalize()
        .unwrap_or_else(|_| input.clone())
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "view".into());
    let mut page = Page {
        title: format!("{name}: marionette view"),
        ..Page::default()
    };
    if input.is_dir() {
        if model.is_some() {
            bail!(
                "--model: {} is a folder; the model maps a motion file",
                input.display()
            );
        }
        view_folder(&mut page, &input, unit_scale)?;
    } else {
        view_file(
            &mut page,
            &input,
            model.as_deref(),
            mapping.as_deref(),
            unit_scale,
        )?;
    }
    let out = out.unwrap_or_else(|| {
        PathBuf::from("out")
            .join("view")
            .join(format!("{name}.html"))
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    write_page(&page, &out)?;
    println!("{}", out.display());
    Ok(())
}

/// The page of a folder: every BVH file in it (a scene's are Y up on the floor already), with a
/// scene's report's headline and its song when they are there.
fn view_folder(page: &mut Page, input: &Path, unit_scale: Option<f64>) -> Result<()> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(input)
        .with_context(|| format!("reading the folder {}", input.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    if files.is_empty() {
        bail!(
            "{}: no .bvh file in this folder (expected a scene's output folder or a folder of BVH files)",
            input.display()
        );
    }
    for f in &files {
        // A scene's BVH files are written Y up on the floor y = 0: drawn as they are.
        page.motions.push(motion(f, None, None, unit_scale)?);
    }
    let report = input.join("report.json");
    if report.is_file() {
        let text = std::fs::read_to_string(&report)
            .with_context(|| format!("reading {}", report.display()))?;
        let v: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{}: expected a scene's report (JSON)", report.display()))?;
        page.headline = headline(&v);
    }
    let song = input.join("song.wav");
    if song.is_file() {
        let a = marionette::choreo::music::decode_file(&song)?;
        page.song = Some(PageSong {
            samples: a.samples,
            sample_rate: a.sample_rate,
            start_s: 0.0,
        });
    }
    page.notes.push(format!(
        "From the files in {}: the scene's own index.html there also has its plots and, for falls, the contact boxes.",
        input.display()
    ));
    Ok(())
}

/// The page of a motion file (mapped onto `model` when given, else stood upright): the
/// motion and its root's height over time.
fn view_file(
    page: &mut Page,
    input: &Path,
    model: Option<&str>,
    mapping: Option<&Path>,
    unit_scale: Option<f64>,
) -> Result<()> {
    let mut m = motion(input, model, mapping, unit_scale)?;
    if model.is_none()
        && let Some(said) = stand_upright(&mut m)
    {
        page.notes.push(said);
    }
    let n = m.frames.len();
    page.plots.push(PagePlot {
        plot: Plot {
            title: "height of the root above the floor".into(),
            x_label: "time (s)".into(),
            y_label: format!("{} height (m)", m.figure.names[0]),
            series: vec![Series {
                name: m.figure.names[0].clone(),
                points: m
                    .frames
                    .iter()
                    .enumerate()
                    .map(|(k, f)| (k as f64 * m.frame_time, f[0].y))
                    .collect(),
            }],
            markers: vec![],
        },
        time_axis: true,
    });
    page.headline.push(format!(
        "{} points, {n} frames at {:.0} frames/s: {:.2} s.",
        m.figure.names.len(),
        1.0 / m.frame_time,
        n.saturating_sub(1) as f64 * m.frame_time
    ));
    page.motions.push(m);
    Ok(())
}
