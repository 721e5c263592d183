//! Result tables of the geometric Doppler-bearing tracking of Zoechmann et
//! al. 2019: written by `mmtrack reproduce zoechmann` (NMSE per epoch, the
//! per-manoeuvre summary, the non-line-of-sight per-path errors and labels;
//! partition `zoechmann`) and by `mmtrack process beam --tracker geometric`
//! (`geometric_per_epoch`, one partition per recording).

use super::TableFrame;

crate::define_table! {
    /// `zoechmann_nmse`: NMSE of the range per epoch, manoeuvre and estimator.
    pub const ZOECHMANN_NMSE = "zoechmann_nmse",
        "NMSE of the range over the Monte Carlo runs of one manoeuvre (Zoechmann et al. 2019, Figs. 4-5), per epoch and \
estimator: sum over runs of (r_est - r)^2 over the sum of r^2, r the true range at the epoch and r_est the estimator's \
range at the same time (the proposed tracker and the genies project their initial state (10); the batch baseline \
estimates it directly).",
        frame: TableFrame::NotApplicable;
    /// One row of [`ZOECHMANN_NMSE`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannNmseRow {
        manoeuvre: String, "", "half-overtaking or full-overtaking";
        estimator: String, "",
            "proposed, ho-chan, error-free-genie, nullspace-genie; variants: proposed-full-scan (the proposed tracker on \
a full scan's azimuth every epoch), proposed-gated (its 3-beam window only after the hand-over to RLS); diagnostics: \
ho-chan-true-azimuth (the baseline on the true azimuths), ho-chan-doppler-mps, error-free-genie-doppler-mps, \
proposed-full-scan-doppler-mps (the Doppler equation (5) multiplied by the wavelength, i.e. in m/s), \
proposed-doppler-mps (the same for the proposed tracker with its own beam window)";
        epoch: u64, "", "epoch index (20 ms each)";
        t_ns: i64, "ns", "time since the start of the manoeuvre (time_base scenario_start)";
        runs: u64, "", "Monte Carlo runs with an estimate at this epoch";
        nmse: f64, "", "sum (r_est - r)^2 / sum r^2";
        nmse_db: f64, "dB", "10 log10(nmse): dB re 1 (nmse is a dimensionless power ratio)";
        rmse_m: f64, "m", "root mean squared range error";
    }
}

crate::define_table! {
    /// `zoechmann_summary`: per manoeuvre, convergence and beam accounting.
    pub const ZOECHMANN_SUMMARY = "zoechmann_summary",
        "Per manoeuvre of reproduce zoechmann: the proposed tracker's hand-over from H-infinity to RLS (the epoch of the \
third distinct azimuth) over the runs, and the beams it measured (full scans for the first 10 epochs, then the 3 beams \
nearest the projected azimuth) against a full scan at every epoch.",
        frame: TableFrame::NotApplicable;
    /// One row of [`ZOECHMANN_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannSummaryRow {
        manoeuvre: String, "", "half-overtaking or full-overtaking";
        runs: u64, "", "Monte Carlo runs";
        epochs: u64, "", "epochs per run";
        not_converged_runs: u64, "", "runs that never saw three distinct azimuths (H-infinity to the end)";
        handover_median_s: Option<f64>, "s", "median hand-over time over converged runs; null if none";
        handover_mean_s: Option<f64>, "s", "mean hand-over time over converged runs; null if none";
        handover_p90_s: Option<f64>, "s", "90th percentile (nearest rank) of the hand-over time; null if none";
        handover_median_full_scan_s: Option<f64>, "s",
            "median hand-over time of the variant fed full-scan azimuths every epoch; null if none";
        beams_measured: u64, "", "beams measured by the proposed tracker, all runs";
        beams_full_scan: u64, "", "beams a full scan at every epoch would measure, all runs";
        saving: f64, "", "beams_full_scan / beams_measured over whole runs";
        windowed_saving: f64, "", "the same over the epochs after the full scans (the paper's 128 / 3)";
        window_hit_rate: f64, "", "share of windowed epochs whose 3 beams include the strongest beam of the codebook";
        gated_saving: f64, "",
            "saving over whole runs of the gated variant (window only after the hand-over to RLS, full scans before)";
        gated_window_hit_rate: f64, "", "window_hit_rate of the gated variant";
        first_window_off_share: f64, "",
            "share of runs whose first 3-beam window (epoch 11) is centred more than 90 deg from the true azimuth";
        estimator_failures: u64, "", "estimator updates that returned an error (all estimators, all runs)";
    }
}

crate::define_table! {
    /// `zoechmann_nlos_error`: per path, position error over time.
    pub const ZOECHMANN_NLOS_ERROR = "zoechmann_nlos_error",
        "The proposed geometric tracker on each path of an overtaking between two walls (line of sight and the two \
single wall bounces, image method), per epoch: RMS error over the Monte Carlo runs of the apparent source's position \
(the transmitter or its mirror image) and velocity, against the simulator's truth.",
        frame: TableFrame::NotApplicable;
    /// One row of [`ZOECHMANN_NLOS_ERROR`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannNlosErrorRow {
        path: String, "", "los, left-wall or right-wall";
        epoch: u64, "", "epoch index (20 ms each)";
        t_ns: i64, "ns", "time since the start of the manoeuvre (time_base scenario_start)";
        runs: u64, "", "runs with an estimate at this epoch";
        position_rmse_m: f64, "m", "RMS distance between estimated and true apparent source";
        velocity_rmse_mps: f64, "m/s", "RMS norm of the relative-velocity error";
    }
}

crate::define_table! {
    /// `zoechmann_path_labels`: per path and epoch, the tracker's state of one run.
    pub const ZOECHMANN_PATH_LABELS = "zoechmann_path_labels",
        "Labels for other sensors (Zoechmann et al. 2019, Sec. II and VII): for each path of the first Monte Carlo run, \
the tracker's estimate of the apparent source (transmitter or wall image) in the receiver's frame (x along its heading, \
y to the left) and its relative velocity, per epoch, beside the simulator's truth and the reflection point.",
        frame: TableFrame::Fixed {
            id: "receiver",
            meaning: "the receiver's frame: x along its heading, y to the left, origin at the receiver; velocities relative to it",
        };
    /// One row of [`ZOECHMANN_PATH_LABELS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannPathLabelRow {
        path: String, "", "los, left-wall or right-wall";
        t_ns: i64, "ns", "time since the start of the manoeuvre (time_base scenario_start)";
        x_m: f64, "m", "estimated x of the apparent source";
        y_m: f64, "m", "estimated y of the apparent source";
        vx_mps: f64, "m/s", "estimated relative velocity, x";
        vy_mps: f64, "m/s", "estimated relative velocity, y";
        true_x_m: f64, "m", "true x of the apparent source";
        true_y_m: f64, "m", "true y of the apparent source";
        true_vx_mps: f64, "m/s", "true relative velocity, x";
        true_vy_mps: f64, "m/s", "true relative velocity, y";
        reflection_x_m: Option<f64>, "m", "x of the reflection point on the wall; null for line of sight";
        reflection_y_m: Option<f64>, "m", "y of the reflection point; null for line of sight";
    }
}

crate::define_table! {
    /// `geometric_per_epoch`: `process beam --tracker geometric`, one row per epoch.
    pub const GEOMETRIC_PER_EPOCH = "geometric_per_epoch",
        "The geometric Doppler-bearing tracker (Zoechmann et al. 2019) on a recording's two vehicles (channel-sounder \
ground truth of transmitter and receiver): the receiver's 60 GHz UCA codebook and Doppler are simulated along the true \
poses every epoch; per epoch the tracker's estimate and the truth in the receiver's frame (x forward, y left), the \
filter in use and the beams measured.",
        frame: TableFrame::Fixed {
            id: "receiver",
            meaning: "the receiver's frame: x forward, y left, origin at the receiver; azimuths counter-clockwise from x; velocities relative to it",
        };
    /// One row of [`GEOMETRIC_PER_EPOCH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct GeometricEpochRow {
        epoch: u64, "", "epoch index";
        t_ns: i64, "ns", "time of the epoch (recording clock)";
        filter: String, "", "h-infinity (not converged) or rls";
        beams_measured: u64, "", "beams measured at this epoch (full scan or window)";
        measured_azimuth_rad: f64, "rad", "azimuth of the strongest measured beam";
        measured_doppler_hz: f64, "Hz", "simulated Doppler shift (range rate / wavelength plus noise)";
        range_m: f64, "m", "estimated range";
        true_range_m: f64, "m", "true range";
        azimuth_rad: f64, "rad", "estimated azimuth (projection (11))";
        true_azimuth_rad: f64, "rad", "true azimuth";
        vx_mps: f64, "m/s", "estimated relative velocity, x";
        vy_mps: f64, "m/s", "estimated relative velocity, y";
        true_vx_mps: f64, "m/s", "true relative velocity in the receiver's frame, x (central difference)";
        true_vy_mps: f64, "m/s", "true relative velocity, y";
    }
}

crate::define_table! {
    /// `geometric_summary`: `mmtrack analyze` of one `geometric_per_epoch` partition.
    pub const GEOMETRIC_SUMMARY = "geometric_summary",
        "The geometric Doppler-bearing tracker (Zoechmann et al. 2019) on one recording, from table \
geometric_per_epoch (process beam --tracker geometric), one row per sequence: the hand-over from H-infinity to RLS \
(the epoch of the third distinct azimuth, Sec. IV), the range and azimuth errors from the hand-over on (before it \
the range is unobservable and the estimate is reported as not converged, never scored), and the beams measured \
against a full scan at every epoch. Written by `mmtrack analyze`.",
        frame: TableFrame::NotApplicable;
    /// One row of [`GEOMETRIC_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct GeometricSummaryRow {
        epochs: u64, "", "epochs (rows of geometric_per_epoch)";
        duration_s: f64, "s", "time from the first to the last epoch";
        handover_epoch: Option<u64>, "", "first epoch in RLS; null if the tracker never left H-infinity";
        handover_s: Option<f64>, "s", "time of the first RLS epoch since the first epoch; null if never";
        rls_share: f64, "", "share of the epochs in RLS (after the hand-over)";
        range_rmse_m: Option<f64>, "m",
            "RMS of range_m - true_range_m over the epochs from the hand-over on; null if never converged";
        final_range_error_m: Option<f64>, "m", "abs(range_m - true_range_m) at the last epoch; null if never converged";
        azimuth_rmse_rad: Option<f64>, "rad",
            "RMS of the wrapped azimuth_rad - true_azimuth_rad from the hand-over on; null if never converged";
        final_azimuth_error_rad: Option<f64>, "rad",
            "abs of the wrapped azimuth error at the last epoch; null if never converged";
        codebook_beams: u64, "",
            "beams of a full scan: the most beams measured at one epoch (the schedule starts with full scans)";
        beams_measured: u64, "", "beams measured over all epochs";
        beams_full_scan: u64, "", "beams a full scan at every epoch would measure (epochs x codebook_beams)";
        saving: f64, "", "beams_full_scan / beams_measured (the paper's 128 / 3 on the windowed epochs)";
    }
}

/// `filter` of a [`GEOMETRIC_PER_EPOCH`] epoch tracked by the H-infinity recursion.
pub const GEOMETRIC_FILTER_H_INFINITY: &str = "h-infinity";
/// `filter` of a [`GEOMETRIC_PER_EPOCH`] epoch tracked by RLS (after the hand-over).
pub const GEOMETRIC_FILTER_RLS: &str = "rls";
