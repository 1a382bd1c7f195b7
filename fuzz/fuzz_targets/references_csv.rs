//! references.csv (contact-thermometer readings): answer or refuse naming the line, never panic;
//! what is accepted is finite and in range.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_pipeline::parse_references;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(refs) = parse_references(text, Path::new("references.csv")) {
        for r in refs {
            assert!(r.xyz.iter().all(|v| v.is_finite()) && r.temperature_c.is_finite());
            assert!(r.std_k > 0.0 && r.std_k < 50.0);
        }
    }
});
