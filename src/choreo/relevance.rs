//! rel(q, m) of the dance-editing paper's eq. (1): how well the music intensity of the bar q
//! being edited matches the motion intensity of a segment m.
//!
//! The two intensities live on different scales (a bar's RMS in dB over one song; a segment's
//! mean W(f) of eq. (2) in m/s over one database), so each is replaced by its **percentile rank**
//! within its own collection: p = r / (n − 1), with r the 0-based rank in ascending order (ties
//! share their mean rank), so the quietest bar and the calmest segment get 0, the loudest and
//! the most intense 1 (a lone value gets ½). Ranks need no assumption about either
//! distribution (RMS dB of a song is skewed by its breaks, motion intensity by a few fast
//! takes) and are invariant under any increasing change of units (RMS or dB, α scaled).
//! Then rel(q, m) = 1 − |p_music(q) − p_motion(m)| ∈ [0, 1]: 1 when the bar is as loud within its
//! song as the segment is intense within the database, 0 for the loudest bar and the calmest
//! segment.

use super::database::Database;
use super::music::Bar;

/// Percentile ranks of `values` in [0, 1] (module docs): p_i = r_i / (n − 1), ties sharing their
/// mean rank; ½ for a single value. NaN sorts above every number (`f64::total_cmp`).
pub fn percentile_ranks(values: &[f64]) -> Vec<f64> {
    let n = values.len();
    if n == 1 {
        return vec![0.5];
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]).then(a.cmp(&b)));
    let mut ranks = vec![0.0; n];
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && values[order[j + 1]].total_cmp(&values[order[i]]).is_eq() {
            j += 1;
        }
        let mean = (i + j) as f64 / 2.0 / (n - 1) as f64;
        for &k in &order[i..=j] {
            ranks[k] = mean;
        }
        i = j + 1;
    }
    ranks
}

/// The normalised music intensity of every bar of a song: the percentile rank of its RMS (in
/// dB; a silent bar's −∞ dB ranks lowest) among the song's bars.
pub fn music_intensity(bars: &[Bar]) -> Vec<f64> {
    let db: Vec<f64> = bars.iter().map(|b| b.rms_db).collect();
    percentile_ranks(&db)
}

/// The normalised motion intensity of every segment of a database: the percentile rank of its
/// mean W(f) (eq. 2) among the database's segments.
pub fn motion_intensity(db: &Database) -> Vec<f64> {
    let w: Vec<f64> = db.segments.iter().map(|s| s.intensity).collect();
    percentile_ranks(&w)
}

/// rel(q, m) = 1 − |p_music − p_motion| ∈ [0, 1] from the two normalised intensities (module
/// docs).
pub fn rel(music: f64, motion: f64) -> f64 {
    (1.0 - (music - motion).abs()).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_span_zero_to_one_and_share_ties() {
        assert_eq!(percentile_ranks(&[3.0, 1.0, 2.0]), vec![1.0, 0.0, 0.5]);
        assert_eq!(
            percentile_ranks(&[1.0, 5.0, 5.0, 9.0, 0.0]),
            vec![0.25, 0.625, 0.625, 1.0, 0.0]
        );
        assert_eq!(percentile_ranks(&[7.0]), vec![0.5]);
        assert!(percentile_ranks(&[]).is_empty());
        // Invariant under an increasing change of units: RMS or dB rank the same.
        let rms = [0.01, 0.2, 0.05, 0.5];
        let db: Vec<f64> = rms.iter().map(|r: &f64| 20.0 * r.log10()).collect();
        assert_eq!(percentile_ranks(&rms), percentile_ranks(&db));
        // A silent bar (−∞ dB) is the quietest.
        assert_eq!(percentile_ranks(&[-10.0, f64::NEG_INFINITY])[1], 0.0);
    }

    #[test]
    fn a_louder_bar_prefers_a_more_intense_segment() {
        let bars = [-30.0, -12.0, -20.0, -6.0].map(|rms_db| Bar {
            start_s: 0.0,
            end_s: 1.0,
            rms: 10f64.powf(rms_db / 20.0),
            rms_db,
        });
        let music = music_intensity(&bars);
        let motion = percentile_ranks(&[0.4, 2.5, 1.1]); // calm, intense, middle
        let best = |q: usize| -> usize {
            (0..3)
                .max_by(|&a, &b| rel(music[q], motion[a]).total_cmp(&rel(music[q], motion[b])))
                .unwrap()
        };
        assert_eq!(best(0), 0, "the quietest bar wants the calmest segment");
        assert_eq!(best(3), 1, "the loudest bar wants the most intense segment");
        assert_eq!(rel(music[3], motion[1]), 1.0);
        assert_eq!(rel(music[0], motion[1]), 0.0);
        // Louder bar → rel of the intense segment rises, of the calm one falls.
        assert!(rel(music[1], motion[1]) > rel(music[2], motion[1]));
        assert!(rel(music[1], motion[0]) < rel(music[2], motion[0]));
    }
}
