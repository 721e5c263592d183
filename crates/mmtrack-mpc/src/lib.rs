//! # mmtrack-mpc
//!
//! Multipath-component (MPC) detection and tracking in wideband channel-sounder
//! data, after Mahler et al., "Tracking of Wideband Multipath Components in a
//! Vehicular Communication Scenario", IEEE TVT 66(1), 2017.
