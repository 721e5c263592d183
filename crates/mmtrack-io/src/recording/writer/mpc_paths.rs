//! Display markers of a simulated sounder run's true propagation paths.

use foxglove::schemas::{Color, LinePrimitive, Point3, SceneEntity, SceneUpdate};
use mmtrack_core::PathGeometry;

use super::RecordingWriter;
use crate::error::Result;
use crate::recording::channels::MPC_PATHS_VIZ_TOPIC;
use crate::recording::tf::{WORLD_FRAME, timestamp};

/// Colour of a path by its number of interactions: direct (blue), one
/// bounce or scatterer (orange), two bounces (green).
fn interactions_color(interactions: usize) -> Color {
    let (r, g, b) = match interactions {
        0 => (0.12, 0.47, 0.71),
        1 => (1.0, 0.50, 0.05),
        _ => (0.17, 0.63, 0.17),
    };
    Color { r, g, b, a: 1.0 }
}

impl RecordingWriter {
    /// Writes where the true paths run at `t_ns` as lines in the 3D panel
    /// (`/viz/mpc_paths`, one `foxglove.SceneUpdate` per call, entity
    /// `paths` replacing the previous one): one line strip per path from
    /// the transmitter through its interaction points to the receiver,
    /// coloured by its number of interactions. Nothing without Foxglove views.
    pub fn write_mpc_paths(&mut self, t_ns: i64, paths: &[PathGeometry]) -> Result<()> {
        if !self.foxglove_views {
            return Ok(());
        }
        let lines = paths
            .iter()
            .map(|path| LinePrimitive {
                r#type: 0, // LINE_STRIP
                thickness: 2.0,
                scale_invariant: true,
                points: path.points_m.iter().map(|p| Point3 { x: p[0], y: p[1], z: 0.0 }).collect(),
                color: Some(interactions_color(path.points_m.len().saturating_sub(2))),
                ..Default::default()
            })
            .collect();
        let entity = SceneEntity {
            timestamp: timestamp(t_ns),
            frame_id: WORLD_FRAME.into(),
            id: "paths".into(),
            lines,
            ..Default::default()
        };
        self.write_foxglove(
            MPC_PATHS_VIZ_TOPIC,
            t_ns,
            &SceneUpdate { deletions: vec![], entities: vec![entity] },
            None,
        )?;
        Ok(())
    }
}
