//! Reading 5G mmWave SLAM epochs: path measurements, the simulator's truth
//! and the sources of the paths.

use mmtrack_core::slam::{PathMeasurement, PathOrigin, SlamEpoch, SourceType, UeState};

use super::{RawMessage, RecordingEvent, RecordingReader};
use crate::error::Result;
use crate::proto;
use crate::recording::channels::{SLAM_PATHS_TOPIC, SLAM_SOURCES_TOPIC, SLAM_UE_TRUTH_TOPIC};

impl RecordingReader {
    /// The event of a message on a SLAM topic, `None` for other topics.
    /// Lists of different lengths and unknown source types are errors naming
    /// the message; the measured values are passed on unchecked (the SLAM
    /// pipeline refuses or skips NaNs and elevations out of range).
    pub(super) fn decode_slam(&self, m: &RawMessage) -> Result<Option<RecordingEvent>> {
        match m.channel.topic.as_str() {
            SLAM_PATHS_TOPIC => {
                let p: proto::PathMeasurements = self.decode(m)?;
                let n = p.toa_m.len();
                let lengths = [p.doa_az_rad.len(), p.doa_el_rad.len(), p.dod_az_rad.len(), p.dod_el_rad.len()];
                if lengths.iter().any(|l| *l != n) {
                    return Err(self.bad(
                        m,
                        format!(
                            "toa_m has {n} values but doa_az_rad, doa_el_rad, dod_az_rad, dod_el_rad have {lengths:?}"
                        ),
                    ));
                }
                let paths = (0..n)
                    .map(|i| PathMeasurement {
                        toa_m: p.toa_m[i],
                        doa_az_rad: p.doa_az_rad[i],
                        doa_el_rad: p.doa_el_rad[i],
                        dod_az_rad: p.dod_az_rad[i],
                        dod_el_rad: p.dod_el_rad[i],
                    })
                    .collect();
                Ok(Some(RecordingEvent::SlamPaths(SlamEpoch { t_ns: p.t_ns, paths })))
            }
            SLAM_UE_TRUTH_TOPIC => {
                let t: proto::SlamUeTruth = self.decode(m)?;
                if t.path_source.len() != t.path_source_index.len() {
                    return Err(self.bad(
                        m,
                        format!(
                            "path_source has {} values but path_source_index has {}",
                            t.path_source.len(),
                            t.path_source_index.len()
                        ),
                    ));
                }
                let mut origins = Vec::with_capacity(t.path_source.len());
                for (i, (kind, index)) in t.path_source.iter().zip(&t.path_source_index).enumerate() {
                    let index = *index as usize;
                    origins.push(match kind.as_str() {
                        "bs" => PathOrigin::LineOfSight,
                        "va" => PathOrigin::VirtualAnchor(index),
                        "sp" => PathOrigin::ScatteringPoint(index),
                        "clutter" => PathOrigin::Clutter,
                        other => {
                            return Err(
                                self.bad(m, format!("path {i}: path_source '{other}', expected bs, va, sp or clutter"))
                            );
                        }
                    });
                }
                let ue = UeState {
                    position_m: [t.x_m, t.y_m, t.z_m],
                    heading_rad: t.heading_rad,
                    speed_mps: t.speed_mps,
                    turn_rate_radps: t.turn_rate_radps,
                    clock_bias_m: t.clock_bias_m,
                };
                Ok(Some(RecordingEvent::SlamUeTruth { t_ns: t.t_ns, ue, origins }))
            }
            SLAM_SOURCES_TOPIC => {
                let s: proto::SlamSource = self.decode(m)?;
                let kind = match s.kind.as_str() {
                    "bs" => SourceType::BaseStation,
                    "va" => SourceType::VirtualAnchor,
                    "sp" => SourceType::ScatteringPoint,
                    other => return Err(self.bad(m, format!("kind '{other}', expected bs, va or sp"))),
                };
                Ok(Some(RecordingEvent::SlamSource {
                    t_ns: s.t_ns,
                    kind,
                    index: s.index as usize,
                    position_m: [s.x_m, s.y_m, s.z_m],
                }))
            }
            _ => Ok(None),
        }
    }
}
