//! [`RadarSimulator`]: sweeps over a trajectory, rendered on demand.

use std::collections::VecDeque;

use mmtrack_core::{PolarScan, StampedPose};
use rayon::prelude::*;

use super::render::RenderContext;
use super::sensor::Prepared;
use super::trajectory::{ScanLimits, Trajectory, scan_stamps};
use super::{Sensor, World};
use crate::SimError;

/// How to run a simulation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SimOptions {
    /// Seed of every random draw (noise, speckle). The output depends on it
    /// and on the inputs only, never on the thread count.
    pub seed: u64,
    /// Which sweeps to render.
    pub limits: ScanLimits,
}

/// Renders the sweeps of a trajectory one after the other, as an iterator of
/// `(scan, ground truth)`: the truth is `world_from_vehicle` at the scan's
/// stamp (the time of its first azimuth).
///
/// Sweeps are rendered on the current rayon pool, one per pool thread at a
/// time (so memory holds about that many scans). Each is rendered from
/// `(seed, sweep index)` alone, so the sequence is bit-identical for any
/// thread count, and [`RadarSimulator::render`] gives any single sweep
/// without the ones before it.
pub struct RadarSimulator<'a> {
    context: RenderContext<'a>,
    stamps: Vec<i64>,
    next: usize,
    ready: VecDeque<(PolarScan, StampedPose)>,
}

impl<'a> RadarSimulator<'a> {
    /// Checks the sensor and plans the sweeps (one every sweep period from
    /// the trajectory's start, each wholly inside its span, cut by the limits).
    pub fn new(
        world: &'a World,
        sensor: &'a Sensor,
        trajectory: &'a Trajectory,
        options: SimOptions,
    ) -> Result<Self, SimError> {
        sensor.validate()?;
        let stamps = scan_stamps(trajectory, sensor.sweep_ns(), options.limits)?;
        let prepared = Prepared::new(sensor, options.seed);
        Ok(Self {
            context: RenderContext { world, sensor, prepared, trajectory, seed: options.seed },
            stamps,
            next: 0,
            ready: VecDeque::new(),
        })
    }

    /// Stamps of all planned sweeps, nanoseconds.
    #[must_use]
    pub fn stamps(&self) -> &[i64] {
        &self.stamps
    }

    /// Sweep `index` and its ground truth, or `None` past the last.
    #[must_use]
    pub fn render(&self, index: usize) -> Option<(PolarScan, StampedPose)> {
        let t_ns = *self.stamps.get(index)?;
        let scan = self.context.render(index as u64, t_ns);
        Some((scan, StampedPose { t_ns, parent_from_child: self.context.trajectory.pose_at(t_ns) }))
    }

    fn refill(&mut self) {
        let end = (self.next + rayon::current_num_threads()).min(self.stamps.len());
        let rendered: Vec<Option<(PolarScan, StampedPose)>> =
            (self.next..end).into_par_iter().map(|i| self.render(i)).collect();
        self.next = end;
        self.ready.extend(rendered.into_iter().flatten());
    }
}

impl Iterator for RadarSimulator<'_> {
    type Item = (PolarScan, StampedPose);

    fn next(&mut self) -> Option<Self::Item> {
        if self.ready.is_empty() {
            self.refill();
        }
        self.ready.pop_front()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.stamps.len() - self.next + self.ready.len();
        (left, Some(left))
    }
}

impl ExactSizeIterator for RadarSimulator<'_> {}
