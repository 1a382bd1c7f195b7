//! Sensor models: D435i-like depth, Lepton-like radiometric thermal, colour by surface, and
//! instance masks with labels. Each renders one frame from a camera pose in the room frame.

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_io::masks::{InstanceInfo, MaskLabels};
use mrtmap_io::{Image16, ThermalEncoding, gaussian_blur};
use mrtmap_physics::ZERO_CELSIUS_K;

use crate::radiometric::CameraErrors;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::render::{Element, Hit, RoomRenderer, temperature_at};
use crate::room::Room;

/// Depth noise of an active stereo camera (RealSense D4xx-like), modelled where it arises: in
/// disparity d = f·b/z. Stereo matching over windows of a few pixels makes the noise spatially
/// correlated: d gets a Gaussian noise field of σ = `disparity_noise_px` drawn every
/// `noise_cell_px` pixels and interpolated bilinearly, a little white noise
/// (`disparity_white_px`), and each frame a smooth tilt of σ = `disparity_tilt_px` (a plane in the
/// image); the result is quantised to 1/`subpixel` px. The depth error therefore grows with z²: σ_z ≈ z²·σ_d/(f·b), with the defaults
/// and f = 385 px about 0.5 % of the distance at 1 m and 1 % at 2 m (the D435i datasheet: under 2 %
/// at 2 m). Pixels go invalid (0) at depth discontinuities (flying pixels), beyond a grazing
/// incidence, out of range and at random.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepthNoise {
    /// Stereo baseline (m).
    pub baseline_m: f64,
    /// Correlated disparity noise σ (px) at the nodes of its field.
    pub disparity_noise_px: f64,
    /// Spacing of the correlated noise field (px): about the stereo matching window.
    pub noise_cell_px: u32,
    /// Independent per-pixel disparity noise σ (px).
    pub disparity_white_px: f64,
    /// Per-frame disparity tilt σ (px, at the image centre and per unit of normalised image
    /// coordinate).
    pub disparity_tilt_px: f64,
    /// Disparity quantisation: 1/`subpixel` px.
    pub subpixel: f64,
    /// Incidence beyond which pixels are invalid (degrees from the normal).
    pub max_incidence_deg: f64,
    /// Relative depth jump to a neighbour that makes a pixel invalid (flying pixels).
    pub edge_jump: f64,
    /// Fraction of pixels randomly invalid.
    pub dropout: f64,
    /// Valid range (m).
    pub min_m: f64,
    /// Valid range (m).
    pub max_m: f64,
    /// Glass (windows, glazing, mirrors: [`crate::is_glass`]), where the scan has it on (see
    /// [`SimConfig::glass`](crate::SimConfig::glass)): the projector's pattern passes through, so
    /// a glass pixel has no depth, except this share that matches on what lies beyond the pane
    /// ([`glass_far_m`](Self::glass_far_m) farther along the ray: outdoors, so often beyond
    /// range).
    #[serde(default = "default_glass_see_through")]
    pub glass_see_through: f64,
    /// How far beyond a pane the far side lies (m).
    #[serde(default = "default_glass_far_m")]
    pub glass_far_m: f64,
}

fn default_glass_see_through() -> f64 {
    0.10
}

fn default_glass_far_m() -> f64 {
    4.0
}

impl Default for DepthNoise {
    fn default() -> Self {
        Self {
            baseline_m: 0.050,
            disparity_noise_px: 0.08,
            noise_cell_px: 4,
            disparity_white_px: 0.0,
            disparity_tilt_px: 0.05,
            subpixel: 32.0,
            max_incidence_deg: 78.0,
            edge_jump: 0.04,
            dropout: 0.005,
            min_m: 0.2,
            max_m: 6.0,
            glass_see_through: default_glass_see_through(),
            glass_far_m: default_glass_far_m(),
        }
    }
}

/// Thermal imperfections (Lepton 3.5-like).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThermalNoise {
    /// Temporal noise σ (K), the camera's NETD.
    pub netd_k: f64,
    /// Optical blur, Gaussian σ in pixels (0 = none).
    pub blur_sigma_px: f64,
    /// Constant offset of every reading (K): camera bias.
    pub bias_k: f64,
    /// Sub-pixel rays per pixel side (1 = one ray at the pixel centre; 3 = 3×3, radiance-averaged).
    pub supersample: u32,
    /// Whether emissivity falls at grazing view (beyond 60°), mixing in reflected radiation.
    pub grazing_emissivity: bool,
    /// The microbolometer's thermal time constant (s): a pixel reads the scene's radiance
    /// averaged over the past with weight exp(−age/τ), which smears edges when the camera turns
    /// fast (0: an instantaneous image). Sampled with the sub-pixel rays: ray j of a pixel looks
    /// at the scene as it was at the j-th quantile of that exponential age.
    #[serde(default)]
    pub time_constant_s: f64,
}

impl ThermalNoise {
    /// Exact: each pixel is the temperature of the point its centre ray hits.
    pub const NONE: ThermalNoise = ThermalNoise {
        netd_k: 0.0,
        blur_sigma_px: 0.0,
        bias_k: 0.0,
        supersample: 1,
        grazing_emissivity: false,
        time_constant_s: 0.0,
    };
    /// Realistic defaults: NETD 50 mK, blur σ 0.5 px, 3×3 supersampling, grazing emissivity, no
    /// bias, a 12 ms time constant (a Lepton's is of order 10 ms).
    pub const REALISTIC: ThermalNoise = ThermalNoise {
        netd_k: 0.05,
        blur_sigma_px: 0.5,
        bias_k: 0.0,
        supersample: 3,
        grazing_emissivity: true,
        time_constant_s: 0.012,
    };

    /// The ages (s) at which a pixel's `n` sub-pixel rays look at the scene: the exponential
    /// age's quantiles (j + ½)/n, each ray weighted equally; all 0 without a time constant.
    pub fn sample_ages_s(&self, n: usize) -> Vec<f64> {
        (0..n)
            .map(|j| {
                if self.time_constant_s > 0.0 {
                    -self.time_constant_s * (1.0 - (j as f64 + 0.5) / n as f64).ln()
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// Ray directions (z = 1 in the camera frame) for every pixel (row-major), with `ss`×`ss`
/// sub-pixel rays per pixel when `ss` > 1 (ordered pixel by pixel).
pub fn camera_rays(cam: &PinholeCamera, ss: u32) -> Vec<Vector3<f64>> {
    let ss = ss.max(1);
    let mut out = Vec::with_capacity((cam.width * cam.height * ss * ss) as usize);
    for v in 0..cam.height {
        for u in 0..cam.width {
            for sv in 0..ss {
                for su in 0..ss {
                    let off = |k: u32| (k as f64 + 0.5) / ss as f64 - 0.5;
                    out.push(cam.unproject(&Point2::new(u as f64 + off(su), v as f64 + off(sv))));
                }
            }
        }
    }
    out
}

/// Renders a depth image (raw units at `scale` per metre), from `rays` (see [`camera_rays`] with 1),
/// with `noise`'s depth noise and, when given, `glass`'s glass model (each independent of the
/// other; without it panes return depth like a wall).
#[allow(clippy::too_many_arguments)]
pub fn render_depth<R: Rng>(
    renderer: &RoomRenderer,
    cam: &PinholeCamera,
    rays: &[Vector3<f64>],
    room_from_cam: &Isometry3<f64>,
    scale: f64,
    noise: Option<&DepthNoise>,
    glass: Option<&DepthNoise>,
    rng: &mut R,
) -> Image16 {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let view = renderer.view(room_from_cam);
    let mut z = vec![0.0f64; w * h];
    let mut cosi = vec![1.0f64; w * h];
    let (see_through, far_m) = match glass {
        Some(g) => (Some(g.glass_see_through), g.glass_far_m),
        None => (None, 0.0),
    };
    for (k, d) in rays.iter().enumerate() {
        if let Some((t, c, on_glass)) = view.cast_depth(d) {
            // d has z = 1 in the camera frame, so t is the z-depth.
            match see_through {
                Some(p) if on_glass => {
                    // Through the pane: nothing, or now and then the far side.
                    if rng.random::<f64>() < p {
                        let range = t * d.norm();
                        z[k] = t * (1.0 + far_m / range);
                        cosi[k] = 1.0;
                    }
                }
                _ => {
                    z[k] = t;
                    cosi[k] = c;
                }
            }
        }
    }
    let mut img = Image16::zeros(cam.width, cam.height);
    let Some(nz) = noise else {
        for (p, zz) in img.data.iter_mut().zip(&z) {
            *p = (zz * scale).round().clamp(0.0, u16::MAX as f64) as u16;
        }
        return img;
    };
    let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
    let tilt =
        [std.sample(rng), std.sample(rng), std.sample(rng)].map(|x| x * nz.disparity_tilt_px);
    let fb = cam.fx * nz.baseline_m;
    // The correlated field: nodes every `cell` pixels (one beyond each edge), bilinear in between.
    let cell = nz.noise_cell_px.max(1) as usize;
    let (gw, gh) = (w / cell + 2, h / cell + 2);
    let field: Vec<f64> = (0..gw * gh)
        .map(|_| nz.disparity_noise_px * std.sample(rng))
        .collect();
    let cos_max = nz.max_incidence_deg.to_radians().cos();
    let columns: Vec<(usize, f64, f64)> = (0..w)
        .map(|u| {
            (
                u / cell,
                (u % cell) as f64 / cell as f64,
                (u as f64 - cam.cx) / cam.fx,
            )
        })
        .collect();
    let drop_below = (nz.dropout.clamp(0.0, 1.0) * u32::MAX as f64) as u32;
    for v in 0..h {
        let (gy, fy) = (v / cell, (v % cell) as f64 / cell as f64);
        let y = (v as f64 - cam.cy) / cam.fy;
        let row_tilt = tilt[0] + tilt[2] * y;
        for (u, &(gx, fx, x)) in columns.iter().enumerate() {
            let k = v * w + u;
            let zz = z[k];
            if zz <= 0.0
                || zz < nz.min_m
                || zz > nz.max_m
                || cosi[k] < cos_max
                || rng.next_u32() < drop_below
            {
                continue;
            }
            let jump = [
                (u > 0, k.wrapping_sub(1)),
                (u + 1 < w, k + 1),
                (v > 0, k.wrapping_sub(w)),
                (v + 1 < h, k + w),
            ]
            .iter()
            .any(|&(ok, j)| ok && (z[j] - zz).abs() > nz.edge_jump * zz);
            if jump {
                continue;
            }
            let g = |i: usize, j: usize| field[j * gw + i];
            let corr = (1.0 - fy) * ((1.0 - fx) * g(gx, gy) + fx * g(gx + 1, gy))
                + fy * ((1.0 - fx) * g(gx, gy + 1) + fx * g(gx + 1, gy + 1));
            let white = if nz.disparity_white_px > 0.0 {
                nz.disparity_white_px * std.sample(rng)
            } else {
                0.0
            };
            let disparity = fb / zz + corr + white + row_tilt + tilt[1] * x;
            let quantised = (disparity * nz.subpixel).round() / nz.subpixel;
            if quantised <= 0.0 {
                continue;
            }
            img.data[k] = (fb / quantised * scale).round().clamp(1.0, u16::MAX as f64) as u16;
        }
    }
    img
}

/// Relative emissivity at incidence `cos` (1 below 60°, falling to 0.75 at 85° and beyond).
fn grazing_emissivity(cos: f64) -> f64 {
    let theta = cos.clamp(-1.0, 1.0).acos().to_degrees();
    if theta <= 60.0 {
        1.0
    } else {
        1.0 - 0.25 * ((theta - 60.0) / 25.0).min(1.0).powi(2)
    }
}

/// Renders a radiometric thermal image from `rays` (see [`camera_rays`] with `noise.supersample`).
/// `room_from_cam` holds the camera's pose at each of a pixel's sub-pixel rays' ages
/// ([`ThermalNoise::sample_ages_s`]; one pose: every ray sees the same instant): sub-pixel ray j
/// looks from pose `(5·j) mod n`, so that time and position within the pixel are not tied.
#[allow(clippy::too_many_arguments)]
pub fn render_thermal<R: Rng>(
    room: &Room,
    renderer: &RoomRenderer,
    cam: &PinholeCamera,
    rays: &[Vector3<f64>],
    room_from_cam: &[Isometry3<f64>],
    encoding: ThermalEncoding,
    noise: &ThermalNoise,
    camera: Option<(&CameraErrors, f64)>,
    rng: &mut R,
) -> Image16 {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let ss = (noise.supersample.max(1) * noise.supersample.max(1)) as usize;
    let views: Vec<_> = room_from_cam
        .iter()
        .map(|p| {
            let o: Point3<f64> = p.translation.vector.into();
            (
                o,
                renderer.view(p),
                p.rotation.to_rotation_matrix(),
                crate::operator::Operator::behind(p),
            )
        })
        .collect();
    // Grey glass is specular: it mirrors the room and the operator.
    let mirrors: Vec<Option<f64>> = (0..room.features.len())
        .map(|k| {
            let e = room.feature_emissivity(k);
            (e < 1.0 && crate::room::is_glass(&room.features[k].label)).then_some(e)
        })
        .collect();
    let n_views = views.len().max(1);
    let t_refl4 = (room.file.air_temperature_c + ZERO_CELSIUS_K).powi(4);
    // Radiance (∝ T⁴) per pixel, averaged over its sub-pixel rays.
    let mut rad = vec![0.0f64; w * h];
    for (k, chunk) in rays.chunks(ss).enumerate() {
        let mut acc = 0.0;
        for (j, d) in chunk.iter().enumerate() {
            let (o, view, rot, operator) = &views[(5 * j) % n_views];
            let dw = rot * d;
            let t4 = match view.cast(d) {
                Some(hit) => {
                    let p = o + dw * hit.t;
                    let mirror = match hit.element {
                        Element::Surface {
                            feature: Some(k), ..
                        } => mirrors[k].map(|e| (k, e)),
                        _ => None,
                    };
                    let t4 = match mirror {
                        Some((k, e)) => crate::render::specular_t4(
                            room,
                            renderer,
                            k,
                            e,
                            &p,
                            &dw.normalize(),
                            &hit.normal,
                            operator,
                        ),
                        None => (temperature_at(room, &hit, &p) + ZERO_CELSIUS_K).powi(4),
                    };
                    if noise.grazing_emissivity {
                        let e = grazing_emissivity((hit.normal.dot(&dw) / dw.norm()).abs());
                        e * t4 + (1.0 - e) * t_refl4
                    } else {
                        t4
                    }
                }
                None => t_refl4,
            };
            acc += t4;
        }
        rad[k] = acc / chunk.len() as f64;
    }
    if noise.blur_sigma_px > 0.0 {
        rad = gaussian_blur(&rad, w, h, noise.blur_sigma_px);
    }
    let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
    let mut img = Image16::zeros(cam.width, cam.height);
    let rmax2 = cam.cx.powi(2) + cam.cy.powi(2);
    for (k, (p, r)) in img.data.iter_mut().zip(&rad).enumerate() {
        let mut t = r.powf(0.25);
        if noise.netd_k > 0.0 {
            t += noise.netd_k * std.sample(rng);
        }
        if let Some((errors, time_s)) = camera {
            let (u, v) = ((k % w) as f64, (k / w) as f64);
            let rho = ((u - cam.cx).powi(2) + (v - cam.cy).powi(2)) / rmax2;
            t = errors.read(t, time_s, rho, k);
        }
        *p = encoding.raw(t + noise.bias_k);
    }
    img
}

/// Instance id of what a hit sees: features 1…F (room order), furniture F+1…; 0 = surface.
pub fn instance_of(room: &Room, hit: &Hit) -> u16 {
    match hit.element {
        Element::Surface {
            feature: Some(f), ..
        } => (f + 1) as u16,
        Element::Surface { feature: None, .. } => 0,
        Element::Furniture(b) => (room.features.len() + b + 1) as u16,
    }
}

/// The label of an instance id.
pub fn instance_label(room: &Room, id: u16) -> Option<&str> {
    let k = (id as usize).checked_sub(1)?;
    if k < room.features.len() {
        Some(&room.features[k].label)
    } else {
        room.file
            .furniture
            .get(k - room.features.len())
            .map(|b| b.label.as_str())
    }
}

fn colour(room: &Room, hit: &Hit) -> [f64; 3] {
    let by_label = |l: &str| -> [f64; 3] {
        use mrtmap_radiation::ElementKind as K;
        match K::of_label(l) {
            K::Glazing(_) => [150.0, 200.0, 235.0],
            K::Light | K::RadiantPanel => [255.0, 245.0, 190.0],
            K::Painting => [170.0, 60.0, 50.0],
            K::Door => [120.0, 80.0, 50.0],
            K::Radiator => [225.0, 225.0, 225.0],
            K::Mirror | K::Desk | K::Other => [180.0, 180.0, 120.0],
        }
    };
    match hit.element {
        Element::Surface {
            feature: Some(f), ..
        } => by_label(&room.features[f].label),
        Element::Surface { surface, .. } => match Room::surface_at(surface) {
            crate::room::SurfaceRef::Floor => [150.0, 110.0, 80.0],
            crate::room::SurfaceRef::Ceiling => [235.0, 235.0, 230.0],
            crate::room::SurfaceRef::Wall(i) => {
                if surface % 2 == 0 {
                    [212.0, 202.0, 186.0]
                } else {
                    [200.0 - (i % 3) as f64 * 6.0, 195.0, 180.0]
                }
            }
        },
        Element::Furniture(_) => [140.0, 100.0, 60.0],
    }
}

/// A seed per element, so that every surface, feature and piece of furniture has its own pattern.
fn element_seed(e: &Element) -> u64 {
    match *e {
        Element::Surface { surface, feature } => {
            0x9e37_79b9 + surface as u64 * 7919 + feature.map_or(0, |f| 104_729 * (f as u64 + 1))
        }
        Element::Furniture(i) => 0x85eb_ca6b + i as u64 * 15_485_863,
    }
}

/// A hash of a lattice point to [0, 1).
fn lattice(i: i64, j: i64, k: i64, seed: u64) -> f64 {
    let mut h = seed
        ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (j as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
        ^ (k as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^= h >> 33;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Value noise in [0, 1): hashed lattice values, smoothly interpolated (no period).
fn value_noise(p: &Vector3<f64>, seed: u64) -> f64 {
    let f = p.map(f64::floor);
    let r = p - f;
    let s = r.map(|x| x * x * (3.0 - 2.0 * x));
    let (i, j, k) = (f.x as i64, f.y as i64, f.z as i64);
    let mut acc = 0.0;
    for (di, wx) in [(0, 1.0 - s.x), (1, s.x)] {
        for (dj, wy) in [(0, 1.0 - s.y), (1, s.y)] {
            for (dk, wz) in [(0, 1.0 - s.z), (1, s.z)] {
                acc += wx * wy * wz * lattice(i + di, j + dj, k + dk, seed);
            }
        }
    }
    acc
}

/// The pattern painted on a surface at room point `p` (m), in [0, 1]: blotches with sharp edges
/// at three scales (50, 13 and 4 cm) over a fine grain (1.2 cm), fixed to the surface and never
/// repeating, so that a visual tracker finds corners to follow everywhere.
pub fn texture(p: &Vector3<f64>, seed: u64) -> f64 {
    let n = 0.5 * value_noise(&(p / 0.5), seed)
        + 0.3 * value_noise(&(p / 0.13), seed ^ 0x51)
        + 0.2 * value_noise(&(p / 0.04), seed ^ 0xa7);
    let blotch = 0.5 + 0.5 * ((n - 0.5) * 14.0).tanh();
    let grain = value_noise(&(p / 0.012), seed ^ 0x3c);
    (0.6 * blotch + 0.25 * n + 0.15 * grain).clamp(0.0, 1.0)
}

/// A label a detector might confuse with `label`.
fn confusable(label: &str) -> &'static str {
    use mrtmap_radiation::ElementKind as K;
    match K::of_label(label) {
        K::Glazing(_) => "mirror",
        K::Light | K::RadiantPanel => "lamp",
        K::Painting => "poster",
        K::Door => "wardrobe",
        K::Radiator => "heater",
        K::Desk => "table",
        K::Mirror | K::Other => "object",
    }
}

/// Renders a colour image (RGB8: each element's colour painted with its own procedural
/// [`texture`], shaded by incidence; with `noisy_labels` also ±2 levels of sensor noise) and an
/// instance mask with labels. With `noisy_labels`, a detector's mistakes are imitated: each instance is missed with probability
/// 0.05 and mislabelled with probability 0.1, scores vary.
pub fn render_rgb_and_mask<R: Rng>(
    room: &Room,
    renderer: &RoomRenderer,
    cam: &PinholeCamera,
    rays: &[Vector3<f64>],
    room_from_cam: &Isometry3<f64>,
    noisy_labels: bool,
    rng: &mut R,
) -> (Vec<u8>, Image16, MaskLabels) {
    let view = renderer.view(room_from_cam);
    let rot = room_from_cam.rotation.to_rotation_matrix();
    let mut rgb = vec![0u8; rays.len() * 3];
    let mut mask = Image16::zeros(cam.width, cam.height);
    // The sensor noise comes from the pose, not from `rng`, which draws the labels' mistakes.
    let tr = room_from_cam.translation.vector;
    let frame_seed =
        tr.x.to_bits() ^ tr.y.to_bits().rotate_left(21) ^ tr.z.to_bits().rotate_left(42);
    for (k, d) in rays.iter().enumerate() {
        let dw = rot * d;
        if let Some(hit) = view.cast(d) {
            let shade = 0.55 + 0.45 * (hit.normal.dot(&dw) / dw.norm()).abs();
            let c = colour(room, &hit);
            let at = room_from_cam * Point3::from(d * hit.t);
            let tex = 0.55 + 0.45 * texture(&at.coords, element_seed(&hit.element));
            for i in 0..3 {
                let grain = if noisy_labels {
                    4.0 * lattice(k as i64, i as i64, 0, frame_seed) - 2.0
                } else {
                    0.0
                };
                rgb[3 * k + i] = (c[i] * shade * tex + grain).round().clamp(0.0, 255.0) as u8;
            }
            mask.data[k] = instance_of(room, &hit);
        }
    }
    let mut present: Vec<u16> = mask.data.iter().copied().filter(|&i| i > 0).collect();
    present.sort_unstable();
    present.dedup();
    let mut labels = MaskLabels::new();
    for id in present {
        let truth = instance_label(room, id).unwrap_or("object");
        if noisy_labels && rng.random::<f64>() < 0.05 {
            mask.data
                .iter_mut()
                .filter(|p| **p == id)
                .for_each(|p| *p = 0);
            continue;
        }
        let (label, score) = if noisy_labels {
            let wrong = rng.random::<f64>() < 0.1;
            (
                if wrong {
                    confusable(truth).to_string()
                } else {
                    truth.to_string()
                },
                rng.random_range(0.45..0.98),
            )
        } else {
            (truth.to_string(), 1.0)
        };
        labels.insert(id, InstanceInfo { label, score });
    }
    (rgb, mask, labels)
}
