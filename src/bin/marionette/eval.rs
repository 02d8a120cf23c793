//! `marionette eval --stdin`: a fitness worker speaking the JSON-lines protocol of
//! `marionette::evolve::evaluator` on standard input and output (a header with the problem,
//! then batches of genomes; one result line per genome keyed by index). Each batch is evaluated
//! in parallel on all cores (a World per core, up to four falls at a time in each).

use std::io::{BufReader, BufWriter};

use anyhow::{Result, bail};

use marionette::evolve::serve;
use marionette::experiments::evolve_fall::FallProblem;

// The command's arguments (its help text is on `Command::Eval`).
#[derive(clap::Args)]
pub struct Args {
    /// Read the protocol from standard input and answer on standard output.
    #[arg(long)]
    stdin: bool,
}

/// Runs the worker until its input ends.
pub fn eval(args: Args) -> Result<()> {
    if !args.stdin {
        bail!("eval speaks only over standard input and output: pass --stdin");
    }
    let input = BufReader::new(std::io::stdin().lock());
    let output = BufWriter::new(std::io::stdout().lock());
    serve(input, output, |p: FallProblem| {
        p.bounds().map_err(|e| e.to_string())?;
        Ok(move |genomes: &[Vec<f64>], refine: u32| p.evaluate(genomes, refine))
    })?;
    Ok(())
}
