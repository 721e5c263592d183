//! Writing 5G mmWave SLAM epochs: path measurements, the simulator's truth
//! and the sources of the paths.

use foxglove::schemas::{
    Color, LinePrimitive, Point3, Pose, SceneEntity, SceneEntityDeletion, SceneUpdate, SpherePrimitive, TextPrimitive,
    Vector3, scene_entity_deletion,
};
use mmtrack_core::slam::{PathOrigin, SlamEpoch, SourceType, UeState};

use super::RecordingWriter;
use crate::error::{IoError, Result};
use crate::proto;
use crate::recording::channels::{
    SLAM_ESTIMATE_VIZ_TOPIC, SLAM_PATHS_TOPIC, SLAM_PATHS_VIZ_TOPIC, SLAM_SOURCES_TOPIC, SLAM_SOURCES_VIZ_TOPIC,
    SLAM_UE_TRUTH_TOPIC,
};
use crate::recording::tf::{WORLD_FRAME, timestamp};
use crate::table::SlamMapRow;

/// Diameter of a source's sphere in the 3D panel, metres.
const SOURCE_MARKER_M: f64 = 1.5;

/// Largest diameter of an estimated source's sphere, metres: a wider belief
/// is drawn at this size (its label states the spread).
const ESTIMATE_MARKER_MAX_M: f64 = 10.0;

/// The display colour of a kind of source (`bs`, `va`, `sp`).
fn kind_color(kind: &str) -> Color {
    let (r, g, b) = match kind {
        "bs" => (0.12, 0.47, 0.71),
        "va" => (1.0, 0.50, 0.05),
        _ => (0.17, 0.63, 0.17),
    };
    Color { r, g, b, a: 1.0 }
}

/// Pose of a marker at `position_m`, lifted by `lift_m`.
fn marker_pose(position_m: [f64; 3], lift_m: f64) -> Pose {
    Pose {
        position: Some(Vector3 { x: position_m[0], y: position_m[1], z: position_m[2] + lift_m }),
        orientation: Some(crate::recording::tf::yaw_quaternion(0.0)),
    }
}

/// A source's label in the 3D panel.
fn source_label(text: String) -> TextPrimitive {
    TextPrimitive {
        billboard: true,
        font_size: 14.0,
        scale_invariant: true,
        color: Some(Color { r: 1.0, g: 1.0, b: 1.0, a: 1.0 }),
        text,
        ..Default::default()
    }
}

fn point(p: [f64; 3]) -> Point3 {
    Point3 { x: p[0], y: p[1], z: p[2] }
}

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
        if self.foxglove_views {
            let update = self.path_markers(t_ns, ue.position_m, origins);
            self.write_foxglove(SLAM_PATHS_VIZ_TOPIC, t_ns, &update, None)?;
        }
        Ok(())
    }

    /// The epoch's true paths as line segments, one line list per kind of
    /// source (channel docs of `/viz/slam_paths`); a path whose source was
    /// not written has no line.
    fn path_markers(&self, t_ns: i64, ue_m: [f64; 3], origins: &[PathOrigin]) -> SceneUpdate {
        let source = |kind: &'static str, index: usize| self.slam_sources_m.get(&(kind, index)).copied();
        let mut lines: Vec<(&str, Vec<Point3>)> = vec![("bs", Vec::new()), ("va", Vec::new()), ("sp", Vec::new())];
        for origin in origins {
            let (slot, segments) = match *origin {
                PathOrigin::LineOfSight => (0, source("bs", 0).map(|bs| vec![bs, ue_m])),
                PathOrigin::VirtualAnchor(v) => (1, source("va", v).map(|va| vec![va, ue_m])),
                PathOrigin::ScatteringPoint(s) => {
                    (2, source("bs", 0).zip(source("sp", s)).map(|(bs, sp)| vec![bs, sp, sp, ue_m]))
                }
                PathOrigin::Clutter => continue,
            };
            lines[slot].1.extend(segments.unwrap_or_default().into_iter().map(point));
        }
        let entity = SceneEntity {
            timestamp: timestamp(t_ns),
            frame_id: WORLD_FRAME.into(),
            id: "paths".into(),
            lines: lines
                .into_iter()
                .filter(|(_, points)| !points.is_empty())
                .map(|(kind, points)| LinePrimitive {
                    r#type: 2, // LINE_LIST: segments 0-1, 2-3, ...
                    thickness: 2.0,
                    scale_invariant: true,
                    points,
                    color: Some(kind_color(kind)),
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        };
        SceneUpdate { deletions: vec![], entities: vec![entity] }
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
        self.slam_sources_m.insert((kind.name(), index), position_m);
        if self.foxglove_views {
            let label = match kind {
                SourceType::BaseStation => "BS".to_string(),
                SourceType::VirtualAnchor => format!("VA {index}"),
                SourceType::ScatteringPoint => format!("SP {index}"),
            };
            let entity = SceneEntity {
                timestamp: timestamp(t_ns),
                frame_id: WORLD_FRAME.into(),
                id: format!("{}-{index}", kind.name()),
                spheres: vec![SpherePrimitive {
                    pose: Some(marker_pose(position_m, 0.0)),
                    size: Some(Vector3 { x: SOURCE_MARKER_M, y: SOURCE_MARKER_M, z: SOURCE_MARKER_M }),
                    color: Some(kind_color(kind.name())),
                }],
                texts: vec![TextPrimitive {
                    pose: Some(marker_pose(position_m, SOURCE_MARKER_M)),
                    ..source_label(label)
                }],
                ..Default::default()
            };
            self.write_foxglove(
                SLAM_SOURCES_VIZ_TOPIC,
                t_ns,
                &SceneUpdate { deletions: vec![], entities: vec![entity] },
                None,
            )?;
        }
        Ok(())
    }

    /// Writes the filter's map after the epoch at `t_ns` (rows of table
    /// `slam_map` of that epoch) as display markers on `/viz/slam_estimate`:
    /// one `foxglove.SceneUpdate` that first deletes the entities of earlier
    /// epochs, then one sphere per source, `est-<source_id>`, as wide as
    /// twice the belief's spread (between the truth markers' 1.5 m and
    /// 10 m), the base station and confirmed VAs / SPs in their kind's
    /// colour half transparent, unconfirmed sources grey, with a label
    /// (`VA 3 est, 0.42 m`). Nothing without Foxglove views.
    pub fn write_slam_estimate(&mut self, t_ns: i64, sources: &[SlamMapRow]) -> Result<()> {
        if !self.foxglove_views {
            return Ok(());
        }
        let entities = sources
            .iter()
            .map(|source| {
                let position_m = [source.x_m, source.y_m, source.z_m];
                let diameter_m = (2.0 * source.spread_m).clamp(SOURCE_MARKER_M, ESTIMATE_MARKER_MAX_M);
                let color = if source.confirmed {
                    Color { a: 0.5, ..kind_color(&source.status) }
                } else {
                    Color { r: 0.6, g: 0.6, b: 0.6, a: 0.35 }
                };
                let label =
                    format!("{} {} est, {:.2} m", source.status.to_uppercase(), source.source_id, source.spread_m);
                SceneEntity {
                    timestamp: timestamp(t_ns),
                    frame_id: WORLD_FRAME.into(),
                    id: format!("est-{}", source.source_id),
                    spheres: vec![SpherePrimitive {
                        pose: Some(marker_pose(position_m, 0.0)),
                        size: Some(Vector3 { x: diameter_m, y: diameter_m, z: diameter_m }),
                        color: Some(color),
                    }],
                    texts: vec![TextPrimitive {
                        pose: Some(marker_pose(position_m, 0.5 * diameter_m + 0.5)),
                        ..source_label(label)
                    }],
                    ..Default::default()
                }
            })
            .collect();
        let update = SceneUpdate {
            deletions: vec![SceneEntityDeletion {
                timestamp: timestamp(t_ns),
                r#type: scene_entity_deletion::Type::All as i32,
                id: String::new(),
            }],
            entities,
        };
        self.write_foxglove(SLAM_ESTIMATE_VIZ_TOPIC, t_ns, &update, None)?;
        Ok(())
    }
}
