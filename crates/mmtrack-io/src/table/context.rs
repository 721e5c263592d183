//! What a table's numbers are measured against: the time base of its `t_ns`
//! and the coordinate frame of its positions and angles, stated in every
//! file's key-value metadata (`time_base`, `time_base.meaning`, `frame`,
//! `frame.meaning`, `frame.origin`) so a file explains itself without the
//! recording it came from.

use std::collections::BTreeMap;
use std::path::Path;

use crate::error::Result;
use crate::recording::{RecordingMetadata, TIME_BASE_MEANING_KEY, TimeBase};

/// Key of the time base in a table file's key-value metadata.
pub const TIME_BASE_KEY: &str = "time_base";
/// Key of the frame in a table file's key-value metadata.
pub const FRAME_KEY: &str = "frame";
/// Key of the frame's meaning.
pub const FRAME_MEANING_KEY: &str = "frame.meaning";
/// Key of the frame's origin (JSON object), where the frame has one the
/// recording names (a GNSS origin, a UTM origin).
pub const FRAME_ORIGIN_KEY: &str = "frame.origin";
/// `frame` of a table that holds no positions or angles.
pub const FRAME_NOT_APPLICABLE: &str = "not_applicable";

/// How a table declares the frame of its positions and angles
/// ([`TableSpec::frame`](super::TableSpec::frame)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFrame {
    /// No positions or angles in a coordinate frame (counts, delays, powers,
    /// errors, indices): `frame = not_applicable`, said explicitly.
    NotApplicable,
    /// Positions in the world frame of the run's input, which the writer must
    /// state ([`RunInfo::frame`](super::RunInfo::frame)); a write without it fails.
    Run,
    /// A frame fixed by the table's definition.
    Fixed {
        /// Short name, the `frame` value.
        id: &'static str,
        /// What it is, the `frame.meaning` value.
        meaning: &'static str,
    },
}

impl TableFrame {
    /// The text `schemas/tables/<name>.md` shows.
    #[must_use]
    pub fn doc(self) -> String {
        match self {
            Self::NotApplicable => format!("`{FRAME_NOT_APPLICABLE}`: {NOT_APPLICABLE_MEANING}"),
            Self::Run => "the run's world frame, stated by the writer from its input (`frame`, `frame.meaning`, and \
                          `frame.origin` where the recording names an origin)"
                .to_string(),
            Self::Fixed { id, meaning } => format!("`{id}`: {meaning}"),
        }
    }
}

/// `frame.meaning` of [`TableFrame::NotApplicable`].
pub const NOT_APPLICABLE_MEANING: &str = "the table holds no positions or angles in a coordinate frame (only times, counts, delays, powers, errors or indices)";

/// The world frame of a run's positions, as its writer states it.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Short name, e.g. `ground_truth` or `first_scan`.
    pub id: String,
    /// What it is, one or two sentences.
    pub meaning: String,
    /// The origin the recording names for it (keys and values as the
    /// recording's metadata gives them, e.g. `latitude_deg`,
    /// `longitude_deg`, `altitude_m` of a GNSS origin, or a UTM
    /// `north_m`/`east_m`), `None` when the frame has no such origin.
    pub origin: Option<BTreeMap<String, String>>,
}

impl Frame {
    /// A frame without an origin.
    #[must_use]
    pub fn new(id: impl Into<String>, meaning: impl Into<String>) -> Self {
        Self { id: id.into(), meaning: meaning.into(), origin: None }
    }

    /// The frame of a recording's ground truth: `id` and `meaning` as the
    /// writer knows them, followed by the recording's own word on its ground
    /// truth (`ground_truth.frame`, `ground_truth.source`) and its origin
    /// (`ground_truth.origin_*`, or the GNSS ENU origin `gnss.enu_origin_*`).
    #[must_use]
    pub fn of_recording(id: &str, meaning: &str, metadata: &BTreeMap<String, String>) -> Self {
        let mut meaning = meaning.to_string();
        if let Some(frame) = metadata.get("ground_truth.frame") {
            meaning.push_str(&format!("; the recording's ground truth is in frame '{frame}'"));
        }
        let origin_of = |prefix: &str| -> BTreeMap<String, String> {
            metadata.iter().filter_map(|(k, v)| k.strip_prefix(prefix).map(|k| (k.to_string(), v.clone()))).collect()
        };
        let mut origin = origin_of("ground_truth.origin_");
        if origin.is_empty() {
            origin = origin_of("gnss.enu_origin_");
            if !origin.is_empty() {
                meaning.push_str("; local east-north-up about the recording's GNSS origin (frame.origin, WGS-84)");
            }
        } else {
            meaning.push_str("; origin as the recording's ground_truth.origin_* keys give it (frame.origin)");
        }
        Self { id: id.to_string(), meaning, origin: (!origin.is_empty()).then_some(origin) }
    }
}

/// The time base of a table's `t_ns` (the `time_base` and
/// `time_base.meaning` keys): the input recording's [`TimeBase`], carried
/// along by every table derived from it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TableTimeBase {
    /// [`TimeBase::as_str`]; `mixed` for a table pooling inputs of different
    /// time bases; `caller` for the Python array calls (the caller's `t_ns`).
    pub name: String,
    /// What it means.
    pub meaning: String,
}

impl From<TimeBase> for TableTimeBase {
    fn from(time_base: TimeBase) -> Self {
        Self { name: time_base.as_str().to_string(), meaning: time_base.meaning().to_string() }
    }
}

impl From<&RecordingMetadata> for TableTimeBase {
    fn from(metadata: &RecordingMetadata) -> Self {
        metadata.time_base.into()
    }
}

impl TableTimeBase {
    /// The time base of a table pooling `inputs`: theirs when they agree,
    /// else `mixed` naming them (`t_ns` of different sequences is then not
    /// comparable). `None` without inputs.
    #[must_use]
    pub fn pooled<'a>(inputs: impl IntoIterator<Item = &'a TableTimeBase>) -> Option<Self> {
        let mut distinct: Vec<&TableTimeBase> = Vec::new();
        for t in inputs {
            if !distinct.contains(&t) {
                distinct.push(t);
            }
        }
        match distinct.as_slice() {
            [] => None,
            [one] => Some((*one).clone()),
            many => Some(Self {
                name: "mixed".to_string(),
                meaning: format!(
                    "pooled over inputs of different time bases ({}); t_ns of different sequences is not comparable",
                    many.iter().map(|t| t.name.as_str()).collect::<Vec<_>>().join(", ")
                ),
            }),
        }
    }

    /// The time base a table file states (`None` for a file written without one).
    ///
    /// # Errors
    /// An unreadable or corrupt file.
    pub fn of_table_file(path: &Path) -> Result<Option<Self>> {
        let kv = crate::table_kv::read_key_value_metadata(path)?;
        Ok(kv.get(TIME_BASE_KEY).map(|name| Self {
            name: name.clone(),
            meaning: kv.get(TIME_BASE_MEANING_KEY).cloned().unwrap_or_default(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{GROUND_TRUTH, ODOMETRY_TIMING, RADAR_SCANS, RunInfo};

    fn map(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
        pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    #[test]
    fn a_recording_frame_carries_the_origin_the_recording_names() {
        let utm = map(&[
            ("ground_truth.frame", "ins (local east-north frame about the origin)"),
            ("ground_truth.origin_north_m", "5736001"),
            ("ground_truth.origin_east_m", "620000"),
        ]);
        let frame = Frame::of_recording("ground_truth", "gt", &utm);
        assert_eq!(frame.origin, Some(map(&[("north_m", "5736001"), ("east_m", "620000")])));
        assert!(frame.meaning.contains("ins (local east-north frame about the origin)"), "{}", frame.meaning);
        let gnss = map(&[("gnss.enu_origin_latitude_deg", "51.76"), ("gnss.enu_origin_longitude_deg", "-1.26")]);
        let frame = Frame::of_recording("ground_truth", "gt", &gnss);
        assert_eq!(frame.origin, Some(map(&[("latitude_deg", "51.76"), ("longitude_deg", "-1.26")])));
        assert!(frame.meaning.contains("GNSS origin"), "{}", frame.meaning);
        assert_eq!(Frame::of_recording("ground_truth", "gt", &map(&[("radar.model", "x")])).origin, None);
    }

    #[test]
    fn every_table_states_time_base_and_frame_and_a_positions_table_needs_the_run_frame() {
        let run = RunInfo::new("{}", TimeBase::ScenarioStart);
        let kv = |spec| run.context_metadata(spec).unwrap().into_iter().collect::<BTreeMap<_, _>>();
        let timing = kv(&ODOMETRY_TIMING);
        assert_eq!(timing[TIME_BASE_KEY], "scenario_start");
        assert_eq!(timing[FRAME_KEY], FRAME_NOT_APPLICABLE);
        assert_eq!(kv(&RADAR_SCANS)[FRAME_KEY], "radar_sensor");
        let err = run.context_metadata(&GROUND_TRUTH).unwrap_err();
        assert!(err.contains("table ground_truth holds positions but the run states no frame"), "{err}");
        let origin = map(&[("latitude_deg", "51.76")]);
        let framed = run.with_frame(Frame { id: "enu".into(), meaning: "m".into(), origin: Some(origin) });
        let truth: BTreeMap<_, _> = framed.context_metadata(&GROUND_TRUTH).unwrap().into_iter().collect();
        assert_eq!(
            (truth[FRAME_KEY].as_str(), truth[FRAME_ORIGIN_KEY].as_str()),
            ("enu", r#"{"latitude_deg":"51.76"}"#)
        );
    }

    #[test]
    fn pooled_time_bases_agree_or_say_mixed() {
        let unix = TableTimeBase::from(TimeBase::UnixEpoch);
        let scenario = TableTimeBase::from(TimeBase::ScenarioStart);
        assert_eq!(TableTimeBase::pooled([&unix, &unix]), Some(unix.clone()));
        let mixed = TableTimeBase::pooled([&unix, &scenario]).unwrap();
        assert_eq!(mixed.name, "mixed");
        assert!(mixed.meaning.contains("unix_epoch, scenario_start"), "{}", mixed.meaning);
        assert_eq!(TableTimeBase::pooled([]), None);
    }
}
