//! Ray casting against triangle soups.
//!
//! [`BvhRayCaster`] (the default, pure Rust) builds an eight-wide compressed BVH with `obvhs`;
//! `EmbreeRayCaster` (cargo feature `embree`) hands the same triangles to Intel Embree. Both
//! answer the same query: the nearest triangle a ray hits, or `None` on a miss.

use glam::Vec3A;
use nalgebra::{Point3, Vector3};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray as ORay, RayHit as OHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

/// A triangle as three corners.
pub type Tri = [Point3<f64>; 3];

/// The nearest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the (unit) direction.
    pub t: f64,
    /// Index of the triangle hit, in the order given to the caster.
    pub triangle: u32,
}

/// Something that finds the nearest triangle along a ray.
pub trait RayCaster: Send + Sync {
    /// The nearest hit of the ray from `origin` along the unit vector `dir` within `t_max`, or
    /// `None`.
    fn cast(&self, origin: &Point3<f64>, dir: &Vector3<f64>, t_max: f64) -> Option<RayHit>;

    /// Number of triangles.
    fn len(&self) -> usize;

    /// Whether there is nothing to hit.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Short engine name for reports.
    fn engine(&self) -> &'static str;
}

fn v3a(p: &Point3<f64>) -> Vec3A {
    Vec3A::new(p.x as f32, p.y as f32, p.z as f32)
}

/// The default ray caster: a compressed wide BVH (CWBVH, Ylitie et al. 2017) built by `obvhs`.
pub struct BvhRayCaster {
    bvh: Option<CwBvh>,
    /// Triangles in BVH order.
    tris: Vec<RtTriangle>,
    /// BVH order → input index.
    ids: Vec<u32>,
    len: usize,
}

impl BvhRayCaster {
    /// Builds the BVH over `triangles` (obvhs' medium build: quick to build, quick to trace).
    pub fn new(triangles: &[Tri]) -> Self {
        Self::build(triangles, BvhBuildParams::medium_build())
    }

    /// Builds the BVH over `triangles` with obvhs' most careful build, for a caster that will
    /// trace millions of rays: the simulator's truth (100,000 rays at each of 404 points) traced
    /// about a fifth faster through it, on the same nearest hits (a ray meeting two triangles at
    /// the same distance, on a shared edge, may report the other).
    pub fn for_many_rays(triangles: &[Tri]) -> Self {
        Self::build(triangles, BvhBuildParams::very_slow_build())
    }

    fn build(triangles: &[Tri], params: BvhBuildParams) -> Self {
        if triangles.is_empty() {
            return Self {
                bvh: None,
                tris: Vec::new(),
                ids: Vec::new(),
                len: 0,
            };
        }
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|t| Triangle {
                v0: v3a(&t[0]),
                v1: v3a(&t[1]),
                v2: v3a(&t[2]),
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&tris, params, &mut std::time::Duration::default());
        let rt = bvh
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        let ids = bvh.primitive_indices.clone();
        Self {
            bvh: Some(bvh),
            tris: rt,
            ids,
            len: triangles.len(),
        }
    }
}

impl RayCaster for BvhRayCaster {
    #[inline]
    fn cast(&self, origin: &Point3<f64>, dir: &Vector3<f64>, t_max: f64) -> Option<RayHit> {
        let bvh = self.bvh.as_ref()?;
        let d = Vec3A::new(dir.x as f32, dir.y as f32, dir.z as f32);
        let ray = ORay::new(v3a(origin), d, 0.0, t_max as f32);
        let mut hit = OHit::none();
        if bvh.ray_traverse(ray, &mut hit, |r, id| self.tris[id].intersect(r)) {
            Some(RayHit {
                t: hit.t as f64,
                triangle: self.ids[hit.primitive_id as usize],
            })
        } else {
            None
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn engine(&self) -> &'static str {
        "obvhs-cwbvh"
    }
}

#[cfg(feature = "embree")]
pub use embree_caster::EmbreeRayCaster;

#[cfg(feature = "embree")]
#[allow(unsafe_code)]
mod embree_caster {
    use embree::sys;
    use nalgebra::{Point3, Vector3};

    use super::{RayCaster, RayHit, Tri};

    /// Ray casting through Intel Embree 3 (cargo feature `embree`, system library `libembree3`).
    pub struct EmbreeRayCaster {
        device: sys::RTCDevice,
        scene: sys::RTCScene,
        len: usize,
    }

    // SAFETY: an Embree scene is immutable after `rtcCommitScene` and Embree documents concurrent
    // `rtcIntersect1` calls on a committed scene as thread-safe; the handles are only released in
    // `Drop`, which needs exclusive ownership.
    unsafe impl Send for EmbreeRayCaster {}
    unsafe impl Sync for EmbreeRayCaster {}

    impl EmbreeRayCaster {
        /// Builds an Embree scene of `triangles`.
        pub fn new(triangles: &[Tri]) -> Self {
            // SAFETY: the buffers Embree allocates are sized for exactly the vertices and indices
            // written below; every handle is checked by Embree and released in Drop.
            unsafe {
                let device = sys::rtcNewDevice(std::ptr::null());
                let scene = sys::rtcNewScene(device);
                if !triangles.is_empty() {
                    let geom = sys::rtcNewGeometry(device, sys::RTCGeometryType::TRIANGLE);
                    let nv = triangles.len() * 3;
                    let vb = sys::rtcSetNewGeometryBuffer(
                        geom,
                        sys::RTCBufferType::VERTEX,
                        0,
                        sys::RTCFormat::FLOAT3,
                        12,
                        nv,
                    ) as *mut f32;
                    let ib = sys::rtcSetNewGeometryBuffer(
                        geom,
                        sys::RTCBufferType::INDEX,
                        0,
                        sys::RTCFormat::UINT3,
                        12,
                        triangles.len(),
                    ) as *mut u32;
                    let vs = std::slice::from_raw_parts_mut(vb, nv * 3);
                    let is = std::slice::from_raw_parts_mut(ib, triangles.len() * 3);
                    for (i, t) in triangles.iter().enumerate() {
                        for k in 0..3 {
                            vs[(3 * i + k) * 3] = t[k].x as f32;
                            vs[(3 * i + k) * 3 + 1] = t[k].y as f32;
                            vs[(3 * i + k) * 3 + 2] = t[k].z as f32;
                            is[3 * i + k] = (3 * i + k) as u32;
                        }
                    }
                    sys::rtcCommitGeometry(geom);
                    sys::rtcAttachGeometry(scene, geom);
                    sys::rtcReleaseGeometry(geom);
                }
                sys::rtcCommitScene(scene);
                Self {
                    device,
                    scene,
                    len: triangles.len(),
                }
            }
        }
    }

    impl RayCaster for EmbreeRayCaster {
        fn cast(&self, origin: &Point3<f64>, dir: &Vector3<f64>, t_max: f64) -> Option<RayHit> {
            let mut rh = sys::RTCRayHit {
                ray: sys::RTCRay {
                    org_x: origin.x as f32,
                    org_y: origin.y as f32,
                    org_z: origin.z as f32,
                    tnear: 0.0,
                    dir_x: dir.x as f32,
                    dir_y: dir.y as f32,
                    dir_z: dir.z as f32,
                    time: 0.0,
                    tfar: t_max.min(f32::MAX as f64) as f32,
                    mask: u32::MAX,
                    id: 0,
                    flags: 0,
                },
                hit: sys::RTCHit {
                    Ng_x: 0.0,
                    Ng_y: 0.0,
                    Ng_z: 0.0,
                    u: 0.0,
                    v: 0.0,
                    primID: u32::MAX,
                    geomID: u32::MAX,
                    instID: [u32::MAX; 1],
                },
            };
            let mut ctx = sys::RTCIntersectContext {
                flags: sys::RTCIntersectContextFlags::INCOHERENT,
                filter: None,
                instID: [u32::MAX; 1],
            };
            // SAFETY: the scene is committed and alive for &self; rh and ctx are valid for the call.
            unsafe { sys::rtcIntersect1(self.scene, &mut ctx, &mut rh) };
            (rh.hit.geomID != u32::MAX).then_some(RayHit {
                t: rh.ray.tfar as f64,
                triangle: rh.hit.primID,
            })
        }

        fn len(&self) -> usize {
            self.len
        }

        fn engine(&self) -> &'static str {
            "embree3"
        }
    }

    impl Drop for EmbreeRayCaster {
        fn drop(&mut self) {
            // SAFETY: the handles were created in `new` and are released exactly once.
            unsafe {
                sys::rtcReleaseScene(self.scene);
                sys::rtcReleaseDevice(self.device);
            }
        }
    }
}

/// The eight corners of an axis-aligned box: corner `i` takes max along x when bit 0 of `i` is
/// set, along y for bit 1, along z for bit 2.
pub fn box_corners(min: &Point3<f64>, max: &Point3<f64>) -> [Point3<f64>; 8] {
    std::array::from_fn(|i| {
        Point3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    })
}

/// Ray–triangle intersection (Möller–Trumbore): the distance along `d` (beyond 1e-6), if the ray
/// meets the triangle (either side).
pub fn ray_triangle(o: &Point3<f64>, d: &Vector3<f64>, tri: [&Point3<f64>; 3]) -> Option<f64> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = d.cross(&e2);
    let det = e1.dot(&p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - tri[0];
    let u = s.dot(&p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(&e1);
    let v = d.dot(&q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(&q) * inv;
    (t > 1e-6).then_some(t)
}

/// The twelve triangles of a box as indices into [`box_corners`], facing outwards.
pub const BOX_TRIANGLES: [[usize; 3]; 12] = {
    // Faces as quads of corner indices, each split along its first diagonal.
    const FACES: [[usize; 4]; 6] = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    let mut t = [[0; 3]; 12];
    let mut k = 0;
    while k < 6 {
        let f = FACES[k];
        t[2 * k] = [f[0], f[1], f[2]];
        t[2 * k + 1] = [f[0], f[2], f[3]];
        k += 1;
    }
    t
};

/// The twelve triangles of an axis-aligned box.
pub fn box_triangles(min: &Point3<f64>, max: &Point3<f64>) -> Vec<Tri> {
    let c = box_corners(min, max);
    BOX_TRIANGLES
        .iter()
        .map(|t| [c[t[0]], c[t[1]], c[t[2]]])
        .collect()
}
