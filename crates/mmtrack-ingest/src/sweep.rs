//! Per-azimuth times and angles for polar images that carry none (MulRan
//! PNGs, ROS 2 `sensor_msgs/Image`): the sweep's azimuths spread evenly over
//! one scan period, placed against the one stamp the image has.
//!
//! Which end of the sweep the stamp marks is not written in these formats.
//! The default, [`StampAt::End`], puts the last azimuth at the stamp: a
//! Navtech driver hands a sweep over once its last azimuth has arrived, and
//! the recording computer stamps it then, so the stamp cannot precede the
//! last azimuth and exceeds it only by the transfer latency. Had the stamp
//! been the start, every azimuth would be at most one period early; either
//! way the choice is recorded in the metadata and can be changed
//! ([`StampAt::Start`]) when a dataset says otherwise.

use std::f64::consts::TAU;

use mmtrack_core::AzimuthSample;

/// Which azimuth of a sweep the image stamp belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StampAt {
    /// The first azimuth is at the stamp.
    Start,
    /// The last azimuth is at the stamp.
    #[default]
    End,
}

impl StampAt {
    /// The name used in metadata and on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Start => "start",
            Self::End => "end",
        }
    }
}

/// How a sweep's azimuths are laid out in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepTiming {
    /// One revolution, nanoseconds (Navtech: 250 ms at 4 Hz).
    pub period_ns: i64,
    /// Which end of the sweep the stamp marks.
    pub stamp_at: StampAt,
}

impl Default for SweepTiming {
    fn default() -> Self {
        Self { period_ns: 250_000_000, stamp_at: StampAt::End }
    }
}

impl SweepTiming {
    /// `count` azimuths: row `i` at angle `i * 2 pi / count` and time
    /// `stamp + i * period / count` (start) or
    /// `stamp - period + (i + 1) * period / count` (end), in integer
    /// nanoseconds; all valid. Fails when the times would not increase
    /// strictly (a period shorter than `count` ns) or overflow.
    pub fn azimuths(&self, stamp_ns: i64, count: usize) -> Result<Vec<AzimuthSample>, String> {
        let n = i128::try_from(count).map_err(|_| "too many azimuths".to_string())?;
        let period = i128::from(self.period_ns);
        if n == 0 || period < n {
            return Err(format!("{count} azimuths do not fit in a scan period of {} ns", self.period_ns));
        }
        let first = match self.stamp_at {
            StampAt::Start => i128::from(stamp_ns),
            StampAt::End => i128::from(stamp_ns) - period,
        };
        let shift = i128::from(self.stamp_at == StampAt::End);
        (0..n)
            .map(|i| {
                let t = first + (i + shift) * period / n;
                let t_ns = i64::try_from(t).map_err(|_| format!("azimuth {i} time overflows"))?;
                Ok(AzimuthSample { t_ns, azimuth_rad: i as f64 * TAU / count as f64, valid: true })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_puts_the_last_azimuth_at_the_stamp_and_start_the_first() {
        let end = SweepTiming::default().azimuths(1_000_000_000, 400).unwrap();
        assert_eq!(end[399].t_ns, 1_000_000_000);
        assert_eq!(end[0].t_ns, 1_000_000_000 - 250_000_000 + 625_000);
        assert!(end.windows(2).all(|w| w[1].t_ns - w[0].t_ns == 625_000));
        assert_eq!(end[100].azimuth_rad, 100.0 * TAU / 400.0);
        let start = SweepTiming { stamp_at: StampAt::Start, ..SweepTiming::default() }.azimuths(5, 3).unwrap();
        // 250 ms / 3 = 83333333.33 ns: times are floored, still increasing.
        assert_eq!(start.iter().map(|a| a.t_ns).collect::<Vec<_>>(), vec![5, 83_333_338, 166_666_671]);
    }

    #[test]
    fn impossible_timings_are_errors() {
        let tight = SweepTiming { period_ns: 3, stamp_at: StampAt::End };
        assert!(tight.azimuths(10, 4).unwrap_err().contains("do not fit"));
        assert!(SweepTiming::default().azimuths(10, 0).is_err());
        assert!(SweepTiming::default().azimuths(i64::MIN + 5, 4).unwrap_err().contains("overflows"));
    }
}
