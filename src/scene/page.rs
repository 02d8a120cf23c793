//! The scene's results page (`index.html`): what each scene kind gives [`crate::render::Page`]
//! — its motions (falls with their contact boxes and impacts), plots and headline figures.

use std::path::{Path, PathBuf};

use super::SceneError;
use crate::experiments::fall::FallResult;
use crate::humanoid::HumanBody;
use crate::render::{Page, PageBox, PageEvent, PageMotion, PagePlot, Plot};
use crate::skeleton::Clip;

/// The page's file name in an output folder.
pub const PAGE_FILE: &str = "index.html";

/// A fall as a page motion: the fall21 figure with its contact boxes (as the fall's body has
/// them at its height) in every frame, and its impacts as events: each link's first touchdown
/// with its peak floor force, and the head's lowest point.
pub fn fall_motion(label: &str, r: &FallResult) -> Result<PageMotion, SceneError> {
    let clip = r.to_figure_clip().to_clip();
    // The boxes' sizes follow the height only; the mass sets inertias, which are not drawn.
    let body =
        crate::humanoid::fall21_body(r.height_m, 65.0, 9.81).map_err(SceneError::FallBody)?;
    let figure = crate::render::StickFigure::of(&clip.skeleton);
    let joints = clip.joint_count();
    if body.boxes.len() != joints {
        return Err(SceneError::BoxCount {
            boxes: body.boxes.len(),
            joints,
        });
    }
    let boxes = contact_boxes(&clip, &body);
    let mut events = touchdowns(r, &body);
    if let Some((k, f)) = r
        .frames
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.head_height_m.total_cmp(&b.1.head_height_m))
    {
        events.push(PageEvent {
            time_s: k as f64 / r.record_hz,
            label: format!("head lowest: {:.2} m above the floor", f.head_height_m),
            tag: format!("head lowest {:.2} m", f.head_height_m),
            point: clip.skeleton.index("head").or_else(|| {
                figure
                    .names
                    .iter()
                    .position(|n| n.to_ascii_lowercase().contains("head"))
            }),
        });
    }
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    Ok(PageMotion {
        label: label.to_string(),
        frames: clip.point_frames(),
        figure,
        frame_time: clip.frame_time,
        start_s: 0.0,
        boxes: Some(boxes),
        box_names: clip
            .skeleton
            .joints
            .iter()
            .map(|j| j.name.clone())
            .collect(),
        events,
    })
}

/// The fall's contact boxes in every frame of `clip`, as `body` has them.
fn contact_boxes(clip: &Clip, body: &HumanBody) -> Vec<Vec<PageBox>> {
    let mut g = Vec::new();
    (0..clip.frame_count())
        .map(|f| {
            clip.globals(f, &mut g);
            g.iter()
                .zip(&body.boxes)
                .map(|(t, b)| PageBox {
                    center: t.translation + t.rotation * b.center,
                    half_axes: [
                        t.rotation * glam::DVec3::X * b.half.x,
                        t.rotation * glam::DVec3::Y * b.half.y,
                        t.rotation * glam::DVec3::Z * b.half.z,
                    ],
                })
                .collect()
        })
        .collect()
}

/// Each link's first touchdown in the fall `r` as an event (or that it is on the floor from
/// the start), with its peak floor force.
fn touchdowns(r: &FallResult, body: &HumanBody) -> Vec<PageEvent> {
    r.impacts
        .iter()
        .filter_map(|i| {
            let t = i.touchdown_s?;
            let point = body.link_names.iter().position(|n| *n == i.link);
            // A link on the floor from the first frame (the feet of a standing start) did
            // not hit it.
            let how = if t < 0.5 / r.record_hz {
                "is on the floor from the start".to_string()
            } else {
                format!(
                    "touches the floor at {:.1} m/s",
                    i.impact_velocity_m_s.abs()
                )
            };
            Some(PageEvent {
                time_s: t,
                label: format!(
                    "{} {how}; its peak floor force {:.0} N",
                    i.link, i.peak_force_n
                ),
                tag: format!("{} {:.0} N", i.link, i.peak_force_n),
                point,
            })
        })
        .collect()
}

/// A plot whose x is time on the page's timeline (s).
pub fn timed(plot: Plot) -> PagePlot {
    PagePlot {
        plot,
        time_axis: true,
    }
}

/// A plot whose x is something else (generation, bar number): no cursor.
pub fn untimed(plot: Plot) -> PagePlot {
    PagePlot {
        plot,
        time_axis: false,
    }
}

/// Writes `page` as `index.html` in the output folder `out`.
pub fn write(page: &Page, out: &Path) -> Result<(), SceneError> {
    crate::render::write_page(page, &out.join(PAGE_FILE))?;
    Ok(())
}

/// A scene of a `marionette run` of several scenes, as the run's index page lists it.
#[derive(Clone, Debug)]
pub struct RunPage {
    /// The scene's name.
    pub name: String,
    /// Its results page.
    pub page: PathBuf,
    /// Its headline ([`super::headline`]), one line each.
    pub headline: Vec<String>,
}

/// Escapes text for HTML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes `index.html` into `dir`, a page linking each scene's results page (relative to
/// `dir` when the page is inside it, else by its absolute `file://` address) with its headline;
/// returns its path.
pub fn write_run_index(scenes: &[RunPage], dir: &Path) -> Result<PathBuf, SceneError> {
    let mut items = String::new();
    for s in scenes {
        let href = match s.page.strip_prefix(dir) {
            Ok(rel) => rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/"),
            Err(_) => {
                let abs = std::path::absolute(&s.page).map_err(|e| SceneError::Io {
                    path: s.page.display().to_string(),
                    source: e,
                })?;
                format!("file://{}", abs.display())
            }
        };
        let lines: String = s
            .headline
            .iter()
            .map(|l| format!("<li>{}</li>", escape(l)))
            .collect();
        items.push_str(&format!(
            "<li><a href=\"{}\">{}</a><ul>{lines}</ul></li>\n",
            escape(&href),
            escape(&s.name)
        ));
    }
    let html = format!(
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>marionette run: {n} scenes</title>\n<link rel=\"icon\" href=\"data:,\">\n\
         <style>body{{font:15px/1.5 system-ui,sans-serif;background:#1e2127;color:#e6e6e6;\
         margin:2em}}a{{color:#4fc3f7;font-size:1.2em}}li{{margin:.3em 0}}ul ul{{color:#b8bcc4}}\
         </style>\n</head>\n<body>\n<h1>marionette run: {n} scenes</h1>\n<ul>\n{items}</ul>\n\
         </body>\n</html>\n",
        n = scenes.len()
    );
    let path = dir.join(PAGE_FILE);
    super::write_output(&path, html.as_bytes())?;
    Ok(path)
}
