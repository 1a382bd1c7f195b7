use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::{Point2, Point3};
use proptest::prelude::*;

fn lepton() -> PinholeCamera {
    let mut c = PinholeCamera::from_hfov(160, 120, 57f64.to_radians());
    c.distortion = BrownConrady::from_array([-0.12, 0.06, 0.001, -0.0015, 0.0]);
    c
}

#[test]
fn hfov_and_principal_point() {
    let c = PinholeCamera::from_hfov(160, 120, 57f64.to_radians());
    assert!((c.fx - 147.35).abs() < 0.01, "{}", c.fx);
    assert!((c.hfov_rad().to_degrees() - 57.0).abs() < 1e-9);
    let px = c.project(&Point3::new(0.0, 0.0, 2.0)).unwrap();
    assert!((px - Point2::new(79.5, 59.5)).norm() < 1e-12);
    assert!(c.project(&Point3::new(0.0, 0.0, -1.0)).is_none());
    assert!(c.contains(&Point2::new(-0.4, 119.4)) && !c.contains(&Point2::new(159.6, 0.0)));
}

#[test]
fn scaled_camera_maps_pixel_areas() {
    let c = PinholeCamera::new(160, 120, 147.4, 147.4, 79.5, 59.5);
    let s = c.scaled(3.0);
    assert_eq!((s.width, s.height), (480, 360));
    // The centre of the top-left big pixel is the centre of the 3×3 block's middle pixel.
    let p = Point3::from(c.unproject(&Point2::new(0.0, 0.0)));
    let q = s.project(&p).unwrap();
    assert!((q - Point2::new(1.0, 1.0)).norm() < 1e-9, "{q}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, rng_seed: proptest::test_runner::RngSeed::Fixed(7), failure_persistence: None, ..ProptestConfig::default() })]
    /// Unprojecting a pixel and projecting it again gives the pixel, distortion included.
    #[test]
    fn unproject_inverts_project(u in 0.0f64..159.0, v in 0.0f64..119.0, depth in 0.3f64..8.0) {
        let c = lepton();
        let ray = c.unproject(&Point2::new(u, v));
        let p = Point3::from(ray * depth);
        let back = c.project(&p).unwrap();
        prop_assert!((back - Point2::new(u, v)).norm() < 1e-7, "{} vs ({u}, {v})", back);
    }
}
