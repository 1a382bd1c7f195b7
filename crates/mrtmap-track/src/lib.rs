//! # mrtmap-track
//!
//! Poses for a recording that has colour and depth frames but no pose source: the built-in RGB-D
//! tracker ([`track`]). It closes loops with mrtmap-geometry's pose graph
//! ([`pose_graph`](mrtmap_geometry::pose_graph), which RTAB-Map conversion shares without
//! depending on the tracker), and needs only the recording and depth back-projection (mrtmap-io's
//! [`depth`](mrtmap_io::depth)), not the scan pipeline.

mod tracker;

pub use tracker::*;
