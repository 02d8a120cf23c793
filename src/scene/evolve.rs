//! The `EvolveFall` scene: the falling paper's GA for each age group over several seeds
//! (SPEC §3, paper §5–6, Figs. 2–7), checkpointed and resumable, with the fitness curves, the
//! head height of the best fall before and after evolution, the four falls drawn and written as
//! BVH, the best controller of each group as a file the `Fall` scene replays, and statistics
//! over seeds.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::fall::{self, Controller, write_falls};
use super::primitives::PrimitiveRender;
use super::{SceneError, page, write_output};
use crate::evolve::{Evaluator, GaConfig, JsonLines, checkpoint, logbook};
use crate::experiments::evolve_fall::{
    self, BestFall, Checkpointing, EvolutionRun, EvolveConfig, EvolveFallError, EvolveOutcome,
    FallProblem, GroupOutcome, InProcessFalls, halted,
};
use crate::experiments::fall::{FallConfig, FallResult};
use crate::humanoid::AgeGroup;
use crate::humanoid::fall21;
use crate::render::{Page, Plot, Series, plot};

/// Who evaluates the generations.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub enum EvaluatorChoice {
    /// In this process, in parallel with rayon (a World per thread, up to four falls at a time
    /// in it).
    #[default]
    InProcess,
    /// A JSON-lines worker started with this command line, e.g.
    /// `["marionette", "eval", "--stdin"]` or `["python3", "tools/ray_eval.py"]`; one worker per
    /// age group.
    Command(Vec<String>),
}

fn default_groups() -> Vec<AgeGroup> {
    vec![AgeGroup::Elderly, AgeGroup::Adult]
}
fn default_seeds() -> Vec<u64> {
    vec![1, 2, 3, 4, 5]
}
fn default_kp_scale() -> f64 {
    1.0
}
/// How the GA's falls are stepped when given outright ([`EvolveFallScene::step`]): e.g. the
/// linearised implicit step at 2 ms with the reaction's first 100 ms in four sub-steps
/// (`(integrator: LinearlyImplicitEuler, dt_s: 0.002, reaction_window_s: 0.1,
/// reaction_substeps: 4)`). The elite check steps at half of `dt_s`, the same window and
/// sub-steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaStep {
    /// The integration scheme.
    pub integrator: crate::dynamics::Integrator,
    /// The step, seconds.
    pub dt_s: f64,
    /// Seconds after the reaction starts stepped finer ([`FallConfig::reaction_window_s`];
    /// default 0: none).
    #[serde(default)]
    pub reaction_window_s: f64,
    /// Sub-steps per step in that window ([`FallConfig::reaction_substeps`]; default 1).
    #[serde(default = "one_substep")]
    pub reaction_substeps: u32,
}

fn one_substep() -> u32 {
    1
}

fn default_step() -> Option<GaStep> {
    Some(GaStep::midpoint_2ms())
}

impl GaStep {
    /// The GA's default stepping: the stiff forces linearised at the step's midpoint
    /// ([`Integrator::LinearlyImplicitMidpoint`](crate::dynamics::Integrator)),
    /// 2 ms, the reaction's first 100 ms in four sub-steps.
    pub fn midpoint_2ms() -> Self {
        Self {
            integrator: crate::dynamics::Integrator::LinearlyImplicitMidpoint,
            dt_s: 0.002,
            reaction_window_s: 0.1,
            reaction_substeps: 4,
        }
    }

    /// Puts this stepping into `fall`.
    fn apply(&self, fall: &mut FallConfig) {
        fall.integrator = self.integrator;
        fall.dt_s = self.dt_s;
        fall.reaction_window_s = self.reaction_window_s;
        fall.reaction_substeps = self.reaction_substeps;
    }

    /// Errors: a step outside (0, 10 ms], a window outside [0, 1 s], sub-steps outside 1..=64.
    fn validate(&self) -> Result<(), SceneError> {
        let checks = [
            (
                "step.dt_s",
                "(0, 0.01] seconds",
                self.dt_s,
                self.dt_s > 0.0 && self.dt_s <= 0.01,
            ),
            (
                "step.reaction_window_s",
                "[0, 1] seconds",
                self.reaction_window_s,
                (0.0..=1.0).contains(&self.reaction_window_s),
            ),
            (
                "step.reaction_substeps",
                "1..=64",
                f64::from(self.reaction_substeps),
                (1..=64).contains(&self.reaction_substeps),
            ),
        ];
        for (field, range, value, ok) in checks {
            if !ok {
                return Err(SceneError::NotInRange {
                    field,
                    range,
                    value,
                });
            }
        }
        Ok(())
    }
}

fn default_step_margin() -> f64 {
    crate::experiments::evolve_fall::STEP_MARGIN
}
fn default_every() -> u64 {
    1
}
fn default_worker_timeout() -> f64 {
    crate::evolve::evaluator::DEFAULT_BATCH_TIMEOUT_S
}

/// Evolution of the fall controller for each age group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvolveFallScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// Age groups to evolve (default both).
    #[serde(default = "default_groups")]
    pub groups: Vec<AgeGroup>,
    /// Seeds: each group is evolved once per seed (default 1–5).
    #[serde(default = "default_seeds")]
    pub seeds: Vec<u64>,
    /// GA settings (the paper: 30 chromosomes, 500 generations).
    #[serde(default)]
    pub ga: GaConfig,
    /// k_p's upper bound as a multiple of the strength bound (the gain at which a 5° error asks
    /// for the age group's maximal torque).
    #[serde(default = "default_kp_scale")]
    pub kp_max_scale: f64,
    /// With `step: None`, the GA's explicit time step as a fraction of the stability bound of
    /// the strongest genome, in (0, 1] (default [`crate::experiments::evolve_fall::STEP_MARGIN`],
    /// 0.8: 0.70 ms): larger is faster and less accurate; the elite check
    /// (`ga.elite_check_tolerance`) rejects individuals that win through the step. Ignored when
    /// `fall` is given (it keeps its own `dt_s`).
    #[serde(default = "default_step_margin")]
    pub step_margin: f64,
    /// The GA's time stepping (integrator, step, finer reaction); default
    /// [`GaStep::midpoint_2ms`]. `None`: the explicit step at `step_margin`. Ignored when
    /// `fall` is given.
    #[serde(default = "default_step")]
    pub step: Option<GaStep>,
    /// The fall every genome is tried on, per field (default: the paper's push of the age
    /// group at the GA's step, [`crate::experiments::evolve_fall::stable_step_for`]; its
    /// key pose and k_p are the genes). A fall given here takes the group's ranges and strength
    /// and keeps its own `dt_s` (0.5 ms unless set).
    #[serde(default)]
    pub fall: Option<FallConfig>,
    /// Generations between checkpoints (default 1: every generation, so a killed run loses at
    /// most the generation in flight; with K, up to the K − 1 generations since the last
    /// checkpoint as well).
    #[serde(default = "default_every")]
    pub checkpoint_every: u64,
    /// Folder of the checkpoint (default: beside the output folder, `<out>.checkpoint`; for
    /// the default output `out/<name>/`, `out/<name>.checkpoint`).
    #[serde(default)]
    pub checkpoint_dir: Option<String>,
    /// Continue from the checkpoint in this folder (`marionette run … --resume DIR`).
    #[serde(default)]
    pub resume: Option<String>,
    /// Who evaluates.
    #[serde(default)]
    pub evaluator: EvaluatorChoice,
    /// Seconds a `Command` worker may take over one batch (a generation, or a round of elite
    /// checks) before the run stops with an error naming it (default
    /// [`crate::evolve::evaluator::DEFAULT_BATCH_TIMEOUT_S`], 600; at most a week). Shapes
    /// no result, so a resume may change it.
    #[serde(default = "default_worker_timeout")]
    pub worker_timeout_s: f64,
    /// Pictures.
    #[serde(default)]
    pub render: PrimitiveRender,
}

impl EvolveFallScene {
    /// The experiment's configuration.
    pub fn config(&self) -> Result<EvolveConfig, SceneError> {
        if self.groups.is_empty() || self.seeds.is_empty() {
            return Err(SceneError::NoRuns);
        }
        // A checkpoint holds one run per group and seed (checkpoint::Consistent).
        for (name, dup) in [
            (
                "groups",
                (1..self.groups.len()).any(|k| self.groups[..k].contains(&self.groups[k])),
            ),
            (
                "seeds",
                (1..self.seeds.len()).any(|k| self.seeds[..k].contains(&self.seeds[k])),
            ),
        ] {
            if dup {
                return Err(SceneError::Repeated {
                    field: name,
                    groups: self.groups.clone(),
                    seeds: self.seeds.clone(),
                });
            }
        }
        if !(self.kp_max_scale.is_finite() && self.kp_max_scale > 0.0 && self.kp_max_scale <= 100.0)
        {
            return Err(SceneError::NotInRange {
                field: "kp_max_scale",
                range: "(0, 100]",
                value: self.kp_max_scale,
            });
        }
        if !(self.worker_timeout_s.is_finite()
            && self.worker_timeout_s > 0.0
            && self.worker_timeout_s <= 7.0 * 86_400.0)
        {
            return Err(SceneError::NotInRange {
                field: "worker_timeout_s",
                range: "(0, 604800] seconds",
                value: self.worker_timeout_s,
            });
        }
        if !(self.step_margin.is_finite() && self.step_margin > 0.0 && self.step_margin <= 1.0) {
            return Err(SceneError::NotInRange {
                field: "step_margin",
                range: "(0, 1]",
                value: self.step_margin,
            });
        }
        self.ga.validate()?;
        if let Some(step) = &self.step {
            step.validate()?;
        }
        let falls = self.groups.len() as u64
            * self.seeds.len() as u64
            * self.ga.population as u64
            * (self.ga.generations + 1);
        if falls > 100_000_000 {
            return Err(SceneError::TooManyFalls(falls));
        }
        let problems = self
            .groups
            .iter()
            .map(|&g| {
                // The step is derived from the strongest genome of the scaled k_p box.
                let mut p = FallProblem::with_strength(g, self.kp_max_scale, self.step_margin);
                if let Some(step) = &self.step {
                    step.apply(&mut p.fall);
                }
                if let Some(f) = &self.fall {
                    p.fall = f.clone();
                    p.fall.ranges = crate::experiments::fall::Ranges::Builtin(g);
                    p.fall.torque_limits_nm = Some(crate::humanoid::strength::torque_limits(g));
                    p.fall.stop_at_rest = true;
                }
                p.bounds()?;
                Ok(p)
            })
            .collect::<Result<Vec<_>, SceneError>>()?;
        Ok(EvolveConfig {
            problems,
            seeds: self.seeds.clone(),
            ga: self.ga.clone(),
        })
    }

    fn evaluators(&self, config: &EvolveConfig) -> Result<Vec<Box<dyn Evaluator>>, SceneError> {
        config
            .problems
            .iter()
            .map(|p| -> Result<Box<dyn Evaluator>, SceneError> {
                match &self.evaluator {
                    EvaluatorChoice::InProcess => Ok(Box::new(InProcessFalls::new(p.clone()))),
                    EvaluatorChoice::Command(argv) => {
                        let (prog, args) = argv.split_first().ok_or(SceneError::NoProgram)?;
                        let mut c = Command::new(prog);
                        c.args(args);
                        Ok(Box::new(JsonLines::start(c, p)?.with_timeout(
                            std::time::Duration::from_secs_f64(self.worker_timeout_s),
                        )))
                    }
                }
            })
            .collect()
    }
}

/// Progress on standard error: one updating line on a terminal, plain lines otherwise.
struct Progress {
    started: Instant,
    total: u64,
    terminal: bool,
    last_plain: u64,
}

impl Progress {
    fn show(&mut self, runs: &[EvolutionRun]) {
        let g = runs.iter().map(|r| r.state.generation).min().unwrap_or(0);
        let best = runs
            .iter()
            .filter_map(|r| r.state.best.as_ref().map(|b| b.1))
            .fold(f64::INFINITY, f64::min);
        let done = g.max(1) as f64;
        let eta = self.started.elapsed().as_secs_f64() / done * (self.total as f64 - done);
        let text = format!(
            "generation {g}/{} · best damage {best:.0} N · ETA {:.0} s",
            self.total,
            eta.max(0.0)
        );
        if self.terminal {
            eprint!("\r{text}   ");
            if g >= self.total {
                eprintln!();
            }
        } else if g >= self.last_plain + (self.total / 20).max(1) || g >= self.total {
            self.last_plain = g;
            eprintln!("{text}");
        }
    }
}

/// The best controller of a run as a `Fall` scene's `controller` block (degrees, N·m/rad),
/// for its `controller_file`.
fn controller_ron(problem: &FallProblem, genes: &[f64]) -> Result<String, SceneError> {
    let names = fall21().dof_names();
    let n = names.len();
    let controller = Controller {
        key_pose_deg: names
            .iter()
            .zip(&genes[..n])
            .map(|(d, x)| (d.clone(), x.to_degrees()))
            .collect(),
        kp: names
            .iter()
            .cloned()
            .zip(genes[n..].iter().copied())
            .collect(),
        kv: Default::default(),
        start_s: Some(problem.fall.control_start_s),
        dt_s: Some(problem.fall.dt_s),
        contact_implicit_damping: Some(problem.fall.contact.implicit_damping),
        integrator: (problem.fall.integrator != FallConfig::paper(problem.age_group).integrator)
            .then_some(problem.fall.integrator),
        reaction_window_s: (problem.fall.reaction_window_s > 0.0)
            .then_some(problem.fall.reaction_window_s),
        reaction_substeps: (problem.fall.reaction_substeps > 1)
            .then_some(problem.fall.reaction_substeps),
        evolved_for: Some(problem.age_group),
    };
    let text = ron::ser::to_string_pretty(&controller, ron::ser::PrettyConfig::default())
        .map_err(SceneError::ControllerFile)?;
    Ok(format!(
        "// The evolved key pose and stiffness, for a Fall scene's controller_file. Evolved at \
         dt = {dt} s (dt_s), the step a Fall scene replays it at, with the floor's damping \
         taken {mode} (contact_implicit_damping), for the {group} figure (evolved_for: a Fall \
         scene of that age_group replays its evolved damage).\n{text}\n",
        group = problem.age_group.name(),
        dt = problem.fall.dt_s,
        mode = if problem.fall.contact.implicit_damping {
            "implicitly"
        } else {
            "explicitly"
        }
    ))
}

/// The default checkpoint folder of a run into `out_dir`: beside it, `<out_dir>.checkpoint`
/// (`out/<name>.checkpoint` if `out_dir` has no folder name of its own, e.g. `.`).
pub fn default_checkpoint_dir(scene: &EvolveFallScene, out_dir: &Path) -> PathBuf {
    match out_dir.file_name() {
        Some(name) => {
            let mut name = name.to_os_string();
            name.push(".checkpoint");
            out_dir.with_file_name(name)
        }
        None => PathBuf::from(format!("out/{}.checkpoint", scene.name)),
    }
}

/// `Ok` if the checkpoint's `runs` continue the experiment `config` asks for: the same age
/// groups and seeds in the same order, the same problem for each group and every GA setting
/// the same but `generations`, which may grow (not below the generation the checkpoint is at);
/// else which setting differs and how.
fn resumable(runs: &[EvolutionRun], config: &EvolveConfig) -> Result<(), ResumeMismatch> {
    let distinct = |items: Vec<serde_json::Value>| {
        let mut out: Vec<serde_json::Value> = Vec::new();
        for i in items {
            if !out.contains(&i) {
                out.push(i);
            }
        }
        serde_json::Value::Array(out)
    };
    let had_groups = distinct(runs.iter().map(|r| to_json(&r.problem.age_group)).collect());
    let groups = distinct(
        config
            .problems
            .iter()
            .map(|p| to_json(&p.age_group))
            .collect(),
    );
    let had_seeds = distinct(runs.iter().map(|r| to_json(&r.state.config.seed)).collect());
    let seeds = to_json(&config.seeds);
    for (name, had, asked) in [("groups", had_groups, groups), ("seeds", had_seeds, seeds)] {
        if had != asked {
            return Err(SettingMismatch::new(name, &had, &asked).into());
        }
    }
    let wanted: Vec<String> = config
        .problems
        .iter()
        .flat_map(|p| {
            config
                .seeds
                .iter()
                .map(move |s| format!("{} seed {s}", p.age_group.name()))
        })
        .collect();
    let held: Vec<String> = runs.iter().map(EvolutionRun::name).collect();
    if held != wanted {
        return Err(SettingMismatch::new(
            "runs",
            format!("[{}]", held.join(", ")),
            format!("[{}]", wanted.join(", ")),
        )
        .into());
    }
    for r in runs {
        let Some(p) = config
            .problems
            .iter()
            .find(|p| p.age_group == r.problem.age_group)
        else {
            continue;
        };
        same_settings(r, p, config)?;
    }
    Ok(())
}

/// Errors unless run `r` of the checkpoint has the scene's problem `p` and GA settings (its
/// seed and generations aside), and has not gone past the scene's generations: the first few
/// differences.
fn same_settings(
    r: &EvolutionRun,
    p: &FallProblem,
    config: &EvolveConfig,
) -> Result<(), ResumeMismatch> {
    let mut diff = Vec::new();
    differences(
        &format!("{}, problem", r.name()),
        &to_json(&r.problem),
        &to_json(p),
        &mut diff,
    );
    let ga = GaConfig {
        seed: r.state.config.seed,
        generations: r.state.config.generations,
        ..config.ga.clone()
    };
    differences("ga", &to_json(&r.state.config), &to_json(&ga), &mut diff);
    if !diff.is_empty() {
        let more = diff.len().saturating_sub(3);
        diff.truncate(3);
        return Err(ResumeMismatch::Settings { differ: diff, more });
    }
    if r.state.generation > config.ga.generations {
        return Err(ResumeMismatch::PastGenerations {
            at: r.state.generation,
            asked: config.ga.generations,
        });
    }
    Ok(())
}

/// `v` as a JSON value (`null` if it cannot be one).
fn to_json<T: Serialize + ?Sized>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// Each leaf where `had` (the checkpoint's) and `asked` (the scene's) differ.
fn differences(
    path: &str,
    had: &serde_json::Value,
    asked: &serde_json::Value,
    out: &mut Vec<SettingMismatch>,
) {
    use serde_json::Value;
    match (had, asked) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, va) in a {
                differences(
                    &format!("{path}.{k}"),
                    va,
                    b.get(k).unwrap_or(&Value::Null),
                    out,
                );
            }
            for (k, vb) in b.iter().filter(|(k, _)| !a.contains_key(*k)) {
                differences(&format!("{path}.{k}"), &Value::Null, vb, out);
            }
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            for (k, (va, vb)) in a.iter().zip(b).enumerate() {
                differences(&format!("{path}[{k}]"), va, vb, out);
            }
        }
        _ if had != asked => {
            out.push(SettingMismatch::new(path, had, asked));
        }
        _ => {}
    }
}

/// How a checkpoint to resume differs from the runs the scene asks for.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ResumeMismatch {
    /// Settings that differ: the first three, and how many more.
    #[error(
        "{}{}",
        .differ.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "),
        if *.more > 0 { format!("; and {} more", .more) } else { String::new() }
    )]
    Settings {
        /// The first settings that differ.
        differ: Vec<SettingMismatch>,
        /// How many more differ.
        more: usize,
    },
    /// The checkpoint is already past the generations the scene asks for.
    #[error(
        "ga.generations: the checkpoint is already at generation {at}, the scene asks {asked} \
         (ga.generations may grow, not fall below the checkpoint's generation)"
    )]
    PastGenerations {
        /// The checkpoint's generation.
        at: u64,
        /// The scene's `ga.generations`.
        asked: u64,
    },
}

/// A setting whose value in the checkpoint is not the scene's.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{setting}: the checkpoint has {checkpoint}, the scene asks {asked}")]
pub struct SettingMismatch {
    /// The setting, e.g. `seeds` or `ga.population`.
    pub setting: String,
    /// Its value in the checkpoint.
    pub checkpoint: String,
    /// The scene's value.
    pub asked: String,
}

impl SettingMismatch {
    /// `setting` differs: `checkpoint` in the checkpoint, `asked` in the scene.
    fn new(setting: &str, checkpoint: impl ToString, asked: impl ToString) -> Self {
        Self {
            setting: setting.to_string(),
            checkpoint: checkpoint.to_string(),
            asked: asked.to_string(),
        }
    }
}

impl From<SettingMismatch> for ResumeMismatch {
    fn from(m: SettingMismatch) -> Self {
        Self::Settings {
            differ: vec![m],
            more: 0,
        }
    }
}

/// Runs an [`EvolveFallScene`] whose outputs are written into `out` (the staging folder of the
/// output folder `out_dir`, [`super::run`]); returns the report.
pub fn run_evolve(
    scene: &EvolveFallScene,
    _base: &Path,
    out: &Path,
    out_dir: &Path,
) -> Result<serde_json::Value, SceneError> {
    let config = scene.config()?;
    let mut evaluators = scene.evaluators(&config)?;
    let ck_dir = match scene.resume.as_ref().or(scene.checkpoint_dir.as_ref()) {
        Some(dir) => PathBuf::from(dir),
        None => default_checkpoint_dir(scene, out_dir),
    };
    let resumed: Option<Vec<EvolutionRun>> = match &scene.resume {
        Some(_) => {
            let mut runs: Vec<EvolutionRun> = checkpoint::load(&ck_dir)?;
            halted(&runs)?;
            resumable(&runs, &config).map_err(|why| SceneError::ResumeSettings {
                dir: ck_dir.clone(),
                why,
            })?;
            for r in &mut runs {
                r.state.config.generations = config.ga.generations;
            }
            Some(runs)
        }
        None => None,
    };
    let ck = Checkpointing {
        dir: ck_dir.clone(),
        every: scene.checkpoint_every.max(1),
    };
    let mut progress = Progress {
        started: Instant::now(),
        total: config.ga.generations,
        terminal: std::io::stderr().is_terminal(),
        last_plain: 0,
    };
    let outcome = evolve_fall::run(&config, resumed, &mut evaluators, Some(&ck), |r| {
        progress.show(r)
    })
    .map_err(|e| match e {
        EvolveFallError::Fall(e) => SceneError::from(e),
        EvolveFallError::Evolve(e) => SceneError::from(e),
        e => SceneError::from(e),
    })?;
    let mut page = write_evolution(scene, &outcome, out)?;
    page.headline = headline(&config, &outcome);
    page::write(&page, out)?;
    Ok(report(&config, &outcome, &ck_dir))
}

/// The evolution's headline figures in words, for the results page.
fn headline(config: &EvolveConfig, outcome: &EvolveOutcome) -> Vec<String> {
    let mut lines = vec![format!(
        "{} generations of {} controllers: {} evaluations in {:.0} s.",
        config.ga.generations,
        config.ga.population,
        outcome.evaluations(),
        outcome.ga_wall_time_s
    )];
    for g in &outcome.groups {
        lines.push(format!(
            "{}: best damage {:.0} ± {:.0} N at generation 0, {:.0} ± {:.0} N after evolution \
             (mean ± sd over {} seed{}).",
            g.age_group.name(),
            g.initial.mean,
            g.initial.std,
            g.final_.mean,
            g.final_.std,
            g.seeds.len(),
            if g.seeds.len() == 1 { "" } else { "s" }
        ));
    }
    for f in outcome.best_falls() {
        lines.push(fall::fall_headline(
            &format!("best fall, {}", f.label),
            &fall::fall_report(&f.result, 0.0),
        ));
    }
    lines
}

/// Writes the outcome's files into `out`: the logbooks, the fitness curves (Fig. 2), the best
/// controller of each group, the best falls (BVH, filmstrip, GIF) and their head height
/// (Fig. 3); returns the results page of them (without its headline).
fn write_evolution(
    scene: &EvolveFallScene,
    outcome: &EvolveOutcome,
    out: &Path,
) -> Result<Page, SceneError> {
    write_logbooks(outcome, out)?;
    let fitness = fitness_plot(scene, outcome);
    plot(&fitness, &out.join("fitness.png"))?;
    for b in &outcome.best {
        let best = &outcome.runs[b.run];
        if let Some((genes, _)) = &best.state.best {
            write_output(
                &out.join(format!("best_{}.controller.ron", b.age_group.name())),
                controller_ron(&best.problem, genes)?.as_bytes(),
            )?;
        }
    }
    let named: Vec<(String, String, &FallResult)> = outcome
        .best_falls()
        .map(|f| {
            let file = format!("fall_{}", f.label.replace(' ', "_"));
            let label = format!("{} (damage {:.0} N)", f.label, f.result.damage);
            (file, label, &f.result)
        })
        .collect();
    let motions = write_falls(&named, &scene.render, out)?;
    let head = Plot {
        title: format!(
            "Head height, best fall before and after evolution: {}",
            scene.name
        ),
        x_label: "time (s)".into(),
        y_label: "head height (m)".into(),
        series: outcome
            .best_falls()
            .map(|f| fall::head_height_series(f.label.clone(), &f.result))
            .collect(),
        markers: vec![],
    };
    plot(&head, &out.join("head_height.png"))?;
    Ok(Page {
        title: format!("{}: evolved falls", scene.name),
        motions,
        plots: vec![page::timed(head), page::untimed(fitness)],
        ..Page::default()
    })
}

/// Writes each run's logbook as `logbook_<group>_seed<seed>.csv` and `.jsonl`.
fn write_logbooks(outcome: &EvolveOutcome, out: &Path) -> Result<(), SceneError> {
    for r in &outcome.runs {
        let stem = format!(
            "logbook_{}_seed{}",
            r.problem.age_group.name(),
            r.state.config.seed
        );
        write_output(
            &out.join(format!("{stem}.csv")),
            logbook::to_csv(&r.state.logbook).as_bytes(),
        )?;
        write_output(
            &out.join(format!("{stem}.jsonl")),
            logbook::to_json_lines(&r.state.logbook).as_bytes(),
        )?;
    }
    Ok(())
}

/// The best damage so far per generation of each age group, the mean over its seeds.
fn fitness_plot(scene: &EvolveFallScene, outcome: &EvolveOutcome) -> Plot {
    let series = outcome
        .groups
        .iter()
        .map(|g| {
            let (seeds, curve) = outcome.mean_best_so_far(g.age_group);
            Series {
                name: format!("{}: mean of {seeds} seeds", g.age_group.name()),
                points: curve
                    .into_iter()
                    .enumerate()
                    .map(|(k, m)| (k as f64, m))
                    .collect(),
            }
        })
        .collect();
    Plot {
        title: format!("Best damage so far: {}", scene.name),
        x_label: "generation".into(),
        y_label: "damage D (N)".into(),
        series,
        markers: vec![],
    }
}

/// The report of one best fall: the figures an evolved fall must not win by an artefact (peak
/// penetration and its link, worst range excursion and its DOF, each DOF's peak PD torque
/// against its strength limit, the DOFs whose limit bound and for how long, the pelvis impact,
/// and the damage re-simulated at half the step).
fn honesty_json(f: &BestFall) -> serde_json::Value {
    let (r, h) = (&f.result, &f.honesty);
    json!({
        "dt_s": r.dt_s,
        "damage": r.damage,
        "max_penetration_m": r.max_penetration_m,
        "max_penetration_link": h.max_penetration_link,
        "worst_range_excursion_deg": h.worst_range_excursion_rad.to_degrees(),
        "worst_range_excursion_dof": h.worst_range_excursion_dof,
        "peak_torques": r.peak_torques,
        "damage_at_half_step": h.damage_at_half_step,
        "half_step_relative_change": h.half_step_relative_change,
        "half_step_within_10_percent": h.half_step_within_10_percent,
        "came_to_rest": r.came_to_rest,
        "torque_saturation": r.torque_saturation,
        "pelvis": r.pelvis,
    })
}

/// The scene's report of `outcome`: counts, statistics per group, the best falls' honesty
/// figures and the comparison of two groups.
fn report(config: &EvolveConfig, outcome: &EvolveOutcome, ck_dir: &Path) -> serde_json::Value {
    let group_json = |g: &GroupOutcome| {
        json!({
            "age_group": g.age_group,
            "seeds": g.seeds,
            "initial_best_damage": g.initial_best,
            "final_best_damage": g.final_best,
            "initial": g.initial,
            "final": g.final_,
        })
    };
    let mut report = json!({
        "generations": config.ga.generations,
        "population": config.ga.population,
        "evaluations": outcome.evaluations(),
        "inherited_fitness": outcome.inherited_fitness(),
        "failed_evaluations": outcome.failed_evaluations(),
        "elite_check": {
            "tolerance": config.ga.elite_check_tolerance,
            "evaluations_at_half_step": outcome.check_evaluations(),
            "rejected": outcome.rejected_elites(),
        },
        "groups": outcome.groups.iter().map(group_json).collect::<Vec<_>>(),
        "ga_wall_time_s": outcome.ga_wall_time_s,
        "checkpoint": ck_dir.display().to_string(),
        "best_falls": outcome.best_falls().map(|f| json!({"fall": f.label, "honesty": honesty_json(f)})).collect::<Vec<_>>(),
    });
    if let Some(c) = &outcome.comparison {
        report["comparison"] = json!({
            "groups": c.groups,
            "initial_gap": c.initial_gap,
            "initial_seed_spread": c.initial_seed_spread,
            "initial_within_seed_spread": c.initial_within_seed_spread,
            "final_gap": c.final_gap,
            "final_seed_spread": c.final_seed_spread,
            "final_gap_exceeds_seed_spread": c.final_gap_exceeds_seed_spread,
        });
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::evolve_fall::{STEP_MARGIN, stable_step_for, strength_kp_max};

    fn scene(step_margin: f64, kp_max_scale: f64) -> EvolveFallScene {
        EvolveFallScene {
            format_version: 1,
            name: "t".into(),
            groups: vec![AgeGroup::Adult],
            seeds: vec![1],
            ga: GaConfig::default(),
            kp_max_scale,
            step_margin,
            step: None,
            fall: None,
            checkpoint_every: 10,
            checkpoint_dir: None,
            resume: None,
            evaluator: EvaluatorChoice::InProcess,
            worker_timeout_s: default_worker_timeout(),
            render: PrimitiveRender::default(),
        }
    }

    #[test]
    fn the_checkpoint_sits_beside_the_output_folder() {
        let s = scene(STEP_MARGIN, 1.0);
        let ck = |out: &str| default_checkpoint_dir(&s, Path::new(out));
        assert_eq!(ck("out/t"), PathBuf::from("out/t.checkpoint"));
        assert_eq!(ck("out/t/"), PathBuf::from("out/t.checkpoint"));
        assert_eq!(ck("/tmp/quick"), PathBuf::from("/tmp/quick.checkpoint"));
        assert_eq!(ck("."), PathBuf::from("out/t.checkpoint"));
    }

    #[test]
    fn a_seed_or_group_given_twice_is_refused_before_any_work() {
        let mut s = scene(STEP_MARGIN, 1.0);
        s.seeds = vec![1, 1];
        let err = s.config().unwrap_err().to_string();
        assert!(
            err.contains("seeds must not repeat") && err.contains("[1, 1]"),
            "{err}"
        );
        let mut s = scene(STEP_MARGIN, 1.0);
        s.groups = vec![AgeGroup::Adult, AgeGroup::Adult];
        assert!(
            s.config()
                .unwrap_err()
                .to_string()
                .contains("groups must not repeat")
        );
    }

    #[test]
    fn the_step_follows_the_margin_and_the_strength_bound() {
        let paper = FallProblem::paper(AgeGroup::Adult);
        let default = scene(STEP_MARGIN, 1.0).config().unwrap();
        assert_eq!(default.problems[0].fall.dt_s, paper.fall.dt_s);
        // A smaller margin gives a smaller step, as `stable_step_for` derives it.
        let half = scene(STEP_MARGIN / 2.0, 1.0).config().unwrap();
        let expected = stable_step_for(&paper.fall, &paper.kp_max, STEP_MARGIN / 2.0).unwrap();
        assert_eq!(half.problems[0].fall.dt_s, expected);
        assert!(expected < paper.fall.dt_s);
        // Stronger genomes are stiffer: the step is re-derived from the scaled k_p bound. Up to
        // about 16× the strength bound the floor contact bounds the step; at 64× the gains do.
        let strong = scene(STEP_MARGIN, 64.0).config().unwrap();
        let p = &strong.problems[0];
        assert_eq!(p.kp_max, strength_kp_max(AgeGroup::Adult, 64.0));
        assert_eq!(
            p.fall.dt_s,
            stable_step_for(&paper.fall, &p.kp_max, STEP_MARGIN).unwrap()
        );
        assert!(p.fall.dt_s < paper.fall.dt_s);
        for bad in [0.0, -0.5, 1.5, f64::NAN] {
            let e = scene(bad, 1.0).config().unwrap_err().to_string();
            assert!(e.contains("step_margin must be in (0, 1]"), "{e}");
        }
    }

    #[test]
    fn a_scene_without_a_step_takes_the_midpoint_at_2_ms_and_none_the_margin() {
        use crate::dynamics::Integrator;
        let parse = |extra: &str| {
            let text = format!(
                "EvolveFall(format_version: 1, name: \"t\", groups: [adult], seeds: [1]{extra})"
            );
            match crate::scene::Scene::parse(&text, "test").unwrap() {
                crate::scene::Scene::EvolveFall(s) => s.config().unwrap().problems[0].fall.clone(),
                other => panic!("{other:?}"),
            }
        };
        let f = parse("");
        assert_eq!(
            (
                f.integrator,
                f.dt_s,
                f.reaction_window_s,
                f.reaction_substeps
            ),
            (Integrator::LinearlyImplicitMidpoint, 0.002, 0.1, 4)
        );
        let f = parse(", step: None");
        assert_eq!(f.dt_s, FallProblem::paper(AgeGroup::Adult).fall.dt_s);
        assert!(matches!(f.integrator, Integrator::SemiImplicitEuler { .. }));
    }

    #[test]
    fn a_step_given_outright_replaces_the_margin_and_a_bad_one_is_refused() {
        use crate::dynamics::Integrator;
        let step = GaStep {
            integrator: Integrator::LinearlyImplicitEuler,
            dt_s: 0.002,
            reaction_window_s: 0.1,
            reaction_substeps: 4,
        };
        let mut s = scene(STEP_MARGIN, 1.0);
        s.step = Some(step.clone());
        let c = s.config().unwrap();
        let f = &c.problems[0].fall;
        assert_eq!(
            (
                f.integrator,
                f.dt_s,
                f.reaction_window_s,
                f.reaction_substeps
            ),
            (Integrator::LinearlyImplicitEuler, 0.002, 0.1, 4)
        );
        // Everything else is the paper's problem.
        let paper = FallProblem::paper(AgeGroup::Adult);
        assert_eq!(f.push, paper.fall.push);
        assert_eq!(c.problems[0].kp_max, paper.kp_max);
        // The controller file carries the stepping, so a Fall scene replays it so; the
        // paper's stepping writes nothing new.
        let genes = vec![0.0; 2 * fall21().dof_names().len()];
        let text = controller_ron(&c.problems[0], &genes).unwrap();
        for field in [
            "integrator: Some(LinearlyImplicitEuler)",
            "reaction_window_s: Some(0.1)",
            "reaction_substeps: Some(4)",
        ] {
            assert!(text.contains(field), "{field} in {text}");
        }
        let plain = controller_ron(&paper, &genes).unwrap();
        assert!(
            !plain.contains("integrator") && !plain.contains("reaction_"),
            "{plain}"
        );
        for (bad, field) in [
            (
                GaStep {
                    dt_s: 0.0,
                    ..step.clone()
                },
                "step.dt_s",
            ),
            (
                GaStep {
                    dt_s: f64::NAN,
                    ..step.clone()
                },
                "step.dt_s",
            ),
            (
                GaStep {
                    reaction_window_s: -0.1,
                    ..step.clone()
                },
                "step.reaction_window_s",
            ),
            (
                GaStep {
                    reaction_substeps: 0,
                    ..step.clone()
                },
                "step.reaction_substeps",
            ),
        ] {
            s.step = Some(bad);
            let e = s.config().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
