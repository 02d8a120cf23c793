//! Who computes the fitness of a generation: the [`Evaluator`] trait, the in-process rayon
//! backend ([`InProcess`]) and the JSON-lines worker protocol ([`JsonLines`] drives a worker
//! process; [`serve`] is the worker side, `marionette eval --stdin`), through which a Ray
//! cluster (`tools/ray_eval.py`) evaluates generations while the GA loop, its checkpoints and
//! its bits stay in the engine.
//!
//! The protocol, one JSON object per line, each message after the header tagged by its one key:
//! 1. client → worker, once: `{"protocol": "marionette-eval/3", "problem": {…}}` (the problem,
//!    any serialisable problem, e.g. the falling paper's `FallProblem`);
//! 2. per batch, client → worker: `{"genome": {"index": i, "genes": [x, …], "refine": k}}` for
//!    each genome (`refine` as in [`Evaluator::evaluate`]; absent means 1), then
//!    `{"evaluate": {"count": n}}`, `n` the number of genomes sent;
//! 3. worker → client: `{"damage": {"index": i, "value": d}}` or
//!    `{"error": {"index": i, "message": "why"}}` for each, then `{"done": {"count": n}}`.
//!
//! Both sides refuse what they do not understand: an unknown message or field, a wrong type, a
//! line with two messages, counts that disagree; the error names the line, the column and the
//! field. Numbers travel as shortest round-trip decimals, so genes and damages cross bit for bit.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStderr, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use super::error::EvolveError;
use super::error::{EvaluatorError, LastWords, LineError, WorkerFailure, WorkerFault};
use super::failure::EvaluationError;
pub use super::formats::{MAX_LINE, MAX_REFINE, PROTOCOL};
use super::genome::Genome;

/// The result of one evaluation: the damage (lower is fitter) or why it failed.
pub type Evaluation = Result<f64, EvaluationError>;

/// Computes the fitness of a generation's genomes, in order.
pub trait Evaluator {
    /// The damage of each genome of `generation` (same order and length as `genomes`), the
    /// problem resolved `refine` times finer than its own resolution (1: as posed; for a fall,
    /// the time step divided by `refine`). The GA re-evaluates its elites at `refine = 2` to
    /// check that their fitness is not an artefact of the resolution.
    fn evaluate(
        &mut self,
        generation: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError>;

    /// The elite checks of `generation`: [`Self::evaluate`] of `checks` at `refine`. Meanwhile
    /// an evaluator may start on `ahead()`, the children the next generation evaluates (at
    /// refinement 1) if the checks change nothing (bred only when called), which `wanted`
    /// tells from the checks' evaluations; it then answers that next [`Self::evaluate`] from
    /// what it found, if the genomes asked for are those bit for bit. Only an evaluator whose
    /// results depend on nothing but the genome and the refinement (as a fall's do) may look
    /// ahead: it changes when results are computed, never what they are. The default
    /// evaluates the checks only (and breeds nothing).
    fn evaluate_checks(
        &mut self,
        generation: u64,
        checks: &[Genome],
        refine: u32,
        ahead: &dyn Fn() -> Vec<Genome>,
        wanted: &(dyn Fn(&[Evaluation]) -> bool + Sync),
    ) -> Result<Vec<Evaluation>, EvolveError> {
        let _ = (ahead, wanted);
        self.evaluate(generation, checks, refine)
    }
}

/// Evaluates in this process, in parallel on the current rayon pool.
pub struct InProcess<F: Fn(&[Genome], u32) -> Vec<Evaluation>> {
    /// Evaluates a batch at a refinement (for falls: in parallel Worlds, each fall to the bits it has alone, at the
    /// time step divided by the refinement).
    pub batch: F,
}

impl<F: Fn(&[Genome], u32) -> Vec<Evaluation>> Evaluator for InProcess<F> {
    fn evaluate(
        &mut self,
        _: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        Ok((self.batch)(genomes, refine))
    }
}

/// Evaluates a batch one genome at a time in parallel with `f`.
pub fn par_map(genomes: &[Genome], f: impl Fn(&[f64]) -> Evaluation + Sync) -> Vec<Evaluation> {
    genomes.par_iter().map(|g| f(g)).collect()
}

/// The first line, client → worker: the protocol and the problem.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    protocol: String,
    problem: serde_json::Value,
}

/// A genome to evaluate (`{"genome": {…}}`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct GenomeLine {
    index: usize,
    genes: Vec<f64>,
    #[serde(default = "unrefined", skip_serializing_if = "is_unrefined")]
    refine: u32,
}

/// The end of a batch (`{"evaluate": {"count": n}}`) or of its replies (`{"done": {…}}`):
/// how many genomes it held.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BatchEnd {
    count: usize,
}

/// A line client → worker after the header, tagged by its one key.
#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Request {
    Genome(GenomeLine),
    Evaluate(BatchEnd),
}

fn unrefined() -> u32 {
    1
}

fn is_unrefined(k: &u32) -> bool {
    *k == 1
}

/// A genome's damage (`{"damage": {…}}`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DamageLine {
    index: usize,
    value: f64,
}

/// Why a genome could not be evaluated (`{"error": {…}}`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ErrorLine {
    index: usize,
    message: String,
}

/// A line worker → client, tagged by its one key.
#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Reply {
    Damage(DamageLine),
    Error(ErrorLine),
    Done(BatchEnd),
}

/// Parses `text`, line `line` of a protocol stream (`side`: "request", "reply"), as `T`: an
/// error names the line, the column, the field and what was expected.
fn parse_line<T: serde::de::DeserializeOwned>(
    text: &str,
    side: &'static str,
    line: usize,
) -> Result<T, LineError> {
    let located = |path: &str, e: &serde_json::Error| {
        let message = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        LineError {
            side,
            line,
            column: e.column(),
            field: match path {
                "" | "." => None,
                p => Some(p.to_string()),
            },
            expected: message
                .strip_suffix(&suffix)
                .unwrap_or(&message)
                .to_string(),
            text: shorten(text),
        }
    };
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        located(&path, e.inner())
    })?;
    de.end().map_err(|e| located("", &e))?;
    Ok(value)
}

/// A request line the worker does not understand.
fn bad_request(e: LineError) -> EvaluatorError {
    EvaluatorError::BadRequest(Box::new(e))
}

/// `text` cut to 120 characters, for messages.
fn shorten(text: &str) -> String {
    let text = text.trim();
    match text.char_indices().nth(120) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

/// Default batch timeout of a [`JsonLines`] worker, seconds (a generation of the paper's
/// falls takes seconds to a few minutes).
pub const DEFAULT_BATCH_TIMEOUT_S: f64 = 600.0;

/// Longest wait between two progress lines while a worker is silent.
const PROGRESS_EVERY: Duration = Duration::from_secs(10);

/// Drives a worker process over the JSON-lines protocol. A batch that the worker does not
/// answer in full within the timeout ([`Self::with_timeout`], default
/// [`DEFAULT_BATCH_TIMEOUT_S`]) stops the worker and fails, naming the worker and what it last
/// said; while waiting, a progress line goes to standard error every few seconds. The worker's
/// standard error is passed through to this process's.
pub struct JsonLines {
    child: Child,
    name: String,
    to_worker: Option<mpsc::Sender<Vec<u8>>>,
    from_worker: mpsc::Receiver<Option<String>>,
    last: Arc<Mutex<LastWords>>,
    timeout: Duration,
    lines_read: usize,
    broken: Option<Box<WorkerFailure>>,
}

impl JsonLines {
    /// Starts `command` (e.g. `marionette eval --stdin`, or `python3 tools/ray_eval.py`) and
    /// sends it `problem`.
    pub fn start(mut command: Command, problem: &impl Serialize) -> Result<Self, EvolveError> {
        let name = std::iter::once(command.get_program())
            .chain(command.get_args())
            .map(|a| a.to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(" ");
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| EvaluatorError::Start {
                worker: name.clone(),
                source,
            })?;
        let (stdin, stdout, stderr) =
            match (child.stdin.take(), child.stdout.take(), child.stderr.take()) {
                (Some(i), Some(o), Some(e)) => (i, o, e),
                _ => return Err(EvaluatorError::NoPipes { worker: name }.into()),
            };
        let last = Arc::new(Mutex::new(LastWords::default()));
        let to_worker = spawn_writer(stdin, noter(&last));
        let from_worker = spawn_reader(stdout, noter(&last));
        spawn_stderr_echo(stderr, noter(&last));
        let mut me = Self {
            child,
            name,
            to_worker: Some(to_worker),
            from_worker,
            last,
            timeout: Duration::from_secs_f64(DEFAULT_BATCH_TIMEOUT_S),
            lines_read: 0,
            broken: None,
        };
        let header = Header {
            protocol: PROTOCOL.into(),
            problem: serde_json::to_value(problem).map_err(EvaluatorError::Encode)?,
        };
        let mut line = serde_json::to_string(&header).map_err(EvaluatorError::Encode)?;
        line.push('\n');
        me.send(line);
        Ok(me)
    }

    /// The same worker, a batch that it has not answered in full after `timeout` failing.
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// Hands `text` to the writing thread (a write that fails is found by the reply that then
    /// never comes, and named by [`LastWords`]).
    fn send(&mut self, text: String) {
        if let Some(t) = &self.to_worker {
            let _ = t.send(text.into_bytes());
        }
    }

    /// Stops the worker after `fault` and remembers that it failed.
    fn fail(&mut self, fault: WorkerFault) -> EvolveError {
        let _ = self.child.kill();
        // The threads see the pipes close; give the last words a moment to arrive.
        std::thread::sleep(Duration::from_millis(50));
        let said = self.last.lock().unwrap_or_else(|e| e.into_inner()).clone();
        let failure = WorkerFailure {
            worker: self.name.clone(),
            fault,
            said,
        };
        self.broken = Some(Box::new(failure.clone()));
        EvaluatorError::Worker(Box::new(failure)).into()
    }

    /// The worker's exit status once it has ended (waiting up to a second); `None` if it is
    /// still running.
    fn exit_status(&mut self) -> Option<std::process::ExitStatus> {
        for _ in 0..20 {
            if let Ok(Some(s)) = self.child.try_wait() {
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        None
    }
}

/// A handle through which a pipe's thread notes in `last` what the worker said.
fn noter(last: &Arc<Mutex<LastWords>>) -> impl Fn(&dyn Fn(&mut LastWords)) + Send + 'static {
    let l = last.clone();
    move |f: &dyn Fn(&mut LastWords)| f(&mut l.lock().unwrap_or_else(|e| e.into_inner()))
}

/// Writes to the worker's input on a thread of its own: a worker that stops reading blocks
/// it, not the GA. A write that fails is noted and ends the thread.
fn spawn_writer(
    mut stdin: ChildStdin,
    note: impl Fn(&dyn Fn(&mut LastWords)) + Send + 'static,
) -> mpsc::Sender<Vec<u8>> {
    let (to_worker, inbox) = mpsc::channel::<Vec<u8>>();
    std::thread::spawn(move || {
        for block in inbox {
            if let Err(e) = stdin.write_all(&block).and_then(|_| stdin.flush()) {
                let e = e.to_string();
                note(&|l| l.stdin_error = Some(e.clone()));
                return;
            }
        }
    });
    to_worker
}

/// Reads the worker's output lines (each at most [`MAX_LINE`] bytes) on a thread of its own;
/// `None` once the output ends.
fn spawn_reader(
    stdout: ChildStdout,
    note: impl Fn(&dyn Fn(&mut LastWords)) + Send + 'static,
) -> mpsc::Receiver<Option<String>> {
    let (outbox, from_worker) = mpsc::channel::<Option<String>>();
    std::thread::spawn(move || {
        let mut stdout = BufReader::new(stdout);
        loop {
            let mut line = String::new();
            match (&mut stdout).take(MAX_LINE as u64 + 1).read_line(&mut line) {
                Ok(n) if n > 0 => {
                    let said = shorten(&line);
                    note(&|l| l.stdout = Some(said.clone()));
                    if outbox.send(Some(line)).is_err() {
                        return;
                    }
                }
                _ => {
                    let _ = outbox.send(None);
                    return;
                }
            }
        }
    });
    from_worker
}

/// Passes the worker's standard error through to this process's, noting its last line.
fn spawn_stderr_echo(stderr: ChildStderr, note: impl Fn(&dyn Fn(&mut LastWords)) + Send + 'static) {
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines() {
            let Ok(line) = line else { return };
            let _ = writeln!(std::io::stderr(), "{line}");
            if !line.trim().is_empty() {
                let said = shorten(&line);
                note(&|l| l.stderr = Some(said.clone()));
            }
        }
    });
}

impl Evaluator for JsonLines {
    fn evaluate(
        &mut self,
        generation: u64,
        genomes: &[Genome],
        refine: u32,
    ) -> Result<Vec<Evaluation>, EvolveError> {
        if let Some(why) = &self.broken {
            return Err(EvaluatorError::FailedBefore(why.clone()).into());
        }
        self.send(batch_text(genomes, refine)?);
        let n = genomes.len();
        let mut out: Vec<Option<Evaluation>> = vec![None; n];
        let mut got = 0;
        let mut clock = BatchClock::start(self.timeout);
        loop {
            let line = self.next_line(&mut clock, got, n, generation)?;
            self.lines_read += 1;
            if line.trim().is_empty() {
                continue;
            }
            let reply: Reply = match parse_line(line.trim_end(), "reply", self.lines_read) {
                Ok(r) => r,
                Err(e) => return Err(self.fail(WorkerFault::BadReply(e))),
            };
            let (index, r) = match reply {
                Reply::Done(BatchEnd { count }) if count == n && got == n => break,
                Reply::Done(BatchEnd { count }) => {
                    return Err(self.fail(WorkerFault::EarlyDone {
                        generation,
                        count,
                        got,
                        n,
                    }));
                }
                Reply::Damage(d) => (d.index, Ok(d.value)),
                Reply::Error(e) => (e.index, Err(EvaluationError::from_message(&e.message))),
            };
            match out.get_mut(index) {
                Some(slot @ None) => *slot = Some(r),
                Some(Some(_)) => {
                    return Err(self.fail(WorkerFault::RepliedTwice { index, generation }));
                }
                None => {
                    return Err(self.fail(WorkerFault::IndexPastBatch {
                        index,
                        n,
                        generation,
                    }));
                }
            }
            got += 1;
        }
        Ok(out.into_iter().flatten().collect())
    }
}

/// The request lines of a batch: one genome line each, then the batch end.
fn batch_text(genomes: &[Genome], refine: u32) -> Result<String, EvolveError> {
    let mut text = String::new();
    for (index, g) in genomes.iter().enumerate() {
        let line = Request::Genome(GenomeLine {
            index,
            genes: g.clone(),
            refine,
        });
        text.push_str(&serde_json::to_string(&line).map_err(EvaluatorError::Encode)?);
        text.push('\n');
    }
    let end = Request::Evaluate(BatchEnd {
        count: genomes.len(),
    });
    text.push_str(&serde_json::to_string(&end).map_err(EvaluatorError::Encode)?);
    text.push('\n');
    Ok(text)
}

/// When a batch started, and when the next progress line is due.
struct BatchClock {
    started: Instant,
    tick: Duration,
    next_note: Instant,
}

impl BatchClock {
    fn start(timeout: Duration) -> Self {
        let started = Instant::now();
        let tick = (timeout / 3).min(PROGRESS_EVERY);
        Self {
            started,
            tick,
            next_note: started + tick,
        }
    }
}

impl JsonLines {
    /// The worker's next line of the batch (`got` of its `n` replies of `generation` in),
    /// writing a progress line while it waits; stops the worker at the batch timeout or when
    /// its output closes.
    fn next_line(
        &mut self,
        clock: &mut BatchClock,
        got: usize,
        n: usize,
        generation: u64,
    ) -> Result<String, EvolveError> {
        loop {
            let now = Instant::now();
            let deadline = clock.started + self.timeout;
            if now >= deadline {
                let seconds = self.timeout.as_secs_f64();
                return Err(self.fail(WorkerFault::Timeout {
                    got,
                    n,
                    generation,
                    seconds,
                }));
            }
            match self
                .from_worker
                .recv_timeout(clock.next_note.min(deadline) - now)
            {
                Ok(Some(line)) => return Ok(line),
                Ok(None) | Err(mpsc::RecvTimeoutError::Disconnected) => {
                    let status = self.exit_status();
                    return Err(self.fail(WorkerFault::Closed {
                        got,
                        n,
                        generation,
                        status,
                    }));
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if Instant::now() >= clock.next_note {
                        let _ = writeln!(
                            std::io::stderr(),
                            "waiting for the worker `{}`: {got} of {n} replies of generation \
                             {generation} after {:.1} s (it is stopped at {:.1} s)",
                            self.name,
                            clock.started.elapsed().as_secs_f64(),
                            self.timeout.as_secs_f64()
                        );
                        clock.next_note += clock.tick;
                    }
                }
            }
        }
    }
}

impl Drop for JsonLines {
    fn drop(&mut self) {
        // Closing its input ends a worker; one that lingers is stopped. Waiting leaves no
        // zombie.
        self.to_worker = None;
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The worker side: reads the header, reads its problem as a `P` and builds the evaluator of
/// it with `make`, then answers batches until its input ends (a batch mixing refinements is evaluated per
/// refinement). A line it does not understand (an unknown message or field, a wrong type, a
/// batch end whose count is not the batch's) ends it with an error naming the line, the column
/// and the field.
pub fn serve<P, R, W, E>(
    input: R,
    mut output: W,
    make: impl FnOnce(P) -> Result<E, String>,
) -> Result<(), EvolveError>
where
    P: serde::de::DeserializeOwned,
    R: BufRead,
    W: Write,
    E: Fn(&[Genome], u32) -> Vec<Evaluation>,
{
    let mut lines = input.lines();
    let first = lines
        .next()
        .ok_or(EvaluatorError::NoHeader)?
        .map_err(|source| EvaluatorError::Read { line: 1, source })?;
    let eval = read_problem(&first, make)?;
    let mut batch: Vec<(usize, Genome, u32)> = Vec::new();
    for (k, line) in lines.enumerate() {
        let at = k + 2;
        let line = line.map_err(|source| EvaluatorError::Read { line: at, source })?;
        if line.len() > MAX_LINE {
            return Err(EvaluatorError::LineTooLong(at).into());
        }
        if line.trim().is_empty() {
            continue;
        }
        match parse_line::<Request>(&line, "request", at).map_err(bad_request)? {
            Request::Genome(g) => add_genome(&mut batch, g, at)?,
            Request::Evaluate(BatchEnd { count }) => {
                if count != batch.len() {
                    return Err(EvaluatorError::BatchCount {
                        line: at,
                        held: batch.len(),
                        count,
                    }
                    .into());
                }
                answer_batch(&eval, &batch, &mut output)?;
                batch.clear();
            }
        }
    }
    if !batch.is_empty() {
        return Err(EvaluatorError::UnendedBatch(batch.len()).into());
    }
    Ok(())
}

/// The evaluator of the problem the header line `first` gives (of the protocol's version),
/// built by `make`.
fn read_problem<P, E>(
    first: &str,
    make: impl FnOnce(P) -> Result<E, String>,
) -> Result<E, EvolveError>
where
    P: serde::de::DeserializeOwned,
{
    let header: Header = parse_line(first, "request", 1).map_err(bad_request)?;
    if header.protocol != PROTOCOL {
        return Err(EvaluatorError::Protocol(header.protocol).into());
    }
    serde_json::from_value(header.problem)
        .map_err(|e| e.to_string())
        .and_then(make)
        .map_err(|e| EvaluatorError::Problem(e).into())
}

/// Adds the genome of request line `at` to the batch: its refinement in range, its index new.
fn add_genome(
    batch: &mut Vec<(usize, Genome, u32)>,
    GenomeLine {
        index,
        genes,
        refine,
    }: GenomeLine,
    at: usize,
) -> Result<(), EvolveError> {
    if !(1..=MAX_REFINE).contains(&refine) {
        return Err(EvaluatorError::Refine { line: at, refine }.into());
    }
    if batch.iter().any(|b| b.0 == index) {
        return Err(EvaluatorError::RepeatedIndex { line: at, index }.into());
    }
    batch.push((index, genes, refine));
    Ok(())
}

/// Evaluates a batch, one call of `eval` per refinement level, and writes its replies and
/// batch end to `output`.
fn answer_batch<E, W>(
    eval: &E,
    batch: &[(usize, Genome, u32)],
    output: &mut W,
) -> Result<(), EvolveError>
where
    W: Write,
    E: Fn(&[Genome], u32) -> Vec<Evaluation>,
{
    let mut results: Vec<Option<Evaluation>> = vec![None; batch.len()];
    let mut levels: Vec<u32> = batch.iter().map(|b| b.2).collect();
    levels.sort_unstable();
    levels.dedup();
    for level in levels {
        let at: Vec<usize> = (0..batch.len()).filter(|&i| batch[i].2 == level).collect();
        let genomes: Vec<Genome> = at.iter().map(|&i| batch[i].1.clone()).collect();
        for (i, r) in at.into_iter().zip(eval(&genomes, level)) {
            results[i] = Some(r);
        }
    }
    let mut text = String::new();
    for ((index, _, _), r) in batch.iter().zip(results) {
        let index = *index;
        let r = r.unwrap_or(Err(EvaluationError::NotEvaluated));
        let reply = match r {
            Ok(value) if value.is_finite() && value >= 0.0 => {
                Reply::Damage(DamageLine { index, value })
            }
            Ok(value) => Reply::Error(ErrorLine {
                index,
                message: EvaluationError::InvalidDamage(value).to_string(),
            }),
            Err(e) => Reply::Error(ErrorLine {
                index,
                message: e.to_string(),
            }),
        };
        text.push_str(&serde_json::to_string(&reply).map_err(EvaluatorError::Encode)?);
        text.push('\n');
    }
    let done = Reply::Done(BatchEnd { count: batch.len() });
    text.push_str(&serde_json::to_string(&done).map_err(EvaluatorError::Encode)?);
    text.push('\n');
    output
        .write_all(text.as_bytes())
        .and_then(|_| output.flush())
        .map_err(|e| EvaluatorError::Write(e).into())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs [`serve`] on `lines` (after a header) with an evaluator giving each genome the
    /// sum of its genes times its refinement: the output, or the error.
    fn serve_lines(lines: &[&str]) -> Result<String, String> {
        let mut input = format!("{{\"protocol\":\"{PROTOCOL}\",\"problem\":null}}\n");
        for l in lines {
            input.push_str(l);
            input.push('\n');
        }
        let mut out = Vec::new();
        serve(input.as_bytes(), &mut out, |_: serde_json::Value| {
            Ok(|g: &[Genome], refine: u32| {
                g.iter()
                    .map(|x| Ok(x.iter().sum::<f64>() * refine as f64))
                    .collect()
            })
        })
        .map_err(|e| e.to_string())?;
        Ok(String::from_utf8(out).unwrap())
    }

    #[test]
    fn a_batch_is_answered_in_tagged_lines() {
        let out = serve_lines(&[
            r#"{"genome": {"index": 0, "genes": [1.5, 2]}}"#,
            r#"{"genome": {"index": 1, "genes": [1], "refine": 2}}"#,
            r#"{"evaluate": {"count": 2}}"#,
        ])
        .unwrap();
        let wanted = [
            r#"{"damage":{"index":0,"value":3.5}}"#,
            r#"{"damage":{"index":1,"value":2.0}}"#,
            r#"{"done":{"count":2}}"#,
        ];
        assert_eq!(out, wanted.map(|l| format!("{l}\n")).concat());
    }

    /// Point 7 of issue 38: each of these was evaluated (or silently dropped) by protocol 2.
    #[test]
    fn what_the_worker_does_not_understand_is_refused_with_line_column_and_field() {
        let genome = r#"{"genome": {"index": 0, "genes": [1]}}"#;
        for (lines, wanted) in [
            // A misspelt field.
            (
                vec![r#"{"genome": {"index": 0, "genes": [1], "refin": 2}}"#],
                vec![
                    "request line 2",
                    "column",
                    "unknown field `refin`",
                    "`refine`",
                ],
            ),
            // The batch end as protocol 2 wrote it, or as false.
            (
                vec![genome, r#"{"evaluate": false}"#],
                vec![
                    "request line 3",
                    "field `evaluate`",
                    "invalid type: boolean `false`",
                ],
            ),
            (
                vec![genome, r#"{"evaluate": true}"#],
                vec!["request line 3", "invalid type: boolean `true`"],
            ),
            // Two messages in one line.
            (
                vec![r#"{"genome": {"index": 0, "genes": [1]}, "evaluate": {"count": 1}}"#],
                vec!["request line 2", "column"],
            ),
            // A wrong type, named with its field.
            (
                vec![r#"{"genome": {"index": "zero", "genes": [1]}}"#],
                vec![
                    "request line 2, column",
                    "field `genome.index`",
                    "invalid type: string \"zero\"",
                ],
            ),
            (
                vec![r#"{"genome": {"index": 0, "genes": [1, "x"]}}"#],
                vec!["field `genome.genes[1]`", "invalid type: string \"x\""],
            ),
            // Protocol 2's untagged genome line.
            (
                vec![r#"{"index": 0, "genes": [1]}"#],
                vec!["request line 2", "unknown variant `index`", "`genome`"],
            ),
            // Counts that disagree, a genome given twice, a batch never ended.
            (
                vec![genome, r#"{"evaluate": {"count": 2}}"#],
                vec!["field `evaluate.count`", "holds 1 genomes, found 2"],
            ),
            (vec![genome, genome], vec!["genome 0 given twice"]),
            (vec![genome], vec!["ended inside a batch of 1"]),
            (
                vec![r#"{"genome": {"index": 0, "genes": [1], "refine": 0}}"#],
                vec!["field `genome.refine`", "found 0"],
            ),
        ] {
            let e = serve_lines(&lines).expect_err(&format!("{lines:?} was accepted"));
            for w in wanted {
                assert!(e.contains(w), "{lines:?}: {e:?} lacks {w:?}");
            }
        }
    }

    #[test]
    fn a_header_with_an_unknown_field_or_another_protocol_is_refused() {
        let mut out = Vec::new();
        let make = |_: serde_json::Value| Ok(|_: &[Genome], _: u32| Vec::new());
        let e = serve(
            &b"{\"protocol\":\"marionette-eval/3\",\"problem\":null,\"seed\":1}\n"[..],
            &mut out,
            make,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("unknown field `seed`"), "{e}");
        let e = serve(
            &b"{\"protocol\":\"marionette-eval/2\",\"problem\":null}\n"[..],
            &mut out,
            make,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("'marionette-eval/2' is not"), "{e}");
    }

    #[test]
    fn a_negative_or_unfinished_damage_is_an_error_line() {
        let mut out = Vec::new();
        let input = [
            format!(r#"{{"protocol":"{PROTOCOL}","problem":null}}"#),
            r#"{"genome":{"index":0,"genes":[]}}"#.to_string(),
            r#"{"evaluate":{"count":1}}"#.to_string(),
        ]
        .map(|l| l + "\n")
        .concat();
        serve(input.as_bytes(), &mut out, |_: serde_json::Value| {
            Ok(|_: &[Genome], _: u32| vec![Ok(-5.0)])
        })
        .unwrap();
        let out = String::from_utf8(out).unwrap();
        assert!(
            out.starts_with("{\"error\":{\"index\":0,\"message\":\"damage -5"),
            "{out}"
        );
    }

    fn shell(script: &str) -> Command {
        let mut c = Command::new("sh");
        c.args(["-c", script]);
        c
    }

    /// Point 6 of issue 38: a worker that never answers hung the GA forever.
    #[test]
    fn a_silent_worker_is_stopped_at_the_timeout_and_named_with_what_it_last_said() {
        let mut w = JsonLines::start(
            shell("echo 'loading the model' >&2; cat > /dev/null"),
            &serde_json::Value::Null,
        )
        .unwrap()
        .with_timeout(Duration::from_millis(600));
        let t0 = Instant::now();
        let e = w.evaluate(7, &[vec![1.0]], 1).unwrap_err().to_string();
        assert!(t0.elapsed() < Duration::from_secs(5), "{:?}", t0.elapsed());
        assert!(e.contains("sh -c echo"), "{e}");
        assert!(
            e.contains("answered 0 of the 1 genomes of generation 7"),
            "{e}"
        );
        assert!(e.contains("the batch timeout"), "{e}");
        assert!(e.contains("on stderr \"loading the model\""), "{e}");
        // The next batch fails at once, with the same cause.
        let again = w.evaluate(8, &[vec![1.0]], 1).unwrap_err().to_string();
        assert!(
            again.contains("failed before") && again.contains("generation 7"),
            "{again}"
        );
    }

    #[test]
    fn a_worker_that_dies_is_named_with_its_status_and_last_words() {
        let mut w = JsonLines::start(
            shell("read header; read genome; echo '{\"damage\":{\"index\":0,\"value\":1}}'; echo 'out of memory' >&2; exit 3"),
            &serde_json::Value::Null,
        )
        .unwrap();
        let e = w
            .evaluate(2, &[vec![1.0], vec![2.0]], 1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("closed its output after 1 of the 2 replies"),
            "{e}"
        );
        assert!(e.contains("exit status: 3"), "{e}");
        assert!(e.contains("on stderr \"out of memory\""), "{e}");
        assert!(e.contains("on stdout \"{\\\"damage\\\""), "{e}");
    }

    #[test]
    fn bad_replies_are_refused_with_line_column_and_field() {
        for (reply, wanted) in [
            (
                r#"{"damage": {"index": 0, "value": 1, "unit": "N"}}"#,
                "unknown field `unit`",
            ),
            (
                r#"{"damage": {"index": 0, "value": "1"}}"#,
                "field `damage.value`",
            ),
            (r#"{"index": 0, "damage": 1}"#, "unknown variant `index`"),
            (r#"{"damage": {"index": 5, "value": 1}}"#, "past the 1"),
            (r#"{"done": {"count": 1}}"#, "after 0 of its 1 replies"),
        ] {
            let mut w = JsonLines::start(
                shell(&format!(
                    "read header; read genome; read end; echo '{reply}'; sleep 5"
                )),
                &serde_json::Value::Null,
            )
            .unwrap();
            let e = w.evaluate(0, &[vec![1.0]], 1).unwrap_err().to_string();
            assert!(e.contains(wanted), "{reply}: {e}");
            assert!(
                !reply.starts_with("{\"damage\": {\"index\": 0, \"value\": 1,")
                    || e.contains("reply line 1, column"),
                "{e}"
            );
        }
    }
}
