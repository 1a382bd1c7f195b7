//! ROS 1 bags: records, chunks (bz2, lz4), connections, and every message decoded as the type
//! its connection names.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_sources::ros::{self, Container, RosOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = ros::survey(Container::Bag, data) {
        let _ = ros::plan(&s, &RosOptions::default());
    }
});
