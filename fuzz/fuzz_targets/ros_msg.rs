//! ROS 1 and CDR message decoders on arbitrary bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_io::ros_msg::{self, Wire};

fuzz_target!(|data: &[u8]| {
    for wire in [Wire::Ros1, Wire::Cdr] {
        let _ = ros_msg::image(data, wire, 0);
        let _ = ros_msg::compressed_image(data, wire, 0);
        let _ = ros_msg::camera_info(data, wire, 0);
        let _ = ros_msg::odometry(data, wire, 0);
        let _ = ros_msg::pose_stamped(data, wire, 0);
        let _ = ros_msg::tf_message(data, wire, 0);
    }
});
