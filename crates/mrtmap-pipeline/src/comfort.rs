//! Comfort for a person: the person's MRT, radiant asymmetry, operative temperature and PMV/PPD
//! at points and over the floor grid, written as one map (PNG, SVG, CSV) per quantity and
//! `comfort.json` (the share of the floor in each ISO 7730 category, the worst asymmetry and
//! where, the values at the marked points).
//!
//! PMV/PPD: ISO 7730:2025's annex D code (Fanger; pythermalcomfort 4's `pmv_ppd_iso`), with the
//! relative air speed vr = v + 0.3 (met − 1) for met > 1 (ISO 7730 / pythermalcomfort
//! `v_relative`) and the clothing insulation as given (no dynamic correction). Operative
//! temperature: ISO 7726, (ta √(10 v) + tr) / (1 + √(10 v)), with the person's tr. Standard errors
//! follow the person's MRT error through each formula (numerical derivative).

use std::path::Path;

use mrtmap_geometry::nalgebra::Point2;
use mrtmap_io::FileError;
use mrtmap_physics::PhysicsError;
use mrtmap_physics::{Category, Posture, SkyAndRoom, Temperature, pmv_ppd, solar_gain_checked};
/// The sun on a person (SolarCal), for callers with their own inputs
/// (mrtmap-physics').
pub use mrtmap_physics::{
    DEFAULT_ASW, DEFAULT_FLOOR_REFLECTANCE, SolarInputs, SolarPosture, f_svv, solar_gain,
};
/// The comfort formulas themselves, for callers with their own inputs (a binding's arrays):
/// PMV/PPD by edition of ISO 7730 and the operative temperature (mrtmap-physics').
pub use mrtmap_physics::{
    Iso7730Edition, OperativeMethod, PmvInputs, operative_temperature, pmv_ppd_each,
};
use mrtmap_radiation::{
    AsymmetryVerdict, Facing, GridSpec, MapFrame, MrtEngine, MrtError, MrtField, RadiantAsymmetry,
    RadiantScene, SunTracer,
};
use mrtmap_report::{MapInput, MapMark, MapQuantity, render_png, render_svg};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::cache::write_json;
use crate::error::{Error, Result};
use crate::layout::ComfortDir;
use crate::points::SunQuery;
use crate::settings::{AirSection, ComfortSection, Quantity};

/// The relative air speed ISO 7730 uses: v + 0.3 (met − 1) for met > 1.
pub(crate) fn relative_air_speed(v: f64, met: f64) -> f64 {
    if met > 1.0 { v + 0.3 * (met - 1.0) } else { v }
}

/// The air around a person and what they wear and do.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Air {
    /// Air temperature at the body centre (°C).
    pub temperature_c: f64,
    /// Air speed (m/s).
    pub speed_m_s: f64,
    /// Relative humidity (%).
    pub relative_humidity_pct: f64,
    /// Metabolic rate (met).
    pub met: f64,
    /// Clothing (clo).
    pub clo: f64,
}

/// Operative temperature, PMV and PPD from air and a radiant temperature, each with the standard
/// error that `tr_se_k` causes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Thermal {
    /// Operative temperature (°C).
    pub operative_c: f64,
    /// Its standard error (K).
    pub operative_se_k: f64,
    /// PMV.
    pub pmv: f64,
    /// Its standard error.
    pub pmv_se: f64,
    /// PPD (%).
    pub ppd_pct: f64,
    /// Its standard error (%).
    pub ppd_se_pct: f64,
    /// Whether the inputs lie within ISO 7730's ranges.
    pub within_iso_ranges: bool,
    /// ISO 7730 category of the PMV.
    pub category: Category,
}

/// Operative temperature and PMV/PPD of a person at mean radiant temperature `tr_c` ± `tr_se_k`.
pub(crate) fn thermal(
    air: &Air,
    tr_c: f64,
    tr_se_k: f64,
) -> std::result::Result<Thermal, PhysicsError> {
    let c = Temperature::from_celsius;
    // The air speed as given is checked before the relative speed is made of it (`--v -0.1`
    // was refused as a relative air speed of −0.04).
    if !(0.0..=10.0).contains(&air.speed_m_s) {
        return Err(PhysicsError::OutOfRange {
            name: "air speed (m/s)",
            value: air.speed_m_s,
            min: 0.0,
            max: 10.0,
        });
    }
    let vr = relative_air_speed(air.speed_m_s, air.met);
    let pmv_at = |tr: f64| {
        pmv_ppd(&PmvInputs {
            air: c(air.temperature_c),
            mrt: c(tr),
            relative_air_speed_m_s: vr,
            relative_humidity_pct: air.relative_humidity_pct,
            met: air.met,
            clo: air.clo,
            external_work_met: 0.0,
        })
    };
    let to = |tr: f64| {
        operative_temperature(
            c(air.temperature_c),
            c(tr),
            air.speed_m_s,
            OperativeMethod::Iso,
        )
        .map(|t| t.celsius())
    };
    let h = 0.01;
    let (p, p_hi, p_lo) = (pmv_at(tr_c)?, pmv_at(tr_c + h)?, pmv_at(tr_c - h)?);
    let (o, o_hi) = (to(tr_c)?, to(tr_c + h)?);
    Ok(Thermal {
        operative_c: o,
        operative_se_k: ((o_hi - o) / h).abs() * tr_se_k,
        pmv: p.pmv,
        pmv_se: ((p_hi.pmv - p_lo.pmv) / (2.0 * h)).abs() * tr_se_k,
        ppd_pct: p.ppd_pct,
        ppd_se_pct: ((p_hi.ppd_pct - p_lo.ppd_pct) / (2.0 * h)).abs() * tr_se_k,
        within_iso_ranges: p.within_iso_ranges,
        category: Category::of_pmv(p.pmv),
    })
}

/// A person's comfort at one place on the floor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComfortPoint {
    /// Map coordinates (m).
    pub xy: [f64; 2],
    /// Posture.
    pub posture: Posture,
    /// The seated person's MRT (°C) and its standard error (K), when asked for.
    pub mrt_seated: Option<(f64, f64)>,
    /// The standing person's MRT (°C) and its standard error (K), when asked for.
    pub mrt_standing: Option<(f64, f64)>,
    /// Radiant asymmetry at the abdomen of the posture: vertical (signed, K), horizontal (K),
    /// and the worse of the two as ISO 7730 judges it.
    pub asymmetry: Option<AsymmetrySummary>,
    /// Operative temperature, PMV, PPD (with the air given; with `[sun]`, from the MRT with the
    /// sun).
    pub thermal: Option<Thermal>,
    /// The person's MRT with SolarCal's ΔMRT of `[sun]` (°C) and its standard error (K), when
    /// asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mrt_sun: Option<(f64, f64)>,
    /// The sun on that person, when `[sun]` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun: Option<SunOnPerson>,
}

/// The sun on the person at a map node (SolarCal, with the exposure traced through the windows).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunOnPerson {
    /// Which way the person faces (degrees from +x towards +y): `[comfort] facing_deg`, else
    /// towards the sun.
    pub facing_deg: f64,
    /// The sun's angle from the person's front (degrees).
    pub sharp_deg: f64,
    /// Sky-vault view fraction through the windows.
    pub f_svv: f64,
    /// Fraction of the body in the beam.
    pub f_bes: f64,
    /// SolarCal's ΔMRT (K).
    pub delta_mrt_k: f64,
    /// The long-wave MRT of that person, facing that way (°C).
    pub mrt_long_wave_c: f64,
}

/// Radiant asymmetry at a point, for files.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AsymmetrySummary {
    /// Up-facing minus down-facing plane radiant temperature (K).
    pub vertical_k: f64,
    /// The largest difference between opposite horizontal faces (K).
    pub horizontal_k: f64,
    /// The warmer horizontal face's direction (degrees from +x towards +y).
    pub horizontal_warm_azimuth_deg: f64,
    /// The worse verdict (higher PD).
    pub worst: AsymmetryVerdict,
    /// Its standard error (K), from the plane radiant temperatures'.
    pub std_error_k: f64,
}

impl AsymmetrySummary {
    fn of(a: &RadiantAsymmetry) -> Self {
        let se =
            a.six.iter().map(|t| t.std_error_k).fold(0.0f64, f64::max) * std::f64::consts::SQRT_2;
        Self {
            vertical_k: a.vertical_k,
            horizontal_k: a.horizontal_k,
            horizontal_warm_azimuth_deg: a.horizontal_warm_azimuth_deg,
            worst: a.worst(),
            std_error_k: se,
        }
    }
}

/// What to compute: the person's quantities of `quantities`.
fn wants(quantities: &[Quantity], q: Quantity) -> bool {
    quantities.contains(&q)
}

/// The sun for a comfort map: the tracer on the scene and the sun.
pub(crate) type SunContext<'s, 'a> = (&'s SunTracer<'a>, &'s SunQuery);

/// The person's quantities at map coordinates `xy` (`stream` selects the random streams); with
/// `sun`, the person of `[comfort]`'s posture gets SolarCal's ΔMRT, facing `[comfort] facing_deg`
/// or, unset, the sun (SHARP 0), and operative temperature, PMV and PPD use that MRT.
#[allow(clippy::too_many_arguments)]
pub(crate) fn comfort_at(
    engine: &MrtEngine<'_>,
    frame: &MapFrame,
    xy: Point2<f64>,
    c: &ComfortSection,
    air: &AirSection,
    quantities: &[Quantity],
    sun: Option<SunContext<'_, '_>>,
    stream: u64,
) -> std::result::Result<ComfortPoint, MrtError> {
    let facing = c.facing();
    let person = |posture: Posture| {
        let centre = frame.point(&xy, posture.centre_height_m());
        engine
            .person_at(&centre, posture, facing, stream)
            .map(|p| (p.mrt.celsius(), p.std_error_k))
    };
    let seated = (wants(quantities, Quantity::MrtSeated)
        || (c.posture == Posture::Seated && quantities.iter().any(|q| q.needs_air())))
    .then(|| person(Posture::Seated))
    .transpose()?;
    let standing = (wants(quantities, Quantity::MrtStanding)
        || (c.posture == Posture::Standing && quantities.iter().any(|q| q.needs_air())))
    .then(|| person(Posture::Standing))
    .transpose()?;
    let asymmetry = wants(quantities, Quantity::Asymmetry)
        .then(|| {
            let p = frame.point(&xy, c.posture.abdomen_height_m());
            engine
                .asymmetry_at(&p, stream)
                .map(|a| AsymmetrySummary::of(&a))
        })
        .transpose()?;
    let mut own = match c.posture {
        Posture::Seated => seated,
        Posture::Standing => standing,
    };
    let needs_sun = wants(quantities, Quantity::MrtSun) || quantities.iter().any(|q| q.needs_air());
    let mut sun_on = None;
    let mut mrt_sun = None;
    if let (Some((tracer, q)), true) = (sun, needs_sun) {
        let facing_deg = c.facing_deg.unwrap_or(q.direction.azimuth_deg);
        let centre = frame.point(&xy, c.posture.centre_height_m());
        let long_wave = match (c.facing_deg, own) {
            (Some(_), Some(m)) => m,
            _ => engine
                .person_at(&centre, c.posture, Facing::Azimuth(facing_deg), stream)
                .map(|p| (p.mrt.celsius(), p.std_error_k))?,
        };
        if let Ok((e, sharp, g)) =
            crate::points::solar_on(tracer, &centre, c.posture, facing_deg, q)
        {
            sun_on = Some(SunOnPerson {
                facing_deg,
                sharp_deg: sharp,
                f_svv: e.f_svv,
                f_bes: e.f_bes,
                delta_mrt_k: g.delta_mrt_k,
                mrt_long_wave_c: long_wave.0,
            });
            mrt_sun = Some((long_wave.0 + g.delta_mrt_k, long_wave.1));
            own = mrt_sun;
        } else {
            own = None;
        }
    }
    let thermal = match (own, c.air_at(air, c.posture.centre_height_m())) {
        (Some((tr, se)), Some(ta)) if quantities.iter().any(|q| q.needs_air()) => {
            let a = Air {
                temperature_c: ta,
                speed_m_s: c.air_speed(air),
                relative_humidity_pct: c.relative_humidity_pct,
                met: c.met,
                clo: c.clo,
            };
            thermal(&a, tr, se).ok()
        }
        _ => None,
    };
    Ok(ComfortPoint {
        xy: [xy.x, xy.y],
        posture: c.posture,
        mrt_seated: seated,
        mrt_standing: standing,
        asymmetry,
        thermal,
        mrt_sun,
        sun: sun_on,
    })
}

/// One quantity's value and standard error at a point, when computed.
pub(crate) fn value_of(p: &ComfortPoint, q: Quantity) -> Option<(f64, f64)> {
    match q {
        Quantity::Mrt => None,
        Quantity::MrtSeated => p.mrt_seated,
        Quantity::MrtStanding => p.mrt_standing,
        Quantity::MrtSun => p.mrt_sun,
        Quantity::Asymmetry => p.asymmetry.map(|a| (a.worst.delta_k, a.std_error_k)),
        Quantity::Operative => p.thermal.map(|t| (t.operative_c, t.operative_se_k)),
        Quantity::Pmv => p.thermal.map(|t| (t.pmv, t.pmv_se)),
        Quantity::Ppd => p.thermal.map(|t| (t.ppd_pct, t.ppd_se_pct)),
    }
}

/// The title of a quantity's map.
pub(crate) fn comfort_title(q: Quantity, c: &ComfortSection) -> String {
    title_of(q, c).0
}

/// Title and unit of a quantity's map.
fn title_of(q: Quantity, c: &ComfortSection) -> (String, &'static str) {
    let who = |p: Posture| {
        format!(
            "a {} person (body centre {:.1} m), {}",
            p.as_str(),
            p.centre_height_m(),
            match c.facing_deg {
                Some(a) => format!("facing {a}°"),
                None => "any direction".into(),
            }
        )
    };
    match q {
        Quantity::Mrt => ("Mean radiant temperature (°C)".into(), "°C"),
        Quantity::MrtSeated => (format!("MRT of {} (°C)", who(Posture::Seated)), "°C"),
        Quantity::MrtStanding => (format!("MRT of {} (°C)", who(Posture::Standing)), "°C"),
        Quantity::MrtSun => (
            format!(
                "MRT with the sun (SolarCal) of a {} person (body centre {:.1} m), {} (°C); orange: in the beam",
                c.posture.as_str(),
                c.posture.centre_height_m(),
                match c.facing_deg {
                    Some(a) => format!("facing {a}°"),
                    None => "facing the sun".into(),
                }
            ),
            "°C",
        ),
        Quantity::Asymmetry => (
            format!(
                "Worst radiant asymmetry at {:.1} m, {} (K)",
                c.posture.abdomen_height_m(),
                c.posture.as_str()
            ),
            "K",
        ),
        Quantity::Operative => (
            format!("Operative temperature of {} (°C)", who(c.posture)),
            "°C",
        ),
        Quantity::Pmv => (format!("PMV (ISO 7730) of {}", who(c.posture)), "PMV"),
        Quantity::Ppd => (format!("PPD (ISO 7730) of {} (%)", who(c.posture)), "%"),
    }
}

/// A node of the comfort grid (the maps' working set; the files hold what it gives).
#[derive(Clone, Debug, PartialEq)]
struct ComfortNode {
    /// Grid indices.
    i: usize,
    /// Grid indices.
    j: usize,
    /// The values, or why not (the CSV's note).
    point: std::result::Result<ComfortPoint, String>,
}

/// `comfort.json`: what the comfort maps say as a whole.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ComfortSummary {
    /// The person.
    pub comfort: ComfortSection,
    /// The PMV/PPD variant.
    pub pmv_model: String,
    /// Quantities mapped.
    pub quantities: Vec<Quantity>,
    /// Nodes computed and refused.
    pub nodes: usize,
    /// Nodes that could not be computed (inside furniture…).
    pub skipped: usize,
    /// Share of the computed floor in each ISO 7730 PMV category (A, B, C, outside), when PMV was
    /// computed.
    pub pmv_category_share: Option<[f64; 4]>,
    /// Share of the computed floor in each radiant-asymmetry category (A/B, C, outside).
    pub asymmetry_category_share: Option<[f64; 3]>,
    /// The worst asymmetry on the grid and where (map x, y).
    pub worst_asymmetry: Option<(AsymmetrySummary, [f64; 2])>,
    /// The sun on the grid (with `[sun]`): the share of the computed nodes whose person the beam
    /// reaches (f_bes > 0), the largest ΔMRT and where (map x, y).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun: Option<SunSummary>,
    /// The share of the computed nodes whose PMV inputs lie outside ISO 7730's ranges (their PMV
    /// and PPD are indicative only), when PMV was computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside_iso_ranges_share: Option<f64>,
    /// The sunlit patch (with `[sun]`): the floor under the nodes whose person the beam reaches,
    /// as the report's 3D view draws it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sunlit_patch: Option<SunlitPatch>,
    /// The marked points' values.
    pub marks: Vec<(String, ComfortPoint)>,
    /// Seconds to compute.
    pub compute_secs: f64,
}

/// The sun over a comfort grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunSummary {
    /// Share of the computed nodes with part of the body in the beam.
    pub sunlit_share: f64,
    /// The largest SolarCal ΔMRT on the grid (K).
    pub max_delta_mrt_k: f64,
    /// Where (map x, y).
    pub max_at: [f64; 2],
}

/// The floor cells under the grid nodes whose person the beam reaches (f_bes > 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunlitPatch {
    /// Each cell's centre on the floor (scene frame, m).
    pub cells: Vec<[f64; 3]>,
    /// The map's axes along its columns and rows (unit vectors, scene frame).
    pub u: [f64; 3],
    /// See `u`.
    pub v: [f64; 3],
    /// The cells' size along u and v (m).
    pub cell_m: [f64; 2],
}

impl SunlitPatch {
    /// The patch of `nodes` on `field`'s floor; `None` when the sun reaches no node's person.
    fn of(field: &MrtField, nodes: &[ComfortNode]) -> Option<Self> {
        let cells: Vec<[f64; 3]> = nodes
            .iter()
            .filter(|n| {
                n.point
                    .as_ref()
                    .is_ok_and(|p| p.sun.is_some_and(|s| s.f_bes > 0.0))
            })
            .map(|n| {
                let p = field
                    .frame
                    .point(&Point2::new(field.u[n.i], field.v[n.j]), 0.0);
                [p.x, p.y, p.z]
            })
            .collect();
        let step = |xs: &[f64]| match xs {
            [a, b, ..] => (b - a).abs(),
            _ => 0.0,
        };
        let axis = |a: &mrtmap_geometry::nalgebra::Unit<
            mrtmap_geometry::nalgebra::Vector3<f64>,
        >| [a.x, a.y, a.z];
        (!cells.is_empty()).then(|| Self {
            cells,
            u: axis(&field.frame.plane.u),
            v: axis(&field.frame.plane.v),
            cell_m: [step(&field.u), step(&field.v)],
        })
    }
}

/// The PMV/PPD variant, in words.
pub(crate) const PMV_MODEL: &str = "ISO 7730:2025 annex D (Fanger), as pythermalcomfort 4 pmv_ppd_iso; vr = v + 0.3 (met − 1) above 1 met; clo as given";

/// A comfort map set computed and written.
pub struct ComfortOutput {
    /// The summary (also comfort.json).
    pub summary: ComfortSummary,
    /// (quantity, title, PNG) per map.
    pub maps: Vec<(Quantity, String, Vec<u8>)>,
}

/// Computes the person's quantities of `quantities` over the floor grid and at `marks` (map x, y
/// with names), writing `<quantity>.csv`, `.png`, `.svg` and `comfort.json` into `out`. With
/// `sun` (`[sun]`), `mrt_sun` can be mapped and operative temperature, PMV and PPD include the
/// sun; `mrt_sun` without it is refused.
#[allow(clippy::too_many_arguments)]
pub(crate) fn make_comfort_maps(
    engine: &MrtEngine<'_>,
    scene: &RadiantScene,
    source: &str,
    (grid, margin_m): ([usize; 2], f64),
    c: &ComfortSection,
    air: &AirSection,
    quantities: &[Quantity],
    sun: Option<&SunQuery>,
    marks: &[(String, [f64; 2])],
    out: &Path,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<ComfortOutput> {
    if quantities.contains(&Quantity::MrtSun) && sun.is_none() {
        return Err(crate::settings::no_sun_error());
    }
    if sun.is_some() {
        crate::points::check_sun_frame(scene, "[sun]")?;
    }
    let tracer = sun.map(|_| SunTracer::new(scene));
    let sun_ctx = tracer.as_ref().zip(sun);
    let frame = MapFrame::of_scene(scene).map_err(|e| Error::Map {
        scene: source.to_string(),
        source: e,
    })?;
    let person = Quantity::person(quantities);
    let spec = GridSpec {
        nx: grid[0],
        ny: grid[1],
        height_m: c.posture.centre_height_m(),
        margin_m,
    };
    let layout = MrtField::layout(&frame, &spec, engine.bounds())?;
    for (name, xy) in marks {
        let p = frame.point(&Point2::new(xy[0], xy[1]), spec.height_m);
        engine.check_inside(&p).map_err(|source| Error::Point {
            name: name.clone(),
            source,
        })?;
    }
    let t0 = std::time::Instant::now();
    let nodes: Vec<ComfortNode> = layout
        .places
        .par_iter()
        .map(|&(i, j, uv)| {
            (!stop()).then(|| ComfortNode {
                i,
                j,
                point: comfort_at(
                    engine,
                    &frame,
                    uv,
                    c,
                    air,
                    &person,
                    sun_ctx,
                    (j * grid[0] + i) as u64,
                )
                .map_err(|e| e.to_string()),
            })
        })
        .collect::<Option<Vec<_>>>()
        .ok_or(Error::Stopped {
            stage: "the comfort maps",
        })?;
    let mark_values = marks
        .iter()
        .enumerate()
        .map(|(k, (name, xy))| {
            comfort_at(
                engine,
                &frame,
                Point2::new(xy[0], xy[1]),
                c,
                air,
                &person,
                sun_ctx,
                (grid[0] * grid[1] + k) as u64,
            )
            .map(|p| (name.clone(), p))
            .map_err(|source| Error::Point {
                name: name.clone(),
                source,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let secs = t0.elapsed().as_secs_f64();
    let field = MrtField {
        frame,
        spec,
        u: layout.u,
        v: layout.v,
        nodes: Vec::new(),
        unseen: Vec::new(),
    };
    let subtitle = format!(
        "{source}; {}×{} grid; {} person rays per point",
        grid[0],
        grid[1],
        engine.ray_settings().rays
    );
    let maps = write_maps(&field, scene, &nodes, marks, &subtitle, (&person, c), out)?;
    let mut summary = summarise(&nodes, c, &person, mark_values, secs);
    summary.sunlit_patch = SunlitPatch::of(&field, &nodes);
    write_json(&ComfortDir::new(out).comfort_json(), &summary)?;
    Ok(ComfortOutput { summary, maps })
}

/// Writes each quantity's map (`<quantity>.png`, `.svg`, `.csv`) into `out`; returns (quantity,
/// title, PNG) per map.
fn write_maps(
    field: &MrtField,
    scene: &RadiantScene,
    nodes: &[ComfortNode],
    marks: &[(String, [f64; 2])],
    subtitle: &str,
    (person, c): (&[Quantity], &ComfortSection),
    out: &Path,
) -> Result<Vec<(Quantity, String, Vec<u8>)>> {
    let map_marks: Vec<MapMark> = marks
        .iter()
        .map(|(name, xy)| MapMark {
            name: name.clone(),
            uv: Point2::new(xy[0], xy[1]),
        })
        .collect();
    let dir = ComfortDir::new(out);
    let mut maps = Vec::new();
    for &q in person {
        let (title, unit) = title_of(q, c);
        let values: Vec<(usize, usize, f64)> = nodes
            .iter()
            .filter_map(|n| {
                let v = value_of(n.point.as_ref().ok()?, q)?;
                Some((n.i, n.j, v.0))
            })
            .collect();
        let outside = nodes.iter().filter(|n| indicative_only(n, q)).count();
        let subtitle = if outside > 0 {
            format!(
                "{subtitle}; inputs outside ISO 7730's ranges at {outside} of {} nodes: indicative only",
                values.len()
            )
        } else {
            subtitle.to_string()
        };
        let input = MapInput {
            field,
            scene,
            marks: &map_marks,
            subtitle,
            quantity: Some(MapQuantity {
                title: title.clone(),
                unit: unit.into(),
                values,
                neutral: (q == Quantity::Pmv).then_some(0.0),
                outlined: if q == Quantity::MrtSun {
                    nodes
                        .iter()
                        .filter(|n| {
                            n.point
                                .as_ref()
                                .is_ok_and(|p| p.sun.is_some_and(|s| s.f_bes > 0.0))
                        })
                        .map(|n| (n.i, n.j))
                        .collect()
                } else {
                    Vec::new()
                },
            }),
        };
        let png = render_png(&input)?;
        mrtmap_io::write_atomic(&dir.png(q), &png)?;
        mrtmap_io::write_atomic(&dir.svg(q), render_svg(&input)?.as_bytes())?;
        mrtmap_io::write_atomic(&dir.csv(q), quantity_csv(field, nodes, q).as_bytes())?;
        maps.push((q, title, png));
    }
    Ok(maps)
}

/// Whether node `n`'s value of `q` is a PMV or PPD whose inputs lie outside ISO 7730's ranges.
fn indicative_only(n: &ComfortNode, q: Quantity) -> bool {
    matches!(q, Quantity::Pmv | Quantity::Ppd)
        && n.point
            .as_ref()
            .is_ok_and(|p| p.thermal.is_some_and(|t| !t.within_iso_ranges))
}

/// One quantity over the grid as CSV: x, y, value, standard error, i, j, note.
fn quantity_csv(field: &MrtField, nodes: &[ComfortNode], q: Quantity) -> String {
    let mut s = format!("x,y,{},std_error,i,j,note\n", q.name());
    for n in nodes {
        let (x, y) = (field.u[n.i], field.v[n.j]);
        let line = match n.point.as_ref().map(|p| value_of(p, q)) {
            Ok(Some((v, e))) => {
                let note = if indicative_only(n, q) {
                    "\"outside ISO 7730's ranges: indicative only\""
                } else {
                    ""
                };
                format!("{x:.4},{y:.4},{v:.4},{e:.4},{},{},{note}\n", n.i, n.j)
            }
            Ok(None) => format!("{x:.4},{y:.4},,,{},{},\"not computed\"\n", n.i, n.j),
            Err(e) => format!(
                "{x:.4},{y:.4},,,{},{},\"{}\"\n",
                n.i,
                n.j,
                e.replace('"', "'")
            ),
        };
        s.push_str(&line);
    }
    s
}

fn summarise(
    nodes: &[ComfortNode],
    c: &ComfortSection,
    quantities: &[Quantity],
    marks: Vec<(String, ComfortPoint)>,
    compute_secs: f64,
) -> ComfortSummary {
    let ok: Vec<&ComfortPoint> = nodes.iter().filter_map(|n| n.point.as_ref().ok()).collect();
    let n = ok.len().max(1) as f64;
    let pmv_category_share = ok.iter().all(|p| p.thermal.is_some()).then(|| {
        let mut share = [0.0; 4];
        for p in &ok {
            if let Some(t) = p.thermal {
                share[t.category as usize] += 1.0 / n;
            }
        }
        share
    });
    let asym: Vec<(AsymmetrySummary, [f64; 2])> = ok
        .iter()
        .filter_map(|p| p.asymmetry.map(|a| (a, p.xy)))
        .collect();
    let asymmetry_category_share = (!asym.is_empty()).then(|| {
        let mut share = [0.0; 3];
        for (a, _) in &asym {
            let k = match a.worst.category {
                Category::A | Category::B => 0,
                Category::C => 1,
                Category::Outside => 2,
            };
            share[k] += 1.0 / asym.len() as f64;
        }
        share
    });
    let worst_asymmetry = asym
        .iter()
        .max_by(|a, b| a.0.worst.pd_pct.total_cmp(&b.0.worst.pd_pct))
        .copied();
    let suns: Vec<(SunOnPerson, [f64; 2])> =
        ok.iter().filter_map(|p| p.sun.map(|s| (s, p.xy))).collect();
    let sun = suns
        .iter()
        .max_by(|a, b| a.0.delta_mrt_k.total_cmp(&b.0.delta_mrt_k))
        .map(|(s, xy)| SunSummary {
            sunlit_share: suns.iter().filter(|(s, _)| s.f_bes > 0.0).count() as f64
                / suns.len() as f64,
            max_delta_mrt_k: s.delta_mrt_k,
            max_at: *xy,
        });
    let thermals: Vec<&Thermal> = ok.iter().filter_map(|p| p.thermal.as_ref()).collect();
    let outside_iso_ranges_share = (!thermals.is_empty()).then(|| {
        thermals.iter().filter(|t| !t.within_iso_ranges).count() as f64 / thermals.len() as f64
    });
    ComfortSummary {
        sun,
        outside_iso_ranges_share,
        sunlit_patch: None,
        comfort: c.clone(),
        pmv_model: PMV_MODEL.into(),
        quantities: quantities.to_vec(),
        nodes: ok.len(),
        skipped: nodes.len() - ok.len(),
        pmv_category_share,
        asymmetry_category_share,
        worst_asymmetry,
        marks,
        compute_secs,
    }
}

/// A person's comfort at one air state and MRT (what `mrtmap comfort` prints).
#[derive(Clone, Debug, Serialize)]
pub struct ComfortAnswer {
    /// The air, activity and clothing.
    pub air: Air,
    /// The mean radiant temperature (°C).
    pub mrt_c: f64,
    /// The PMV model, in words.
    pub model: &'static str,
    /// Operative temperature (°C, ISO 7726).
    pub operative_c: f64,
    /// Predicted mean vote.
    pub pmv: f64,
    /// Predicted percentage dissatisfied (%).
    pub ppd_pct: f64,
    /// Whether the inputs lie within ISO 7730's ranges.
    pub within_iso_ranges: bool,
    /// ISO 7730 category.
    pub category: &'static str,
}

/// Operative temperature, PMV and PPD for `air` at the mean radiant temperature `mrt_c`.
pub fn comfort_of(air: Air, mrt_c: f64) -> Result<ComfortAnswer> {
    let t = thermal(&air, mrt_c, 0.0)?;
    Ok(ComfortAnswer {
        air,
        mrt_c,
        model: PMV_MODEL,
        operative_c: t.operative_c,
        pmv: t.pmv,
        ppd_pct: t.ppd_pct,
        within_iso_ranges: t.within_iso_ranges,
        category: t.category.as_str(),
    })
}

impl ComfortAnswer {
    /// The answer in lines.
    pub fn lines(&self) -> Vec<String> {
        vec![
            format!("model: {}", self.model),
            format!(
                "operative temperature {:.2} °C (ISO 7726)",
                self.operative_c
            ),
            format!(
                "PMV {:.3}, PPD {:.1} %: ISO 7730 category {}{}",
                self.pmv,
                self.ppd_pct,
                self.category,
                if self.within_iso_ranges {
                    ""
                } else {
                    " (inputs outside ISO 7730's ranges: indicative only)"
                }
            ),
        ]
    }
}

/// Many cases at once: a CSV with the columns ta,tr,v,rh,met,clo (header first, in any order,
/// other columns kept) becomes the same CSV with operative_c, pmv and ppd added; a case the
/// model refuses gets empty cells and the reason. A cell that is not a number is refused, naming
/// the line.
pub fn comfort_csv(path: &Path) -> Result<Vec<String>> {
    let text = std::fs::read_to_string(path).map_err(|e| FileError::io(path, e))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text); // Excel's "CSV UTF-8"
    let mut rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = rows.next() else {
        return Err(FileError::syntax(
            path,
            1,
            "empty: give a header ta,tr,v,rh,met,clo and one row per case",
        )
        .into());
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |n: &str| {
        names.iter().position(|h| *h == n).ok_or_else(|| {
            FileError::syntax(
                path,
                1,
                format!("the header has no column '{n}' (needs ta,tr,v,rh,met,clo)"),
            )
        })
    };
    let idx = [
        col("ta")?,
        col("tr")?,
        col("v")?,
        col("rh")?,
        col("met")?,
        col("clo")?,
    ];
    let mut lines = vec![format!("{header},operative_c,pmv,ppd")];
    for (k, line) in rows {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |i: usize| {
            cells
                .get(i)
                .and_then(|c| c.parse::<f64>().ok())
                .ok_or_else(|| {
                    FileError::syntax(path, k + 1, format!("column {} is not a number", names[i]))
                })
        };
        let air = Air {
            temperature_c: num(idx[0])?,
            speed_m_s: num(idx[2])?,
            relative_humidity_pct: num(idx[3])?,
            met: num(idx[4])?,
            clo: num(idx[5])?,
        };
        lines.push(match thermal(&air, num(idx[1])?, 0.0) {
            Ok(t) => format!("{line},{:.6},{:.6},{:.6}", t.operative_c, t.pmv, t.ppd_pct),
            Err(e) => format!("{line},,,\"{e}\""),
        });
    }
    Ok(lines)
}

/// What `mrtmap solar-gain` reports: the model, its inputs and its answer.
pub(crate) const SOLAR_MODEL: &str =
    "SolarCal (ASHRAE 55-2023 Appendix C), as pythermalcomfort 4.8 solar_gain; h_r 6 W/m²K";

/// The sun's gain on a person: SolarCal's inputs and answer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolarAnswer {
    /// The model.
    pub model: &'static str,
    /// The inputs.
    #[serde(flatten)]
    pub inputs: SolarInputs,
    /// The effective radiant field (W/m²).
    pub erf_w_m2: f64,
    /// The rise of the mean radiant temperature (K).
    pub delta_mrt_k: f64,
}

impl SolarAnswer {
    /// The answer in lines.
    pub fn lines(&self) -> Vec<String> {
        let i = &self.inputs;
        vec![
            format!("model: {}", self.model),
            format!(
                "sun {:.1}° high, SHARP {:.0}°, {:.0} W/m² direct through transmittance {}; f_svv {:.4}, f_bes {}; {} person, α_sw {}, floor reflectance {}",
                i.altitude_deg,
                i.sharp_deg,
                i.dni_w_m2,
                i.transmittance,
                i.f_svv,
                i.f_bes,
                i.posture.as_str(),
                i.asw,
                i.floor_reflectance
            ),
            format!("effective radiant field ERF {:.2} W/m²", self.erf_w_m2),
            format!(
                "ΔMRT {:+.2} K: add it to the long-wave MRT for the MRT in this sun",
                self.delta_mrt_k
            ),
        ]
    }
}

/// SolarCal for one person ([`solar_gain`]); an input out of its range is refused naming its
/// `mrtmap solar-gain` flag.
pub fn solar_gain_of(inputs: SolarInputs) -> Result<SolarAnswer> {
    let g = solar_gain_checked(&inputs, &SkyAndRoom::SOLARCAL)
        .map_err(crate::points::solar_flag_error)?;
    Ok(SolarAnswer {
        model: SOLAR_MODEL,
        inputs,
        erf_w_m2: g.erf_w_m2,
        delta_mrt_k: g.delta_mrt_k,
    })
}
