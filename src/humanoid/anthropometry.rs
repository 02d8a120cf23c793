//! Anthropometry: segment masses, centres of mass and radii of gyration from **de Leva (1996)**,
//! *Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters*, J. Biomech.
//! 29(9):1223–1230, Table 4 (males: stature 1741 mm, 73.0 kg). A subject of height `H` and mass
//! `M` gets `m_i = μ_i M`, lengths `ℓ_i = ℓ_i,ref · H / 1.741` and `I = m (r ℓ)²`.

/// Stature of de Leva's male reference subject (m).
pub const DE_LEVA_STATURE: f64 = 1.741;

/// One row of de Leva (1996) Table 4 (males): length (mm), mass (% of body mass), centre of
/// mass (% of length from the proximal end point) and radii of gyration (% of length) about the
/// sagittal (medio-lateral), transverse (antero-posterior) and longitudinal axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentRow {
    /// Segment length between de Leva's end points (mm).
    pub length_mm: f64,
    /// Mass as a percentage of body mass.
    pub mass_pct: f64,
    /// Centre of mass, percent of the length from the proximal end point.
    pub com_pct: f64,
    /// Radius of gyration about the sagittal (medio-lateral) axis, percent of length.
    pub r_sagittal_pct: f64,
    /// Radius of gyration about the transverse (antero-posterior) axis, percent of length.
    pub r_transverse_pct: f64,
    /// Radius of gyration about the longitudinal axis, percent of length.
    pub r_longitudinal_pct: f64,
}

const fn row(length_mm: f64, mass_pct: f64, com_pct: f64, rs: f64, rt: f64, rl: f64) -> SegmentRow {
    SegmentRow {
        length_mm,
        mass_pct,
        com_pct,
        r_sagittal_pct: rs,
        r_transverse_pct: rt,
        r_longitudinal_pct: rl,
    }
}

/// Head + neck (vertex → cervicale).
pub const DE_LEVA_HEAD: SegmentRow = row(242.9, 6.94, 59.76, 36.2, 37.6, 31.2);
/// Upper trunk (cervicale → xiphion).
pub const DE_LEVA_UPPER_TRUNK: SegmentRow = row(242.1, 15.96, 50.66, 50.5, 32.0, 46.5);
/// Middle trunk (xiphion → omphalion).
pub const DE_LEVA_MIDDLE_TRUNK: SegmentRow = row(215.5, 16.33, 45.02, 48.2, 38.3, 46.8);
/// Lower trunk (omphalion → hip-joint centres).
pub const DE_LEVA_LOWER_TRUNK: SegmentRow = row(145.7, 11.17, 61.15, 61.5, 55.1, 58.7);
/// Upper arm (shoulder → elbow joint centre).
pub const DE_LEVA_UPPER_ARM: SegmentRow = row(281.7, 2.71, 57.72, 28.5, 26.9, 15.8);
/// Forearm (elbow → wrist joint centre).
pub const DE_LEVA_FOREARM: SegmentRow = row(268.9, 1.62, 45.74, 27.6, 26.5, 12.1);
/// Hand (wrist joint centre → 3rd metacarpale).
pub const DE_LEVA_HAND: SegmentRow = row(86.2, 0.61, 79.00, 62.8, 51.3, 40.1);
/// Thigh (hip → knee joint centre).
pub const DE_LEVA_THIGH: SegmentRow = row(422.2, 14.16, 40.95, 32.9, 32.9, 14.9);
/// Shank (knee joint centre → lateral malleolus).
pub const DE_LEVA_SHANK: SegmentRow = row(434.0, 4.33, 44.59, 25.5, 24.9, 10.3);
/// Foot (heel → tip of the longest toe).
pub const DE_LEVA_FOOT: SegmentRow = row(258.1, 1.37, 44.15, 25.7, 24.5, 12.4);
