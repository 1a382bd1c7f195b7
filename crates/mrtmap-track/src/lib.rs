//! # mrtmap-track
//!
//! Poses for a recording that has colour and depth frames but no pose source: the built-in RGB-D
//! tracker ([`track`]) and the pose graph it closes loops with ([`pose_graph`], also used for
//! RTAB-Map databases that did not save their optimised graph). It reads depth frames through
//! mrtmap-scan's [`depth_points`](mrtmap_scan::frame::depth_points) and nothing else of the scan
//! pipeline.

pub mod pose_graph;
mod tracker;

pub use tracker::*;
