//! FLIR R-JPEG / FFF parsing: any bytes give a file or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(f) = mrtmap_io::flir::parse_flir(data) {
        let c = f.params.converter();
        for &r in f.raw.data.iter().take(64) {
            let _ = c.celsius(r as f64);
        }
    }
});
