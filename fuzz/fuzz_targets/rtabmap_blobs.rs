//! RTAB-Map blobs: depth (RVL or PNG), calibration, poses; and a raw RVL stream whose pixel count
//! comes from the first two bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_sources::rtabmap::{self, rvl};

fuzz_target!(|data: &[u8]| {
    let _ = rtabmap::depth_blob(data);
    let _ = rtabmap::calibration(data);
    let _ = rtabmap::pose_blob(data, "pose");
    if data.len() >= 2 {
        let n = u16::from_le_bytes([data[0], data[1]]) as usize;
        let _ = rvl::decode(&data[2..], n, 2);
    }
});
