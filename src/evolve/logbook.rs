//! The logbook of a run: per generation the best, mean, median, worst and spread of the damage,
//! the best so far, failed evaluations and the gene diversity; written as CSV and JSON lines.

use serde::{Deserialize, Serialize};

use super::genome::{Bounds, Genome};

/// One generation's figures (damage in N; diversity dimensionless).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GenerationRecord {
    /// Generation (0 = the initial population).
    pub generation: u64,
    /// Evaluations so far, this generation included.
    pub evaluations: u64,
    /// Lowest damage of the generation.
    #[serde(with = "nan_as_null")]
    pub best: f64,
    /// Mean damage of the evaluations that succeeded.
    #[serde(with = "nan_as_null")]
    pub mean: f64,
    /// Median damage.
    #[serde(with = "nan_as_null")]
    pub median: f64,
    /// Highest damage.
    #[serde(with = "nan_as_null")]
    pub worst: f64,
    /// Standard deviation of the damage.
    #[serde(with = "nan_as_null")]
    pub std: f64,
    /// Lowest damage of any generation so far (never rises).
    #[serde(with = "nan_as_null")]
    pub best_so_far: f64,
    /// Individuals of this generation given the worst fitness: evaluations that failed
    /// (unstable simulations) and elites rejected by the elite check.
    pub failures: usize,
    /// Re-evaluations of elites at twice the resolution this generation (the elite check).
    #[serde(default)]
    pub elite_checks: u64,
    /// Gene diversity: the mean over genes of the population's standard deviation divided by
    /// the gene's range.
    pub diversity: f64,
}

impl GenerationRecord {
    /// The figures of `population` with `fitness` (`None` = failed), of which `failures` failed
    /// in this generation's evaluations, with `elite_checks` re-evaluations by the elite check.
    pub fn of(
        (generation, evaluations, failures, elite_checks): (u64, u64, usize, u64),
        population: &[Genome],
        fitness: &[Option<f64>],
        bounds: &Bounds,
        best_before: Option<f64>,
    ) -> Self {
        let mut ok: Vec<f64> = fitness.iter().flatten().copied().collect();
        ok.sort_by(f64::total_cmp);
        let n = ok.len();
        let nan = f64::NAN;
        let (best, worst) = (
            ok.first().copied().unwrap_or(nan),
            ok.last().copied().unwrap_or(nan),
        );
        let mean = if n > 0 {
            ok.iter().sum::<f64>() / n as f64
        } else {
            nan
        };
        let median = match n {
            0 => nan,
            _ if n % 2 == 1 => ok[n / 2],
            _ => 0.5 * (ok[n / 2 - 1] + ok[n / 2]),
        };
        let std = if n > 0 {
            (ok.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64).sqrt()
        } else {
            nan
        };
        let best_so_far = match best_before {
            Some(b) if best.is_nan() || best >= b => b,
            _ => best,
        };
        Self {
            generation,
            evaluations,
            best,
            mean,
            median,
            worst,
            std,
            best_so_far,
            failures,
            elite_checks,
            diversity: diversity(population, bounds),
        }
    }
}

/// Mean over genes of `std(gene) / (hi − lo)` (genes with an empty range count 0).
pub fn diversity(population: &[Genome], bounds: &Bounds) -> f64 {
    let n = population.len() as f64;
    if population.is_empty() {
        return 0.0;
    }
    let mut total = 0.0;
    for i in 0..bounds.len() {
        let w = bounds.width(i);
        if w <= 0.0 {
            continue;
        }
        let mean = population.iter().map(|g| g[i]).sum::<f64>() / n;
        let var = population
            .iter()
            .map(|g| (g[i] - mean).powi(2))
            .sum::<f64>()
            / n;
        total += var.sqrt() / w;
    }
    total / bounds.len() as f64
}

/// The header of the CSV logbook.
pub const CSV_HEADER: &str =
    "generation,evaluations,best,mean,median,worst,std,best_so_far,failures,elite_checks,diversity";

/// The logbook as CSV (shortest round-trip decimals).
pub fn to_csv(records: &[GenerationRecord]) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in records {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{}\n",
            r.generation,
            r.evaluations,
            r.best,
            r.mean,
            r.median,
            r.worst,
            r.std,
            r.best_so_far,
            r.failures,
            r.elite_checks,
            r.diversity
        ));
    }
    s
}

/// The logbook as JSON lines, one record per line.
pub fn to_json_lines(records: &[GenerationRecord]) -> String {
    let mut s = String::new();
    for r in records {
        s.push_str(&serde_json::to_string(r).unwrap_or_default());
        s.push('\n');
    }
    s
}

/// JSON has no NaN: a figure with no successful evaluation behind it is written as `null` and
/// read back as NaN.
mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}
