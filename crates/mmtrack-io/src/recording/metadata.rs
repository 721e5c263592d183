//! Recording-level metadata (the MCAP metadata record `mmtrack.recording`)
//! and the time base it names.

use std::collections::BTreeMap;

/// What `t_ns` counts from. Only [`TimeBase::UnixEpoch`] is a date; viewers
/// that show log times as dates (Foxglove) show the others near 1970-01-01.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeBase {
    /// Nanoseconds since the UNIX epoch (real recordings).
    UnixEpoch,
    /// A simulated scenario's clock: nanoseconds since the UNIX epoch, the
    /// scenario starting at its stated `start_t_ns` (simulators default to
    /// 2023-11-14 22:13:20 UTC), not a time anything was measured.
    ScenarioStart,
    /// A simulator's clock (ROS 2 `/clock`, `use_sim_time`), as the source
    /// stamps it: counts from the simulation's start, not a date.
    SimTime,
    /// Nanoseconds since an unknown instant at or before the start of the
    /// source's log (the source has no absolute time, e.g. a row index times
    /// a period, or a receiver's free-running counter).
    Relative,
}

impl TimeBase {
    /// Every time base.
    pub const ALL: [TimeBase; 4] = [Self::UnixEpoch, Self::ScenarioStart, Self::SimTime, Self::Relative];

    /// Value stored under the metadata key `time_base`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::UnixEpoch => "unix_epoch",
            Self::ScenarioStart => "scenario_start",
            Self::SimTime => "sim_time",
            Self::Relative => "relative",
        }
    }

    /// What the value means, stored beside it under `time_base.meaning`.
    #[must_use]
    pub fn meaning(self) -> &'static str {
        match self {
            Self::UnixEpoch => "t_ns and log times are nanoseconds since 1970-01-01 00:00 UTC (UNIX time)",
            Self::ScenarioStart => {
                "t_ns and log times are a simulated scenario's clock in nanoseconds since 1970-01-01 00:00 UTC: \
                 the scenario starts at its start_t_ns (by default 2023-11-14 22:13:20 UTC), a stated date, not when \
                 anything was measured"
            }
            Self::SimTime => {
                "t_ns and log times are a simulator's clock (ROS sim time) as the source stamps them, not UNIX time \
                 (viewers showing dates show dates near 1970-01-01)"
            }
            Self::Relative => {
                "t_ns and log times count from an unknown instant at or before the start of the source's log; the \
                 source has no absolute time (viewers showing dates show dates near 1970-01-01)"
            }
        }
    }

    /// Parses [`TimeBase::as_str`].
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.as_str() == s)
    }

    /// The time base of a source's stamps that may or may not be UNIX time:
    /// `otherwise` (e.g. [`TimeBase::SimTime`] for a ROS 2 bag,
    /// [`TimeBase::Relative`] for a log without dates) when the first stamp
    /// lies before 2000-01-01 (no real recording of ours is older, and sim
    /// time and relative logs start near 0), else [`TimeBase::UnixEpoch`].
    #[must_use]
    pub fn unix_or(first_t_ns: i64, otherwise: TimeBase) -> Self {
        if first_t_ns < YEAR_2000_NS { otherwise } else { Self::UnixEpoch }
    }
}

/// 2000-01-01 00:00:00 UTC, nanoseconds since the UNIX epoch: stamps before
/// it are taken as not UNIX time ([`TimeBase::unix_or`]).
pub const YEAR_2000_NS: i64 = 946_684_800_000_000_000;

/// Metadata key holding [`TimeBase::meaning`].
pub const TIME_BASE_MEANING_KEY: &str = "time_base.meaning";

/// Recording-level metadata, stored as the MCAP metadata record `mmtrack.recording`.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingMetadata {
    /// Sequence identifier (becomes the `sequence=` partition of every table).
    pub sequence_id: String,
    /// Where the data came from, e.g. `oxford:/data/2019-01-10-14-36-48` or `simulate:scenario.toml`.
    pub source: String,
    /// What `t_ns` counts from.
    pub time_base: TimeBase,
    /// Sensor configuration and provenance, e.g. `radar.model = CTS350-X`.
    pub extra: BTreeMap<String, String>,
}

impl RecordingMetadata {
    /// Parses the map stored in a recording (the inverse of [`Self::to_map`]);
    /// `None` when a required key is missing.
    #[must_use]
    pub fn from_map(map: &BTreeMap<String, String>) -> Option<Self> {
        let mut extra = map.clone();
        let sequence_id = extra.remove("sequence_id")?;
        let source = extra.remove("source")?;
        let time_base = TimeBase::parse(&extra.remove("time_base")?)?;
        extra.remove("mmtrack_version");
        extra.remove(TIME_BASE_MEANING_KEY);
        Some(Self { sequence_id, source, time_base, extra })
    }

    /// Flattens to the string map stored in the file.
    #[must_use]
    pub fn to_map(&self) -> BTreeMap<String, String> {
        let mut map = self.extra.clone();
        map.insert("sequence_id".into(), self.sequence_id.clone());
        map.insert("source".into(), self.source.clone());
        map.insert("time_base".into(), self.time_base.as_str().into());
        map.insert(TIME_BASE_MEANING_KEY.into(), self.time_base.meaning().into());
        map.insert("mmtrack_version".into(), env!("CARGO_PKG_VERSION").into());
        map
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_time_base_round_trips_with_its_meaning() {
        for time_base in TimeBase::ALL {
            let metadata = RecordingMetadata {
                sequence_id: "s".into(),
                source: "test".into(),
                time_base,
                extra: BTreeMap::from([("time.note".to_string(), "n".to_string())]),
            };
            let map = metadata.to_map();
            assert_eq!(map["time_base"], time_base.as_str());
            assert_eq!(map[TIME_BASE_MEANING_KEY], time_base.meaning());
            assert_eq!(RecordingMetadata::from_map(&map), Some(metadata));
        }
        assert_eq!(TimeBase::parse("gps_week"), None);
    }

    #[test]
    fn stamps_before_2000_are_not_unix_time() {
        assert_eq!(TimeBase::unix_or(928_800_000_000, TimeBase::SimTime), TimeBase::SimTime);
        assert_eq!(TimeBase::unix_or(YEAR_2000_NS - 1, TimeBase::Relative), TimeBase::Relative);
        assert_eq!(TimeBase::unix_or(YEAR_2000_NS, TimeBase::Relative), TimeBase::UnixEpoch);
        assert_eq!(TimeBase::unix_or(1_547_131_046_353_776_000, TimeBase::SimTime), TimeBase::UnixEpoch);
    }
}
