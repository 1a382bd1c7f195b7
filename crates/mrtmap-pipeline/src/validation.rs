//! A map against black-globe readings: `validation.csv` and `validation.json`.

use std::path::{Path, PathBuf};

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_physics::PhysicsError;
/// Globe ↔ MRT conversions and why one fails (mrtmap-physics').
pub use mrtmap_physics::{Convection, Globe, MIXED_CONVECTION_DIAMETERS_M, Temperature};
pub(crate) use mrtmap_physics::{
    GlobeFormula, GlobeMethod, GlobeReading, globe_temperature, mrt_from_globe,
};
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_report::{GlobeRow, ValidationRow, parse_globe_csv, validate, validation_csv};
/// The ISO 7726 accuracy bounds a validation judges by (mrtmap-report's).
use mrtmap_report::{IN_SUN_NOTE, ISO_DESIRED_K, ISO_REQUIRED_K};

use serde::Serialize;

use crate::cache::write_json;
use crate::error::{Error, Result};
use crate::layout::{RunLayout, SegmentDir};
use crate::points::to_scene_frame;
use crate::settings::PointFrame;

/// Rays per globe location: a standard error well below the globes' own.
const RAYS: usize = 200_000;

/// The validation of a map.
pub struct Validation {
    /// The scene the map came from.
    pub scene: PathBuf,
    /// One row per globe reading.
    pub rows: Vec<ValidationRow>,
    /// The shift given to every temperature so that the map matches the calibrating readings (K),
    /// when some were named.
    pub level_shift_k: Option<f64>,
}

impl Validation {
    /// What `mrtmap validate` prints: the scene, a row per reading with ISO 7726's verdict, the
    /// level's shift when `calibrate_with` fixed it, notes on missing values, the files in `out`.
    pub fn lines(&self, calibrate_with: &[String], out: &Path) -> Vec<String> {
        use mrtmap_report::numbers::{signed, uncertainty};
        let mut lines = vec![
            format!("scene: {}", self.scene.display()),
            format!(
                "{:<10} {:>7} {:>7} {:>5} {:>9} {:>9} {:>15} {:>8} {:>8}  ISO 7726",
                "location",
                "Tg °C",
                "Ta °C",
                "v",
                "ISO °C",
                "mixed °C",
                "mrtmap °C",
                "Δ ISO",
                "Δ mixed"
            ),
        ];
        let mut notes = Vec::new();
        for r in &self.rows {
            let label = &r.globe.label;
            let mut f = |what: &str, x: std::result::Result<f64, String>| match x {
                Ok(v) => format!("{v:.2}"),
                Err(e) => {
                    notes.push(format!("{label}: no {what}: {e}"));
                    format!("— ({})", notes.len())
                }
            };
            let words =
                |x: &std::result::Result<f64, PhysicsError>| x.clone().map_err(|e| e.to_string());
            let iso = f("ISO 7726 MRT", words(&r.mrt_iso_c));
            let mixed = f("mixed-convection MRT", words(&r.mrt_mixed_c));
            let ours = match &r.ours_c {
                Ok((o, s)) => format!("{o:.2} ± {}", uncertainty(*s, 2)),
                Err(e) => {
                    notes.push(format!("{label}: no mrtmap MRT: {e}"));
                    format!("— ({})", notes.len())
                }
            };
            let class = match (r.meets_desired, r.meets_required) {
                _ if r.in_sun.is_some() => IN_SUN_NOTE.to_string() + " (not judged)",
                _ if r.calibrates => "fixed the level: not judged".into(),
                (Some(true), _) => format!("meets desired ±{ISO_DESIRED_K} K"),
                (_, Some(true)) => format!("meets required ±{ISO_REQUIRED_K} K"),
                (_, Some(false)) => format!("outside ±{ISO_REQUIRED_K} K"),
                _ => "not judged: a value is missing (see the notes)".into(),
            };
            lines.push(format!(
                "{:<10} {:>7.2} {:>7.2} {:>5.2} {:>9} {:>9} {:>15} {:>8} {:>8}  {class}",
                label,
                r.globe.tg_c,
                r.globe.ta_c,
                r.globe.va_m_s,
                iso,
                mixed,
                ours,
                r.diff_iso_k.map_or("—".into(), |v| signed(v, 2)),
                r.diff_mixed_k.map_or("—".into(), |v| signed(v, 2)),
            ));
        }
        if let Some(s) = self.level_shift_k {
            lines.push(format!(
                "every temperature shifted by {s:+.2} K so that the map matches {} (ISO 7726); the others are compared",
                calibrate_with.join(", ")
            ));
        }
        for (k, n) in notes.iter().enumerate() {
            lines.push(format!("({}) {n}", k + 1));
        }
        lines.push(format!(
            "wrote validation.csv and validation.json in {}",
            out.display()
        ));
        lines
    }

    /// The readings judged against the map: none missing a value, in the sun, or fixing the level.
    pub fn judged(&self) -> usize {
        self.rows
            .iter()
            .filter(|r| r.meets_required.is_some() && r.in_sun.is_none() && !r.calibrates)
            .count()
    }
}

/// The scene of a `run` output folder or of a folder holding scene.json.
fn scene_of(map: &Path) -> Result<PathBuf> {
    if !map.exists() {
        return Err(Error::source(
            map,
            "does not exist: give the output folder of `mrtmap run` (--map)",
        ));
    }
    if map.is_file() {
        return Err(Error::source(
            map,
            "is a file: --map takes the output folder of `mrtmap run` (or a folder holding scene.json), not a file",
        ));
    }
    [
        SegmentDir::new(map).scene_json(),
        RunLayout::new(map).scene_json(),
    ]
        .into_iter()
        .find(|p| p.exists())
        .ok_or_else(|| {
            Error::source(
                map,
                "has no scene.json (nor segment/scene.json): give a `mrtmap run` output or a folder with scene.json",
            )
        })
}

/// The engine MRTs are compared with globes by: exact where valid, else Monte Carlo of `RAYS`.
fn globe_engine(scene: &RadiantScene) -> Result<MrtEngine<'_>> {
    Ok(mrtmap_radiation::enclosure::engine(
        scene,
        Method::Auto(MonteCarlo {
            rays: RAYS,
            ..MonteCarlo::default()
        }),
    )?)
}

/// The scene with every temperature shifted by `shift_k`.
fn shifted(scene: &RadiantScene, shift_k: f64) -> Result<RadiantScene> {
    let mut f = scene.to_file();
    for s in &mut f.surfaces {
        s.temperature_c += shift_k;
        for x in &mut s.features {
            x.temperature_c += shift_k;
        }
    }
    for o in &mut f.occluders {
        o.temperature_c += shift_k;
    }
    Ok(RadiantScene::new(&f)?)
}

/// The level shift that makes the map's MRT match the ISO 7726 MRT of the readings labelled
/// `labels` (mean difference, refined once for the T⁴ average), and the rows' MRT recomputed.
fn calibrate_level(
    scene: &RadiantScene,
    readings: &[GlobeRow],
    labels: &[String],
    globe: &Path,
) -> Result<f64> {
    let idx: Vec<usize> = labels
        .iter()
        .map(|l| {
            readings.iter().position(|r| &r.label == l).ok_or_else(|| {
                Error::source(
                    globe,
                    format!("has no reading labelled '{l}' to calibrate with (--calibrate-with)"),
                )
            })
        })
        .collect::<Result<_>>()?;
    let mut shift = 0.0;
    for _ in 0..2 {
        let s = shifted(scene, shift)?;
        let engine = globe_engine(&s)?;
        let rows = validate(
            &idx.iter().map(|&k| readings[k].clone()).collect::<Vec<_>>(),
            &|x: &[f64; 3]| {
                engine
                    .at(&Point3::from(*x), 0)
                    .map(|r| (r.mrt.celsius(), r.std_error_k))
            },
        );
        let d: Vec<f64> = rows.iter().filter_map(|r| r.diff_iso_k).collect();
        if d.len() != idx.len() {
            return Err(Error::source(
                globe,
                "a calibrating reading has no ISO 7726 MRT or no map MRT: choose readings that convert",
            ));
        }
        shift -= d.iter().sum::<f64>() / d.len() as f64;
    }
    Ok(shift)
}

/// Compares the MRT of the scene in `map` with the globe readings of `globe`, writing
/// validation.csv and validation.json into `out`. Readings labelled in `calibrate_with` fix the
/// map's temperature level first (every temperature shifted by one amount) and are not judged.
/// With `sun` (`[sun]`), a globe whose centre the beam reaches through a window is flagged
/// (`in_sun`) and not judged: its reading includes short-wave radiation the long-wave map does
/// not; calibrating with it is refused.
pub fn validate_map(
    map: &Path,
    globe: &Path,
    frame: PointFrame,
    calibrate_with: &[String],
    sun: Option<&crate::points::SunQuery>,
    out: &Path,
) -> Result<Validation> {
    let scene_path = scene_of(map)?;
    let scene = RadiantScene::load(&scene_path)?;
    let text = std::fs::read_to_string(globe).map_err(|e| mrtmap_io::FileError::io(globe, e))?;
    let mut readings = parse_globe_csv(&text, &globe.display().to_string())?;
    let engine = globe_engine(&scene)?;
    for r in &mut readings {
        let p = to_scene_frame(r.xyz, frame, &scene, &scene_path.display().to_string())?;
        engine.check_inside(&p).map_err(|e| Error::Config {
            path: globe.to_path_buf(),
            line: r.line as usize,
            message: format!(
                "reading '{}': {e}; give x, y, z in metres from the room's origin corner (the report's room coordinates){}",
                r.label,
                match frame {
                    PointFrame::Room => ", or in the scan's frame with --frame scan",
                    PointFrame::Scan => "",
                }
            ),
        })?;
        r.xyz = [p.x, p.y, p.z];
    }
    let in_sun: Vec<Option<String>> = match sun {
        Some(q) => {
            let tracer = mrtmap_radiation::SunTracer::new(&scene);
            readings
                .iter()
                .map(|r| tracer.beam_at(&Point3::from(r.xyz), &q.direction))
                .collect()
        }
        None => vec![None; readings.len()],
    };
    if let Some((r, _)) = readings
        .iter()
        .zip(&in_sun)
        .find(|(r, s)| s.is_some() && calibrate_with.contains(&r.label))
    {
        return Err(Error::setting(
            format!("--calibrate-with {}", r.label),
            "names a globe in the sun ([sun]): its reading includes short-wave radiation the long-wave map does not, so it cannot fix the map's level",
        ));
    }
    let level_shift_k = if calibrate_with.is_empty() {
        None
    } else {
        Some(calibrate_level(&scene, &readings, calibrate_with, globe)?)
    };
    let calibrated;
    let engine = match level_shift_k {
        Some(s) => {
            calibrated = shifted(&scene, s)?;
            globe_engine(&calibrated)?
        }
        None => engine,
    };
    let ours = |x: &[f64; 3]| {
        engine
            .at(&Point3::from(*x), 0)
            .map(|r| (r.mrt.celsius(), r.std_error_k))
    };
    let mut rows = validate(&readings, &ours);
    for (r, sun) in rows.iter_mut().zip(in_sun) {
        if calibrate_with.contains(&r.globe.label) {
            r.calibrates = true;
            r.meets_required = None;
            r.meets_desired = None;
        }
        if sun.is_some() {
            r.in_sun = sun;
            r.meets_required = None;
            r.meets_desired = None;
        }
    }
    let layout = RunLayout::new(out);
    mrtmap_io::write_atomic(&layout.validation_csv(), validation_csv(&rows)?.as_bytes())?;
    write_json(&layout.validation_json(), &rows)?;
    Ok(Validation {
        scene: scene_path,
        rows,
        level_shift_k,
    })
}

/// The globe formula to convert with: one choice for `mrtmap globe --method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum GlobeFormulaChoice {
    /// ISO 7726 general formula (any diameter and emissivity).
    Iso,
    /// ISO 7726 closed forms for the standard globe (0.15 m, ε 0.95), as printed in the seed paper.
    IsoClosedForm,
    /// Mixed-convection correction (Teitelbaum et al. 2022), 0.04–0.15 m globes.
    Mixed,
}

impl GlobeFormulaChoice {
    /// The method, with the convection regime for the ISO formulas.
    pub fn method(self, convection: Convection) -> GlobeMethod {
        match self {
            Self::Iso => GlobeMethod::Iso { convection },
            Self::IsoClosedForm => GlobeMethod::IsoClosedForm { convection },
            Self::Mixed => GlobeMethod::MixedConvection,
        }
    }
}

/// A globe reading converted to MRT, or an MRT to the reading a globe would give.
#[derive(Clone, Debug, Serialize)]
pub struct GlobeConversion {
    /// Mean radiant temperature (°C).
    pub mrt_c: f64,
    /// Globe temperature (°C).
    pub globe_c: f64,
    /// Air temperature (°C).
    pub air_c: f64,
    /// Air speed (m/s).
    pub air_speed_m_s: f64,
    /// Globe diameter (m).
    pub diameter_m: f64,
    /// Globe emissivity.
    pub emissivity: f64,
    /// The formula used.
    pub formula: GlobeFormula,
    /// The formula in words.
    pub formula_description: &'static str,
    /// Convective heat transfer coefficient (W/m²K).
    pub h_w_m2k: f64,
    /// Whether the globe's reading was given and the MRT found (in JSON `direction`:
    /// "mrt_from_globe"), or an MRT given and the globe's reading found ("globe_from_mrt").
    #[serde(rename = "direction", serialize_with = "direction_name")]
    pub from_globe: bool,
}

/// [`GlobeConversion::from_globe`] as JSON's `direction`.
fn direction_name<S: serde::Serializer>(
    from_globe: &bool,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_str(if *from_globe {
        "mrt_from_globe"
    } else {
        "globe_from_mrt"
    })
}

/// What a globe reads: its temperature `globe_c` (°C) to convert to MRT, or an MRT `mrt_c` to
/// give the globe temperature for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GlobeInput {
    /// A globe temperature (°C).
    Globe(f64),
    /// A mean radiant temperature (°C).
    Mrt(f64),
}

/// Converts a globe reading to MRT, or an MRT to the globe's reading, with `globe` in air at
/// `air_c` (°C) moving at `air_speed_m_s`.
pub fn convert_globe(
    input: GlobeInput,
    globe: &Globe,
    air_c: f64,
    air_speed_m_s: f64,
    method: GlobeMethod,
) -> Result<GlobeConversion> {
    let air = Temperature::from_celsius(air_c);
    let (tg, from_globe) = match input {
        GlobeInput::Globe(tg) => (Temperature::from_celsius(tg), true),
        GlobeInput::Mrt(tr) => (
            globe_temperature(
                globe,
                Temperature::from_celsius(tr),
                air,
                air_speed_m_s,
                method,
            )?,
            false,
        ),
    };
    let r = mrt_from_globe(
        globe,
        &GlobeReading {
            globe: tg,
            air,
            air_speed_m_s,
        },
        method,
    )?;
    Ok(GlobeConversion {
        mrt_c: r.mrt.celsius(),
        globe_c: tg.celsius(),
        air_c,
        air_speed_m_s,
        diameter_m: globe.diameter_m,
        emissivity: globe.emissivity,
        formula: r.formula,
        formula_description: r.formula.describe(),
        h_w_m2k: r.h_w_m2k,
        from_globe,
    })
}

impl GlobeConversion {
    /// The conversion in lines, as `mrtmap globe` prints it.
    pub fn lines(&self) -> Vec<String> {
        let conditions = format!(
            "air {:.2} °C, air speed {} m/s, globe {} m, ε {}",
            self.air_c, self.air_speed_m_s, self.diameter_m, self.emissivity
        );
        if self.from_globe {
            vec![
                format!("MRT {:.2} °C", self.mrt_c),
                format!("  from globe {:.2} °C, {conditions}", self.globe_c),
                format!(
                    "  formula: {} (h = {:.2} W/m²K)",
                    self.formula_description, self.h_w_m2k
                ),
            ]
        } else {
            vec![
                format!("globe temperature {:.2} °C", self.globe_c),
                format!("  at MRT {:.2} °C, {conditions}", self.mrt_c),
                format!(
                    "  formula: {} (h = {:.2} W/m²K), solved numerically",
                    self.formula_description, self.h_w_m2k
                ),
            ]
        }
    }
}
