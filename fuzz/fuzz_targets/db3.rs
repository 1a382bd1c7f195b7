//! ROS 2 bags in SQLite storage: the file opened in memory, topics and messages read, CDR
//! messages (some zstd-compressed) decoded.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_sources::ros::{self, Container, RosOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = ros::survey(Container::Db3, data) {
        let _ = ros::plan(&s, &RosOptions::default());
    }
});
