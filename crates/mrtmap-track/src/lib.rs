//! # mrtmap-track
//!
//! Poses for a recording that has colour and depth frames but no pose source: the built-in RGB-D
//! tracker ([`track`]) and the pose graph it closes loops with ([`pose_graph`], also used for
//! RTAB-Map databases that did not save their optimised graph). It needs only the recording and
//! depth back-projection (mrtmap-io's [`depth`](mrtmap_io::depth)), not the scan pipeline, so
//! source conversion can use its pose graph.

pub mod pose_graph;
mod tracker;

pub use tracker::*;
