//! The beam trackers as pipelines: the sweep trackers on measured beam
//! sweeps ([`sweep`]), SPEBT along a recording's ground truth ([`spebt`]) and
//! geometric Doppler-bearing tracking between two vehicles ([`geometric`]).

pub mod geometric;
pub mod spebt;
pub mod sweep;
