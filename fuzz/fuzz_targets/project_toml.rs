//! project.toml: parse, then check every setting; answer or refuse, never panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(p) = mrtmap_pipeline::Project::parse(text) {
        let _ = p.check();
    }
});
