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
    #[serde(with = "figure")]
    pub best: f64,
    /// Mean damage of the evaluations that succeeded.
    #[serde(with = "figure")]
    pub mean: f64,
    /// Median damage.
    #[serde(with = "figure")]
    pub median: f64,
    /// Highest damage.
    #[serde(with = "figure")]
    pub worst: f64,
    /// Standard deviation of the damage.
    #[serde(with = "figure")]
    pub std: f64,
    /// Lowest damage of any generation so far (never rises).
    #[serde(with = "figure")]
    pub best_so_far: f64,
    /// Individuals of this generation given the worst fitness: evaluations that failed
    /// (unstable simulations) and elites rejected by the elite check.
    pub failures: usize,
    /// Re-evaluations of elites at twice the resolution this generation (the elite check).
    #[serde(default)]
    pub elite_checks: u64,
    /// Gene diversity: the mean over genes of the population's standard deviation divided by
    /// the gene's range.
    #[serde(with = "figure")]
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

/// The logbook as JSON lines, one record per line (a figure that is not finite as in
/// [`GenerationRecord`]'s fields: NaN as `null`, ±∞ as `"inf"` and `"-inf"`).
pub fn to_json_lines(records: &[GenerationRecord]) -> String {
    let mut s = String::new();
    for r in records {
        // A record is numbers and a figure's representation: serialising it cannot fail.
        s.push_str(&serde_json::to_string(r).expect("a logbook record serialises"));
        s.push('\n');
    }
    s
}

/// The records of a JSON-lines logbook ([`to_json_lines`]); `Err` names the line.
pub fn from_json_lines(text: &str) -> Result<Vec<GenerationRecord>, String> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(k, l)| serde_json::from_str(l).map_err(|e| format!("line {}: {e}", k + 1)))
        .collect()
}

/// JSON has no NaN nor infinity: a figure with no successful evaluation behind it (NaN) is
/// written as `null`, an infinite one (a sum or spread past the largest `f64`) as `"inf"` or
/// `"-inf"`, and each is read back as it was.
mod figure {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        match *x {
            x if x.is_finite() => s.serialize_f64(x),
            x if x.is_nan() => s.serialize_none(),
            f64::INFINITY => s.serialize_str("inf"),
            _ => s.serialize_str("-inf"),
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Figure {
        Number(f64),
        Word(String),
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Option::<Figure>::deserialize(d)? {
            None => Ok(f64::NAN),
            Some(Figure::Number(x)) => Ok(x),
            Some(Figure::Word(w)) => match w.as_str() {
                "inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                _ => Err(D::Error::custom(format!(
                    "a figure is a number, null, \"inf\" or \"-inf\", found {w:?}"
                ))),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Any `f64`: every bit pattern, so NaN, ±∞, ±0 and subnormals among them.
    fn any_f64() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<u64>().prop_map(f64::from_bits),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(f64::NAN),
        ]
    }

    proptest! {
        #[test]
        fn a_logbook_reads_back_what_it_wrote(
            rows in prop::collection::vec(
                (any::<u64>(), any::<u64>(), prop::array::uniform7(any_f64()), any::<usize>(), any::<u64>()),
                0..6,
            )
        ) {
            let records: Vec<GenerationRecord> = rows
                .iter()
                .map(|&(generation, evaluations, f, failures, elite_checks)| GenerationRecord {
                    generation,
                    evaluations,
                    best: f[0],
                    mean: f[1],
                    median: f[2],
                    worst: f[3],
                    std: f[4],
                    best_so_far: f[5],
                    diversity: f[6],
                    failures,
                    elite_checks,
                })
                .collect();
            // A figure's text is one number's (shortest round trip) or one of null, "inf" and
            // "-inf": the same text read back is the same values (NaN as NaN).
            let text = to_json_lines(&records);
            let back = from_json_lines(&text).unwrap();
            prop_assert_eq!(back.len(), records.len());
            prop_assert_eq!(to_json_lines(&back), text);
            for (a, b) in records.iter().zip(&back) {
                prop_assert!(a.diversity.to_bits() == b.diversity.to_bits() || a.diversity.is_nan());
            }
        }
    }

    #[test]
    fn a_figure_that_is_not_a_number_or_infinity_is_refused_by_name() {
        let line = to_json_lines(&[GenerationRecord::of(
            (0, 1, 0, 0),
            &[vec![0.5]],
            &[Some(2.0)],
            &Bounds::new(vec![0.0], vec![1.0]).unwrap(),
            None,
        )]);
        let bad = line.replacen("\"best\":2.0", "\"best\":\"huge\"", 1);
        assert_ne!(bad, line);
        let err = from_json_lines(&bad).unwrap_err();
        assert!(err.contains("line 1") && err.contains("huge"), "{err}");
    }
}
