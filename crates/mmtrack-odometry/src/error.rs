use thiserror::Error;

/// What can go wrong when configuring or running the odometry.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum OdometryError {
    /// A configuration value is outside its meaningful range.
    #[error("odometry config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The scan's geometry is unusable (no rows, bad resolution, NaN angles).
    #[error("scan at t_ns {t_ns}: {detail}")]
    BadScan {
        /// Scan stamp.
        t_ns: i64,
        /// What is wrong.
        detail: String,
    },
    /// Two rows of one scan report the same azimuth angle.
    #[error("scan at t_ns {t_ns}: rows {first_row} and {second_row} have the same azimuth {azimuth_rad} rad")]
    DuplicateAzimuth {
        /// Scan stamp.
        t_ns: i64,
        /// The earlier row.
        first_row: usize,
        /// The later row.
        second_row: usize,
        /// The repeated angle.
        azimuth_rad: f64,
    },
    /// Scans must arrive in strictly increasing time.
    #[error("scan at t_ns {t_ns} is not after the previous scan at t_ns {previous_t_ns}")]
    NonMonotonicTime {
        /// Previous scan stamp.
        previous_t_ns: i64,
        /// This scan's stamp.
        t_ns: i64,
    },
}
