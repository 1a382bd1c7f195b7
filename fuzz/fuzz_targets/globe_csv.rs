//! globe.csv (black-globe readings): answer or refuse naming the line, never panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = mrtmap_report::parse_globe_csv(text, "globe.csv");
});
