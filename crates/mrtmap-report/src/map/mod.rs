//! The MRT heatmap: cells coloured by MRT, labelled contour lines, the room outline with its
//! corners numbered and the origin's axes, features and furniture drawn and named, marked points,
//! a colour bar in °C and a title with the height. Labels are placed without overlap
//! ([`labels`]). One drawing routine serves both the PNG and the SVG backend.

mod labels;

use std::sync::OnceLock;

use mrtmap_geometry::nalgebra::{Point2, Vector2, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_radiation::{MrtField, OccluderShape, RadiantScene, SurfaceKind};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::ReportError;
use labels::{LABEL_H, Label, PixelBox, Placer, centred_box, draw_label};

static FONT: OnceLock<bool> = OnceLock::new();
const FONT_FAMILY: &str = "sans-serif";

/// Registers the embedded font once; whether it could be.
fn register_font() -> bool {
    *FONT.get_or_init(|| {
        plotters::style::register_font(
            FONT_FAMILY,
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        )
        .is_ok()
    })
}

/// A named point to mark on the map, in map coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct MapMark {
    /// Its name (e.g. "A").
    pub name: String,
    /// Map coordinates (m).
    pub uv: Point2<f64>,
}

/// What to draw.
pub struct MapInput<'a> {
    /// The computed field.
    pub field: &'a MrtField,
    /// The scene (outline, features, occluders).
    pub scene: &'a RadiantScene,
    /// Points to mark.
    pub marks: &'a [MapMark],
    /// Second title line (method, grid…).
    pub subtitle: String,
    /// Another quantity on the field's grid instead of its MRT (a person's MRT, PMV…).
    pub quantity: Option<MapQuantity>,
}

/// A quantity other than the sphere's MRT, drawn on a field's grid.
#[derive(Clone, Debug, PartialEq)]
pub struct MapQuantity {
    /// The title ("Operative temperature of a seated person (°C)").
    pub title: String,
    /// The colour bar's unit ("°C", "K", "%", or "" for PMV).
    pub unit: String,
    /// Values at nodes (i, j, value); nodes without a value are left empty.
    pub values: Vec<(usize, usize, f64)>,
    /// The value at the palette's middle, for a quantity with a neutral point (PMV: 0): the
    /// scale is then symmetric about it, so a cool map is blue however narrow its range (a map
    /// from −0.8 to −0.6 was drawn from blue to red).
    pub neutral: Option<f64>,
    /// Nodes whose cells are outlined together (the sunlit patch: where the beam reaches the
    /// person); empty: none.
    pub outlined: Vec<(usize, usize)>,
}

/// Colour of a value `t` in 0…1 on the map's palette (blue cold → red warm).
pub(crate) fn palette(t: f64) -> RGBColor {
    let g = colorgrad::preset::rd_yl_bu();
    let c = colorgrad::Gradient::at(&g, (1.0 - t.clamp(0.0, 1.0)) as f32).to_rgba8();
    RGBColor(c[0], c[1], c[2])
}

/// A "nice" contour step for a range: 1, 2, 2.5 or 5 × 10ⁿ giving about 6–12 levels.
pub fn contour_step(range_k: f64) -> f64 {
    if range_k.is_nan() || range_k <= 0.0 {
        return 0.1;
    }
    let raw = range_k / 8.0;
    let mag = 10f64.powf(raw.log10().floor());
    let best = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .min_by(|a, b| (a - raw).abs().total_cmp(&(b - raw).abs()))
        .unwrap_or(raw);
    best.max(0.01)
}

fn decimals(step: f64) -> usize {
    let mut d = 0;
    while d < 3
        && ((step * 10f64.powi(d as i32)).round() - step * 10f64.powi(d as i32)).abs() > 1e-6
    {
        d += 1;
    }
    d
}

/// An axis name for a map axis: "x", "−y"… for world axes, else the generic name.
fn axis_name(axis: &Vector3<f64>, generic: &str) -> String {
    for (k, n) in ["x", "y", "z"].iter().enumerate() {
        if axis[k] > 1.0 - 1e-9 {
            return n.to_string();
        }
        if axis[k] < -1.0 + 1e-9 {
            return format!("−{n}");
        }
    }
    generic.to_string()
}

struct Layout {
    w: u32,
    h: u32,
}

fn layout(field: &MrtField) -> Layout {
    let (lo, hi) = field.frame.floor_bounds();
    let (du, dv) = ((hi.x - lo.x).max(1e-3), (hi.y - lo.y).max(1e-3));
    let s = 620.0 / du.max(dv);
    let (pw, ph) = ((du * s).round().max(240.0), (dv * s).round().max(240.0));
    Layout {
        w: pw as u32 + 90 + 150,
        h: ph as u32 + 110 + 60,
    }
}

/// The parts of a polyline whose segments' midpoints lie inside `poly` and that do not run along
/// the contour grid's border `(lo, hi)` (where contour rings are closed), as separate runs.
fn runs_inside(
    pts: &[contour::Pt],
    poly: &[Point2<f64>],
    lo: (f64, f64),
    hi: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let eps = 1e-9 * (1.0 + hi.0.abs().max(hi.1.abs()));
    let on_border = |a: &contour::Pt, b: &contour::Pt| {
        [
            (a.x, b.x, lo.0),
            (a.x, b.x, hi.0),
            (a.y, b.y, lo.1),
            (a.y, b.y, hi.1),
        ]
        .iter()
        .any(|&(p, q, edge)| (p - edge).abs() < eps && (q - edge).abs() < eps)
    };
    let mut runs = Vec::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    for w in pts.windows(2) {
        let mid = Point2::new((w[0].x + w[1].x) / 2.0, (w[0].y + w[1].y) / 2.0);
        if !on_border(&w[0], &w[1]) && point_in_polygon_fast(&mid, poly) {
            if run.is_empty() {
                run.push((w[0].x, w[0].y));
            }
            run.push((w[1].x, w[1].y));
        } else if run.len() >= 2 {
            runs.push(std::mem::take(&mut run));
        } else {
            run.clear();
        }
    }
    if run.len() >= 2 {
        runs.push(run);
    }
    runs
}

/// The map's chart: map coordinates (m) on both axes.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A drawing error, in words.
#[allow(clippy::needless_pass_by_value)] // used as map_err(de)
fn de<E: std::error::Error + Send + Sync>(x: DrawingAreaErrorKind<E>) -> ReportError {
    ReportError::Draw(x.to_string())
}

/// A computed node: grid indices, map coordinates, MRT (°C).
type Node = (usize, usize, Point2<f64>, f64);

/// The colour scale: MRT range mapped onto the palette.
#[derive(Clone, Copy)]
struct Scale {
    vmin: f64,
    vmax: f64,
}

impl Scale {
    /// The range of the computed nodes, widened to at least 0.1 K; with a `neutral` value,
    /// symmetric about it (at least ±0.5).
    fn of(ok: &[Node], neutral: Option<f64>) -> Self {
        if let Some(n) = neutral {
            let m = ok.iter().map(|x| (x.3 - n).abs()).fold(0.5f64, f64::max);
            return Self {
                vmin: n - m,
                vmax: n + m,
            };
        }
        let (vmin, vmax) = ok
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x.3), b.max(x.3))
            });
        let (vmin, vmax) = if ok.is_empty() {
            (0.0, 1.0)
        } else if vmax - vmin < 0.05 {
            ((vmin + vmax) / 2.0 - 0.05, (vmin + vmax) / 2.0 + 0.05)
        } else {
            (vmin, vmax)
        };
        Self { vmin, vmax }
    }

    /// A value's place on the palette, 0…1 within the range.
    fn norm(&self, v: f64) -> f64 {
        (v - self.vmin) / (self.vmax - self.vmin)
    }
}

/// The computed nodes of a field.
/// The nodes to colour: the quantity's values when one is given, else the field's MRT.
fn nodes_of(input: &MapInput<'_>) -> Vec<Node> {
    let Some(q) = &input.quantity else {
        return computed_nodes(input.field);
    };
    let f = input.field;
    q.values
        .iter()
        .filter(|(i, j, v)| *i < f.u.len() && *j < f.v.len() && v.is_finite())
        .map(|&(i, j, v)| (i, j, Point2::new(f.u[i], f.v[j]), v))
        .collect()
}

fn computed_nodes(field: &MrtField) -> Vec<Node> {
    field
        .nodes
        .iter()
        .filter_map(|n| {
            n.result
                .as_ref()
                .ok()
                .map(|r| (n.i, n.j, n.uv, r.mrt.celsius()))
        })
        .collect()
}

fn draw_titles<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    input: &MapInput<'_>,
) -> Result<(), ReportError> {
    let title = match &input.quantity {
        Some(q) => q.title.clone(),
        None => format!(
            "Mean radiant temperature at {:.2} m above the floor (°C)",
            input.field.spec.height_m
        ),
    };
    root.draw(&Text::new(
        title,
        (20, 12),
        (FONT_FAMILY, 22).into_font().color(&BLACK),
    ))
    .map_err(de)?;
    root.draw(&Text::new(
        input.subtitle.clone(),
        (20, 42),
        (FONT_FAMILY, 14).into_font().color(&RGBColor(80, 80, 80)),
    ))
    .map_err(de)
}

/// The chart over the floor's bounds, with its axes.
fn build_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    field: &MrtField,
) -> Result<Chart<'a, DB>, ReportError> {
    let frame = &field.frame;
    let (lo, hi) = frame.floor_bounds();
    let pad = 0.02 * (hi.x - lo.x).max(hi.y - lo.y);
    let (u_name, v_name) = (
        axis_name(&frame.plane.u, "u"),
        axis_name(&frame.plane.v, "v"),
    );
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d((lo.x - pad)..(hi.x + pad), (lo.y - pad)..(hi.y + pad))
        .map_err(de)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(format!("{u_name} (m)"))
        .y_desc(format!("{v_name} (m)"))
        .label_style((FONT_FAMILY, 13))
        .axis_desc_style((FONT_FAMILY, 14))
        .draw()
        .map_err(de)?;
    Ok(chart)
}

/// Heat cells, centred on the nodes, clipped to the floor's bounds.
fn draw_cells<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    field: &MrtField,
    ok: &[Node],
    scale: Scale,
) -> Result<(), ReportError> {
    let (lo, hi) = field.frame.floor_bounds();
    let half = |c: &[f64], k: usize| {
        let d = if c.len() > 1 {
            (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64
        } else {
            hi.x - lo.x
        };
        (c[k] - d / 2.0, c[k] + d / 2.0)
    };
    chart
        .draw_series(ok.iter().map(|&(i, j, _, v)| {
            let (u0, u1) = half(&field.u, i);
            let (v0, v1) = half(&field.v, j);
            Rectangle::new(
                [(u0.max(lo.x), v0.max(lo.y)), (u1.min(hi.x), v1.min(hi.y))],
                palette(scale.norm(v)).filled(),
            )
        }))
        .map_err(de)?;
    Ok(())
}

/// The node grid's values; nodes without a value take their nearest computed neighbour's.
fn filled_grid(field: &MrtField, ok: &[Node], fallback: f64) -> Vec<f64> {
    let (nx, ny) = (field.u.len(), field.v.len());
    let mut grid = vec![f64::NAN; nx * ny];
    for &(i, j, _, v) in ok {
        grid[j * nx + i] = v;
    }
    (0..nx * ny)
        .map(|k| {
            if grid[k].is_finite() {
                return grid[k];
            }
            let (i, j) = ((k % nx) as f64, (k / nx) as f64);
            ok.iter()
                .min_by(|a, b| {
                    let da = (a.0 as f64 - i).powi(2) + (a.1 as f64 - j).powi(2);
                    let db = (b.0 as f64 - i).powi(2) + (b.1 as f64 - j).powi(2);
                    da.total_cmp(&db)
                })
                .map_or(fallback, |x| x.3)
        })
        .collect()
}

/// Contour levels strictly inside the range, at the scale's step.
fn contour_levels(scale: Scale) -> Vec<f64> {
    let step = contour_step(scale.vmax - scale.vmin);
    let first = (scale.vmin / step).ceil() * step;
    (0..)
        .map(|k| first + k as f64 * step)
        .take_while(|l| *l < scale.vmax)
        .filter(|l| *l > scale.vmin)
        .collect()
}

/// Labels a contour along its longer runs first, at the first spot clear of earlier labels and
/// marks (`placed`, which the label joins).
fn label_contour<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    runs: &[Vec<(f64, f64)>],
    label: String,
    placer: &mut Placer,
) -> Result<(), ReportError> {
    let tw = 7 * label.len() as i32 + 6;
    let mut sorted: Vec<&Vec<(f64, f64)>> = runs.iter().collect();
    sorted.sort_by_key(|r| std::cmp::Reverse(r.len()));
    let spot = sorted
        .iter()
        .flat_map(|r| [0.5, 0.3, 0.7, 0.15, 0.85].map(|t| r[((r.len() - 1) as f64 * t) as usize]))
        .find_map(|at| {
            let (px, py) = chart.backend_coord(&at);
            let rect: PixelBox = (px - tw / 2 - 2, py - 10, px + tw / 2 + 2, py + 10);
            placer.is_clear(rect).then_some((px, py, rect))
        });
    let Some((px, py, rect)) = spot else {
        return Ok(());
    };
    placer.reserve(rect);
    root.draw(&Rectangle::new(
        [(px - tw / 2, py - 8), (px + tw / 2, py + 8)],
        WHITE.mix(0.85).filled(),
    ))
    .map_err(de)?;
    root.draw(&Text::new(
        label,
        (px, py),
        (FONT_FAMILY, 12)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center)),
    ))
    .map_err(de)
}

/// A contour's runs inside the room and its label text.
type ContourRuns = (Vec<Vec<(f64, f64)>>, String);

/// Contour lines on the node grid (segments outside the floor are not drawn); their labels are
/// placed last, around everything else.
fn draw_contours<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    input: &MapInput<'_>,
    ok: &[Node],
    scale: Scale,
) -> Result<Vec<ContourRuns>, ReportError> {
    let field = input.field;
    let (nx, ny) = (field.u.len(), field.v.len());
    if ok.len() < 4 || nx < 2 || ny < 2 {
        return Ok(Vec::new());
    }
    let filled = filled_grid(field, ok, scale.vmin);
    let dec = decimals(contour_step(scale.vmax - scale.vmin));
    let levels = contour_levels(scale);
    let du = (field.u[nx - 1] - field.u[0]) / (nx - 1) as f64;
    let dv = (field.v[ny - 1] - field.v[0]) / (ny - 1) as f64;
    // contour-rs places value k at k + 0.5 in grid units; shift so nodes land on their coordinates.
    let (gx, gy) = (field.u[0] - du / 2.0, field.v[0] - dv / 2.0);
    let grid_box = ((gx, gy), (gx + nx as f64 * du, gy + ny as f64 * dv));
    let builder = contour::ContourBuilder::new(nx, ny, true)
        .x_origin(gx)
        .y_origin(gy)
        .x_step(du)
        .y_step(dv);
    let Ok(lines) = builder.lines(&filled, &levels) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for line in lines {
        let level = line.threshold();
        let runs: Vec<Vec<(f64, f64)>> = line
            .geometry()
            .0
            .iter()
            .flat_map(|ls| runs_inside(&ls.0, &field.frame.floor_uv, grid_box.0, grid_box.1))
            .collect();
        chart
            .draw_series(
                runs.iter()
                    .map(|r| PathElement::new(r.clone(), BLACK.mix(0.75).stroke_width(1))),
            )
            .map_err(de)?;
        out.push((runs, format!("{level:.dec$}")));
    }
    Ok(out)
}

/// The border of the outlined cells (each side of an outlined cell whose neighbour is not), in a
/// dashed-looking orange.
fn draw_patch<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    field: &MrtField,
    cells: &[(usize, usize)],
) -> Result<(), ReportError> {
    if cells.is_empty() {
        return Ok(());
    }
    let (lo, hi) = field.frame.floor_bounds();
    let step = |c: &[f64], span: f64| {
        if c.len() > 1 {
            (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64
        } else {
            span
        }
    };
    let (du, dv) = (step(&field.u, hi.x - lo.x), step(&field.v, hi.y - lo.y));
    let has = |i: isize, j: isize| i >= 0 && j >= 0 && cells.contains(&(i as usize, j as usize));
    let mut segments = Vec::new();
    for &(i, j) in cells {
        let (Some(&u), Some(&v)) = (field.u.get(i), field.v.get(j)) else {
            continue;
        };
        let (u0, u1) = ((u - du / 2.0).max(lo.x), (u + du / 2.0).min(hi.x));
        let (v0, v1) = ((v - dv / 2.0).max(lo.y), (v + dv / 2.0).min(hi.y));
        let (ii, jj) = (i as isize, j as isize);
        if !has(ii - 1, jj) {
            segments.push(vec![(u0, v0), (u0, v1)]);
        }
        if !has(ii + 1, jj) {
            segments.push(vec![(u1, v0), (u1, v1)]);
        }
        if !has(ii, jj - 1) {
            segments.push(vec![(u0, v0), (u1, v0)]);
        }
        if !has(ii, jj + 1) {
            segments.push(vec![(u0, v1), (u1, v1)]);
        }
    }
    let orange = RGBColor(255, 140, 0);
    chart
        .draw_series(
            segments
                .into_iter()
                .map(|s| PathElement::new(s, orange.stroke_width(3))),
        )
        .map_err(de)?;
    Ok(())
}

/// The room's outline.
fn draw_outline<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    field: &MrtField,
) -> Result<(), ReportError> {
    let mut outline: Vec<(f64, f64)> = field.frame.floor_uv.iter().map(|p| (p.x, p.y)).collect();
    if let Some(first) = outline.first().copied() {
        outline.push(first);
    }
    chart
        .draw_series(std::iter::once(PathElement::new(
            outline,
            BLACK.stroke_width(3),
        )))
        .map_err(de)?;
    Ok(())
}

/// A feature on a wall: a band along the wall in its colour; its label goes just inside the room.
fn draw_wall_feature<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    field: &MrtField,
    uv: &[(f64, f64)],
    colour: RGBColor,
    text: String,
) -> Result<Option<Label>, ReportError> {
    let frame = &field.frame;
    let (lo, hi) = frame.floor_bounds();
    // The projection is a segment along the wall: its two extreme points.
    let c = uv.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let c = (c.0 / uv.len() as f64, c.1 / uv.len() as f64);
    let far = |from: (f64, f64)| {
        uv.iter().copied().max_by(|a, b| {
            let da = (a.0 - from.0).hypot(a.1 - from.1);
            let db = (b.0 - from.0).hypot(b.1 - from.1);
            da.total_cmp(&db)
        })
    };
    let (Some(a), Some(b)) = (far(c), far(far(c).unwrap_or(c))) else {
        return Ok(None);
    };
    for style in [colour.stroke_width(7), BLACK.stroke_width(1)] {
        chart
            .draw_series(std::iter::once(PathElement::new(vec![a, b], style)))
            .map_err(de)?;
    }
    let mid = Point2::new((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
    let centre = frame.floor_uv.iter().fold(Point2::origin(), |acc, p| {
        acc + p.coords / frame.floor_uv.len() as f64
    });
    let inward = (centre - mid).try_normalize(1e-9).unwrap_or_default();
    let at = mid + inward * (0.06 * (hi.x - lo.x).max(hi.y - lo.y));
    Ok(Some(Label {
        anchor: chart.backend_coord(&(at.x, at.y)),
        text,
    }))
}

/// A feature on the floor or ceiling: its outline in its colour; its label goes at its centre.
fn draw_flat_feature<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    kind: SurfaceKind,
    uv: &[(f64, f64)],
    colour: RGBColor,
    text: &str,
) -> Result<Label, ReportError> {
    let mut ring = uv.to_vec();
    ring.push(uv[0]);
    let (style, where_) = if kind == SurfaceKind::Ceiling {
        (colour.stroke_width(2), " (ceiling)")
    } else {
        (colour.stroke_width(3), " (floor)")
    };
    chart
        .draw_series(std::iter::once(PathElement::new(ring, style)))
        .map_err(de)?;
    let c = uv.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + p.0 / uv.len() as f64, a.1 + p.1 / uv.len() as f64)
    });
    Ok(Label {
        anchor: chart.backend_coord(&c),
        text: format!("{text}{where_}"),
    })
}

/// Features: on walls as bands along the wall, on floor and ceiling as outlines; their labels.
fn draw_features<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    input: &MapInput<'_>,
    scale: Scale,
) -> Result<Vec<Label>, ReportError> {
    let frame = &input.field.frame;
    let mut labels = Vec::new();
    for s in &input.scene.surfaces {
        for f in &s.features {
            let uv: Vec<(f64, f64)> = f
                .polygon
                .iter()
                .map(|p| frame.uv(p))
                .map(|q| (q.x, q.y))
                .collect();
            let colour = palette(scale.norm(f.temperature.celsius()));
            let name = if f.label.is_empty() {
                f.id.clone()
            } else {
                f.label.clone()
            };
            let text = format!("{name} {:.1} °C", f.temperature.celsius());
            match s.kind {
                SurfaceKind::Wall | SurfaceKind::Other => {
                    labels.extend(draw_wall_feature(chart, input.field, &uv, colour, text)?);
                }
                SurfaceKind::Ceiling | SurfaceKind::Floor => {
                    labels.push(draw_flat_feature(chart, s.kind, &uv, colour, &text)?);
                }
            }
        }
    }
    Ok(labels)
}

/// Furniture: its footprint's bounding rectangle; its label.
fn draw_furniture<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    input: &MapInput<'_>,
) -> Result<Vec<Label>, ReportError> {
    let frame = &input.field.frame;
    let mut labels = Vec::new();
    for o in &input.scene.occluders {
        let corners: Vec<Point2<f64>> = match &o.shape {
            OccluderShape::Box { min, max } => mrtmap_geometry::box_corners(min, max)
                .iter()
                .map(|p| frame.uv(p))
                .collect(),
            OccluderShape::Mesh { vertices, .. } => vertices.iter().map(|p| frame.uv(p)).collect(),
        };
        let (a, b) = corners.iter().fold(
            (
                (f64::INFINITY, f64::INFINITY),
                (f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |(a, b), p| ((a.0.min(p.x), a.1.min(p.y)), (b.0.max(p.x), b.1.max(p.y))),
        );
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [a, b],
                RGBColor(90, 90, 90).mix(0.35).filled(),
            )))
            .map_err(de)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [a, b],
                RGBColor(60, 60, 60).stroke_width(1),
            )))
            .map_err(de)?;
        let name = if o.label.is_empty() {
            o.id.clone()
        } else {
            o.label.clone()
        };
        labels.push(Label {
            anchor: chart.backend_coord(&((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0)),
            text: name,
        });
    }
    Ok(labels)
}

/// Marked points: a ringed dot and the name beside it, in the first free spot.
fn draw_marks<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    marks: &[MapMark],
    placer: &mut Placer,
) -> Result<(), ReportError> {
    let dots: Vec<(i32, i32)> = marks
        .iter()
        .map(|m| chart.backend_coord(&(m.uv.x, m.uv.y)))
        .collect();
    for &(px, py) in &dots {
        root.draw(&Circle::new((px, py), 6, WHITE.filled()))
            .map_err(de)?;
        root.draw(&Circle::new((px, py), 6, BLACK.stroke_width(2)))
            .map_err(de)?;
        placer.reserve((px - 8, py - 8, px + 8, py + 8));
    }
    for (m, &(px, py)) in marks.iter().zip(&dots) {
        let w = 10 * m.name.chars().count() as i32 + 4;
        let spots = [(px + 10 + w / 2, py - 10), (px - 10 - w / 2, py - 10)];
        let at = spots
            .into_iter()
            .chain(placer.find((px, py), w, 18))
            .find(|&c| placer.is_clear(centred_box(c, w, 18)))
            .unwrap_or(spots[0]);
        placer.reserve(centred_box(at, w, 18));
        root.draw(&Text::new(
            m.name.clone(),
            at,
            (FONT_FAMILY, 15)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(de)?;
    }
    Ok(())
}

/// The direction into the room at floor corner `k` (the bisector of its two walls, turned inward).
fn inward(floor: &[Point2<f64>], k: usize) -> Vector2<f64> {
    let n = floor.len();
    let p = floor[k];
    let e1 = (floor[(k + 1) % n] - p)
        .try_normalize(1e-12)
        .unwrap_or_default();
    let e0 = (floor[(k + n - 1) % n] - p)
        .try_normalize(1e-12)
        .unwrap_or_default();
    let twice_area: f64 = (0..n)
        .map(|i| {
            let (a, b) = (floor[i], floor[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum();
    // The side of the first wall the room is on: left for a counter-clockwise outline.
    let side = Vector2::new(-e1.y, e1.x) * twice_area.signum();
    let b = e0 + e1;
    match b.try_normalize(1e-6) {
        Some(b) if b.dot(&side) >= 0.0 => b,
        Some(b) => -b,
        None => side,
    }
}

/// Floor corners numbered (corner k starts wall k) and, when the map is in the room's frame and
/// its origin is a corner, that corner in red with the x and y axes drawn from it.
fn draw_corners<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    field: &MrtField,
    placer: &mut Placer,
) -> Result<(), ReportError> {
    let frame = &field.frame;
    let floor = &frame.floor_uv;
    // The map's axes are the room's x and y (the origin corner is the room frame's origin).
    let room_frame = frame.plane.u.x > 1.0 - 1e-9 && frame.plane.v.y > 1.0 - 1e-9;
    let origin = floor
        .iter()
        .position(|p| room_frame && p.coords.norm() < 0.02);
    let red = RGBColor(180, 20, 20);
    let px = |p: &Point2<f64>| chart.backend_coord(&(p.x, p.y));
    if let Some(k) = origin {
        let o = px(&floor[k]);
        // Each axis's name sits beside its arrow's tip, on the room's side.
        for (axis, name, turn) in [(Vector2::x(), "x", 1.0), (Vector2::y(), "y", -1.0)] {
            let tip = px(&(floor[k] + axis));
            let d = Vector2::new(f64::from(tip.0 - o.0), f64::from(tip.1 - o.1))
                .try_normalize(1e-12)
                .unwrap_or_default();
            let at = |l: f64| {
                (
                    o.0 + (d.x * l).round() as i32,
                    o.1 + (d.y * l).round() as i32,
                )
            };
            let (end, l1, l2) = (at(56.0), (d.y, -d.x), (-d.y, d.x));
            root.draw(&PathElement::new(vec![o, end], red.stroke_width(3)))
                .map_err(de)?;
            let wing = |n: (f64, f64)| {
                let b = at(46.0);
                (
                    b.0 + (n.0 * 6.0).round() as i32,
                    b.1 + (n.1 * 6.0).round() as i32,
                )
            };
            root.draw(&Polygon::new(vec![end, wing(l1), wing(l2)], red.filled()))
                .map_err(de)?;
            let tip_at = at(50.0);
            let text_at = (
                tip_at.0 + (turn * d.y * 13.0).round() as i32,
                tip_at.1 - (turn * d.x * 13.0).round() as i32,
            );
            placer.reserve(centred_box(text_at, 14, LABEL_H));
            root.draw(&Text::new(
                name,
                text_at,
                (FONT_FAMILY, 15)
                    .into_font()
                    .color(&red)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))
            .map_err(de)?;
        }
    }
    for (k, p) in floor.iter().enumerate() {
        let c = px(p);
        let tip = px(&(p + inward(floor, k)));
        let d = Vector2::new(f64::from(tip.0 - c.0), f64::from(tip.1 - c.1))
            .try_normalize(1e-12)
            .unwrap_or_default();
        let at = (
            c.0 + (d.x * 16.0).round() as i32,
            c.1 + (d.y * 16.0).round() as i32,
        );
        let (fill, ink) = if Some(k) == origin {
            (red, WHITE)
        } else {
            (WHITE, BLACK)
        };
        root.draw(&Circle::new(at, 9, fill.filled())).map_err(de)?;
        root.draw(&Circle::new(at, 9, ink.mix(0.9).stroke_width(1)))
            .map_err(de)?;
        root.draw(&Text::new(
            (k + 1).to_string(),
            at,
            (FONT_FAMILY, 12)
                .into_font()
                .color(&ink)
                .pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(de)?;
        placer.reserve((at.0 - 10, at.1 - 10, at.0 + 10, at.1 + 10));
    }
    Ok(())
}

/// The colour bar with its ticks, in `unit`.
fn draw_colour_bar<DB: DrawingBackend>(
    bar_area: &DrawingArea<DB, Shift>,
    scale: Scale,
    unit: &str,
) -> Result<(), ReportError> {
    let (_, bh) = bar_area.dim_in_pixel();
    let (x0, y0, bar_h) = (30i32, 40i32, (bh as i32 - 100).max(100));
    let steps = 200;
    for k in 0..steps {
        let t = 1.0 - k as f64 / steps as f64;
        let ya = y0 + k * bar_h / steps;
        let yb = y0 + (k + 1) * bar_h / steps;
        bar_area
            .draw(&Rectangle::new(
                [(x0, ya), (x0 + 24, yb + 1)],
                palette(t).filled(),
            ))
            .map_err(de)?;
    }
    bar_area
        .draw(&Rectangle::new(
            [(x0, y0), (x0 + 24, y0 + bar_h)],
            BLACK.stroke_width(1),
        ))
        .map_err(de)?;
    bar_area
        .draw(&Text::new(
            unit.to_string(),
            (x0, y0 - 26),
            (FONT_FAMILY, 15).into_font().color(&BLACK),
        ))
        .map_err(de)?;
    let step = contour_step(scale.vmax - scale.vmin);
    let dec = decimals(step).max(1);
    let mut l = (scale.vmin / step).ceil() * step;
    while l <= scale.vmax + 1e-9 {
        let y = y0 + ((1.0 - scale.norm(l)) * bar_h as f64).round() as i32;
        bar_area
            .draw(&PathElement::new(
                vec![(x0 + 24, y), (x0 + 30, y)],
                BLACK.stroke_width(1),
            ))
            .map_err(de)?;
        bar_area
            .draw(&Text::new(
                format!("{l:.dec$}"),
                (x0 + 34, y),
                (FONT_FAMILY, 12)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(de)?;
        l += step;
    }
    Ok(())
}

/// Draws the whole map on `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    input: &MapInput<'_>,
) -> Result<(), ReportError> {
    if !register_font() {
        return Err(ReportError::Draw(
            "the embedded font could not be registered".into(),
        ));
    }
    root.fill(&WHITE).map_err(de)?;
    draw_titles(root, input)?;
    let (w, _) = root.dim_in_pixel();
    let body = root.margin(70, 10, 10, 10);
    let (map_area, bar_area) = body.split_horizontally(w as i32 - 20 - 140);
    let ok = nodes_of(input);
    let scale = Scale::of(&ok, input.quantity.as_ref().and_then(|q| q.neutral));
    let mut chart = build_chart(&map_area, input.field)?;
    draw_cells(&mut chart, input.field, &ok, scale)?;
    let contours = draw_contours(&mut chart, input, &ok, scale)?;
    if let Some(q) = &input.quantity {
        draw_patch(&mut chart, input.field, &q.outlined)?;
    }
    draw_outline(&mut chart, input.field)?;
    let mut labels = draw_features(&mut chart, input, scale)?;
    labels.extend(draw_furniture(&mut chart, input)?);
    // Labels go last, each around what was placed before it: corners and marks, then the
    // features' and furniture's names, then the contour values.
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let mut placer = Placer::new((xr.start, yr.start, xr.end, yr.end));
    draw_corners(root, &chart, input.field, &mut placer)?;
    draw_marks(root, &chart, input.marks, &mut placer)?;
    for l in labels {
        draw_label(root, &mut placer, l)?;
    }
    for (runs, text) in contours {
        label_contour(root, &chart, &runs, text, &mut placer)?;
    }
    let unit = input.quantity.as_ref().map_or("°C", |q| q.unit.as_str());
    draw_colour_bar(&bar_area, scale, unit)?;
    root.present().map_err(de)?;
    Ok(())
}

/// The map as PNG bytes.
pub fn render_png(input: &MapInput<'_>) -> Result<Vec<u8>, ReportError> {
    let Layout { w, h } = layout(input.field);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw(&root, input)?;
    }
    let img = image::RgbImage::from_raw(w, h, buf)
        .ok_or_else(|| ReportError::Draw("image buffer size".into()))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|x| ReportError::Draw(x.to_string()))?;
    Ok(out.into_inner())
}

/// The map as SVG text.
pub fn render_svg(input: &MapInput<'_>) -> Result<String, ReportError> {
    let Layout { w, h } = layout(input.field);
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (w, h)).into_drawing_area();
        draw(&root, input)?;
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PMV map from −0.8 to −0.6 (issue 41: its −0.6 end was drawn red): with PMV's neutral 0
    /// at the palette's middle both ends fall on the cool half; without it, the range's top
    /// is the warm end.
    #[test]
    fn a_cool_pmv_map_is_coloured_cool() {
        let nodes: Vec<Node> = [-0.8, -0.7, -0.6]
            .iter()
            .enumerate()
            .map(|(i, &v)| (i, 0, Point2::new(i as f64, 0.0), v))
            .collect();
        let pmv = Scale::of(&nodes, Some(0.0));
        assert!((pmv.vmin + 0.8).abs() < 1e-12 && (pmv.vmax - 0.8).abs() < 1e-12);
        for n in &nodes {
            let c = palette(pmv.norm(n.3));
            assert!(c.2 > c.0, "{} is drawn {c:?}", n.3);
        }
        let plain = Scale::of(&nodes, None);
        let top = palette(plain.norm(-0.6));
        assert!(top.0 > top.2, "{top:?}");
    }
}
