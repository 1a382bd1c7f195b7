//! # mrtmap-geometry
//!
//! Space for mrtmap: solid angles (Van Oosterom–Strackee), planar polygons in 3D with a 2D frame
//! and the 2D tests a radiant scene needs, direction sets on the sphere, ray casting against
//! triangle soups through a BVH, and pose-graph optimisation ([`pose_graph`], shared by the tracker
//! and RTAB-Map conversion).
//!
//! Conventions: metres, radians, `f64` points and vectors from `nalgebra`; transforms are named
//! `a_from_b` (`p_in_a = a_from_b * p_in_b`).
//!
//! ```
//! use mrtmap_geometry::{sphere_view_factor, nalgebra::Point3};
//! // A unit square seen from one unit above its corner: F = (π/6)/(4π) = 1/24.
//! let sq = [
//!     Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
//!     Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0),
//! ];
//! let f = sphere_view_factor(&Point3::new(0.0, 0.0, 1.0), &sq);
//! assert!((f - 1.0 / 24.0).abs() < 1e-12);
//! ```

pub mod camera;
pub mod cloud;
pub mod icp;
pub mod plane;
pub mod polygon;
pub mod pose_graph;
pub mod ray;
pub mod sampling;
pub mod shape2d;
mod solid_angle;

pub use camera::{BrownConrady, PinholeCamera};
pub use icp::{IcpParams, IcpTarget, Registration, icp_point_to_plane};
pub use nalgebra;
pub use plane::{Plane, RansacParams, intersect_three, ransac_plane};
pub use polygon::{Containment, NotSimple, PlaneFrame};
#[cfg(feature = "embree")]
pub use ray::EmbreeRayCaster;
pub use ray::{
    BOX_TRIANGLES, BvhRayCaster, RayCaster, RayHit, Tri, box_corners, box_triangles, ray_triangle,
};
pub use sampling::DirectionSet;
pub use solid_angle::{
    clip_polygon_to_halfspace, plane_view_factor, polygon_solid_angle, sphere_view_factor,
    triangle_solid_angle,
};

/// Errors of geometric constructions.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// A polygon could not be triangulated (not simple, or degenerate).
    #[error("a polygon of {vertices} vertices could not be triangulated")]
    Triangulation {
        /// Vertex count.
        vertices: usize,
    },
}
