//! MCAP files: records, chunks (zstd, lz4), channels, CDR messages.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_sources::ros::{self, Container, RosOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = ros::survey(Container::Mcap, data) {
        let _ = ros::plan(&s, &RosOptions::default());
    }
});
