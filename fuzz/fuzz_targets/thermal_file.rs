//! Every thermal image format by content (FLIR, 16-bit PNG/TIFF, float TIFF, raw).
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_io::{ThermalOptions, decode_thermal};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let o = ThermalOptions::default();
    if let Ok(img) = decode_thermal(Path::new("f.y16"), data, &o) {
        let _ = img.stats();
        let _ = img.centikelvin();
    }
});
