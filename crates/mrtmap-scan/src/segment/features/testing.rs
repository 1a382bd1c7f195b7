//! Test walls shared by the features' tests: walls in the plane y = 0, their points, and their
//! analyses.

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_physics::ZERO_CELSIUS_K;

use super::detect::FoundFeature;
use super::{SurfaceAnalysis, analyse_surface};
use crate::segment::SegmentParams;

/// A `w` × `h` m wall in the plane y = 0 from the origin: its frame and outline.
pub(super) fn wall_in_y0(w: f64, h: f64) -> (PlaneFrame, Vec<Point2<f64>>) {
    use mrtmap_geometry::nalgebra::{Unit, Vector3};
    let frame = PlaneFrame::new(
        Point3::origin(),
        Unit::new_normalize(Vector3::y()),
        &Vector3::x(),
    );
    let host = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
        .iter()
        .map(|q| frame.to_2d(&Point3::new(q[0], 0.0, q[1])))
        .collect();
    (frame, host)
}

/// A 4 × 2.5 m wall at 17.6 °C in the plane y = 0, each point seen 40 times, and `extra`
/// points (x, z, °C, observations) on it.
pub(super) fn wall_with(extra: &[(f64, f64, f64, f64)]) -> SurfaceAnalysis {
    let (mut pos, mut temp, mut w) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..134 {
        for j in 0..84 {
            pos.push(Point3::new(
                (i as f64 + 0.5) * 0.03,
                0.0,
                (j as f64 + 0.5) * 0.03,
            ));
            temp.push(ZERO_CELSIUS_K + 17.6);
            w.push(40.0);
        }
    }
    for &(x, z, c, o) in extra {
        pos.push(Point3::new(x, 0.0, z));
        temp.push(ZERO_CELSIUS_K + c);
        w.push(o);
    }
    let (frame, host) = wall_in_y0(4.0, 2.5);
    let idx: Vec<usize> = (0..pos.len()).collect();
    analyse_surface(
        &frame,
        &host,
        &idx,
        (&pos, &temp, &w),
        true,
        &SegmentParams::default(),
    )
}

/// Points (x, z, °C) on every 3 cm texel of `x0..x1` × `z0..z1` of [`wall_with`]'s wall,
/// each seen 4000 times (so the texel reads their temperature).
pub(super) fn patch(x0: f64, x1: f64, z0: f64, z1: f64, c: f64) -> Vec<(f64, f64, f64, f64)> {
    let mut out = Vec::new();
    for i in 0..134 {
        for j in 0..84 {
            let (x, z) = ((i as f64 + 0.5) * 0.03, (j as f64 + 0.5) * 0.03);
            if (x0..x1).contains(&x) && (z0..z1).contains(&z) {
                out.push((x, z, c, 4000.0));
            }
        }
    }
    out
}

/// A feature of [`wall_with`]'s wall: its extent along x and z.
pub(super) fn extent(f: &FoundFeature) -> (f64, f64, f64, f64) {
    let frame = wall_in_y0(4.0, 2.5).0;
    f.polygon_2d.iter().map(|q| frame.to_3d(q)).fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), q| (a.min(q.x), b.max(q.x), c.min(q.z), d.max(q.z)),
    )
}

/// A `w` × `h` m wall in the plane y = 0 sampled every centimetre: `seen(x, z)` is the
/// temperature (°C) where the walk saw it, `None` where it did not; analysed with a linear
/// background when `linear`.
pub(super) fn analyse_seen(
    w: f64,
    h: f64,
    seen: impl Fn(f64, f64) -> Option<f64>,
    linear: bool,
) -> (PlaneFrame, SurfaceAnalysis) {
    let (mut pos, mut temp) = (Vec::new(), Vec::new());
    for i in 0..(w * 100.0).round() as usize {
        for j in 0..(h * 100.0).round() as usize {
            let (x, z) = ((i as f64 + 0.5) * 0.01, (j as f64 + 0.5) * 0.01);
            if let Some(t) = seen(x, z) {
                pos.push(Point3::new(x, 0.0, z));
                temp.push(ZERO_CELSIUS_K + t);
            }
        }
    }
    let (frame, host) = wall_in_y0(w, h);
    let idx: Vec<usize> = (0..pos.len()).collect();
    let ones = vec![1.0; pos.len()];
    let a = analyse_surface(
        &frame,
        &host,
        &idx,
        (&pos, &temp, &ones),
        linear,
        &SegmentParams::default(),
    );
    (frame, a)
}
