//! Grey surfaces: emissivities, the irradiance a surface receives, and its true temperature.
//!
//! A grey diffuse surface at temperature T with emissivity ε that receives irradiance G leaves
//! radiosity J = εσT⁴ + (1 − ε)G. A thermal camera set to ε = 1 reads J as an apparent (radiant)
//! temperature T_r = (J/σ)^¼: the right input to the MRT, since a person exchanges radiation with
//! the radiosities around them. A contact thermometer reads T. The two are tied by the
//! irradiance, which the scene itself gives: σT_irr⁴, T_irr the plane radiant temperature of the
//! hemisphere the surface looks into, from the scene's own view factors. So
//!
//! 1. each element's emissivity is taken from its label ([`default_emissivity`], the table in
//!    docs/scene-format.md) unless given;
//! 2. its irradiance temperature is the T⁴ mean of the plane radiant temperatures at a few points
//!    on it, 2 cm into the room, facing into the room ([`irradiance`]);
//! 3. its true temperature is T⁴ = (T_r⁴ − (1 − ε)T_irr⁴)/ε ([`surface_temperature`]), and a
//!    reading T is predicted to look like T_r⁴ = εT⁴ + (1 − ε)T_irr⁴ to the camera
//!    ([`radiant_temperature`]).
//!
//! The irradiance is one value per element (the radiosity method of building simulation, one node
//! per surface): over a wall beside a cold window it varies by a fraction of a kelvin, which a
//! wall's 1 − ε ≈ 0.07 turns into hundredths.

use mrtmap_geometry::nalgebra::{Point2, Point3, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_physics::Temperature;

use crate::engine::MrtEngine;
use crate::scene::{RadiantScene, SurfaceKind};
use crate::vocabulary::ElementKind;

/// The standard uncertainty of an emissivity taken from the table (or given without one).
pub const EMISSIVITY_STD: f64 = 0.02;

/// How far into the room the irradiance is taken (m): past the bounds' tolerance, close enough
/// that the surface's own neighbours are seen as from the surface.
const IRRADIANCE_OFFSET_M: f64 = 0.02;

/// Sample points per side of an element's bounding box for its irradiance (at most this squared,
/// those on the element).
const IRRADIANCE_GRID: usize = 3;

/// Long-wave emissivities by what an element is made of: the first entry whose keyword the label
/// contains wins, after glass (glazing and mirrors, [`GLASS_EMISSIVITY`]) and before the
/// element's kind ([`KIND_EMISSIVITY`]), so that "aluminium radiator" is bare metal.
/// Sources: ASHRAE Handbook — Fundamentals (2021), ch. 4, table 5 (emissivities of surfaces);
/// ISO 18434-1 annex and thermography makers' tables (FLIR, Testo) for the ranges, of which the
/// middle is taken.
pub const EMISSIVITY_TABLE: &[(&str, f64, &str)] = &[
    ("polished", 0.10, "polished metal (0.03–0.2)"),
    ("aluminium", 0.10, "bare aluminium (0.03–0.2)"),
    ("aluminum", 0.10, "bare aluminium (0.03–0.2)"),
    ("stainless", 0.20, "stainless steel, unpainted (0.1–0.3)"),
    ("bare metal", 0.20, "bare metal (0.1–0.3)"),
    ("metal", 0.93, "painted metal (0.90–0.95)"),
];

/// Glass's long-wave emissivity: soda-lime window glass, uncoated (0.84–0.92); a mirror's front
/// pane emits as glass.
pub const GLASS_EMISSIVITY: f64 = 0.84;

/// Emissivities by element kind ([`ElementKind`], after glass and [`EMISSIVITY_TABLE`]'s
/// materials).
pub const KIND_EMISSIVITY: &[(ElementKind, f64, &str)] = &[
    (
        ElementKind::Radiator,
        0.93,
        "painted steel radiator (0.90–0.95)",
    ),
    (
        ElementKind::RadiantPanel,
        0.93,
        "painted metal radiant panel (0.90–0.95)",
    ),
    (
        ElementKind::Light,
        0.90,
        "light fitting: painted housing and diffuser (0.85–0.95)",
    ),
    (
        ElementKind::Painting,
        0.92,
        "paint on canvas or paper (0.90–0.95)",
    ),
    (ElementKind::Door, 0.90, "painted wood (0.85–0.95)"),
    (ElementKind::Desk, 0.90, "wood or laminate (0.85–0.95)"),
];

/// Emissivities of building materials and of the surface kinds, the last word: the first entry
/// whose keyword the label contains, else the surface kind's.
pub const MATERIAL_EMISSIVITY: &[(&str, f64, &str)] = &[
    ("wood", 0.90, "wood (0.85–0.95)"),
    ("carpet", 0.93, "carpet (0.90–0.95)"),
    ("tile", 0.93, "ceiling tile (0.90–0.95)"),
    ("brick", 0.90, "brick (0.85–0.95)"),
    ("concrete", 0.91, "concrete (0.85–0.95)"),
    ("wall", 0.93, "painted plaster or drywall (0.90–0.95)"),
    (
        "ceiling",
        0.93,
        "painted plaster or ceiling tile (0.90–0.95)",
    ),
    (
        "floor",
        0.93,
        "floor covering: carpet, vinyl, wood (0.90–0.95)",
    ),
];

/// The emissivity of an element from its label (glass by [`ElementKind`], then the materials of
/// [`EMISSIVITY_TABLE`], then the element's kind, then [`MATERIAL_EMISSIVITY`]), else its surface
/// kind's (painted plaster, floor covering), else 0.93 (most building materials lie within
/// 0.90–0.95).
pub fn default_emissivity(label: &str, kind: Option<SurfaceKind>) -> f64 {
    let element = ElementKind::of_label(label);
    if element.is_glass() {
        return GLASS_EMISSIVITY;
    }
    let l = label.to_lowercase();
    if let Some(e) = EMISSIVITY_TABLE.iter().find(|(k, _, _)| l.contains(k)) {
        return e.1;
    }
    if let Some(e) = KIND_EMISSIVITY.iter().find(|(k, _, _)| *k == element) {
        return e.1;
    }
    if let Some(e) = MATERIAL_EMISSIVITY.iter().find(|(k, _, _)| l.contains(k)) {
        return e.1;
    }
    let by_kind = kind.map(|k| k.as_str()).unwrap_or("wall");
    MATERIAL_EMISSIVITY
        .iter()
        .find(|(k, _, _)| *k == by_kind)
        .map_or(0.93, |e| e.1)
}

/// The radiant (apparent) temperature of a surface at `surface` with emissivity `emissivity` that
/// receives the irradiance of `irradiance`: T_r⁴ = εT⁴ + (1 − ε)T_irr⁴.
pub fn radiant_temperature(
    surface: Temperature,
    irradiance: Temperature,
    emissivity: f64,
) -> Temperature {
    let t4 =
        emissivity * surface.kelvin().powi(4) + (1.0 - emissivity) * irradiance.kelvin().powi(4);
    Temperature::from_kelvin(t4.powf(0.25))
}

/// The true temperature of a surface that looks `radiant` to the camera, with emissivity
/// `emissivity` and irradiance `irradiance`: T⁴ = (T_r⁴ − (1 − ε)T_irr⁴)/ε. `None` when the
/// reading is colder than what the surface reflects alone (no temperature explains it: the
/// emissivity is lower than taken, or the reading is off).
pub fn surface_temperature(
    radiant: Temperature,
    irradiance: Temperature,
    emissivity: f64,
) -> Option<Temperature> {
    let t4 =
        (radiant.kelvin().powi(4) - (1.0 - emissivity) * irradiance.kelvin().powi(4)) / emissivity;
    (t4 > 0.0).then(|| Temperature::from_kelvin(t4.powf(0.25)))
}

/// The standard uncertainty of [`surface_temperature`] (K) from the radiant temperature's own
/// (`radiant_std_k`), the emissivity's (`emissivity_std`), the irradiance's (`irradiance_std_k`)
/// and the common level's (`level_std_k`: it moves the radiant and the irradiance together).
#[allow(clippy::too_many_arguments)]
pub fn surface_temperature_std_k(
    radiant: Temperature,
    irradiance: Temperature,
    emissivity: f64,
    surface: Temperature,
    radiant_std_k: f64,
    emissivity_std: f64,
    irradiance_std_k: f64,
    level_std_k: f64,
) -> f64 {
    let (tr, ti, ts, e) = (
        radiant.kelvin(),
        irradiance.kelvin(),
        surface.kelvin(),
        emissivity,
    );
    let ts3 = ts.powi(3);
    // ∂T/∂T_r, ∂T/∂T_irr, ∂T/∂ε from T⁴ = (T_r⁴ − (1 − ε)T_irr⁴)/ε.
    let d_tr = tr.powi(3) / (e * ts3);
    let d_ti = -(1.0 - e) * ti.powi(3) / (e * ts3);
    let d_e = (ti.powi(4) - tr.powi(4)) / (e * e * 4.0 * ts3);
    let parts = [
        d_tr * radiant_std_k,
        d_ti * irradiance_std_k,
        d_e * emissivity_std,
        (d_tr + d_ti) * level_std_k,
    ];
    parts.iter().map(|p| p * p).sum::<f64>().sqrt()
}

/// The irradiance on a surface element: the T⁴ mean of the plane radiant temperatures at points
/// on it (`on`, in the plane of `normal`), each 2 cm into the room and facing into it, with its
/// standard error (K, the camera's level left out). Points where no answer can be had (inside
/// furniture, outside the room on both sides) are skipped; `None` when none is left.
pub fn irradiance(
    engine: &MrtEngine<'_>,
    on: &[Point3<f64>],
    normal: &Vector3<f64>,
    stream: u64,
) -> Option<(Temperature, f64)> {
    let level = engine.scene().temperature_level_std_k;
    let (mut t4, mut var, mut n) = (0.0, 0.0, 0usize);
    for (k, p) in on.iter().enumerate() {
        let into = [*normal, -normal].into_iter().find_map(|d| {
            let q = p + d * IRRADIANCE_OFFSET_M;
            engine.check_inside(&q).ok().map(|()| (q, d))
        });
        let Some((q, d)) = into else { continue };
        let Ok(pr) = engine.plane_radiant(&q, &[d], stream.wrapping_add(k as u64)) else {
            continue;
        };
        let t = pr[0].temperature.kelvin();
        t4 += t.powi(4);
        var += (pr[0].std_error_k.powi(2) - level * level).max(0.0);
        n += 1;
    }
    (n > 0).then(|| {
        let m = n as f64;
        (
            Temperature::from_kelvin((t4 / m).powf(0.25)),
            (var / m).sqrt(),
        )
    })
}

/// Up to [`IRRADIANCE_GRID`]² points of a polygon (2D, in `to_3d`'s frame) that lie on it and in
/// none of `holes`, on a grid over its bounding box inset by a sixth; its centroid when none.
pub fn sample_points(
    poly: &[Point2<f64>],
    holes: &[&[Point2<f64>]],
    to_3d: impl Fn(&Point2<f64>) -> Point3<f64>,
) -> Vec<Point3<f64>> {
    let (mut lo, mut hi) = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for q in poly {
        lo = lo.inf(q);
        hi = hi.sup(q);
    }
    let g = IRRADIANCE_GRID;
    let mut out = Vec::new();
    for i in 0..g {
        for j in 0..g {
            let fx = (2 * i + 1) as f64 / (2 * g) as f64;
            let fy = (2 * j + 1) as f64 / (2 * g) as f64;
            let q = Point2::new(lo.x + fx * (hi.x - lo.x), lo.y + fy * (hi.y - lo.y));
            if point_in_polygon_fast(&q, poly)
                && !holes.iter().any(|h| point_in_polygon_fast(&q, h))
            {
                out.push(to_3d(&q));
            }
        }
    }
    if out.is_empty() {
        let c = poly.iter().fold(Point2::origin(), |a, q| a + q.coords) / poly.len().max(1) as f64;
        out.push(to_3d(&c));
    }
    out
}

/// One element's grey numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct GreyElement {
    /// Surface index in the scene.
    pub surface: usize,
    /// Feature index on it, for a feature.
    pub feature: Option<usize>,
    /// Its irradiance temperature and standard error (K).
    pub irradiance: Option<(Temperature, f64)>,
}

/// The irradiance on every surface (its background: features left out) and feature of the engine's
/// scene.
pub fn irradiances(engine: &MrtEngine<'_>) -> Vec<GreyElement> {
    let scene = engine.scene();
    let mut out = Vec::new();
    for (si, s) in scene.surfaces.iter().enumerate() {
        let holes: Vec<&[Point2<f64>]> =
            s.features.iter().map(|f| f.polygon_2d.as_slice()).collect();
        let pts = sample_points(&s.polygon_2d, &holes, |q| s.frame.to_3d(q));
        let n = s.frame.normal.into_inner();
        out.push(GreyElement {
            surface: si,
            feature: None,
            irradiance: irradiance(engine, &pts, &n, 1_000 * si as u64),
        });
        for (fi, f) in s.features.iter().enumerate() {
            let pts = sample_points(&f.polygon_2d, &[], |q| s.frame.to_3d(q));
            out.push(GreyElement {
                surface: si,
                feature: Some(fi),
                irradiance: irradiance(engine, &pts, &n, 1_000 * si as u64 + 100 * (fi as u64 + 1)),
            });
        }
    }
    out
}

/// Sets every surface's and feature's true temperature from its radiant one, its emissivity and
/// the irradiance of `elements` (see [`irradiances`]), with `emissivity_std` for each emissivity's
/// uncertainty. Elements without an irradiance, or whose reading no temperature explains, are
/// left without one; their ids are returned.
pub fn set_surface_temperatures(
    scene: &mut RadiantScene,
    elements: &[GreyElement],
    emissivity_std: f64,
) -> Vec<String> {
    let level = scene.temperature_level_std_k;
    let mut unexplained = Vec::new();
    for el in elements {
        let s = &mut scene.surfaces[el.surface];
        let (id, radiant, e, std_k, slot) = match el.feature {
            None => (
                s.id.clone(),
                s.temperature,
                s.emissivity,
                s.temperature_std_k.unwrap_or(0.0),
                &mut s.surface_temperature,
            ),
            Some(fi) => {
                let f = &mut s.features[fi];
                (
                    f.id.clone(),
                    f.temperature,
                    f.emissivity,
                    f.temperature_std_k.unwrap_or(0.0),
                    &mut f.surface_temperature,
                )
            }
        };
        *slot = None;
        let Some((irr, irr_std)) = el.irradiance else {
            unexplained.push(id);
            continue;
        };
        match surface_temperature(radiant, irr, e) {
            Some(t) => {
                let sd = surface_temperature_std_k(
                    radiant,
                    irr,
                    e,
                    t,
                    std_k,
                    if e < 1.0 { emissivity_std } else { 0.0 },
                    irr_std,
                    level,
                );
                *slot = Some((t, sd));
            }
            None => unexplained.push(id),
        }
    }
    unexplained
}

/// The surface temperatures of a scene whose temperatures are radiant, set in place: see
/// [`irradiances`] and [`set_surface_temperatures`].
pub fn derive_surface_temperatures<E>(
    scene: &mut RadiantScene,
    engine_of: impl Fn(&RadiantScene) -> Result<MrtEngine<'_>, E>,
    emissivity_std: f64,
) -> Result<Vec<String>, E> {
    let elements = irradiances(&engine_of(scene)?);
    Ok(set_surface_temperatures(scene, &elements, emissivity_std))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn c(x: f64) -> Temperature {
        Temperature::from_celsius(x)
    }

    /// grey-and-sun.md: a window at 11.5 °C with ε 0.84 in a 20 °C room reads about 13.0 °C; a wall at
    /// 20.9 °C with ε 0.93 within 0.05 K of its true temperature.
    #[test]
    fn the_reference_magnitudes_hold_and_invert() {
        let w = radiant_temperature(c(11.5), c(20.0), 0.84);
        assert!((w.celsius() - 13.0).abs() < 0.15, "{}", w.celsius());
        let back = surface_temperature(w, c(20.0), 0.84).unwrap();
        assert!((back.celsius() - 11.5).abs() < 1e-9);
        let wall = radiant_temperature(c(20.9), c(20.4), 0.93);
        assert!((wall.celsius() - 20.9).abs() < 0.05);
        // A polished radiator reads close to the room, not its own 45 °C.
        let r = radiant_temperature(c(45.0), c(20.0), 0.1);
        assert!(r.celsius() < 24.0, "{}", r.celsius());
        // Colder than what it reflects alone: nothing explains it.
        assert!(surface_temperature(c(10.0), c(20.0), 0.1).is_none());
    }

    #[test]
    fn the_uncertainty_matches_finite_differences() {
        let (tr, ti, e) = (c(13.0), c(20.0), 0.84);
        let ts = surface_temperature(tr, ti, e).unwrap();
        let de = 1e-4;
        let up = surface_temperature(tr, ti, e + de).unwrap().kelvin();
        let dn = surface_temperature(tr, ti, e - de).unwrap().kelvin();
        let fd = (up - dn) / (2.0 * de) * 0.02;
        let sd = surface_temperature_std_k(tr, ti, e, ts, 0.0, 0.02, 0.0, 0.0);
        assert!((sd - fd.abs()).abs() < 1e-6, "{sd} {fd}");
        // The level moves the reading and the irradiance together: one to one.
        let lv = surface_temperature_std_k(tr, ti, e, ts, 0.0, 0.0, 0.0, 0.3);
        let moved = surface_temperature(c(13.3), c(20.3), e).unwrap().kelvin() - ts.kelvin();
        assert!((lv - moved).abs() < 0.01, "{lv} {moved}");
    }

    /// Radiant temperatures are used as they are, whatever the emissivity; true surface
    /// temperatures (or a file that does not say) are weighted by it, as the format's version 1 says.
    /// In a uniform room every surface receives the room's temperature: a grey surface's true
    /// temperature is its radiant one; a cold window's comes out colder than it looks.
    #[test]
    fn the_scene_gives_each_surface_its_irradiance() {
        use crate::engine::{Method, MrtEngine};
        use crate::scene::TemperatureKind;
        let mut scene = crate::example_office();
        scene.temperatures = Some(TemperatureKind::Radiant);
        for s in &mut scene.surfaces {
            s.emissivity = 0.9;
            s.temperature = c(20.0);
            for f in &mut s.features {
                f.emissivity = 0.84;
                f.temperature = c(20.0);
            }
        }
        let unexplained = derive_surface_temperatures(
            &mut scene,
            |s| MrtEngine::new(s, Method::Exact),
            EMISSIVITY_STD,
        )
        .unwrap();
        assert!(unexplained.is_empty(), "{unexplained:?}");
        for s in &scene.surfaces {
            let (t, sd) = s.surface_temperature.unwrap();
            assert!(
                (t.celsius() - 20.0).abs() < 1e-6,
                "{}: {}",
                s.id,
                t.celsius()
            );
            assert!(sd < 1e-6, "{sd}");
        }
        let window = scene
            .surfaces
            .iter_mut()
            .flat_map(|s| s.features.iter_mut())
            .find(|f| f.label.contains("window"))
            .unwrap();
        window.temperature = c(13.0);
        derive_surface_temperatures(&mut scene, |s| MrtEngine::new(s, Method::Exact), 0.02)
            .unwrap();
        let w = scene
            .surfaces
            .iter()
            .flat_map(|s| s.features.iter())
            .find(|f| f.label.contains("window"))
            .unwrap();
        let (t, sd) = w.surface_temperature.unwrap();
        // 13 °C radiant in a room near 20 °C: about 11.7 °C true, ± the emissivity's ~0.2 K.
        assert!(t.celsius() < 12.0 && t.celsius() > 11.0, "{}", t.celsius());
        assert!(sd > 0.1 && sd < 0.4, "{sd}");
    }

    #[test]
    fn labels_give_the_table_s_emissivities() {
        assert_eq!(default_emissivity("window", None), 0.84);
        assert_eq!(default_emissivity("Glass door", None), 0.84);
        assert_eq!(default_emissivity("radiator", None), 0.93);
        assert_eq!(
            default_emissivity("polished aluminium radiator", None),
            0.10
        );
        assert_eq!(
            default_emissivity("unlabelled", Some(SurfaceKind::Floor)),
            0.93
        );
        assert_eq!(default_emissivity("recessed light", None), 0.90);
    }
}
