//! The windowed viewer (feature `viewer`: full Bevy rendering, not built by CI): the active
//! jumping knee kick of `scenes/active_knee_kick.ron` (the motion learned as the scene learns
//! it, the character's PD, assistance and strength from the scene) played by two physical
//! humanoid24 characters through `MarionettePlugin`. Each link is drawn as its contact box
//! following the published joint `Transform`s. Character 1 is pushed only from the keyboard;
//! character 2 gets the scene's own push (during the landing), and the assistance of either
//! is released the scene's `release_delay_s` after its first push, so it falls. The two are
//! drawn side by side (a display offset along x: they do not touch each other); each stands on
//! its own floor, which is drawn.
//!
//!     cargo run --release --example viewer --features viewer --ignore-rust-version
//!     cargo run --release --example viewer --features viewer --ignore-rust-version -- \
//!         --screenshot docs/viewer.png --after-s 1.0
//!
//! (`--ignore-rust-version`: bevy 0.20.1 declares Rust 1.97.1; it builds on 1.95.)
//!
//! Options: `--scene PATH` (another `ActiveKneeKick` scene), `--set FIELD=VALUE` (as the
//! command's `run --set`, repeatable), `--screenshot PATH --after-s T` (simulate T seconds
//! at 1/30 s of simulated time per frame, save the window to PATH and exit).
//!
//! Controls: left mouse drag orbits, wheel zooms, `1` / `2` push character 1 / 2 now, `R`
//! restarts, `Space` pauses, `Esc` quits.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll, MouseScrollUnit};
use bevy::prelude::*;
use bevy::render::view::Tonemapping;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured, save_to_disk};
use bevy::window::WindowResolution;
use marionette::bevy::{JointEntities, MarionettePlugin, TicksPerUpdate, spawn_joint_entities};
use marionette::ecs::Clock;
use marionette::ecs::character::{
    CharacterLog, Reaction, RootAssist, push_now, spawn_physical_character,
};
use marionette::ecs::physics::{BodyState, ExternalForces, FloorContact};
use marionette::experiments::knee_kick;
use marionette::humanoid::{HumanBody, humanoid24_body};
use marionette::primitive::Primitive;
use marionette::scene::{ActiveKneeKickScene, Scene, apply_overrides, knee_kick_config};

/// Display offset between the two characters (m, along x).
const SPACING_M: f32 = 1.2;
/// Simulated time per frame in screenshot mode (s).
const SCREENSHOT_FRAME_S: f64 = 1.0 / 30.0;
/// Frames drawn with the simulation held before a screenshot is taken (pipelines compile
/// on the first frames).
const SETTLE_FRAMES: u32 = 30;
/// Most simulated time one interactive frame may take (s): a slow frame slows the motion down
/// instead of piling up ticks.
const MAX_FRAME_S: f64 = 0.1;

/// What the command line asked for.
struct Args {
    scene: PathBuf,
    sets: Vec<String>,
    screenshot: Option<(PathBuf, f64)>,
}

fn parse_args() -> Result<Args, String> {
    let mut scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/active_knee_kick.ron");
    let (mut sets, mut shot, mut after) = (Vec::new(), None, None);
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--scene" => scene = PathBuf::from(value("--scene")?),
            "--set" => sets.push(value("--set")?),
            "--screenshot" => shot = Some(PathBuf::from(value("--screenshot")?)),
            "--after-s" => {
                let v = value("--after-s")?;
                let t: f64 = v
                    .parse()
                    .map_err(|_| format!("--after-s: expected seconds, found '{v}'"))?;
                if !(t.is_finite() && t >= 0.0) {
                    return Err(format!("--after-s: expected seconds ≥ 0, found {t}"));
                }
                after = Some(t);
            }
            "-h" | "--help" => {
                return Err("usage: viewer [--scene PATH] [--set FIELD=VALUE]... \
                     [--screenshot PATH --after-s T]"
                    .into());
            }
            other => return Err(format!("unknown argument '{other}' (see --help)")),
        }
    }
    let screenshot = match (shot, after) {
        (Some(p), Some(t)) => Some((p, t)),
        (None, None) => None,
        _ => return Err("--screenshot and --after-s go together".into()),
    };
    Ok(Args {
        scene,
        sets,
        screenshot,
    })
}

/// The scene, its learned motion and the body, shared by every (re)spawn.
#[derive(Resource)]
struct Setup {
    scene: ActiveKneeKickScene,
    body: Arc<HumanBody>,
    sequence: Vec<Arc<Primitive>>,
    push_link: usize,
}

/// Loads the scene and learns its motion as the scene does.
fn setup_from(args: &Args) -> Result<Setup, String> {
    let shown = args.scene.display();
    let scene = Scene::load(&args.scene).map_err(|e| e.to_string())?;
    let scene = apply_overrides(&scene, &args.sets).map_err(|e| e.to_string())?;
    let Scene::ActiveKneeKick(scene) = scene else {
        return Err(format!("{shown}: the viewer plays ActiveKneeKick scenes"));
    };
    let scene = *scene;
    if scene.key_pose_deg.is_some() {
        return Err(format!(
            "{shown}: key_pose_deg is set; the viewer does not switch to key poses (run the scene \
             with the marionette command instead)"
        ));
    }
    let base = args.scene.parent().unwrap_or(Path::new("."));
    let config = knee_kick_config(&scene.motion, base).map_err(|e| e.to_string())?;
    let learned = knee_kick::run(&config).map_err(|e| e.to_string())?;
    let c = &scene.character;
    let body = Arc::new(humanoid24_body(c.height_m, c.mass_kg, 9.81).map_err(|e| e.to_string())?);
    let push_link = body.link_index(&scene.push.link).ok_or(format!(
        "{shown}: push.link '{}' is not a link ({:?})",
        scene.push.link, body.link_names
    ))?;
    Ok(Setup {
        sequence: learned.sequence().into_iter().map(Arc::new).collect(),
        scene,
        body,
        push_link,
    })
}

/// One drawn character: its engine entity and its label.
#[derive(Resource, Default)]
struct Characters(Vec<(Entity, &'static str)>);

/// Spawns the two characters with their meshes; returns their entities.
fn spawn_characters(world: &mut World) -> Vec<(Entity, &'static str)> {
    let (body, sequence, scene, push_link) = {
        let s = world.resource::<Setup>();
        (
            s.body.clone(),
            s.sequence.clone(),
            s.scene.clone(),
            s.push_link,
        )
    };
    let settings = scene.character.settings();
    let colors = [Color::srgb(0.25, 0.45, 0.85), Color::srgb(0.9, 0.5, 0.15)];
    let labels = ["1: pushed by key", "2: the scene's push"];
    let mut out = Vec::new();
    for k in 0..2 {
        let reaction = Reaction {
            release_delay_s: scene.release_delay_s,
            ..Reaction::default()
        };
        let e = spawn_physical_character(
            world,
            labels[k],
            body.clone(),
            sequence.clone(),
            &settings,
            reaction,
        )
        .expect("the scene's character was checked when it was learned");
        if k == 1 {
            world
                .get_mut::<ExternalForces>(e)
                .expect("spawned with external forces")
                .push(scene.push.to_force(push_link));
        }
        let x = (k as f32 - 0.5) * SPACING_M;
        world
            .entity_mut(e)
            .insert((Transform::from_xyz(x, 0.0, 0.0), Visibility::default()));
        let joints = spawn_joint_entities(world, e);
        let material = world
            .resource_mut::<Assets<StandardMaterial>>()
            .add(StandardMaterial {
                base_color: colors[k],
                perceptual_roughness: 0.7,
                ..default()
            });
        for (j, b) in joints.iter().zip(&body.boxes) {
            let size = (b.half * 2.0).as_vec3();
            let mesh = world
                .resource_mut::<Assets<Mesh>>()
                .add(Cuboid::from_size(size));
            world.entity_mut(*j).insert(Visibility::default());
            world.spawn((
                Mesh3d(mesh),
                MeshMaterial3d(material.clone()),
                Transform::from_translation(b.center.as_vec3()),
                ChildOf(*j),
            ));
        }
        out.push((e, labels[k]));
    }
    out
}

/// The floor plane (at the first character's floor height) with a 0.5 m grid, the light and
/// the camera.
fn spawn_stage(world: &mut World, floor_y: f32) {
    let mut meshes = world.resource_mut::<Assets<Mesh>>();
    let plane = meshes.add(Plane3d::default().mesh().size(16.0, 16.0));
    let line_x = meshes.add(Cuboid::new(16.0, 0.002, 0.012));
    let line_z = meshes.add(Cuboid::new(0.012, 0.002, 16.0));
    let mut materials = world.resource_mut::<Assets<StandardMaterial>>();
    let floor = materials.add(StandardMaterial {
        base_color: Color::srgb(0.78, 0.78, 0.74),
        perceptual_roughness: 0.95,
        ..default()
    });
    let grid = materials.add(StandardMaterial {
        base_color: Color::srgb(0.55, 0.55, 0.52),
        perceptual_roughness: 0.95,
        ..default()
    });
    world.spawn((
        Mesh3d(plane),
        MeshMaterial3d(floor),
        Transform::from_xyz(0.0, floor_y, 0.0),
    ));
    for i in -16..=16 {
        let d = i as f32 * 0.5;
        world.spawn((
            Mesh3d(line_x.clone()),
            MeshMaterial3d(grid.clone()),
            Transform::from_xyz(0.0, floor_y + 0.001, d),
        ));
        world.spawn((
            Mesh3d(line_z.clone()),
            MeshMaterial3d(grid.clone()),
            Transform::from_xyz(d, floor_y + 0.001, 0.0),
        ));
    }
    world.spawn((
        DirectionalLight {
            illuminance: 6000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    world.insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness: 400.0,
        affects_lightmapped_meshes: true,
    });
    world.spawn((
        Camera3d::default(),
        Tonemapping::AcesFitted,
        Transform::IDENTITY,
    ));
    world.spawn((
        Text::new(""),
        TextFont::from_font_size(FontSize::Px(15.0)),
        TextColor(Color::srgb(0.08, 0.08, 0.1)),
        Node {
            position_type: PositionType::Absolute,
            top: Val::Px(10.0),
            left: Val::Px(12.0),
            ..default()
        },
        HelpText,
    ));
}

/// The help and status text.
#[derive(Component)]
struct HelpText;

/// The orbit camera: yaw and pitch (radians) about the characters' mean pelvis position,
/// distance (m).
#[derive(Resource)]
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

/// How the engine is advanced: in real time (interactive) or by fixed steps up to a time
/// (screenshot mode).
#[derive(Resource)]
struct Pace {
    paused: bool,
    /// Real time not yet simulated (s).
    owed_s: f64,
    /// Screenshot mode: the file, the simulated time, frames drawn since reaching it.
    screenshot: Option<(PathBuf, f64, u32)>,
}

/// Sets how many engine ticks this update runs ([`TicksPerUpdate`]).
fn pace(
    real: Res<Time<Real>>,
    clock: Res<Clock>,
    mut pace: ResMut<Pace>,
    mut ticks: ResMut<TicksPerUpdate>,
) {
    let dt = clock.tick_s;
    let n = if let Some((_, after_s, _)) = &pace.screenshot {
        let left = ((after_s - clock.time_s) / dt).round().max(0.0);
        left.min((SCREENSHOT_FRAME_S / dt).round())
    } else if pace.paused {
        pace.owed_s = 0.0;
        0.0
    } else {
        pace.owed_s = (pace.owed_s + real.delta_secs_f64()).min(MAX_FRAME_S);
        let n = (pace.owed_s / dt).floor();
        pace.owed_s -= n * dt;
        n
    };
    ticks.0 = n as u32;
}

/// In screenshot mode: once the simulated time is reached and the picture has settled, saves
/// the window and exits.
fn take_screenshot(mut commands: Commands, clock: Res<Clock>, mut pace: ResMut<Pace>) {
    let Some((path, after_s, frames)) = &mut pace.screenshot else {
        return;
    };
    if clock.time_s + 0.5 * clock.tick_s < *after_s {
        return;
    }
    *frames += 1;
    if *frames == SETTLE_FRAMES {
        println!(
            "screenshot at {:.3} s of simulated time ({} ticks): {}",
            clock.time_s,
            clock.tick,
            path.display()
        );
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(path.clone()))
            .observe(
                |_: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                    exit.write(AppExit::Success);
                },
            );
    }
}

/// Keys: push, restart, pause, quit.
fn keys(world: &mut World) {
    let input = world.resource::<ButtonInput<KeyCode>>();
    let pressed: Vec<KeyCode> = [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::KeyR,
        KeyCode::Space,
        KeyCode::Escape,
    ]
    .into_iter()
    .filter(|k| input.just_pressed(*k))
    .collect();
    for key in pressed {
        match key {
            KeyCode::Digit1 | KeyCode::Digit2 => {
                let k = usize::from(key == KeyCode::Digit2);
                let e = world.resource::<Characters>().0[k].0;
                // The scene's push (link, point, direction, force, duration), starting now.
                let push = world.resource::<Setup>().scene.push.clone();
                push_now(world, e, &push);
            }
            KeyCode::KeyR => {
                let old = std::mem::take(&mut world.resource_mut::<Characters>().0);
                for (e, _) in old {
                    world.entity_mut(e).despawn();
                }
                let dt = world.resource::<Setup>().scene.dt_s;
                world.insert_resource(Clock::physics(dt));
                let spawned = spawn_characters(world);
                world.resource_mut::<Characters>().0 = spawned;
            }
            KeyCode::Space => {
                let mut p = world.resource_mut::<Pace>();
                p.paused = !p.paused;
            }
            _ => {
                world.write_message(AppExit::Success);
            }
        }
    }
}

/// The mean pelvis position of the characters as drawn (display frame).
fn pelvis_centre(
    characters: &[(Entity, &str)],
    q: &Query<(&JointEntities, &Transform)>,
    t: &Query<&Transform, Without<Camera3d>>,
) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut n = 0.0;
    for (e, _) in characters {
        if let Ok((joints, root)) = q.get(*e)
            && let Some(p) = joints.0.first().and_then(|j| t.get(*j).ok())
        {
            sum += root.translation + p.translation;
            n += 1.0;
        }
    }
    if n > 0.0 { sum / n } else { Vec3::ZERO }
}

/// Orbit on a left-button drag, zoom on the wheel; the camera looks at the characters' mean
/// pelvis (its height kept at least 0.8 m above the floor).
#[allow(clippy::too_many_arguments)]
fn orbit_camera(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut orbit: ResMut<Orbit>,
    characters: Res<Characters>,
    floor: Res<FloorY>,
    roots: Query<(&JointEntities, &Transform)>,
    transforms: Query<&Transform, Without<Camera3d>>,
    mut camera: Single<&mut Transform, (With<Camera3d>, Without<JointEntities>)>,
) {
    if buttons.pressed(MouseButton::Left) {
        orbit.yaw -= motion.delta.x * 0.005;
        orbit.pitch = (orbit.pitch + motion.delta.y * 0.005).clamp(-0.2, 1.4);
    }
    let lines = match scroll.unit {
        MouseScrollUnit::Line => scroll.delta.y,
        MouseScrollUnit::Pixel => scroll.delta.y / 40.0,
    };
    orbit.distance = (orbit.distance * (-0.1 * lines).exp()).clamp(1.0, 30.0);
    let mut target = pelvis_centre(&characters.0, &roots, &transforms);
    target.y = target.y.max(floor.0 + 0.8);
    let dir = Vec3::new(
        orbit.yaw.sin() * orbit.pitch.cos(),
        orbit.pitch.sin(),
        orbit.yaw.cos() * orbit.pitch.cos(),
    );
    **camera =
        Transform::from_translation(target + dir * orbit.distance).looking_at(target, Vec3::Y);
}

/// The floor height (m) the stage was drawn at.
#[derive(Resource)]
struct FloorY(f32);

/// Writes the help and each character's state (from its components) into the text.
fn status_text(
    clock: Res<Clock>,
    pace: Res<Pace>,
    characters: Res<Characters>,
    q: Query<(
        &Reaction,
        &RootAssist,
        &BodyState,
        &CharacterLog,
        &FloorContact,
    )>,
    mut text: Single<&mut Text, With<HelpText>>,
) {
    let mut s = format!(
        "active jumping knee kick  t = {:.2} s{}\n",
        clock.time_s,
        if pace.paused { " (paused)" } else { "" }
    );
    for (e, label) in &characters.0 {
        let Ok((r, a, state, log, floor)) = q.get(*e) else {
            continue;
        };
        let above = state.q[1] - floor.0.params.floor_height;
        let mut line = format!("{label}: pelvis {above:.2} m above the floor");
        if let Some(p) = r.pushed_at_s {
            line.push_str(&format!(", pushed at {p:.2} s"));
        }
        match r.released_at_s {
            Some(t) if a.released => line.push_str(&format!(", assistance released at {t:.2} s")),
            _ => line.push_str(&format!(", assistance {:.2}", a.gains.strength)),
        }
        if let Some(last) = log.samples.last() {
            line.push_str(&format!(
                ", joint RMS error {:.1} deg",
                last.mean_sq_error.sqrt().to_degrees()
            ));
        }
        s.push_str(&line);
        s.push('\n');
    }
    if pace.screenshot.is_none() {
        s.push_str(
            "drag: orbit   wheel: zoom   1 / 2: push   R: restart   Space: pause   Esc: quit",
        );
    }
    text.0 = s;
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("viewer: {e}");
            std::process::exit(2);
        }
    };
    let setup = match setup_from(&args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("viewer: {e}");
            std::process::exit(1);
        }
    };
    let dt = setup.scene.dt_s;
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: "marionette: active jumping knee kick".into(),
            resolution: WindowResolution::new(960, 540),
            ..default()
        }),
        ..default()
    }))
    .add_plugins(MarionettePlugin {
        clock: Clock::physics(dt),
        ticks_per_update: 0,
    })
    .insert_resource(ClearColor(Color::srgb(0.86, 0.89, 0.93)))
    .insert_resource(setup)
    .insert_resource(Orbit {
        yaw: 0.6,
        pitch: 0.25,
        distance: 3.6,
    })
    .insert_resource(Pace {
        paused: false,
        owed_s: 0.0,
        screenshot: args.screenshot.clone().map(|(p, t)| (p, t, 0)),
    })
    .add_systems(PreUpdate, pace)
    .add_systems(
        Update,
        (keys, orbit_camera, status_text, take_screenshot).chain(),
    );
    // Bevy's own fixed loop runs `FixedMain` by virtual time; with virtual time paused only
    // the plugin's `TicksPerUpdate` advances the engine.
    app.world_mut().resource_mut::<Time<Virtual>>().pause();
    let world = app.world_mut();
    let spawned = spawn_characters(world);
    let floor_y = world
        .get::<FloorContact>(spawned[0].0)
        .map_or(0.0, |f| f.0.params.floor_height as f32);
    spawn_stage(world, floor_y);
    world.insert_resource(FloorY(floor_y));
    world.insert_resource(Characters(spawned));
    let exit = app.run();
    if exit.is_error() {
        std::process::exit(1);
    }
    if let Some((path, _)) = &args.screenshot
        && !path.exists()
    {
        eprintln!("viewer: the screenshot {} was not written", path.display());
        std::process::exit(1);
    }
}
