//! # mmtrack-filter
//!
//! Estimation building blocks shared by the trackers (MPC, beam, SLAM): Kalman
//! predict/update, gating, assignment, the GM-PHD filter and the OSPA/GOSPA
//! metrics. Pure computation on in-memory types: no files, no printing.
