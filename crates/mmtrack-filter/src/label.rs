//! The identity of a component lineage, shared by the gate role
//! ([`crate::gating`]) and the GM-PHD filter ([`crate::gmphd`], whose
//! labelling rule gives it meaning).

/// Identity of a component lineage; extracted states with the same label form
/// a track.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Label(pub u64);
