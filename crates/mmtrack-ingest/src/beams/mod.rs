//! Measured beam sweeps: a phased array sweeping a codebook of beams while a
//! vehicle drives past, with both units' positions.
//!
//! Each source becomes canonical recordings with beam sweeps on
//! `/beam/sweeps` (`mmtrack.BeamSweep`), the vehicle's GNSS fixes on
//! `/gnss/fix` and the sweeping array's on `/gnss/array`; one recording per
//! pass of the vehicle, since a pass is the unit a tracker starts afresh on.
//!
//! Sources so far: the DeepSense 6G 60 GHz arrays ([`deepsense`]).

pub mod deepsense;

pub use deepsense::{
    DeepsenseOptions, PassRecording, ScenarioArrays, ScenarioFiles, VehiclePositions, find_scenarios, ingest_deepsense,
    read_scenario,
};
