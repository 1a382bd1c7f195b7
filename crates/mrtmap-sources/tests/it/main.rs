//! Source tests: bags, MCAP files, ROS 2 bags and RTAB-Map databases written by this crate read
//! back frame for frame; broken files give errors with offsets.
#![allow(clippy::unwrap_used, clippy::print_stdout)]

mod sources;
