//! Upper bounds on the counts, sizes and rates a user can set (flags and
//! configuration keys) that scale memory or run time.
//!
//! Each bound is far above any published scenario and any run that fits on
//! a workstation, and far below what aborts the process (an allocation of
//! terabytes, a capacity overflow) or runs for days. Readers and validators
//! check a value against its [`Limit`] before they allocate, and the error
//! names the flag or key, the value and the limit (`expected` below), so a
//! typo such as `--particles 100000000` is a one-line refusal, not an abort
//! after minutes of swapping. Issue 26 lists the inputs that motivated each.
//!
//! Derived sizes have their own bound where the product of two settings is
//! what costs (scan pixels, path length, reflectors along a path).

/// An upper bound on a count or size, and the text of an error that refuses
/// a larger value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// The largest accepted value.
    pub max: f64,
    /// What an error says was expected; it states [`Limit::max`].
    pub expected: &'static str,
}

impl Limit {
    /// Whether `value` is within the bound (NaN is not).
    #[must_use]
    pub fn allows(&self, value: f64) -> bool {
        value <= self.max
    }

    /// Whether the count `value` is within the bound.
    #[must_use]
    pub fn allows_count(&self, value: u64) -> bool {
        (value as f64) <= self.max
    }

    /// The count `value` of command-line flag `flag`, at least `min` and
    /// within the bound, or a usage error (exit status 2) naming the flag.
    ///
    /// # Errors
    /// `value` below `min` or beyond the bound.
    pub fn check_flag(&self, flag: &str, value: u64, min: u64) -> Result<(), crate::error::UsageError> {
        if value >= min && self.allows_count(value) {
            Ok(())
        } else {
            Err(crate::error::UsageError::new(format!("{flag} {value}: expected {}", self.expected)))
        }
    }
}

/// Worker threads (`--threads`): starting a pool costs about quadratically in
/// its size (8000 threads took 66 s), and no machine this targets gains
/// beyond a thousand.
pub const THREADS: Limit = Limit { max: 1024.0, expected: "at most 1024 threads (0: one per core)" };

/// Particles of the SLAM filter (`--particles`, `particles`): about 150 bytes
/// each before any source, so the bound is 150 MB of particles; the paper
/// uses 2000.
pub const PARTICLES: Limit = Limit { max: 1_000_000.0, expected: "between 2 and 1000000 particles" };

/// Monte Carlo runs of one experiment or `process beam --runs`; the papers
/// use at most 10 000.
pub const MONTE_CARLO_RUNS: Limit = Limit { max: 1_000_000.0, expected: "between 1 and 1000000 runs" };

/// Epochs of a simulated SLAM drive (held in memory with their paths; the
/// paper's lap has 100).
pub const SLAM_EPOCHS: Limit = Limit { max: 1_000_000.0, expected: "between 1 and 1000000 epochs" };

/// Clutter measurements per SLAM epoch (drawn and associated per particle).
pub const CLUTTER_PER_EPOCH: Limit = Limit { max: 10_000.0, expected: "at most 10000 clutter measurements per epoch" };

/// Random scattering points of a SLAM scenario (each a map feature every
/// particle tracks).
pub const SCATTERING_POINTS: Limit = Limit { max: 100_000.0, expected: "at most 100000 scattering points" };

/// Snapshots of a channel simulated in memory (`[artificial]`): 2048 complex
/// taps are 32 KiB, so the bound is about 3.3 GB.
pub const SNAPSHOTS_IN_MEMORY: Limit = Limit { max: 100_000.0, expected: "between 2 and 100000 snapshots" };

/// Snapshots of a streamed channel (`[convoy]`, sets x snapshots per set):
/// written as they are made, bounded by run time and disk (32 KiB each).
pub const SNAPSHOTS_STREAMED: Limit =
    Limit { max: 100_000_000.0, expected: "at most 100000000 snapshots in all (sets x snapshots_per_set)" };

/// Pixels of one radar scan (azimuths x range bins): the same 64 MiB as the
/// PNG decoder's cap, so every simulated scan can be written and read back.
pub const SCAN_PIXELS: Limit =
    Limit { max: 67_108_864.0, expected: "at most 64 Mi pixels per scan (sensor.azimuths x sensor.bins)" };

/// Speed of a simulated vehicle, m/s (faster than any road vehicle or train).
pub const SPEED_MPS: Limit = Limit { max: 150.0, expected: "a speed with |v| <= 150 m/s" };

/// Duration of a simulated drive, seconds (one day).
pub const DURATION_S: Limit = Limit { max: 86_400.0, expected: "a positive duration of at most 86400 s (one day)" };

/// Length of a simulated drive's path, metres (sampled every metre).
pub const PATH_LENGTH_M: Limit =
    Limit { max: 1_000_000.0, expected: "a path of at most 1000 km (speed_mps x duration_s)" };

/// Reflectors a generated world may hold (poles, clutter, buildings along
/// the path; each is kept in memory and tested against every beam).
pub const REFLECTORS: Limit = Limit {
    max: 10_000_000.0,
    expected: "at most 10000000 generated reflectors along the path (raise pole_spacing_m or lower clutter_per_100m)",
};

/// Iteration counts of an optimiser or association loop (`association_rounds`,
/// `max_iterations`): each round is a full solve; published values are <= 100.
pub const ITERATIONS: Limit = Limit { max: 10_000.0, expected: "between 1 and 10000 iterations" };

/// Size of a text input read whole (CSV ground truth and GNSS, timestamps,
/// pose files, sidecars, DecaWave logs, CIR CSV), bytes: 1 GiB, five times
/// the largest such file of the supported datasets (a Boreas
/// `gps_post_process.csv` of an hour at 200 Hz, about 200 MB). NMEA logs are
/// streamed and have no bound.
pub const TEXT_FILE_BYTES: Limit =
    Limit { max: 1_073_741_824.0, expected: "a text file of at most 1073741824 bytes (1 GiB)" };

/// Size of a configuration file read whole (a scenario, a pipeline or
/// experiment configuration, a manifest, a regression suite, a SLAM prior),
/// bytes: 16 MiB, thousands of times the largest we ship (a few kB).
pub const CONFIG_FILE_BYTES: Limit =
    Limit { max: 16_777_216.0, expected: "a configuration file of at most 16777216 bytes (16 MiB)" };

/// Size of a binary array input read whole (`.npy`, `.npz`, `.mat`, SigMF
/// data), bytes: 4 GiB.
pub const ARRAY_FILE_BYTES: Limit =
    Limit { max: 4_294_967_296.0, expected: "an array file of at most 4294967296 bytes (4 GiB)" };

/// Size of one radar scan PNG read whole, bytes: 128 MiB, twice the
/// [`SCAN_PIXELS`] image stored without compression.
pub const SCAN_PNG_BYTES: Limit =
    Limit { max: 134_217_728.0, expected: "a scan PNG of at most 134217728 bytes (128 MiB)" };

/// Runs per measurement of a benchmark (`--repeats`, `bench odometry
/// --passes`): each is a whole run of the measured pipeline; the benches
/// default to 3-20.
pub const BENCH_RUNS: Limit = Limit { max: 1000.0, expected: "between 1 and 1000 runs per measurement" };

/// Oxford-size scans (400 x 3768, about 1.5 MB each) a benchmark holds in
/// memory at once (`bench io --scans`): the bound is 3 GB.
pub const BENCH_SCANS_IN_MEMORY: Limit =
    Limit { max: 2000.0, expected: "between 1 and 2000 scans (1.5 MB each, held in memory)" };

/// Oxford-size scans a benchmark writes to disk (`bench ingest --scans`,
/// `bench odometry --memory-scans`): about 0.6-1.5 MB each, so the bound is
/// 12-30 GB of temporary files.
pub const BENCH_SCANS_ON_DISK: Limit =
    Limit { max: 20_000.0, expected: "between 4 and 20000 scans (up to 1.5 MB each on disk)" };

/// Snapshots of `bench mpc` (`--snapshots`), generated 64 sets at a time:
/// bounded by run time (about half an hour on one thread at the bound).
pub const BENCH_SNAPSHOTS: Limit = Limit { max: 10_000_000.0, expected: "between 1 and 10000000 snapshots" };

/// Paths per simulated snapshot of `bench mpc` (`--mpcs`): the detector
/// stops at `detection.max_mpcs` (200) in any case.
pub const BENCH_PATHS: Limit = Limit { max: 1000.0, expected: "between 1 and 1000 paths per snapshot" };

#[cfg(test)]
mod tests {
    use super::*;

    /// Every message states its bound, written as the number it is.
    #[test]
    fn each_message_states_its_bound() {
        let limits = [
            THREADS,
            PARTICLES,
            MONTE_CARLO_RUNS,
            SLAM_EPOCHS,
            CLUTTER_PER_EPOCH,
            SCATTERING_POINTS,
            SNAPSHOTS_IN_MEMORY,
            SNAPSHOTS_STREAMED,
            SPEED_MPS,
            DURATION_S,
            REFLECTORS,
            ITERATIONS,
            TEXT_FILE_BYTES,
            CONFIG_FILE_BYTES,
            ARRAY_FILE_BYTES,
            SCAN_PNG_BYTES,
            BENCH_RUNS,
            BENCH_SCANS_IN_MEMORY,
            BENCH_SCANS_ON_DISK,
            BENCH_SNAPSHOTS,
            BENCH_PATHS,
        ];
        for limit in limits {
            assert!(limit.expected.contains(&format!("{}", limit.max)), "{limit:?}");
        }
        assert_eq!(SCAN_PIXELS.max, f64::from(64u32 << 20));
        assert_eq!(PATH_LENGTH_M.max, 1000.0 * 1000.0);
    }

    #[test]
    fn nan_and_larger_values_are_refused() {
        assert!(THREADS.allows(1024.0) && !THREADS.allows(1025.0) && !THREADS.allows(f64::NAN));
        assert!(PARTICLES.allows_count(1_000_000) && !PARTICLES.allows_count(u64::MAX));
    }
}
