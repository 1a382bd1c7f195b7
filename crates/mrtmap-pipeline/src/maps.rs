//! Computing an MRT map and writing it: `mrt_grid.csv`, `mrt_map.png`, `mrt_map.svg` and
//! `summary.json` (shared by `map`, `run` and `demo`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_io::write_atomic;
pub(crate) use mrtmap_radiation::FieldSummary;
/// A map's grid, the summary of its values and the radiant scene it is computed on
/// (mrtmap-radiation's).
pub use mrtmap_radiation::{GridSpec, RadiantScene};
use mrtmap_radiation::{MapFrame, Method, MrtEngine, MrtError, MrtField, PointRecord};
/// Where a map lies in the scene (mrtmap-report's).
pub(crate) use mrtmap_report::MapAxes;
use mrtmap_report::numbers::{fixed, uncertainty, xyz};
use mrtmap_report::{MapInput, MapMark, MapSummary, grid_csv, render_png, render_svg};
use serde::{Deserialize, Serialize};

use crate::cache::write_json;
use crate::error::{Error, Result};
use crate::layout::MapDir;
use crate::settings::{MrtSection, Quantity};

/// A point to mark on a map: map coordinates U,V at the map's height, or scene coordinates X,Y,Z.
#[derive(Clone, Debug, PartialEq)]
pub struct Mark {
    /// Name.
    pub name: String,
    /// Where.
    pub at: MarkAt,
}

/// Where a mark is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MarkAt {
    /// Map coordinates at the map's height.
    Map([f64; 2]),
    /// Scene coordinates.
    Scene([f64; 3]),
}

/// `summary.json` of a map.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// Where the scene came from.
    pub scene: String,
    /// The map.
    #[serde(flatten)]
    pub map: MapSummary,
    /// The marked points.
    pub marks: Vec<PointRecord>,
}

/// A map computed and written.
pub struct MapOutput {
    /// Its summary (also in summary.json).
    pub summary: Summary,
    /// The method described for people.
    pub method: String,
    /// The PNG written.
    pub png: Vec<u8>,
}

/// Where each mark is in the scene, refused when outside the room (before any MRT is computed).
fn mark_points(
    engine: &MrtEngine<'_>,
    frame: &MapFrame,
    spec: &GridSpec,
    marks: &[Mark],
) -> Result<Vec<Point3<f64>>> {
    marks
        .iter()
        .map(|m| {
            let p = match m.at {
                MarkAt::Map([u, v]) => frame.point(&Point2::new(u, v), spec.height_m),
                MarkAt::Scene([x, y, z]) => Point3::new(x, y, z),
            };
            engine.check_inside(&p).map_err(|source| Error::Point {
                name: m.name.clone(),
                source,
            })?;
            Ok(p)
        })
        .collect()
}

/// The MRT at each mark, with where it falls on the map.
fn mark_records(
    engine: &MrtEngine<'_>,
    field: &MrtField,
    spec: &GridSpec,
    marks: &[Mark],
    points: &[Point3<f64>],
) -> Result<(Vec<PointRecord>, Vec<MapMark>)> {
    let mut records = Vec::new();
    let mut map_marks = Vec::new();
    for (k, (m, p)) in marks.iter().zip(points).enumerate() {
        let r = engine
            .at(p, (spec.nx * spec.ny + k) as u64)
            .map_err(|source| Error::Point {
                name: m.name.clone(),
                source,
            })?;
        records.push(PointRecord::new(Some(m.name.clone()), &r, engine.patches()));
        map_marks.push(MapMark {
            name: m.name.clone(),
            uv: field.frame.uv(p),
        });
    }
    Ok((records, map_marks))
}

/// What [`crate::Pipeline::map`] made: the MRT map and, when a person's quantities were asked for, the
/// comfort maps beside it.
pub struct SceneMaps {
    /// The MRT map.
    pub map: MapOutput,
    /// The person's comfort maps.
    pub comfort: Option<crate::comfort::ComfortOutput>,
    /// What the maps leave out, in words (a sun in a scene without glazing).
    pub warnings: Vec<String>,
}

impl SceneMaps {
    /// What `mrtmap map` prints: the scene `source`, the method, the map's summary, and for the
    /// person's `quantities` their summary and values at the marks; the files are in `out`.
    pub fn lines(&self, source: &str, quantities: &[Quantity], out: &Path) -> Vec<String> {
        let m = &self.map;
        let mut lines = vec![format!("scene: {source}"), format!("method: {}", m.method)];
        lines.extend(self.warnings.iter().map(|w| format!("warning: {w}")));
        lines.extend(m.summary.lines());
        lines.push(format!(
            "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
            m.summary.map.compute_secs,
            out.display()
        ));
        let Some(c) = &self.comfort else {
            return lines;
        };
        let person = Quantity::person(quantities);
        let s = &c.summary;
        lines.push(String::new());
        // With the sun and no facing given the person faces the sun (docs/comfort.md).
        let facing = if s.sun.is_some() && s.comfort.facing_deg.is_none() {
            "facing the sun (SHARP 0)".to_string()
        } else {
            s.comfort.facing().describe()
        };
        lines.push(format!(
            "a {} person, {facing}: {} nodes in {:.1} s",
            s.comfort.posture.as_str(),
            s.nodes,
            s.compute_secs
        ));
        if let Some(sh) = s.pmv_category_share {
            lines.push(format!(
                "  floor by ISO 7730 PMV category: A {:.0} %, B {:.0} %, C {:.0} %, outside {:.0} %",
                100.0 * sh[0],
                100.0 * sh[1],
                100.0 * sh[2],
                100.0 * sh[3]
            ));
        }
        if let Some(share) = s.outside_iso_ranges_share.filter(|x| *x > 0.0) {
            lines.push(format!(
                "  PMV inputs outside ISO 7730's ranges on {:.0} % of the floor: PMV and PPD there are indicative only",
                100.0 * share
            ));
        }
        if let Some((w, xy)) = &s.worst_asymmetry {
            lines.push(format!(
                "  worst radiant asymmetry {:.2} K at ({}, {}): PD {:.1} %, category {}",
                w.worst.delta_k,
                fixed(xy[0], 2),
                fixed(xy[1], 2),
                w.worst.pd_pct,
                w.worst.category.as_str()
            ));
        }
        if let Some(sun) = &s.sun {
            lines.push(format!(
                "  the sun (SolarCal): the beam reaches the person on {:.0} % of the floor; ΔMRT up to {:.2} K at ({}, {})",
                100.0 * sun.sunlit_share,
                sun.max_delta_mrt_k,
                fixed(sun.max_at[0], 2),
                fixed(sun.max_at[1], 2)
            ));
        }
        for (name, p) in &s.marks {
            let cells: Vec<String> = person
                .iter()
                .filter_map(|q| {
                    crate::comfort::value_of(p, *q)
                        .map(|(v, e)| format!("{} {v:.2} ± {}", q.name(), uncertainty(e, 2)))
                })
                .collect();
            lines.push(format!("  {name}: {}", cells.join(", ")));
        }
        let names: Vec<String> = person.iter().map(|q| format!("{}.png", q.name())).collect();
        lines.push(format!(
            "wrote {} and comfort.json in {}",
            names.join(", "),
            out.display()
        ));
        lines
    }
}

/// What `mrtmap map` writes into `out`: the MRT over `spec`'s grid of `scene` (view factors by
/// `project.mrt`) with `marks`, and the person's comfort maps that `project.map.quantities` asks
/// for (the person and the air from `project`, checked before anything is computed).
pub(crate) fn map_scene(
    scene: &RadiantScene,
    source: &str,
    project: &crate::Project,
    spec: GridSpec,
    marks: &[Mark],
    out: &Path,
) -> Result<SceneMaps> {
    let person = Quantity::person(&project.map.quantities);
    project.comfort.check(&project.air, &person)?;
    project.sun.check()?;
    let sun = project.sun.query()?;
    if person.contains(&Quantity::MrtSun) && sun.is_none() {
        return Err(crate::settings::no_sun_error());
    }
    let map = make_map(scene, source, &project.mrt, spec, marks, out, &|| false)?;
    if person.is_empty() {
        return Ok(SceneMaps {
            map,
            comfort: None,
            warnings: Vec::new(),
        });
    }
    let engine = project.mrt.engine(scene)?;
    let frame = MapFrame::of_scene(scene).map_err(|e| Error::Map {
        scene: source.to_string(),
        source: e,
    })?;
    let xy_marks: Vec<(String, [f64; 2])> = marks
        .iter()
        .map(|mk| {
            let uv = match mk.at {
                MarkAt::Map(uv) => uv,
                MarkAt::Scene(p) => {
                    let q = frame.uv(&Point3::from(p));
                    [q.x, q.y]
                }
            };
            (mk.name.clone(), uv)
        })
        .collect();
    let comfort = crate::comfort::make_comfort_maps(
        &engine,
        scene,
        source,
        ([spec.nx, spec.ny], spec.margin_m),
        &project.comfort,
        &project.air,
        &person,
        sun.as_ref(),
        &xy_marks,
        out,
        &|| false,
    )?;
    let warnings = if sun.is_some() && !mrtmap_radiation::SunTracer::new(scene).has_windows() {
        vec![crate::points::NO_GLAZING.to_string()]
    } else {
        Vec::new()
    };
    Ok(SceneMaps {
        map,
        comfort: Some(comfort),
        warnings,
    })
}

/// The map frame of `scene` (from `source`) with `spec`'s height checked against the room.
fn map_frame(
    engine: &MrtEngine<'_>,
    scene: &RadiantScene,
    source: &str,
    spec: GridSpec,
) -> Result<MapFrame> {
    let frame = MapFrame::of_scene(scene).map_err(|source_err| Error::Map {
        scene: source.to_string(),
        source: source_err,
    })?;
    if let Some(b) = engine.bounds() {
        b.check_height(spec.height_m)?;
    }
    Ok(frame)
}

/// The MRT over `spec`'s grid and the seconds it took; an open scene is refused as a whole, not
/// drawn as a map with holes.
fn compute_field(
    engine: &MrtEngine<'_>,
    frame: MapFrame,
    spec: GridSpec,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<(MrtField, f64)> {
    let t0 = Instant::now();
    let field = MrtField::compute_until(engine, frame, spec, stop)?
        .ok_or(Error::Stopped { stage: "a map" })?;
    let secs = t0.elapsed().as_secs_f64();
    if let Some(e) = field.nodes.iter().find_map(|n| match &n.result {
        Err(e @ MrtError::NotEnclosed { .. }) => Some(e.clone()),
        _ => None,
    }) {
        return Err(e.into());
    }
    Ok((field, secs))
}

/// An MRT map as arrays, nothing written: what a binding hands to numpy. Grids are row-major,
/// `ny` rows (along v) of `nx` columns (along u); NaN where the grid has no node (outside the
/// floor outline, inside furniture, refused), with the reason in `refused`.
#[derive(Clone, Debug, Serialize)]
pub struct MapArrays {
    /// Height above the floor (m).
    pub height_m: f64,
    /// Node coordinates along u (m, map frame).
    pub u: Vec<f64>,
    /// Node coordinates along v (m, map frame).
    pub v: Vec<f64>,
    /// The map frame in the scene's frame: origin on the floor, u, v and up.
    pub axes: MapAxes,
    /// MRT (°C), `ny × nx`.
    pub mrt_c: Vec<f64>,
    /// Its standard error (K), `ny × nx`.
    pub std_error_k: Vec<f64>,
    /// Each node's point in the scene's frame (m), `ny × nx × 3`.
    pub xyz: Vec<f64>,
    /// Nodes without a value: (row j, column i, why).
    pub refused: Vec<(usize, usize, String)>,
    /// Extremes, mean, largest ± and its parts, unseen patches (None without a node).
    pub summary: Option<FieldSummary>,
    /// How view factors were computed.
    pub method: String,
    /// Seconds computing.
    pub compute_secs: f64,
}

/// The MRT of `scene` (from `source`, named in errors) over `spec`'s grid with the view-factor
/// settings `mrt`, as arrays; nothing is written. The same nodes and values as `mrtmap map`'s
/// mrt_grid.csv.
pub fn map_arrays(
    scene: &RadiantScene,
    source: &str,
    mrt: &MrtSection,
    spec: GridSpec,
) -> Result<MapArrays> {
    let method = mrt.method(scene)?;
    let engine = mrt.engine(scene)?;
    let frame = map_frame(&engine, scene, source, spec)?;
    let (field, secs) = compute_field(&engine, frame, spec, &|| false)?;
    let (nx, ny) = (spec.nx, spec.ny);
    let mut out = MapArrays {
        height_m: spec.height_m,
        u: field.u.clone(),
        v: field.v.clone(),
        axes: MapAxes::of(&field),
        mrt_c: vec![f64::NAN; nx * ny],
        std_error_k: vec![f64::NAN; nx * ny],
        xyz: vec![f64::NAN; nx * ny * 3],
        refused: Vec::new(),
        summary: field.summary(),
        method: method.describe(engine.ray_engine()),
        compute_secs: secs,
    };
    for n in &field.nodes {
        let k = n.j * nx + n.i;
        out.xyz[3 * k..3 * k + 3].copy_from_slice(&[n.point.x, n.point.y, n.point.z]);
        match &n.result {
            Ok(r) => {
                out.mrt_c[k] = r.mrt.celsius();
                out.std_error_k[k] = r.std_error_k;
            }
            Err(e) => out.refused.push((n.j, n.i, e.to_string())),
        }
    }
    Ok(out)
}

/// Computes the MRT map of `scene` (from `source`, for people) on `spec` with `marks`, and writes
/// mrt_grid.csv, mrt_map.png, mrt_map.svg and summary.json into `out`. The height and the marks
/// are checked against the room before anything is computed.
pub(crate) fn make_map(
    scene: &RadiantScene,
    source: &str,
    mrt: &MrtSection,
    spec: GridSpec,
    marks: &[Mark],
    out: &Path,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<MapOutput> {
    let method = mrt.method(scene)?;
    let engine = mrt.engine(scene)?;
    let frame = map_frame(&engine, scene, source, spec)?;
    let points = mark_points(&engine, &frame, &spec, marks)?;
    let (field, secs) = compute_field(&engine, frame, spec, stop)?;
    let (records, map_marks) = mark_records(&engine, &field, &spec, marks, &points)?;
    let how = method.describe(engine.ray_engine());
    let input = MapInput {
        field: &field,
        scene,
        marks: &map_marks,
        subtitle: format!("{source}; {}×{} grid; {}", spec.nx, spec.ny, method.brief()),
        quantity: None,
    };
    let (rays, seed) = match method {
        Method::MonteCarlo(mc) | Method::Auto(mc) => (Some(mc.rays), Some(mc.seed)),
        Method::Exact => (None, None),
    };
    let summary = Summary {
        scene: source.to_string(),
        map: MapSummary {
            height_m: spec.height_m,
            grid: [spec.nx, spec.ny],
            margin_m: spec.margin_m,
            method: method.name().to_string(),
            rays,
            seed,
            axes: MapAxes::of(&field),
            field: field.summary(),
            compute_secs: secs,
        },
        marks: records,
    };
    let png = render_png(&input)?;
    let dir = MapDir::new(out);
    write_atomic(&dir.mrt_grid_csv(), grid_csv(&field).as_bytes())?;
    write_atomic(&dir.mrt_map_png(), &png)?;
    write_atomic(&dir.mrt_map_svg(), render_svg(&input)?.as_bytes())?;
    write_json(&dir.summary_json(), &summary)?;
    Ok(MapOutput {
        summary,
        method: how,
        png,
    })
}

/// A map's nodes read back from its `mrt_grid.csv`: x, y, z (m) and the MRT (°C) of each node
/// that has one.
pub(crate) fn read_grid_nodes(csv: &Path) -> Result<Vec<[f64; 4]>> {
    let text = std::fs::read_to_string(csv).map_err(|e| mrtmap_io::FileError::io(csv, e))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| Error::source(csv, format!("has no `{name}` column")))
    };
    let idx = [col("x")?, col("y")?, col("z")?, col("mrt_c")?];
    Ok(lines
        .filter_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let v: Option<Vec<f64>> = idx
                .iter()
                .map(|&i| cells.get(i).and_then(|c| c.parse().ok()))
                .collect();
            v.map(|v| [v[0], v[1], v[2], v[3]])
        })
        .collect())
}

/// Where a scene comes from (`--scene`, `--temperatures`, `--room`).
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct SceneSource {
    /// The radiant scene file (`scene.json`, format mrtmap-scene/1) or a Honeybee model
    /// (`.hbjson`, with `--temperatures`). Without it, the built-in example office (see
    /// `mrtmap example-scene`).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// For a Honeybee model: a CSV of `identifier,temperature_c` (optionally
    /// `temperature_std_k`, `emissivity`) for its faces, apertures and doors; a `*` row for the
    /// rest. Without it, the model's own mrtmap temperatures.
    #[arg(long, value_name = "CSV", requires = "scene")]
    pub temperatures: Option<PathBuf>,
    /// For a Honeybee model with several rooms: the room's identifier.
    #[arg(long, value_name = "ID", requires = "scene")]
    pub room: Option<String>,
}

impl SceneSource {
    /// A scene file, with nothing else.
    pub fn file(path: &Path) -> Self {
        Self {
            scene: Some(path.to_path_buf()),
            ..Self::default()
        }
    }
}

/// The scene `src` names (a scene file, a Honeybee model with its temperatures), or the built-in
/// example office; the string says which, for people.
pub fn load_scene(src: &SceneSource) -> Result<(RadiantScene, String)> {
    let Some(p) = src.scene.as_deref() else {
        return Ok((
            mrtmap_radiation::example_office(),
            "the built-in example office".to_string(),
        ));
    };
    if crate::export::is_hbjson(p) {
        return crate::export::load_hbjson(p, src.temperatures.as_deref(), src.room.as_deref());
    }
    if src.temperatures.is_some() || src.room.is_some() {
        return Err(Error::setting(
            "--temperatures and --room",
            format!(
                "are for a Honeybee model (.hbjson); {} is a scene with its own temperatures",
                p.display()
            ),
        ));
    }
    Ok((RadiantScene::load(p)?, p.display().to_string()))
}

impl Summary {
    /// A map's extremes, the parts of its largest ±, the unseen patches that matter most and its
    /// marks, in lines (what `map` and `run` print).
    pub fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        match &self.map.field {
            Some(f) => {
                lines.push(format!(
                    "MRT at {:.2} m over {} nodes: min {:.2} °C at ({}, {}), max {:.2} °C at ({}, {}), mean {:.2} °C; largest standard error {} K",
                    self.map.height_m,
                    f.nodes,
                    f.min.mrt_c,
                    fixed(f.min.uv[0], 2),
                    fixed(f.min.uv[1], 2),
                    f.max.mrt_c,
                    fixed(f.max.uv[0], 2),
                    fixed(f.max.uv[1], 2),
                    f.mean_c,
                    uncertainty(f.max_std_error_k, 3)
                ));
                if f.skipped > 0 {
                    lines.push(format!(
                        "{} nodes skipped (inside furniture, or refused): see the note column of mrt_grid.csv",
                        f.skipped
                    ));
                }
                lines.push(format!(
                    "  its parts, the largest of each: {}",
                    mrtmap_report::parts_line(&f.max_std_error_parts, 3)
                ));
                for u in f.unseen_patches.iter().take(3) {
                    lines.push(format!("  not seen: {}", mrtmap_report::unseen_line(u)));
                }
            }
            None => lines.push("no grid node could be computed".to_string()),
        }
        for m in &self.marks {
            lines.push(format!(
                "  {}: MRT {:.2} °C ± {} K at {}",
                m.name.as_deref().unwrap_or("?"),
                m.mrt_c,
                uncertainty(m.std_error_k, 2),
                xyz(&m.xyz)
            ));
        }
        lines
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::settings::Quantity;

    /// `mrtmap map` from one call: the MRT map always; the comfort maps only when a person's
    /// quantity is asked for, and then only with the air they need.
    #[test]
    fn a_scene_is_mapped_with_the_comfort_maps_asked_for() {
        let scene = mrtmap_radiation::example_office();
        let dir = tempfile::tempdir().unwrap();
        let spec = GridSpec {
            nx: 6,
            ny: 5,
            ..GridSpec::default()
        };
        let mut project = crate::Project::default();
        let plain = map_scene(&scene, "example", &project, spec, &[], dir.path()).unwrap();
        assert!(plain.comfort.is_none());
        assert!(dir.path().join("mrt_grid.csv").exists());
        project.map.quantities = vec![Quantity::Pmv];
        project.air.temperature_c = None;
        assert!(map_scene(&scene, "example", &project, spec, &[], dir.path()).is_err());
        assert!(!dir.path().join("pmv.png").exists());
        project.air.temperature_c = Some(21.0);
        let both = map_scene(&scene, "example", &project, spec, &[], dir.path()).unwrap();
        assert_eq!(both.comfort.unwrap().summary.nodes, 30);
        assert!(dir.path().join("pmv.png").exists());
    }

    /// `[sun]` on the example office (window on the +x wall, sun 30° high due +x): `mrt_sun`
    /// adds SolarCal's ΔMRT of a person facing the sun (facing unset), large in the beam and small
    /// beside it, and the operative temperature includes it; `mrt_sun` without `[sun]` is refused.
    #[test]
    fn the_sun_map_adds_solarcal_in_the_beam() {
        let scene = mrtmap_radiation::example_office();
        let dir = tempfile::tempdir().unwrap();
        let spec = GridSpec {
            nx: 4,
            ny: 3,
            ..GridSpec::default()
        };
        let mut project = crate::Project::default();
        project.map.quantities = vec![Quantity::MrtSun, Quantity::Operative];
        project.air.temperature_c = Some(21.0);
        let e = map_scene(&scene, "example", &project, spec, &[], dir.path())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("mrt_sun") && e.contains("[sun]"), "{e}");
        let marks = [
            Mark {
                name: "lit".into(),
                at: MarkAt::Scene([2.65, 1.8, 0.6]),
            },
            Mark {
                name: "beside".into(),
                at: MarkAt::Scene([2.65, 0.3, 0.6]),
            },
        ];
        let mut without_project = project.clone();
        without_project.map.quantities = vec![Quantity::Operative];
        let without = map_scene(
            &scene,
            "example",
            &without_project,
            spec,
            &marks,
            dir.path(),
        )
        .unwrap()
        .comfort
        .unwrap();
        project.sun = crate::Project::parse(
            "[sun]\naltitude_deg = 30.0\nazimuth_deg = 0.0\ndni_w_m2 = 700\ntransmittance = 0.6\n",
        )
        .unwrap()
        .sun;
        let with = map_scene(&scene, "example", &project, spec, &marks, dir.path())
            .unwrap()
            .comfort
            .unwrap();
        assert!(dir.path().join("mrt_sun.png").exists());
        // The sunlit patch is outlined in orange on the mrt_sun map only.
        let svg = |q: &str| std::fs::read_to_string(dir.path().join(format!("{q}.svg"))).unwrap();
        assert!(svg("mrt_sun").contains("#FF8C00"));
        assert!(!svg("operative").contains("#FF8C00"));
        let csv = std::fs::read_to_string(dir.path().join("mrt_sun.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 12, "{csv}");
        let lit = &with.summary.marks[0].1;
        let sun = lit.sun.unwrap();
        assert_eq!((sun.facing_deg, sun.sharp_deg), (0.0, 0.0));
        assert!(sun.f_bes > 0.9, "{sun:?}");
        // The example's acceptance value for this person is 16.76 K (points.rs).
        assert!((14.0..19.0).contains(&sun.delta_mrt_k), "{sun:?}");
        let (m, _) = lit.mrt_sun.unwrap();
        assert!((m - sun.mrt_long_wave_c - sun.delta_mrt_k).abs() < 1e-9);
        let beside = with.summary.marks[1].1.sun.unwrap();
        assert_eq!(beside.f_bes, 0.0);
        // The patch the 3D view draws: on the floor, holding the cell under the lit person and
        // not the one beside the beam.
        let patch = with.summary.sunlit_patch.clone().unwrap();
        assert!(patch.cells.iter().all(|c| c[2].abs() < 1e-9), "{patch:?}");
        let near = |x: f64, y: f64| {
            patch.cells.iter().any(|c| {
                (c[0] - x).abs() <= 0.5 * patch.cell_m[0] + 1e-9
                    && (c[1] - y).abs() <= 0.5 * patch.cell_m[1] + 1e-9
            })
        };
        assert!(near(2.65, 1.8) && !near(2.65, 0.3), "{patch:?}");
        assert!(without.summary.sunlit_patch.is_none());
        assert!(beside.delta_mrt_k < sun.delta_mrt_k / 4.0, "{beside:?}");
        // Operative temperature with the sun: about half of ΔMRT warmer in the beam.
        let op = |p: &crate::comfort::ComfortPoint| p.thermal.unwrap().operative_c;
        let rise = op(lit) - op(&without.summary.marks[0].1);
        assert!(
            rise > 0.3 * sun.delta_mrt_k && rise < 0.7 * sun.delta_mrt_k,
            "{rise}"
        );
    }
}
