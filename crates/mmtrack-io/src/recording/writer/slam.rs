//! Writing 5G mmWave SLAM epochs: path measurements, the simulator's truth
//! and the sources of the paths.

use mmtrack_core::slam::{PathOrigin, SlamEpoch, SourceType, UeState};

use super::RecordingWriter;
use crate::error::{IoError, Result};
use crate::proto;
use crate::recording::channels::{SLAM_PATHS_TOPIC, SLAM_SOURCES_TOPIC, SLAM_UE_TRUTH_TOPIC};

impl RecordingWriter {
    /// Writes the path measurements of one epoch (`mmtrack.PathMeasurements`
    /// on `/slam/paths`, log time `epoch.t_ns`); an epoch without paths is
    /// written too. Values are written as given (a NaN stays a NaN).
    pub fn write_slam_paths(&mut self, epoch: &SlamEpoch) -> Result<()> {
        let p = &epoch.paths;
        let message = proto::PathMeasurements {
            t_ns: epoch.t_ns,
            toa_m: p.iter().map(|z| z.toa_m).collect(),
            doa_az_rad: p.iter().map(|z| z.doa_az_rad).collect(),
            doa_el_rad: p.iter().map(|z| z.doa_el_rad).collect(),
            dod_az_rad: p.iter().map(|z| z.dod_az_rad).collect(),
            dod_el_rad: p.iter().map(|z| z.dod_el_rad).collect(),
        };
        self.write_spec(SLAM_PATHS_TOPIC, epoch.t_ns, &message, None)?;
        Ok(())
    }

    /// Writes the true UE state of the epoch at `t_ns` and the origin of each
    /// of its paths, in the order of its `/slam/paths` message
    /// (`mmtrack.SlamUeTruth` on `/slam/ue_truth`).
    pub fn write_slam_ue_truth(&mut self, t_ns: i64, ue: &UeState, origins: &[PathOrigin]) -> Result<()> {
        let mut path_source = Vec::with_capacity(origins.len());
        let mut path_source_index = Vec::with_capacity(origins.len());
        for (i, origin) in origins.iter().enumerate() {
            let (kind, index) = match origin {
                PathOrigin::LineOfSight => ("bs", 0),
                PathOrigin::VirtualAnchor(v) => ("va", *v),
                PathOrigin::ScatteringPoint(s) => ("sp", *s),
                PathOrigin::Clutter => ("clutter", 0),
            };
            let index = u32::try_from(index).map_err(|_| IoError::BadValue {
                path: self.path().to_path_buf(),
                record: format!("SLAM truth at {t_ns} ns, path {i}"),
                field: "path_source_index",
                detail: format!("{index} does not fit in 32 bits"),
            })?;
            path_source.push(kind.to_string());
            path_source_index.push(index);
        }
        let message = proto::SlamUeTruth {
            t_ns,
            x_m: ue.position_m[0],
            y_m: ue.position_m[1],
            z_m: ue.position_m[2],
            heading_rad: ue.heading_rad,
            speed_mps: ue.speed_mps,
            turn_rate_radps: ue.turn_rate_radps,
            clock_bias_m: ue.clock_bias_m,
            path_source,
            path_source_index,
        };
        self.write_spec(SLAM_UE_TRUTH_TOPIC, t_ns, &message, None)?;
        Ok(())
    }

    /// Writes one source of the paths (`mmtrack.SlamSource` on
    /// `/slam/sources`): the base station or a true VA or SP, `index` among
    /// the sources of its kind.
    pub fn write_slam_source(&mut self, t_ns: i64, kind: SourceType, index: usize, position_m: [f64; 3]) -> Result<()> {
        let index_u32 = u32::try_from(index).map_err(|_| IoError::BadValue {
            path: self.path().to_path_buf(),
            record: format!("SLAM source {} {index}", kind.name()),
            field: "index",
            detail: format!("{index} does not fit in 32 bits"),
        })?;
        let message = proto::SlamSource {
            t_ns,
            kind: kind.name().to_string(),
            index: index_u32,
            x_m: position_m[0],
            y_m: position_m[1],
            z_m: position_m[2],
        };
        self.write_spec(SLAM_SOURCES_TOPIC, t_ns, &message, None)?;
        Ok(())
    }
}
