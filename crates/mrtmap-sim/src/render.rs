//! An analytic ray caster for rooms, in the room frame: surfaces are planes with 2D polygons,
//! furniture is axis-aligned boxes. For a convex room the nearest facing plane is always the
//! surface hit; otherwise candidate planes are tested against their polygons in order of distance.

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Rotation3, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;

use crate::room::Room;

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Element {
    /// A room surface (index into [`Room::surfaces`]), and the feature on it (index into
    /// `room.features`), if any.
    Surface {
        /// Surface index.
        surface: usize,
        /// Feature index.
        feature: Option<usize>,
    },
    /// A furniture box (index into `room.file.furniture`).
    Furniture(usize),
}

/// A ray's nearest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance in units of the ray direction's length.
    pub t: f64,
    /// What was hit.
    pub element: Element,
    /// Unit normal of the surface hit, on the side the ray came from.
    pub normal: Vector3<f64>,
}

struct Plane {
    origin: Point3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
    n: Vector3<f64>,
    offset: f64,
    poly: Vec<Point2<f64>>,
    lo: Point2<f64>,
    hi: Point2<f64>,
    rect: bool,
    features: Vec<PlaneFeature>,
    /// Whether any of its features is glass.
    has_glass: bool,
}

/// A feature on a plane: its index in the room, polygon and bounds in the plane's 2D frame, and
/// whether it is glass (which an active-stereo depth camera does not see).
struct PlaneFeature {
    index: usize,
    glass: bool,
    poly: Vec<Point2<f64>>,
    lo: Point2<f64>,
    hi: Point2<f64>,
}

/// A room prepared for ray casting.
pub struct RoomRenderer {
    planes: Vec<Plane>,
    boxes: Vec<(Vector3<f64>, Vector3<f64>)>,
    convex: bool,
}

fn bounds(p: &[Point2<f64>]) -> (Point2<f64>, Point2<f64>) {
    p.iter().fold(
        (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(a, b), q| {
            (
                Point2::new(a.x.min(q.x), a.y.min(q.y)),
                Point2::new(b.x.max(q.x), b.y.max(q.y)),
            )
        },
    )
}

impl RoomRenderer {
    /// Prepares a room.
    pub fn new(room: &Room) -> Self {
        let planes = room
            .surfaces()
            .into_iter()
            .map(|s| {
                let (origin, u, v) = room.surface_frame(s);
                let n = room.inward_normal(s);
                let poly = room.surface_polygon_2d(s);
                let (lo, hi) = bounds(&poly);
                let rect = poly.len() == 4
                    && (polygon_area(&poly) - (hi.x - lo.x) * (hi.y - lo.y)).abs() < 1e-9;
                let features = room
                    .features
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| f.on == s)
                    .map(|(k, f)| {
                        let (lo, hi) = bounds(&f.polygon_2d);
                        PlaneFeature {
                            index: k,
                            glass: crate::room::is_glass(&f.label),
                            poly: f.polygon_2d.clone(),
                            lo,
                            hi,
                        }
                    })
                    .collect::<Vec<PlaneFeature>>();
                Plane {
                    has_glass: features.iter().any(|f| f.glass),
                    offset: n.dot(&origin.coords),
                    origin,
                    u,
                    v,
                    n,
                    poly,
                    lo,
                    hi,
                    rect,
                    features,
                }
            })
            .collect();
        let boxes = room
            .file
            .furniture
            .iter()
            .map(|b| (Vector3::from(b.min), Vector3::from(b.max)))
            .collect();
        Self {
            planes,
            boxes,
            convex: room.convex,
        }
    }

    /// The nearest hit of the ray `o + t·d` (room frame, t > 0), or `None`.
    pub fn cast(&self, o: &Point3<f64>, d: &Vector3<f64>) -> Option<Hit> {
        self.view(&Isometry3::translation(o.x, o.y, o.z)).cast(d)
    }

    /// Prepares many casts from one camera pose; rays are then given in the camera frame.
    pub fn view(&self, room_from_cam: &Isometry3<f64>) -> View<'_> {
        let o: Point3<f64> = room_from_cam.translation.vector.into();
        let rot = room_from_cam.rotation.to_rotation_matrix();
        let cam_from_room = rot.inverse();
        View {
            r: self,
            o,
            rot,
            nums: self
                .planes
                .iter()
                .map(|p| p.offset - p.n.dot(&o.coords))
                .collect(),
            normals_cam: self.planes.iter().map(|p| cam_from_room * p.n).collect(),
            spheres: self
                .boxes
                .iter()
                .map(|(lo, hi)| {
                    let c = Point3::from((lo + hi) / 2.0);
                    (cam_from_room * (c - o), ((hi - lo) / 2.0).norm_squared())
                })
                .collect(),
        }
    }
}

/// Ray casts from one camera pose: each plane's `offset − n·o` and normal in the camera frame,
/// and each box's bounding sphere, computed once per frame.
pub struct View<'a> {
    r: &'a RoomRenderer,
    o: Point3<f64>,
    rot: Rotation3<f64>,
    nums: Vec<f64>,
    normals_cam: Vec<Vector3<f64>>,
    spheres: Vec<(Vector3<f64>, f64)>,
}

/// What a ray hit before features are looked up.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Plane(usize),
    Box(usize),
}

impl View<'_> {
    /// Distance (in units of `d_cam`'s length), target and normal (room frame) of the nearest hit
    /// of a ray given in the camera frame; features are not looked up.
    fn nearest(&self, d_cam: &Vector3<f64>) -> Option<(f64, Target, Vector3<f64>)> {
        let planes = &self.r.planes;
        let mut best: Option<(f64, usize)> = None;
        if self.r.convex {
            // From inside a convex room the nearest facing plane is the surface hit.
            // Compare t = num/den as fractions (den < 0 for facing planes, num < 0 in front):
            // num/den < nb/db ⟺ num·db < nb·den. One division for the winner only.
            let (mut nb, mut db, mut kb) = (0.0, 0.0, usize::MAX);
            for (k, n) in self.normals_cam.iter().enumerate() {
                let den = n.x * d_cam.x + n.y * d_cam.y + n.z * d_cam.z;
                let num = self.nums[k];
                if den < 0.0 && num < -1e-12 && (kb == usize::MAX || num * db < nb * den) {
                    (nb, db, kb) = (num, den, k);
                }
            }
            if kb != usize::MAX {
                best = Some((nb / db, kb));
            }
        } else {
            let d = self.rot * d_cam;
            let mut cands: Vec<(f64, usize)> = Vec::with_capacity(planes.len());
            for (k, n) in self.normals_cam.iter().enumerate() {
                let den = n.dot(d_cam);
                if den < 0.0 {
                    let t = self.nums[k] / den;
                    if t > 1e-9 {
                        cands.push((t, k));
                    }
                }
            }
            cands.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            best = cands.into_iter().find(|&(t, k)| {
                let p = &planes[k];
                let q = self.o + d * t - p.origin;
                let q2 = Point2::new(p.u.dot(&q), p.v.dot(&q));
                q2.x >= p.lo.x
                    && q2.x <= p.hi.x
                    && q2.y >= p.lo.y
                    && q2.y <= p.hi.y
                    && (p.rect || point_in_polygon_fast(&q2, &p.poly))
            });
        }
        let mut hit = best.map(|(t, k)| (t, Target::Plane(k), planes[k].n));
        let o = &self.o;
        let mut d_room: Option<Vector3<f64>> = None;
        for (k, (lo, hi)) in self.r.boxes.iter().enumerate() {
            // Skip boxes whose bounding sphere the ray misses (unless the camera is inside it).
            let (c, r2) = self.spheres[k];
            if c.norm_squared() > r2
                && (c.dot(d_cam) <= 0.0
                    || c.cross(d_cam).norm_squared() > r2 * d_cam.norm_squared())
            {
                continue;
            }
            let d = *d_room.get_or_insert_with(|| self.rot * d_cam);
            let mut t0 = 1e-9;
            let mut t1 = hit.map_or(f64::INFINITY, |h| h.0);
            let mut axis = usize::MAX;
            let mut inside = true;
            for i in 0..3 {
                if d[i].abs() < 1e-15 {
                    if o[i] < lo[i] || o[i] > hi[i] {
                        inside = false;
                        break;
                    }
                    continue;
                }
                let inv = 1.0 / d[i];
                let (mut a, mut b) = ((lo[i] - o[i]) * inv, (hi[i] - o[i]) * inv);
                if a > b {
                    std::mem::swap(&mut a, &mut b);
                }
                if a > t0 {
                    t0 = a;
                    axis = i;
                }
                t1 = t1.min(b);
                if t0 > t1 {
                    inside = false;
                    break;
                }
            }
            if inside && axis != usize::MAX {
                let mut n = Vector3::zeros();
                n[axis] = -d[axis].signum();
                hit = Some((t0, Target::Box(k), n));
            }
        }
        hit
    }

    /// Distance (in units of `d_cam`), the cosine of incidence of the nearest hit of a ray in the
    /// camera frame, and whether it landed on glass (features are looked up only on surfaces that
    /// carry glass: what depth needs).
    pub fn cast_depth(&self, d_cam: &Vector3<f64>) -> Option<(f64, f64, bool)> {
        let (t, target, n) = self.nearest(d_cam)?;
        let (den, glass) = match target {
            Target::Plane(k) => {
                let p = &self.r.planes[k];
                let glass = p.has_glass && {
                    let q = self.o + self.rot * d_cam * t - p.origin;
                    let q2 = Point2::new(p.u.dot(&q), p.v.dot(&q));
                    p.features.iter().any(|f| f.glass && f.contains(&q2))
                };
                (self.normals_cam[k].dot(d_cam), glass)
            }
            Target::Box(_) => ((self.rot.transpose() * n).dot(d_cam), false),
        };
        Some((t, den.abs() / d_cam.norm(), glass))
    }

    /// The nearest hit of a ray in the camera frame, with the feature it lands on; `t` is in units
    /// of `d_cam`'s length, the normal in the room frame.
    pub fn cast(&self, d_cam: &Vector3<f64>) -> Option<Hit> {
        let (t, target, normal) = self.nearest(d_cam)?;
        let d = self.rot * d_cam;
        let element = match target {
            Target::Box(k) => Element::Furniture(k),
            Target::Plane(k) => {
                let p = &self.r.planes[k];
                let feature = if p.features.is_empty() {
                    None
                } else {
                    let q = self.o + d * t - p.origin;
                    let q2 = Point2::new(p.u.dot(&q), p.v.dot(&q));
                    p.features.iter().find(|f| f.contains(&q2)).map(|f| f.index)
                };
                Element::Surface {
                    surface: k,
                    feature,
                }
            }
        };
        Some(Hit { t, element, normal })
    }
}

impl PlaneFeature {
    /// Whether a point of the plane's 2D frame lies on the feature.
    fn contains(&self, q: &Point2<f64>) -> bool {
        q.x >= self.lo.x
            && q.x <= self.hi.x
            && q.y >= self.lo.y
            && q.y <= self.hi.y
            && point_in_polygon_fast(q, &self.poly)
    }
}

fn polygon_area(p: &[Point2<f64>]) -> f64 {
    mrtmap_geometry::polygon::signed_area(p).abs()
}

/// Radiant temperature (°C) at a hit point (room frame): what a thermal camera reads of a diffuse
/// surface there (its own temperature in a black room, its radiosity's in a grey one).
pub fn temperature_at(room: &Room, hit: &Hit, point: &Point3<f64>) -> f64 {
    match hit.element {
        Element::Surface {
            feature: Some(f), ..
        } => room.feature_radiant_c(f),
        Element::Surface {
            surface,
            feature: None,
        } => room.background_radiant_c(Room::surface_at(surface), point.z),
        Element::Furniture(b) => room.file.furniture[b].temperature_c,
    }
}

#[allow(clippy::too_many_arguments)]
/// What the thermal camera sees of glass feature `k` at `p` looking along `d` (unit): its emission
/// and what the mirrored ray meets (the operator, a surface's radiosity, or the air), as T⁴ (K⁴).
pub fn specular_t4(
    room: &Room,
    renderer: &RoomRenderer,
    k: usize,
    e: f64,
    p: &Point3<f64>,
    d: &Vector3<f64>,
    normal: &Vector3<f64>,
    operator: &crate::operator::Operator,
) -> f64 {
    let r = d - normal * (2.0 * d.dot(normal));
    let start = p + r * 1e-6;
    let hit = renderer.cast(&start, &r);
    let by_operator = operator
        .hit(&start, &r)
        .filter(|t| hit.is_none_or(|h| *t < h.t));
    let reflected_c = match (by_operator, hit) {
        (Some(_), _) => crate::operator::OPERATOR_C,
        (None, Some(h)) => temperature_at(room, &h, &(start + r * h.t)),
        (None, None) => room.file.air_temperature_c,
    };
    let t = room.features[k].temperature_c + mrtmap_physics::ZERO_CELSIUS_K;
    e * t.powi(4) + (1.0 - e) * (reflected_c + mrtmap_physics::ZERO_CELSIUS_K).powi(4)
}
