//! MCAP files: records, chunks (zstd, lz4), channels, CDR messages.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_io::ros_scan::{self, Container, RosOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = ros_scan::survey(Container::Mcap, data) {
        let _ = ros_scan::plan(&s, &RosOptions::default());
    }
});
