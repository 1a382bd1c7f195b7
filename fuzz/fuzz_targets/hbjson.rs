//! A Honeybee model and a temperatures table (split at the first NUL byte): read as a scene or
//! refused naming where, never a panic; a scene that validates exports to every format.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_export::{gbxml, gltf, hbjson, radiance};
use mrtmap_radiation::RadiantScene;

fuzz_target!(|data: &[u8]| {
    let (model, table) = match data.iter().position(|b| *b == 0) {
        Some(i) => (&data[..i], Some(&data[i + 1..])),
        None => (data, None),
    };
    let Ok(model) = std::str::from_utf8(model) else {
        return;
    };
    let table = match table.map(std::str::from_utf8) {
        Some(Ok(t)) => match hbjson::parse_temperatures(t) {
            Ok(t) => Some(t),
            Err(e) => {
                assert!(!e.to_string().is_empty());
                return;
            }
        },
        Some(Err(_)) => return,
        None => None,
    };
    let Ok(read) = hbjson::read(model, None, table.as_ref()) else {
        return;
    };
    let Ok(scene) = RadiantScene::new(&read.scene) else {
        return;
    };
    let text = hbjson::write(&scene, "fuzz");
    assert!(hbjson::read(&text, None, None).is_ok(), "our own export reads back");
    assert!(gbxml::write(&scene, "fuzz").ends_with("</gbXML>\n"));
    assert!(gltf::write(&scene, None, "fuzz").starts_with(b"glTF"));
    let _ = radiance::write(&scene, "fuzz");
});
