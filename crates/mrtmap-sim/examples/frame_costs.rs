//! Time per frame of each sensor model and of PNG encoding (release build), to see where the
//! simulator's time goes. `cargo run --release -p mrtmap-sim --example frame_costs`
#![allow(clippy::unwrap_used, clippy::print_stdout)]

use std::time::Instant;

use mrtmap_io::{ThermalEncoding, encode_png_rgb8, encode_png16};
use mrtmap_sim::*;
use rand::SeedableRng;

fn main() {
    let room = preset("office").unwrap().unwrap();
    let cfg = SimConfig::default();
    let walk = Walk::new(&room, cfg.walk, 1);
    let r = RoomRenderer::new(&room);
    let rays = camera_rays(&cfg.depth_camera, 1);
    let trays = camera_rays(&cfg.thermal_camera, 3);
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let n = 30;
    let time = |name: &str, f: &mut dyn FnMut(usize)| {
        let t = Instant::now();
        for k in 0..n {
            f(k);
        }
        println!(
            "{name:<28} {:8.2} ms/frame",
            t.elapsed().as_secs_f64() * 1e3 / n as f64
        );
    };
    let mut imgs = Vec::new();
    time("depth render, no noise", &mut |k| {
        imgs.push(render_depth(
            &r,
            &cfg.depth_camera,
            &rays,
            &walk.room_from_depth(k as f64),
            1000.0,
            None,
            None,
            &mut rng,
        ));
    });
    let mut noisy = Vec::new();
    time("depth render, realistic", &mut |k| {
        noisy.push(render_depth(
            &r,
            &cfg.depth_camera,
            &rays,
            &walk.room_from_depth(k as f64),
            1000.0,
            Some(&cfg.depth_noise),
            None,
            &mut rng,
        ));
    });
    let mut sz = 0;
    time("png16 encode, no noise", &mut |k| {
        sz += encode_png16(&imgs[k]).expect("encodes").len();
    });
    println!("   {} KB/frame", sz / n / 1000);
    let mut sz = 0;
    time("png16 encode, realistic", &mut |k| {
        sz += encode_png16(&noisy[k]).expect("encodes").len();
    });
    println!("   {} KB/frame", sz / n / 1000);
    for (name, ct, ft) in [
        (
            "default/adaptive",
            image::codecs::png::CompressionType::Default,
            image::codecs::png::FilterType::Adaptive,
        ),
        (
            "fast/up",
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Up,
        ),
        (
            "fast/paeth",
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Paeth,
        ),
        (
            "default/paeth",
            image::codecs::png::CompressionType::Default,
            image::codecs::png::FilterType::Paeth,
        ),
    ] {
        let mut sz = 0;
        time(&format!("png16 {name}"), &mut |k| {
            use image::ImageEncoder;
            let img = &noisy[k];
            let bytes: Vec<u8> = img.data.iter().flat_map(|v| v.to_ne_bytes()).collect();
            let mut out = Vec::new();
            image::codecs::png::PngEncoder::new_with_quality(&mut out, ct, ft)
                .write_image(&bytes, img.width, img.height, image::ExtendedColorType::L16)
                .unwrap();
            sz += out.len();
        });
        println!("   {} KB/frame", sz / n / 1000);
    }
    time("thermal 3x3, realistic", &mut |k| {
        let p = walk.room_from_depth(k as f64) * cfg.depth_from_thermal;
        render_thermal(
            &room,
            &r,
            &cfg.thermal_camera,
            &trays,
            std::slice::from_ref(&p),
            ThermalEncoding::Centikelvin,
            &ThermalNoise::REALISTIC,
            None,
            &mut rng,
        );
    });
    time("rgb + mask", &mut |k| {
        let (rgb, m, _) = render_rgb_and_mask(
            &room,
            &r,
            &cfg.depth_camera,
            &rays,
            &walk.room_from_depth(k as f64),
            true,
            &mut rng,
        );
        encode_png_rgb8(640, 480, &rgb).expect("encodes");
        encode_png16(&m).expect("encodes");
    });
}
