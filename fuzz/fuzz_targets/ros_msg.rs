//! ROS 1 and CDR message decoders on arbitrary bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_sources::ros::msg::{self, Wire};

fuzz_target!(|data: &[u8]| {
    for wire in [Wire::Ros1, Wire::Cdr] {
        let _ = msg::image(data, wire, 0);
        let _ = msg::compressed_image(data, wire, 0);
        let _ = msg::camera_info(data, wire, 0);
        let _ = msg::odometry(data, wire, 0);
        let _ = msg::pose_stamped(data, wire, 0);
        let _ = msg::tf_message(data, wire, 0);
    }
});
