//! [`RadarSimulator`]: sweeps over a trajectory, rendered on demand.

use std::collections::VecDeque;

use mmtrack_core::{PolarScan, StampedPose};

use super::render::RenderContext;
use super::sensor::Prepared;
use super::trajectory::{ScanLimits, Trajectory, scan_stamps};
use super::{Sensor, World};
use crate::SimError;

/// How to run a simulation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SimOptions {
    /// Seed of every random draw (noise, speckle). The output depends on it
    /// and on the inputs only, never on `threads`.
    pub seed: u64,
    /// Which sweeps to render.
    pub limits: ScanLimits,
    /// Worker threads; 0 = as many as the machine has. Sweeps are rendered
    /// `threads` at a time, so memory holds at most that many scans.
    pub threads: usize,
}

/// Renders the sweeps of a trajectory one after the other, as an iterator of
/// `(scan, ground truth)`: the truth is `world_from_vehicle` at the scan's
/// stamp (the time of its first azimuth).
///
/// Each sweep is rendered from `(seed, sweep index)` alone, so the sequence
/// is bit-identical for any thread count, and [`RadarSimulator::render`]
/// gives any single sweep without the ones before it.
pub struct RadarSimulator<'a> {
    context: RenderContext<'a>,
    stamps: Vec<i64>,
    next: usize,
    threads: usize,
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
        let threads = match options.threads {
            0 => std::thread::available_parallelism().map_or(1, std::num::NonZero::get),
            n => n,
        };
        let prepared = Prepared::new(sensor, options.seed);
        Ok(Self {
            context: RenderContext { world, sensor, prepared, trajectory, seed: options.seed },
            stamps,
            next: 0,
            threads,
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
        let end = (self.next + self.threads).min(self.stamps.len());
        let indices: Vec<usize> = (self.next..end).collect();
        self.next = end;
        if indices.len() <= 1 {
            let rendered: Vec<_> = indices.iter().filter_map(|i| self.render(*i)).collect();
            self.ready.extend(rendered);
            return;
        }
        let this = &*self;
        let rendered: Vec<Option<(PolarScan, StampedPose)>> = std::thread::scope(|scope| {
            let handles: Vec<_> = indices.iter().map(|i| scope.spawn(move || this.render(*i))).collect();
            // A worker panics only on a bug; re-raise it on the caller's thread.
            handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
        });
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
