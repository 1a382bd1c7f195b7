//! Whether a rig calibration is believable: how well the fit constrains the thermal camera's pose,
//! and whether the result looks like a rig at all. A calibration that converged can still be
//! wrong (a board misdetected in some pairs, too few tilted views); these checks say so, with what
//! to do, instead of writing a rig that paints every surface with its neighbour's temperature.

use crate::calibrate::StereoResult;
use mrtmap_geometry::PinholeCamera;

/// The thermal camera may sit this far from the colour camera on a handheld rig (m).
pub const MAX_BASELINE_M: f64 = 0.25;
/// The extrinsic's translation is poorly constrained beyond this standard deviation (m) …
pub const MAX_TRANSLATION_STD_M: f64 = 0.01;
/// … and its rotation beyond this one (degrees).
pub const MAX_ROTATION_STD_DEG: f64 = 0.5;

const ADVICE: &str =
    "more pairs, the board closer and tilted in several directions, the whole board in both views";

/// Warnings about a stereo calibration, each a sentence with what to do; empty when it looks right.
pub fn plausibility(r: &StereoResult) -> Vec<String> {
    let mut w = Vec::new();
    let baseline = r.rgb_from_thermal.translation.vector.norm();
    if baseline > MAX_BASELINE_M {
        w.push(format!(
            "the thermal camera comes out {:.0} cm from the colour camera; on a handheld rig they sit within {:.0} cm: check that the board was found correctly in both images of every pair (the report's overlay shows it), and use {ADVICE}",
            baseline * 100.0,
            MAX_BASELINE_M * 100.0
        ));
    }
    if let Some(s) = r.std.as_deref().filter(|s| s.len() >= 24) {
        let t = s[21].hypot(s[22]).hypot(s[23]);
        let rot = s[18].hypot(s[19]).hypot(s[20]).to_degrees();
        if t > MAX_TRANSLATION_STD_M || rot > MAX_ROTATION_STD_DEG {
            w.push(format!(
                "the thermal camera's pose is poorly constrained (± {:.0} mm, ± {:.2}°; a good calibration gives under {:.0} mm and {:.1}°): use {ADVICE}",
                t * 1e3,
                rot,
                MAX_TRANSLATION_STD_M * 1e3,
                MAX_ROTATION_STD_DEG
            ));
        }
    }
    for (name, cam, alone) in [
        ("thermal", &r.thermal, &r.thermal_alone.camera),
        ("colour", &r.rgb, &r.rgb_alone.camera),
    ] {
        w.extend(camera_warnings(name, cam, alone));
    }
    w
}

/// Implausible intrinsics of one camera: non-square pixels, a field of view no lens has, a
/// principal point far from the centre, strong distortion, or a joint fit far from the camera's
/// own.
fn camera_warnings(name: &str, c: &PinholeCamera, alone: &PinholeCamera) -> Vec<String> {
    let mut w = Vec::new();
    let ratio = c.fx / c.fy;
    if (ratio - 1.0).abs() > 0.03 {
        w.push(format!(
            "the {name} camera's fx/fy is {ratio:.3}; sensors have square pixels (1.000 within a few per mille): the views do not constrain the focal lengths, use {ADVICE}"
        ));
    }
    let hfov = 2.0 * (c.width as f64 / (2.0 * c.fx)).atan().to_degrees();
    if !(15.0..=130.0).contains(&hfov) {
        w.push(format!(
            "the {name} camera's horizontal field of view comes out {hfov:.0}°, which no such lens has: check the board size and square size given"
        ));
    }
    let (dx, dy) = (
        (c.cx - (c.width as f64 - 1.0) / 2.0) / c.width as f64,
        (c.cy - (c.height as f64 - 1.0) / 2.0) / c.height as f64,
    );
    if dx.abs() > 0.15 || dy.abs() > 0.15 {
        w.push(format!(
            "the {name} camera's principal point is {:.0} % and {:.0} % of the image from its centre: lenses sit within a few per cent; use {ADVICE}",
            dx * 100.0,
            dy * 100.0
        ));
    }
    let k1 = c.distortion.to_array()[0];
    if k1.abs() > 1.0 {
        w.push(format!(
            "the {name} camera's radial distortion k1 = {k1:.2} is implausibly strong: try --distortion radial, and {ADVICE}"
        ));
    }
    if alone.fx > 0.0 && (c.fx / alone.fx - 1.0).abs() > 0.1 {
        w.push(format!(
            "the joint fit moved the {name} camera's focal length from {:.0} px (its own images) to {:.0} px: the pairs disagree with the single-camera calibration",
            alone.fx, c.fx
        ));
    }
    w
}
