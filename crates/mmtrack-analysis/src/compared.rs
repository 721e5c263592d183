//! What `analyze` of several runs compares, and how a compared value is
//! shown: per result table, the columns compared, each with the header, unit
//! and decimals of the single-run report (angles stored in radians shown in
//! degrees, shares in percent). The single-run trajectory table and the
//! compare table format their cells through the same [`Metric::cell`], so a
//! number reads the same in a run's report and in the comparison.
//!
//! The values in `run_comparison` stay in the stored unit of their column
//! (metric = column name, unit = the column's unit); only the report converts.

use mmtrack_io::table::TableSpec;

/// How a stored value becomes the shown one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Shown as stored.
    Same,
    /// Stored in radians, shown in degrees.
    RadToDeg,
    /// Stored as a share in [0, 1], shown in percent.
    ShareToPct,
}

/// One compared column: its stored name and how the reports show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Metric {
    /// The column of the result table.
    pub column: &'static str,
    /// The single-run report's header, with the shown unit (`yaw RMSE (deg)`).
    pub label: &'static str,
    /// Stored to shown unit.
    pub scale: Scale,
    /// Decimals shown (as in the single-run report).
    pub decimals: usize,
}

const fn metric(column: &'static str, label: &'static str, scale: Scale, decimals: usize) -> Metric {
    Metric { column, label, scale, decimals }
}

impl Metric {
    /// The stored value in the shown unit.
    #[must_use]
    pub fn shown(&self, stored: f64) -> f64 {
        match self.scale {
            Scale::Same => stored,
            Scale::RadToDeg => stored.to_degrees(),
            Scale::ShareToPct => 100.0 * stored,
        }
    }

    /// A stored value as the reports print it: shown unit, the metric's
    /// decimals, `n/a` for none, never `-0.000`.
    #[must_use]
    pub fn cell(&self, stored: Option<f64>) -> String {
        stored.map_or_else(|| "n/a".to_string(), |v| fixed(self.shown(v), self.decimals))
    }

    /// `B - A` of two stored values in the shown unit, signed (`+0.012`),
    /// `n/a` when either is missing; a difference that rounds to zero is `0.000`.
    #[must_use]
    pub fn difference(&self, a: Option<f64>, b: Option<f64>) -> String {
        match (a, b) {
            (Some(a), Some(b)) => {
                let d = self.shown(b) - self.shown(a);
                let text = fixed(d, self.decimals);
                // A sign only on a difference that shows a non-zero digit.
                if d > 0.0 && text.chars().any(|c| matches!(c, '1'..='9')) { format!("+{text}") } else { text }
            }
            _ => "n/a".into(),
        }
    }
}

/// `v` with `decimals` decimals; a value that rounds to zero has no sign.
#[must_use]
pub fn fixed(v: f64, decimals: usize) -> String {
    let text = format!("{v:.decimals$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

/// A result table and the columns compared across runs.
#[derive(Debug, Clone, Copy)]
pub struct ComparedTable {
    /// The table.
    pub spec: &'static TableSpec,
    /// String columns that tell rows of one sequence apart (joined by ` / `).
    pub keys: &'static [&'static str],
    /// Columns compared, in report order.
    pub metrics: &'static [Metric],
    /// Whether the report shows the table (else its rows are only in
    /// `run_comparison`, e.g. the per-pass beam rows behind the pooled ones).
    pub in_report: bool,
}

/// The main metric columns of `trajectory_metrics`, compared and pooled, in
/// the order and format of the single-run trajectory table.
pub const TRAJECTORY_COMPARED: [Metric; 11] = [
    metric("kitti_translational_pct", "KITTI t (%)", Scale::Same, 3),
    metric("kitti_rotational_deg_per_100m", "KITTI r (deg/100 m)", Scale::Same, 3),
    metric("ate_rmse_m", "ATE (m)", Scale::Same, 3),
    metric("ate_max_m", "ATE max (m)", Scale::Same, 3),
    metric("x_rmse_m", "x RMSE (m)", Scale::Same, 3),
    metric("y_rmse_m", "y RMSE (m)", Scale::Same, 3),
    metric("position_rmse_m", "position RMSE (m)", Scale::Same, 3),
    metric("yaw_rmse_rad", "yaw RMSE (deg)", Scale::RadToDeg, 3),
    metric("rpe_translation_rmse_m", "RPE t (m)", Scale::Same, 4),
    metric("rpe_yaw_rmse_rad", "RPE yaw (deg)", Scale::RadToDeg, 4),
    metric("final_position_error_m", "end-point error (m)", Scale::Same, 3),
];

/// The compared columns of the beam-sweep summaries (per pass and pooled per
/// site), as the beam report prints them.
const BEAM_SWEEP_COMPARED: [Metric; 7] = [
    metric("mean_loss_db", "mean loss (dB)", Scale::Same, 3),
    metric("median_loss_db", "median loss (dB)", Scale::Same, 3),
    metric("p90_loss_db", "p90 loss (dB)", Scale::Same, 3),
    metric("top1", "top-1", Scale::Same, 3),
    metric("within_one", "within one", Scale::Same, 3),
    metric("mean_beams_per_sweep", "beams per sweep", Scale::Same, 2),
    metric("reinitialisations", "re-initialisations", Scale::Same, 0),
];

/// What the side-by-side compares, per result table, in report order.
pub const COMPARED: [ComparedTable; 7] = [
    ComparedTable {
        spec: &mmtrack_io::table::TRAJECTORY_METRICS,
        keys: &[],
        metrics: &TRAJECTORY_COMPARED,
        in_report: true,
    },
    ComparedTable {
        spec: &mmtrack_io::table::MPC_SUMMARY,
        keys: &[],
        metrics: &[
            metric("mean_mpcs_per_set", "MPCs/set mean", Scale::Same, 2),
            metric("birth_rate_per_m", "birth rate (1/m)", Scale::Same, 3),
            metric("death_rate_per_m", "death rate (1/m)", Scale::Same, 3),
            metric("mean_detection_loss_db", "detection loss (dB)", Scale::Same, 2),
            metric("mean_tracking_loss_db", "tracking loss (dB)", Scale::Same, 2),
            metric("mean_gmphd_tracking_loss_db", "GM-PHD loss (dB)", Scale::Same, 2),
            metric("precision", "precision", Scale::Same, 3),
            metric("recall", "recall", Scale::Same, 3),
            metric("track_purity", "track purity", Scale::Same, 3),
        ],
        in_report: true,
    },
    ComparedTable {
        spec: &mmtrack_io::table::BEAM_SWEEP_POOLED,
        keys: &["site", "tracker"],
        metrics: &BEAM_SWEEP_COMPARED,
        in_report: true,
    },
    ComparedTable {
        spec: &mmtrack_io::table::BEAM_SWEEP_SUMMARY,
        keys: &["tracker"],
        metrics: &BEAM_SWEEP_COMPARED,
        in_report: false,
    },
    ComparedTable {
        spec: &mmtrack_io::table::SPEBT_SUMMARY,
        keys: &["experiment", "trajectory"],
        metrics: &[
            metric("rmse_gain_pct", "abs(alpha) RMSE (%)", Scale::Same, 2),
            metric("rmse_aod_rad", "AoD RMSE (deg)", Scale::RadToDeg, 3),
            metric("rmse_aoa_rad", "AoA RMSE (deg)", Scale::RadToDeg, 3),
            metric("reinitialisation_share_pct", "re-initialisations (%)", Scale::Same, 2),
        ],
        in_report: true,
    },
    ComparedTable {
        spec: &mmtrack_io::table::GEOMETRIC_SUMMARY,
        keys: &[],
        metrics: &[
            metric("handover_s", "hand-over (s)", Scale::Same, 2),
            metric("rls_share", "RLS epochs (%)", Scale::ShareToPct, 1),
            metric("range_rmse_m", "range RMSE (m)", Scale::Same, 2),
            metric("azimuth_rmse_rad", "azimuth RMSE (deg)", Scale::RadToDeg, 2),
            metric("saving", "saving", Scale::Same, 1),
        ],
        in_report: true,
    },
    ComparedTable {
        spec: &mmtrack_io::table::SLAM_SUMMARY,
        keys: &["row"],
        metrics: &[
            metric("ue_position_error_m", "UE position (m)", Scale::Same, 3),
            metric("ue_heading_error_rad", "heading (rad)", Scale::Same, 4),
            metric("ue_clock_bias_error_m", "clock bias (m)", Scale::Same, 3),
            metric("va_error_m", "VA (m)", Scale::Same, 3),
            metric("sp_error_m", "SP (m)", Scale::Same, 3),
        ],
        in_report: true,
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_compared_column_and_key_is_a_numeric_or_string_column_of_its_table() {
        for compared in &COMPARED {
            let column = |name: &str| compared.spec.columns.iter().find(|c| c.name == name);
            for key in compared.keys {
                assert!(column(key).is_some(), "{}: no key column {key}", compared.spec.name);
            }
            for m in compared.metrics {
                let found = column(m.column);
                assert!(found.is_some(), "{}: no column {}", compared.spec.name, m.column);
                // The shown unit follows the stored one.
                let unit = found.map_or("", |c| c.unit);
                match m.scale {
                    Scale::RadToDeg => assert_eq!(unit, "rad", "{}", m.column),
                    Scale::ShareToPct => assert_eq!(unit, "", "{}", m.column),
                    Scale::Same => assert!(!m.label.contains("(deg)") || unit == "deg", "{}", m.column),
                }
            }
        }
    }

    #[test]
    fn cells_convert_units_and_drop_negative_zero() {
        let yaw = TRAJECTORY_COMPARED[7];
        assert_eq!(yaw.cell(Some(std::f64::consts::PI / 180.0 * 0.229)), "0.229");
        assert_eq!(yaw.cell(None), "n/a");
        assert_eq!(fixed(-0.0001, 2), "0.00");
        assert_eq!(fixed(-0.02, 2), "-0.02");
        let ate = TRAJECTORY_COMPARED[2];
        assert_eq!(ate.difference(Some(1.5), Some(1.2)), "-0.300");
        assert_eq!(ate.difference(Some(1.2), Some(1.5)), "+0.300");
        assert_eq!(ate.difference(Some(1.0), Some(1.0)), "0.000");
        assert_eq!(ate.difference(Some(1.0), Some(1.00001)), "0.000");
        assert_eq!(ate.difference(None, Some(1.0)), "n/a");
    }
}
