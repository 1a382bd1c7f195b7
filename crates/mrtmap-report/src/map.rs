//! The MRT heatmap: cells coloured by MRT, labelled contour lines, the room outline, features and
//! occluders drawn and named, marked points, a colour bar in °C and a title with the height.
//! One drawing routine serves both the PNG and the SVG backend.

use std::sync::Once;

use mrtmap_geometry::nalgebra::{Point2, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_radiation::{MrtField, OccluderShape, RadiantScene, SurfaceKind};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::ReportError;

static FONT: Once = Once::new();
const FONT_FAMILY: &str = "sans-serif";

fn register_font() {
    FONT.call_once(|| {
        // The embedded font is valid; were it not, text would fail to draw and say so.
        let _ = plotters::style::register_font(
            FONT_FAMILY,
            FontStyle::Normal,
            include_bytes!("../assets/DejaVuSans.ttf"),
        );
    });
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
}

/// Colour of a value `t` in 0…1 on the map's palette (blue cold → red warm).
fn palette(t: f64) -> RGBColor {
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

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    input: &MapInput<'_>,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    register_font();
    let field = input.field;
    let frame = &field.frame;
    root.fill(&WHITE).map_err(e)?;
    let (w, _h) = root.dim_in_pixel();
    let title = format!(
        "Mean radiant temperature at {:.2} m above the floor (°C)",
        field.spec.height_m
    );
    root.draw(&Text::new(
        title,
        (20, 12),
        (FONT_FAMILY, 22).into_font().color(&BLACK),
    ))
    .map_err(e)?;
    root.draw(&Text::new(
        input.subtitle.clone(),
        (20, 42),
        (FONT_FAMILY, 14).into_font().color(&RGBColor(80, 80, 80)),
    ))
    .map_err(e)?;
    let body = root.margin(70, 10, 10, 10);
    let (map_area, bar_area) = body.split_horizontally(w as i32 - 20 - 140);

    let ok: Vec<(usize, usize, Point2<f64>, f64)> = field
        .nodes
        .iter()
        .filter_map(|n| {
            n.result
                .as_ref()
                .ok()
                .map(|r| (n.i, n.j, n.uv, r.mrt.celsius()))
        })
        .collect();
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
    let norm = |v: f64| (v - vmin) / (vmax - vmin);

    let (lo, hi) = frame.floor_bounds();
    let pad = 0.02 * (hi.x - lo.x).max(hi.y - lo.y);
    let (u_name, v_name) = (
        axis_name(&frame.plane.u, "u"),
        axis_name(&frame.plane.v, "v"),
    );
    let mut chart = ChartBuilder::on(&map_area)
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d((lo.x - pad)..(hi.x + pad), (lo.y - pad)..(hi.y + pad))
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(format!("{u_name} (m)"))
        .y_desc(format!("{v_name} (m)"))
        .label_style((FONT_FAMILY, 13))
        .axis_desc_style((FONT_FAMILY, 14))
        .draw()
        .map_err(e)?;

    // Heat cells, centred on the nodes, clipped to the floor's bounds.
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
                palette(norm(v)).filled(),
            )
        }))
        .map_err(e)?;

    // Contours on the node grid; nodes without a value take their nearest computed neighbour's,
    // and segments outside the floor are not drawn.
    if ok.len() >= 4 && field.u.len() >= 2 && field.v.len() >= 2 {
        let (nx, ny) = (field.u.len(), field.v.len());
        let mut grid = vec![f64::NAN; nx * ny];
        for &(i, j, _, v) in &ok {
            grid[j * nx + i] = v;
        }
        let filled: Vec<f64> = (0..nx * ny)
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
                    .map_or(vmin, |x| x.3)
            })
            .collect();
        let step = contour_step(vmax - vmin);
        let dec = decimals(step);
        let first = (vmin / step).ceil() * step;
        let levels: Vec<f64> = (0..)
            .map(|k| first + k as f64 * step)
            .take_while(|l| *l < vmax)
            .filter(|l| *l > vmin)
            .collect();
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
        let mut placed: Vec<(i32, i32, i32, i32)> = input
            .marks
            .iter()
            .map(|m| {
                let (px, py) = chart.backend_coord(&(m.uv.x, m.uv.y));
                (px - 10, py - 22, px + 30, py + 10)
            })
            .collect();
        if let Ok(lines) = builder.lines(&filled, &levels) {
            for line in lines {
                let level = line.threshold();
                let runs: Vec<Vec<(f64, f64)>> = line
                    .geometry()
                    .0
                    .iter()
                    .flat_map(|ls| runs_inside(&ls.0, &frame.floor_uv, grid_box.0, grid_box.1))
                    .collect();
                chart
                    .draw_series(
                        runs.iter()
                            .map(|r| PathElement::new(r.clone(), BLACK.mix(0.75).stroke_width(1))),
                    )
                    .map_err(e)?;
                // Label: along the longer runs first, at the first spot clear of earlier labels and marks.
                let label = format!("{level:.dec$}");
                let tw = 7 * label.len() as i32 + 6;
                let mut sorted: Vec<&Vec<(f64, f64)>> = runs.iter().collect();
                sorted.sort_by_key(|r| std::cmp::Reverse(r.len()));
                let spot = sorted
                    .iter()
                    .flat_map(|r| {
                        [0.5, 0.3, 0.7, 0.15, 0.85].map(|t| r[((r.len() - 1) as f64 * t) as usize])
                    })
                    .find_map(|at| {
                        let (px, py) = chart.backend_coord(&at);
                        let rect = (px - tw / 2 - 2, py - 10, px + tw / 2 + 2, py + 10);
                        let clear = placed.iter().all(|b: &(i32, i32, i32, i32)| {
                            rect.2 < b.0 || rect.0 > b.2 || rect.3 < b.1 || rect.1 > b.3
                        });
                        clear.then_some((px, py, rect))
                    });
                if let Some((px, py, rect)) = spot {
                    placed.push(rect);
                    root.draw(&Rectangle::new(
                        [(px - tw / 2, py - 8), (px + tw / 2, py + 8)],
                        WHITE.mix(0.85).filled(),
                    ))
                    .map_err(e)?;
                    root.draw(&Text::new(
                        label,
                        (px, py),
                        (FONT_FAMILY, 12)
                            .into_font()
                            .color(&BLACK)
                            .pos(Pos::new(HPos::Center, VPos::Center)),
                    ))
                    .map_err(e)?;
                }
            }
        }
    }

    // Room outline.
    let mut outline: Vec<(f64, f64)> = frame.floor_uv.iter().map(|p| (p.x, p.y)).collect();
    if let Some(first) = outline.first().copied() {
        outline.push(first);
    }
    chart
        .draw_series(std::iter::once(PathElement::new(
            outline,
            BLACK.stroke_width(3),
        )))
        .map_err(e)?;

    // Features: on walls as bands along the wall, on floor and ceiling as outlines.
    let label_font = (FONT_FAMILY, 12).into_font().color(&RGBColor(20, 20, 20));
    for s in &input.scene.surfaces {
        for f in &s.features {
            let uv: Vec<(f64, f64)> = f
                .polygon
                .iter()
                .map(|p| frame.uv(p))
                .map(|q| (q.x, q.y))
                .collect();
            let colour = palette(norm(f.temperature.celsius()));
            let name = if f.label.is_empty() {
                f.id.clone()
            } else {
                f.label.clone()
            };
            let text = format!("{name} {:.1}°", f.temperature.celsius());
            match s.kind {
                SurfaceKind::Wall | SurfaceKind::Other => {
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
                    if let (Some(a), Some(b)) = (far(c), far(far(c).unwrap_or(c))) {
                        chart
                            .draw_series(std::iter::once(PathElement::new(
                                vec![a, b],
                                colour.stroke_width(7),
                            )))
                            .map_err(e)?;
                        chart
                            .draw_series(std::iter::once(PathElement::new(
                                vec![a, b],
                                BLACK.stroke_width(1),
                            )))
                            .map_err(e)?;
                        // Label just inside the room from the band's middle.
                        let mid = Point2::new((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
                        let centre = frame.floor_uv.iter().fold(Point2::origin(), |acc, p| {
                            acc + p.coords / frame.floor_uv.len() as f64
                        });
                        let inward = (centre - mid).try_normalize(1e-9).unwrap_or_default();
                        let at = mid + inward * (0.06 * (hi.x - lo.x).max(hi.y - lo.y));
                        let (px, py) = chart.backend_coord(&(at.x, at.y));
                        root.draw(&Text::new(
                            text,
                            (px, py),
                            label_font.clone().pos(Pos::new(HPos::Center, VPos::Center)),
                        ))
                        .map_err(e)?;
                    }
                }
                SurfaceKind::Ceiling | SurfaceKind::Floor => {
                    let mut ring = uv.clone();
                    ring.push(uv[0]);
                    let style = if s.kind == SurfaceKind::Ceiling {
                        colour.stroke_width(2)
                    } else {
                        colour.stroke_width(3)
                    };
                    chart
                        .draw_series(std::iter::once(PathElement::new(ring, style)))
                        .map_err(e)?;
                    let c = uv.iter().fold((0.0, 0.0), |a, p| {
                        (a.0 + p.0 / uv.len() as f64, a.1 + p.1 / uv.len() as f64)
                    });
                    let (px, py) = chart.backend_coord(&c);
                    let where_ = if s.kind == SurfaceKind::Ceiling {
                        " (ceiling)"
                    } else {
                        " (floor)"
                    };
                    root.draw(&Text::new(
                        format!("{text}{where_}"),
                        (px, py),
                        label_font.clone().pos(Pos::new(HPos::Center, VPos::Center)),
                    ))
                    .map_err(e)?;
                }
            }
        }
    }
    for o in &input.scene.occluders {
        let corners: Vec<Point2<f64>> = match &o.shape {
            OccluderShape::Box { min, max } => (0..8)
                .map(|k| {
                    let p = mrtmap_geometry::nalgebra::Point3::new(
                        if k & 1 == 0 { min.x } else { max.x },
                        if k & 2 == 0 { min.y } else { max.y },
                        if k & 4 == 0 { min.z } else { max.z },
                    );
                    frame.uv(&p)
                })
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
            .map_err(e)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [a, b],
                RGBColor(60, 60, 60).stroke_width(1),
            )))
            .map_err(e)?;
        let (px, py) = chart.backend_coord(&((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0));
        let name = if o.label.is_empty() {
            o.id.clone()
        } else {
            o.label.clone()
        };
        root.draw(&Text::new(
            name,
            (px, py),
            label_font.clone().pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(e)?;
    }

    // Marked points.
    for m in input.marks {
        let (px, py) = chart.backend_coord(&(m.uv.x, m.uv.y));
        root.draw(&Circle::new((px, py), 6, WHITE.filled()))
            .map_err(e)?;
        root.draw(&Circle::new((px, py), 6, BLACK.stroke_width(2)))
            .map_err(e)?;
        root.draw(&Text::new(
            m.name.clone(),
            (px + 9, py - 9),
            (FONT_FAMILY, 15)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(e)?;
    }

    // Colour bar.
    let (bw, bh) = bar_area.dim_in_pixel();
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
            .map_err(e)?;
    }
    bar_area
        .draw(&Rectangle::new(
            [(x0, y0), (x0 + 24, y0 + bar_h)],
            BLACK.stroke_width(1),
        ))
        .map_err(e)?;
    bar_area
        .draw(&Text::new(
            "°C",
            (x0, y0 - 26),
            (FONT_FAMILY, 15).into_font().color(&BLACK),
        ))
        .map_err(e)?;
    let step = contour_step(vmax - vmin);
    let dec = decimals(step).max(1);
    let first = (vmin / step).ceil() * step;
    let mut l = first;
    while l <= vmax + 1e-9 {
        let y = y0 + ((1.0 - norm(l)) * bar_h as f64).round() as i32;
        bar_area
            .draw(&PathElement::new(
                vec![(x0 + 24, y), (x0 + 30, y)],
                BLACK.stroke_width(1),
            ))
            .map_err(e)?;
        bar_area
            .draw(&Text::new(
                format!("{l:.dec$}"),
                (x0 + 34, y),
                (FONT_FAMILY, 12)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(e)?;
        l += step;
    }
    let _ = bw;
    root.present().map_err(e)?;
    Ok(())
}

/// The map as PNG bytes.
pub fn render_png(input: &MapInput<'_>) -> Result<Vec<u8>, ReportError> {
    let Layout { w, h } = layout(input.field);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw(&root, input).map_err(ReportError::Draw)?;
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
        draw(&root, input).map_err(ReportError::Draw)?;
    }
    Ok(s)
}
