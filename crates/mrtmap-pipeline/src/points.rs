//! MRT at points of a scene: a small sphere's (with its view-factor table), a person's (with
//! its angle factors) and the six plane radiant temperatures with the radiant asymmetry. What
//! `mrtmap mrt` prints, and what a binding returns, from one call.

pub(crate) use mrtmap_physics::AsymmetryKind;
/// A person's posture and the asymmetry kinds (mrtmap-physics' types).
pub use mrtmap_physics::Posture;
use std::path::Path;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_physics::PhysicsError;
use mrtmap_physics::{
    SkyAndRoom, SolarInput, SolarInputError, SolarInputs, sharp_deg, solar_gain_checked,
};
/// A sphere's MRT at a point with its view-factor table (mrtmap-radiation's).
pub use mrtmap_radiation::PointRecord;
/// The sun in the room's frame and a person's exposure to it (mrtmap-radiation's).
pub(crate) use mrtmap_radiation::SunExposure;
pub(crate) use mrtmap_radiation::{AsymmetryVerdict, ENCLOSURE_TOLERANCE};
/// Which way a person faces, an asymmetry's verdict, the enclosure tolerance and the built-in
/// example scene (mrtmap-radiation's).
pub use mrtmap_radiation::{EXAMPLE_OFFICE_JSON, Facing};

/// Writes the built-in example scene (an office with a cold window) to `path`, whole or not at all.
pub fn write_example_scene(path: &Path) -> Result<()> {
    mrtmap_io::write_atomic(path, EXAMPLE_OFFICE_JSON.as_bytes())?;
    Ok(())
}
use mrtmap_radiation::{PersonMrt, RadiantAsymmetry, RadiantScene, SunTracer};
use mrtmap_report::numbers::{fixed, uncertainty};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{Error, Result};
pub use crate::settings::sun::SunQuery;
use crate::settings::{MrtSection, PointFrame};

/// What to compute at the points.
#[derive(Clone, Debug)]
pub struct PointQuery {
    /// The points (m), in `frame`.
    pub at: Vec<[f64; 3]>,
    /// Their frame: the room's, or the scan's (carried through the scene's `world_from_room`).
    pub frame: PointFrame,
    /// A person's MRT (posture and facing) instead of a small sphere's; the points are the body
    /// centres.
    pub person: Option<(Posture, Facing)>,
    /// The six plane radiant temperatures and the radiant asymmetry as well.
    pub planes: bool,
    /// The sun through the scene's windows on the person (SolarCal), which needs `person` with a
    /// facing.
    pub sun: Option<SunQuery>,
}

/// The sun on a person: the exposure traced in the scene and SolarCal's answer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SunAnswer {
    /// The sun's altitude (degrees).
    pub sun_altitude_deg: f64,
    /// The sun's azimuth in the room's frame (degrees from +x towards +y).
    pub sun_azimuth_deg: f64,
    /// The sun's angle from the person's front (degrees, 0…180).
    pub sharp_deg: f64,
    /// Sky-vault view fraction through the windows (traced).
    pub f_svv: f64,
    /// Fraction of the body in the beam (traced).
    pub f_bes: f64,
    /// The windows the beam reaches the body through.
    pub beam_windows: Vec<String>,
    /// SolarCal's effective radiant field (W/m²).
    pub erf_w_m2: f64,
    /// The rise of the MRT (K).
    pub delta_mrt_k: f64,
    /// The long-wave MRT plus ΔMRT (°C).
    pub mrt_with_sun_c: f64,
}

/// The answers, in the order of the points; `mrtmap mrt --json` writes this.
#[derive(Clone, Debug, Serialize)]
pub struct PointAnswers {
    /// Where the scene came from.
    pub scene: String,
    /// How view factors were computed.
    pub method: mrtmap_radiation::Method,
    /// The method in words, with the ray engine used.
    #[serde(skip)]
    pub method_description: String,
    /// A small sphere's MRT at each point (empty with a person).
    pub points: Vec<PointRecord>,
    /// A person's MRT at each point (empty without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub persons: Vec<PersonAnswer>,
    /// The plane radiant temperatures at each point (empty unless asked for).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub planes: Vec<PlaneAnswer>,
    /// What the answers leave out or rest on, in words (a sun asked for in a scene without
    /// glazing).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// A person's MRT at a point.
#[derive(Clone, Debug, Serialize)]
pub struct PersonAnswer {
    /// The body centre (room frame, m).
    pub centre: [f64; 3],
    /// Seated or standing.
    pub posture: Posture,
    /// Which way the person faces.
    pub facing: Facing,
    /// MRT (°C).
    pub mrt_c: f64,
    /// Its standard error (K).
    pub std_error_k: f64,
    /// The sum of the angle factors (about 0.99 for fp's projected areas; the MRT is normalised
    /// by it).
    pub angle_factor_sum: f64,
    /// Each patch's angle factor.
    pub angle_factors: Vec<(String, f64)>,
    /// Rays cast.
    pub rays: usize,
    /// The sun on the person, when asked for: ΔMRT beside the long-wave MRT above.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub sun: Option<SunAnswer>,
}

/// The plane radiant temperatures and the radiant asymmetry at a point.
#[derive(Clone, Debug, Serialize)]
pub struct PlaneAnswer {
    /// The point (room frame, m).
    pub point: [f64; 3],
    /// Faces up, down, +x, −x, +y, −y: T_pr (°C) and standard error (K).
    pub faces: Vec<(String, f64, f64)>,
    /// All six from exact view factors (not rays).
    pub exact: bool,
    /// Vertical asymmetry (K).
    pub vertical_k: f64,
    /// The largest horizontal asymmetry (K).
    pub horizontal_k: f64,
    /// The azimuth of its warmer side (degrees).
    pub horizontal_warm_azimuth_deg: f64,
    /// ISO 7730's verdict on the vertical asymmetry.
    pub vertical: AsymmetryVerdict,
    /// ISO 7730's verdict on the horizontal asymmetry.
    pub horizontal: AsymmetryVerdict,
}

/// The faces of [`PlaneAnswer::faces`], in order.
pub const FACES: [&str; 6] = ["up", "down", "+x", "-x", "+y", "-y"];

fn person_answer(p: &PersonMrt, patches: &[mrtmap_radiation::Patch]) -> PersonAnswer {
    PersonAnswer {
        centre: [p.centre.x, p.centre.y, p.centre.z],
        posture: p.posture,
        facing: p.facing,
        mrt_c: p.mrt.celsius(),
        std_error_k: p.std_error_k,
        angle_factor_sum: p.angle_factor_sum,
        angle_factors: patches
            .iter()
            .zip(&p.angle_factors)
            .map(|(pa, f)| (pa.id.clone(), *f))
            .collect(),
        rays: p.rays,
        sun: None,
    }
}

/// Refuses a sun without a person facing one way, or below the horizon, before any ray.
fn check_sun(q: &PointQuery) -> Result<()> {
    let Some(sun) = &q.sun else {
        return Ok(());
    };
    let (alt, az) = (sun.direction.altitude_deg, sun.direction.azimuth_deg);
    match q.person {
        None => Err(Error::setting(
            "--sun",
            "is for a person: give --person seated|standing and --facing DEG",
        )),
        Some((_, Facing::Any)) => Err(Error::setting(
            "--sun",
            "needs --facing: SolarCal's SHARP is the sun's angle from the person's front",
        )),
        Some(_) if !(0.0..=90.0).contains(&alt) => Err(Error::setting(
            format!("--sun {alt},{az}"),
            "has its altitude outside 0…90°: no sun above the horizon, no beam",
        )),
        // As [sun] azimuth_deg: one turn either way.
        Some(_) if !(-360.0..=360.0).contains(&az) => Err(Error::setting(
            format!("--sun {alt},{az}"),
            "has its azimuth outside -360…360°",
        )),
        Some(_) => Ok(()),
    }
}

/// SolarCal for a person of `posture` facing `facing_deg` (body centre `at` in the scene's frame)
/// in the sun `sun`: the exposure traced through the windows, SHARP and SolarCal's answer.
pub(crate) fn solar_on(
    tracer: &SunTracer<'_>,
    at: &Point3<f64>,
    posture: Posture,
    facing_deg: f64,
    sun: &SunQuery,
) -> std::result::Result<(SunExposure, f64, mrtmap_physics::SolarGain), SolarInputError> {
    let exposure = tracer.exposure(at, posture, &sun.direction);
    let sharp = sharp_deg(facing_deg, sun.direction.azimuth_deg);
    let sky = SkyAndRoom {
        diffuse_horizontal_w_m2: sun.diffuse_horizontal_w_m2,
        beam_enters: tracer.beam_enters(&sun.direction),
    };
    let g = solar_gain_checked(
        &SolarInputs {
            altitude_deg: sun.direction.altitude_deg,
            sharp_deg: sharp,
            dni_w_m2: sun.dni_w_m2,
            transmittance: sun.transmittance,
            f_svv: exposure.f_svv,
            f_bes: exposure.f_bes,
            asw: sun.asw,
            posture: posture.into(),
            floor_reflectance: sun.floor_reflectance,
        },
        &sky,
    )?;
    Ok((exposure, sharp, g))
}

/// SolarCal for the person `p` (body centre `at` in the scene's frame) in the sun `sun`.
fn sun_on(
    tracer: &SunTracer<'_>,
    at: &Point3<f64>,
    p: &PersonAnswer,
    sun: &SunQuery,
) -> Result<SunAnswer> {
    let facing = match p.facing {
        Facing::Azimuth(a) => a,
        Facing::Any => 0.0,
    };
    let (exposure, sharp, g) =
        solar_on(tracer, at, p.posture, facing, sun).map_err(solar_flag_error)?;
    Ok(SunAnswer {
        sun_altitude_deg: sun.direction.altitude_deg,
        sun_azimuth_deg: sun.direction.azimuth_deg.rem_euclid(360.0) + 0.0,
        sharp_deg: sharp,
        f_svv: exposure.f_svv,
        f_bes: exposure.f_bes,
        beam_windows: exposure.beam_windows,
        erf_w_m2: g.erf_w_m2,
        delta_mrt_k: g.delta_mrt_k,
        mrt_with_sun_c: p.mrt_c + g.delta_mrt_k,
    })
}

fn plane_answer(a: &RadiantAsymmetry) -> PlaneAnswer {
    PlaneAnswer {
        point: [a.point.x, a.point.y, a.point.z],
        faces: FACES
            .iter()
            .zip(&a.six)
            .map(|(n, t)| (n.to_string(), t.temperature.celsius(), t.std_error_k))
            .collect(),
        exact: a.six.iter().all(|t| t.exact),
        vertical_k: a.vertical_k,
        horizontal_k: a.horizontal_k,
        horizontal_warm_azimuth_deg: a.horizontal_warm_azimuth_deg,
        vertical: a.vertical,
        horizontal: a.horizontal,
    }
}

/// Refuses the sun (asked for by `what`) in a scene whose up is not +z: its altitude and azimuth
/// are in the room's frame, z up.
pub(crate) fn check_sun_frame(scene: &RadiantScene, what: &str) -> Result<()> {
    if mrtmap_radiation::sun_frame_is_z_up(scene) {
        return Ok(());
    }
    Err(Error::setting(
        what,
        "needs a scene whose up is +z: the sun's altitude and azimuth are in the room's frame (z up, the floor at z = 0); write the scene with z up",
    ))
}

/// The warning for a sun asked for in a scene that has no glazing.
pub(crate) const NO_GLAZING: &str = "the scene has no glazing (no feature labelled window, skylight, roof light, glazed door or curtain wall): the sun cannot reach anyone, so ΔMRT is 0 everywhere";

/// Answers `q` on `scene` (read from `source`, which errors name) with the view-factor settings
/// `mrt`. A point outside the room or inside its furniture is refused with an error naming it;
/// the k-th point draws its rays from stream k, so answers do not depend on the other points.
/// Points are answered in parallel.
pub fn mrt_at_points(
    scene: &RadiantScene,
    source: &str,
    mrt: &MrtSection,
    q: &PointQuery,
) -> Result<PointAnswers> {
    check_sun(q)?;
    if q.sun.is_some() {
        check_sun_frame(scene, "--sun")?;
    }
    let method = mrt.method(scene)?;
    let engine = mrt.engine(scene)?;
    let tracer = q.sun.as_ref().map(|_| SunTracer::new(scene));
    let mut answers = PointAnswers {
        scene: source.to_string(),
        method_description: method.describe(engine.ray_engine()),
        method,
        points: Vec::new(),
        persons: Vec::new(),
        planes: Vec::new(),
        warnings: Vec::new(),
    };
    if tracer.as_ref().is_some_and(|t| !t.has_windows()) {
        answers.warnings.push(NO_GLAZING.into());
    }
    // In parallel: the k-th point draws from stream k, so the answers are those of a loop; the
    // first point refused (in order) is the one named.
    type One = (
        Option<PointRecord>,
        Option<PersonAnswer>,
        Option<PlaneAnswer>,
    );
    let each: Vec<Result<One>> =
        q.at.par_iter()
            .enumerate()
            .map(|(k, p)| {
                let at = to_scene_frame(*p, q.frame, scene, source)?;
                let mut one: One = (None, None, None);
                if let Some((posture, facing)) = q.person {
                    let r = engine.person_at(&at, posture, facing, k as u64)?;
                    let mut answer = person_answer(&r, engine.patches());
                    if let (Some(sun), Some(tracer)) = (&q.sun, &tracer) {
                        answer.sun = Some(sun_on(tracer, &at, &answer, sun)?);
                    }
                    one.1 = Some(answer);
                } else {
                    let r = engine.at(&at, k as u64)?;
                    one.0 = Some(PointRecord::new(None, &r, engine.patches()));
                }
                if q.planes {
                    one.2 = Some(plane_answer(&engine.asymmetry_at(&at, k as u64)?));
                }
                Ok(one)
            })
            .collect();
    for one in each {
        let (point, person, plane) = one?;
        answers.points.extend(point);
        answers.persons.extend(person);
        answers.planes.extend(plane);
    }
    Ok(answers)
}

/// An asymmetry's verdict in words.
fn verdict_text(v: &AsymmetryVerdict) -> String {
    let kind = match v.kind {
        AsymmetryKind::WarmCeiling => "warm ceiling",
        AsymmetryKind::CoolCeiling => "cool ceiling",
        AsymmetryKind::WarmWall => "warm wall",
        AsymmetryKind::CoolWall => "cool wall",
    };
    format!(
        "{:.2} K ({kind}): {:.1} % dissatisfied, ISO 7730 category {}",
        v.delta_k,
        v.pd_pct,
        v.category.as_str()
    )
}

impl PointAnswers {
    /// What `mrtmap mrt` prints, in lines: each person's MRT with its angle factors, each plane's
    /// radiant temperatures and asymmetries, and each point's MRT, its ± in parts and its
    /// view-factor table.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if !self.persons.is_empty() || !self.planes.is_empty() {
            lines.push(format!("scene: {}", self.scene));
            lines.extend(self.warnings.iter().map(|w| format!("warning: {w}")));
            lines.extend(person_and_plane_lines(&self.persons, &self.planes));
            if self.points.is_empty() {
                return lines;
            }
        }
        lines.push(format!("scene: {}", self.scene));
        lines.push(format!("method: {}", self.method_description));
        for p in &self.points {
            lines.push(String::new());
            lines.push(format!(
                "point ({}, {}, {}): MRT {:.2} °C ± {} K   (ΣF = {:.4})",
                fixed(p.xyz[0], 3),
                fixed(p.xyz[1], 3),
                fixed(p.xyz[2], 3),
                p.mrt_c,
                uncertainty(p.std_error_k, 2),
                p.view_factor_sum
            ));
            lines.push(format!(
                "  ± in parts: {}",
                mrtmap_report::parts_line(&p.parts(), 2)
            ));
            if (p.view_factor_sum - 1.0).abs() > ENCLOSURE_TOLERANCE {
                lines.push(format!(
                    "  warning: the scene covers only {:.1} % of the view here (asked for with --allow-open): the MRT leaves the rest out",
                    p.view_factor_sum * 100.0
                ));
            }
            lines.push(format!(
                "  {:<28} {:<18} {:>9} {:>9} {:>8}",
                "id", "label", "F", "±", "T (°C)"
            ));
            for v in &p.view_factors {
                let label = if v.label.is_empty() {
                    "-"
                } else {
                    v.label.as_str()
                };
                let id = match &v.host {
                    Some(h) => format!("{} (on {h})", v.id),
                    None => v.id.clone(),
                };
                lines.push(format!(
                    "  {:<28} {:<18} {:>9.5} {:>9.5} {:>8.2}",
                    id, label, v.view_factor, v.view_factor_std_error, v.temperature_c
                ));
            }
        }
        lines
    }
}

/// Each person's MRT and angle factors, each plane's radiant temperatures, in lines.
fn person_and_plane_lines(persons: &[PersonAnswer], planes: &[PlaneAnswer]) -> Vec<String> {
    let mut lines = Vec::new();
    for p in persons {
        lines.push(String::new());
        lines.push(format!(
            "{} person, body centre ({}, {}, {}), {}: MRT {:.2} °C ± {} K",
            p.posture.as_str(),
            fixed(p.centre[0], 3),
            fixed(p.centre[1], 3),
            fixed(p.centre[2], 3),
            p.facing.describe(),
            p.mrt_c,
            uncertainty(p.std_error_k, 2)
        ));
        lines.push(format!(
            "  angle factors (sum {:.4}; fp's closure is about 0.99, the MRT is normalised by it):",
            p.angle_factor_sum
        ));
        if let Some(s) = &p.sun {
            lines.push(format!(
                "  sun {:.1}° high towards {:.0}° (SHARP {:.0}°): f_svv {:.4}, f_bes {:.2}{}; ERF {:.2} W/m², ΔMRT {:+.2} K: MRT with the sun {:.2} °C (SolarCal)",
                s.sun_altitude_deg,
                s.sun_azimuth_deg,
                s.sharp_deg,
                s.f_svv,
                s.f_bes,
                if s.beam_windows.is_empty() {
                    " (out of the beam)".to_string()
                } else {
                    format!(" through {}", s.beam_windows.join(", "))
                },
                s.erf_w_m2,
                s.delta_mrt_k,
                s.mrt_with_sun_c
            ));
        }
        for (id, f) in p.angle_factors.iter().filter(|(_, f)| *f > 0.0) {
            lines.push(format!("  {id:<28} {f:>9.5}"));
        }
    }
    for pl in planes {
        lines.push(String::new());
        lines.push(format!(
            "plane radiant temperatures at ({}, {}, {}) ({}):",
            fixed(pl.point[0], 3),
            fixed(pl.point[1], 3),
            fixed(pl.point[2], 3),
            if pl.exact { "exact" } else { "rays" }
        ));
        for (face, t, e) in &pl.faces {
            lines.push(format!(
                "  {face:<5} {t:>7.2} °C ± {} K",
                uncertainty(*e, 2)
            ));
        }
        lines.push(format!(
            "  vertical asymmetry   {}",
            verdict_text(&pl.vertical)
        ));
        lines.push(format!(
            "  horizontal asymmetry {} (warmer side towards {:.0}°)",
            verdict_text(&pl.horizontal),
            pl.horizontal_warm_azimuth_deg
        ));
    }
    lines
}

/// A point of `frame` in the scene's own frame: a scan-frame point is carried through the scene's
/// `world_from_room` (`source` names the scene for the error when it has none).
pub(crate) fn to_scene_frame(
    xyz: [f64; 3],
    frame: PointFrame,
    scene: &RadiantScene,
    source: &str,
) -> Result<Point3<f64>> {
    let p = Point3::from(xyz);
    match frame {
        PointFrame::Room => Ok(p),
        PointFrame::Scan => match scene.world_from_room {
            Some(w) => Ok(w.inverse() * p),
            None => Err(Error::source(
                Path::new(source),
                "has no world_from_room (it was not written by segmentation), so points in the scan's frame cannot be placed in it: give them in its own frame",
            )),
        },
    }
}

/// The command line's flag for each SolarCal input, and what the input is.
fn solar_flag(input: SolarInput) -> (&'static str, &'static str) {
    match input {
        SolarInput::Altitude => ("--altitude", "the solar altitude in degrees"),
        SolarInput::Sharp => (
            "--sharp",
            "the sun's angle from the person's front in degrees",
        ),
        SolarInput::Dni => ("--dni", "the direct normal irradiance in W/m²"),
        SolarInput::Transmittance => ("--transmittance", "the glazing's solar transmittance"),
        SolarInput::FSvv => ("--f-svv", "the sky-vault view fraction"),
        SolarInput::FBes => ("--f-bes", "the fraction of the body in the beam"),
        SolarInput::Asw => ("--asw", "the person's short-wave absorptivity"),
        SolarInput::FloorReflectance => ("--floor-reflectance", "the floor's reflectance"),
        SolarInput::DiffuseHorizontal => (
            "[sun] epw",
            "the weather file's diffuse horizontal irradiance in W/m²",
        ),
    }
}

/// A SolarCal input refused, as its flag with the value given.
pub(crate) fn solar_flag_error(e: SolarInputError) -> Error {
    let (f, what) = solar_flag(e.input);
    match e.error {
        PhysicsError::OutOfRange {
            value, min, max, ..
        } => Error::setting(
            format!("{f} {value}"),
            format!("is outside {min}…{max} ({what})"),
        ),
        PhysicsError::NotFinite { value, .. } => Error::setting(
            format!("{f} {value}"),
            format!("is not a finite number ({what})"),
        ),
        other => other.into(),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The example office: a sphere's, a person's and the planes' answers at the same point, in
    /// both frames; a point outside the room is refused.
    #[test]
    fn points_persons_and_planes_from_one_call() {
        let scene = mrtmap_radiation::example_office();
        let mrt = MrtSection::default();
        let mut q = PointQuery {
            at: vec![[2.0, 1.5, 1.1], [1.0, 1.0, 0.6]],
            frame: PointFrame::Room,
            person: None,
            planes: true,
            sun: None,
        };
        let a = mrt_at_points(&scene, "example", &mrt, &q).unwrap();
        assert_eq!((a.points.len(), a.persons.len(), a.planes.len()), (2, 0, 2));
        let sphere = a.points[0].mrt_c;
        assert!((15.0..30.0).contains(&sphere), "{sphere}");
        assert_eq!(a.planes[0].faces.len(), 6);
        q.person = Some((Posture::Seated, Facing::Any));
        q.planes = false;
        let p = mrt_at_points(&scene, "example", &mrt, &q).unwrap();
        assert_eq!((p.points.len(), p.persons.len()), (0, 2));
        assert!((p.persons[0].mrt_c - sphere).abs() < 1.0);
        q.at = vec![[20.0, 1.5, 1.1]];
        assert!(mrt_at_points(&scene, "example", &mrt, &q).is_err());
    }

    /// Issue 52's acceptance: the example office's window is on the +x wall (x = 4.2 m, y
    /// 0.9…2.7, z 0.9…2.2), so a sun 30° high due +x (azimuth 0 in the room's frame) shines
    /// through it onto a seated person facing it 1.55 m away, centred on it; SolarCal for that
    /// person wholly in the beam with the CBE form's f_svv for the window gives ΔMRT 16.41 K
    /// (grey-and-sun.md). A person at y = 0.3, beside the beam, gets sky and floor only.
    #[test]
    fn the_sun_through_the_example_window() {
        let scene = mrtmap_radiation::example_office();
        let mrt = MrtSection::default();
        let q = PointQuery {
            at: vec![[2.65, 1.8, 0.6], [2.65, 0.3, 0.6]],
            frame: PointFrame::Room,
            person: Some((Posture::Seated, Facing::Azimuth(0.0))),
            planes: false,
            sun: Some(SunQuery::new(30.0, 0.0, 700.0, 0.6)),
        };
        let a = mrt_at_points(&scene, "example", &mrt, &q).unwrap();
        let solarcal = mrtmap_physics::solar_gain(&SolarInputs {
            altitude_deg: 30.0,
            sharp_deg: 0.0,
            dni_w_m2: 700.0,
            transmittance: 0.6,
            f_svv: mrtmap_physics::f_svv(1.8, 1.3, 1.55).unwrap(),
            f_bes: 1.0,
            asw: 0.7,
            posture: mrtmap_physics::SolarPosture::Seated,
            floor_reflectance: 0.6,
        })
        .unwrap()
        .delta_mrt_k;
        assert!((solarcal - 16.41).abs() < 0.01);
        let lit = a.persons[0].sun.as_ref().unwrap();
        assert!(lit.f_bes > 0.95, "{lit:?}");
        assert_eq!(lit.beam_windows, vec!["window-1".to_string()]);
        assert!(
            (lit.delta_mrt_k - solarcal).abs() < 0.1 * solarcal,
            "{} against {solarcal}",
            lit.delta_mrt_k
        );
        assert!((lit.mrt_with_sun_c - a.persons[0].mrt_c - lit.delta_mrt_k).abs() < 1e-9);
        let beside = a.persons[1].sun.as_ref().unwrap();
        assert_eq!(beside.f_bes, 0.0);
        assert!(beside.delta_mrt_k > 0.0, "sky and floor still count");
        assert!(beside.delta_mrt_k < 0.25 * lit.delta_mrt_k, "{beside:?}");
        // The JSON has ΔMRT beside the long-wave MRT.
        let json = serde_json::to_value(&a).unwrap();
        let person = &json["persons"][0];
        for key in [
            "mrt_c",
            "delta_mrt_k",
            "f_svv",
            "f_bes",
            "sharp_deg",
            "erf_w_m2",
        ] {
            assert!(person[key].is_number(), "{key}: {person}");
        }
        // A sun without a facing, without a person or below the horizon is refused.
        let mut bad = q.clone();
        bad.person = Some((Posture::Seated, Facing::Any));
        assert!(
            mrt_at_points(&scene, "example", &mrt, &bad)
                .unwrap_err()
                .to_string()
                .contains("--facing")
        );
        bad.person = None;
        assert!(mrt_at_points(&scene, "example", &mrt, &bad).is_err());
        let mut low = q.clone();
        low.sun = Some(SunQuery::new(-3.0, 0.0, 700.0, 0.6));
        let e = mrt_at_points(&scene, "example", &mrt, &low)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--sun -3,0 has its altitude outside"), "{e}");
        low.sun = Some(SunQuery::new(30.0, 0.0, 700.0, 1.6));
        let e = mrt_at_points(&scene, "example", &mrt, &low)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--transmittance 1.6 is outside 0…1"), "{e}");
    }
}
