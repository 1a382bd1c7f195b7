//! The HTML report: one self-contained file (images embedded) that opens in any browser.

use base64::Engine;
use mrtmap_radiation::PointRecord;
use serde::Serialize;

use crate::numbers::{fixed, signed, uncertainty, xyz};
use crate::tables::MapSummary;
use crate::validate::ValidationRow;

/// A map in the report.
pub struct ReportMap {
    /// Its PNG.
    pub png: Vec<u8>,
    /// Its summary.
    pub summary: MapSummary,
    /// The CSV's file name (relative to the report).
    pub csv: String,
}

/// The comparison with the truth of a simulated scan (the seed paper's table).
#[derive(Clone, Debug, Serialize)]
pub struct ComparisonRow {
    /// Point name.
    pub name: String,
    /// The exact truth (°C).
    pub truth_c: f64,
    /// What a simulated black globe reads back through the ISO formula (°C).
    pub globe_c: f64,
    /// Ours (°C).
    pub ours_c: f64,
    /// Ours − truth (K).
    pub diff_k: f64,
}

/// A table of label/value rows.
pub type KeyValues = Vec<(String, String)>;

/// Everything the report shows.
#[derive(Default)]
pub struct ReportData {
    /// Title.
    pub title: String,
    /// What was scanned (recording path).
    pub source: String,
    /// Maps, one per height.
    pub maps: Vec<ReportMap>,
    /// The paper's comparison (simulated scans).
    pub comparison: Vec<ComparisonRow>,
    /// Grid error against the truth: max |Δ| and RMSE (K), nodes compared.
    pub grid_error: Option<(f64, f64, usize)>,
    /// Validation against globe readings.
    pub validation: Vec<ValidationRow>,
    /// MRT at named points with their view factors.
    pub points: Vec<PointRecord>,
    /// Surfaces: id, kind, temperature, uncertainty, observed fraction, area.
    pub surfaces: Vec<[String; 8]>,
    /// Features: id, host, label (source, vote share), temperature, contrast, area.
    pub features: Vec<[String; 8]>,
    /// Furniture: id, label, size, temperature.
    pub furniture: Vec<[String; 4]>,
    /// Coverage and uncertainty.
    pub coverage: KeyValues,
    /// Each surface's coverage drawn: (caption, inline SVG) (see [`crate::coverage_svg`]).
    pub coverage_drawings: Vec<(String, String)>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Time per stage.
    pub timing: KeyValues,
    /// Parameters (pretty text).
    pub parameters: String,
    /// When, by which version and by which command the report was made.
    pub made: String,
    /// The room frame in words (where the origin is, which way x points).
    pub room_frame: String,
    /// The room's corners: number, x, y (m, room frame).
    pub corners: Vec<[String; 3]>,
    /// The room's walls: id, from corner, to corner, length (m).
    pub walls: Vec<[String; 4]>,
    /// A person's comfort: maps (title, PNG, CSV name).
    pub comfort_maps: Vec<(String, Vec<u8>, String)>,
    /// The person, the PMV model, category shares and the worst asymmetry.
    pub comfort: KeyValues,
    /// The person's values at the marked points: name, then one cell per column of
    /// `comfort_point_columns`.
    pub comfort_points: Vec<Vec<String>>,
    /// The columns of `comfort_points` after the name.
    pub comfort_point_columns: Vec<String>,
    /// What the temperatures rest on: the level, the self-calibration.
    pub level: KeyValues,
    /// Reference readings: label, reading, camera, residual, used.
    pub references: Vec<[String; 7]>,
    /// The room in 3D (see [`crate::view3d::view3d`]), when there is a scene to show.
    pub view3d: Option<crate::view3d::View3d>,
}

/// HTML-escapes text.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn table(out: &mut String, headers: &[&str], rows: &[Vec<String>]) {
    out.push_str("<table><thead><tr>");
    for h in headers {
        out.push_str(&format!("<th>{}</th>", esc(h)));
    }
    out.push_str("</tr></thead><tbody>");
    for r in rows {
        out.push_str("<tr>");
        for c in r {
            // Cells are pre-escaped, and may carry a marked-up value.
            out.push_str(&format!("<td>{c}</td>"));
        }
        out.push_str("</tr>");
    }
    out.push_str("</tbody></table>");
}

fn num(id: &str, v: f64, decimals: usize) -> String {
    format!("<span id=\"{}\">{v:.decimals$}</span>", esc(id))
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1100px;color:#222}\
h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}table{border-collapse:collapse;margin:.6em 0}\
td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right}th{background:#f3f3f3}td:first-child{text-align:left}\
.ok{color:#176d1a}.bad{color:#b00020}.warn{background:#fff4d6;padding:.4em .8em;border-left:4px solid #e0a800}\
img{max-width:100%;border:1px solid #ddd}table.kv td{text-align:left}pre{background:#f7f7f7;padding:.8em;overflow-x:auto}\
#view3d{width:100%;height:560px;display:block;border:1px solid #ddd;cursor:grab}#view3d-stage{position:relative}\
#view3d-labels{position:absolute;left:0;top:0;right:0;bottom:0;pointer-events:none;overflow:hidden}\
.view3d-label{position:absolute;font-size:12px;background:rgba(255,255,255,.85);padding:0 3px;border:1px solid #999;white-space:nowrap}\
#view3d-buttons button{margin:0 .3em .4em 0;padding:.25em .7em;border:1px solid #888;background:#fff;border-radius:3px;cursor:pointer}\
#view3d-buttons button.on{background:#2b5d8a;color:#fff}#view3d-bars{position:absolute;left:8px;top:8px;display:flex;flex-direction:column;gap:.4em;padding:.3em .6em;background:rgba(255,255,255,.85);border:1px solid #ccc;font-size:.9em;pointer-events:none}\
.view3d-gradient{height:12px;width:260px;border:1px solid #999}.view3d-ticks{display:flex;justify-content:space-between;width:260px;font-size:12px}\
body.view3d-full{max-width:none;margin:.5em}body.view3d-full>*:not(#view3d-section){display:none}body.view3d-full #view3d{height:calc(100vh - 150px)}";

/// The 3D view: canvas, layer buttons, colour bars, the data and the viewer.
fn view3d_section(o: &mut String, d: &ReportData) {
    let Some(view) = &d.view3d else {
        return;
    };
    let mut marks: Vec<crate::view3d::ViewMark> = d
        .points
        .iter()
        .map(|p| crate::view3d::ViewMark {
            text: format!(
                "{}: {} °C",
                p.name.as_deref().unwrap_or("point"),
                fixed(p.mrt_c, 2)
            ),
            xyz: p.xyz,
            kind: "point",
        })
        .collect();
    marks.extend(d.validation.iter().map(|v| crate::view3d::ViewMark {
        text: match &v.mrt_iso_c {
            Ok(t) => format!("globe {}: {} °C", v.globe.label, fixed(*t, 2)),
            Err(_) => format!("globe {}", v.globe.label),
        },
        xyz: v.globe.xyz,
        kind: "globe",
    }));
    let heights: Vec<f64> = d.maps.iter().map(|m| m.summary.height_m).collect();
    view3d_block(o, view, &marks, &heights);
}

/// The 3D view's section: buttons, canvas, colour bars, the data and the viewer (`heights`: the
/// maps' heights, a layer each).
fn view3d_block(
    o: &mut String,
    view: &crate::view3d::View3d,
    marks: &[crate::view3d::ViewMark],
    heights: &[f64],
) {
    let safe = |s: &str| s.replace("</", "<\\/");
    o.push_str("<section id=\"view3d-section\"><h2>The room in 3D</h2><div id=\"view3d-buttons\">");
    let mut buttons: Vec<(String, String)> = vec![
        ("surfaces".into(), "Surfaces".into()),
        ("features".into(), "Features".into()),
        ("furniture".into(), "Furniture".into()),
        ("cloud".into(), "Thermal cloud".into()),
    ];
    for (k, h) in heights.iter().enumerate() {
        buttons.push((format!("grid{k}"), format!("MRT at {h:.2} m")));
    }
    if view.1.sun {
        buttons.push(("sun".into(), "Sunlit patch".into()));
    }
    buttons.push(("marks".into(), "Points and globes".into()));
    for (layer, label) in buttons {
        o.push_str(&format!(
            "<button data-layer=\"{layer}\">{}</button>",
            esc(&label)
        ));
    }
    o.push_str(
        "<button id=\"view3d-fullscreen\">Full window</button></div>\
         <div id=\"view3d-stage\"><canvas id=\"view3d\"></canvas><div id=\"view3d-labels\"></div>\
         <div id=\"view3d-bars\"><div id=\"view3d-bar\"></div><div id=\"view3d-gridbar\"></div></div></div>\
         <p id=\"view3d-info\">Hover or click a surface to name it.</p>\
         <p><small>Left drag turns the room, right drag (or shift and drag) moves it, the wheel zooms. \
         Walls and ceiling facing you are left out, so you look in. The buttons show and hide each \
         layer; the thermal cloud is thinned for the report and drawn at the temperatures' corrected \
         level (level.json), on the surfaces' colour scale. Open <code>report.html#3d</code> for \
         the view alone.</small></p>",
    );
    o.push_str(&format!(
        "<script type=\"application/json\" id=\"view3d-data\">{}</script>\
         <script type=\"application/json\" id=\"view3d-marks\">{}</script><script>{}</script></section>",
        safe(&view.0),
        safe(&serde_json::to_string(&marks).unwrap_or_else(|_| "[]".into())),
        crate::view3d::VIEWER_JS
    ));
}

/// A page with the 3D view alone (the live page shows it in a frame): `marks` are drawn and named
/// as the report's points are; `heights` are the maps' heights.
pub fn view3d_page(
    view: &crate::view3d::View3d,
    marks: &[crate::view3d::ViewMark],
    heights: &[f64],
) -> String {
    let mut o = format!(
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>mrtmap: the room in 3D</title><style>{STYLE}</style></head><body class=\"view3d-full\">"
    );
    view3d_block(&mut o, view, marks, heights);
    o.push_str("</body></html>");
    o
}

fn map_section(o: &mut String, m: &ReportMap) {
    let b64 = base64::engine::general_purpose::STANDARD;
    let h = m.summary.height_m;
    let key = format!("{h:.2}");
    o.push_str(&format!(
        "<h2>Mean radiant temperature at {h:.2} m</h2><img alt=\"MRT map at {key} m\" src=\"data:image/png;base64,{}\">",
        b64.encode(&m.png)
    ));
    let Some(f) = &m.summary.field else {
        return;
    };
    o.push_str(&format!(
        "<p>{} nodes ({}×{} grid, {} m margin, {} view factors): min {} °C at {}, max {} °C at {}, mean {} °C; largest standard error {} K. Grid values: <code>{}</code>.</p>",
        f.nodes,
        m.summary.grid[0],
        m.summary.grid[1],
        m.summary.margin_m,
        esc(&m.summary.method),
        num(&format!("map-{key}-min"), f.min.mrt_c, 2),
        xyz(&f.min.xyz),
        num(&format!("map-{key}-max"), f.max.mrt_c, 2),
        xyz(&f.max.xyz),
        num(&format!("map-{key}-mean"), f.mean_c, 2),
        num(&format!("map-{key}-maxse"), f.max_std_error_k, 3),
        esc(&m.csv)
    ));
}

fn comparison_section(o: &mut String, d: &ReportData) {
    if d.comparison.is_empty() {
        return;
    }
    o.push_str("<h2>Against the truth (simulated scan)</h2><p>Reference: the exact MRT of the simulated room, and what a standard black globe (0.15 m, ε 0.95) in the room's air would read back through the ISO 7726 formula.</p>");
    let rows: Vec<Vec<String>> = d
        .comparison
        .iter()
        .map(|c| {
            vec![
                esc(&c.name),
                format!("{:.2}", c.truth_c),
                format!("{:.2}", c.globe_c),
                num(&format!("cmp-{}-ours", c.name), c.ours_c, 2),
                format!(
                    "<span class=\"{}\">{}</span>",
                    if c.diff_k.abs() <= 0.2 { "ok" } else { "bad" },
                    signed(c.diff_k, 2)
                ),
            ]
        })
        .collect();
    table(
        o,
        &[
            "point",
            "truth (°C)",
            "globe via ISO (°C)",
            "mrtmap (°C)",
            "mrtmap − truth (K)",
        ],
        &rows,
    );
    if let Some((max, rmse, n)) = d.grid_error {
        o.push_str(&format!(
            "<p>Over the grid ({n} nodes): max |Δ| {} K, RMSE {} K.</p>",
            num("grid-max-abs", max, 3),
            num("grid-rmse", rmse, 3)
        ));
    }
}

fn validation_row(r: &ValidationRow) -> Vec<String> {
    let f = |r: &Result<f64, mrtmap_physics::PhysicsError>| {
        r.as_ref()
            .map(|v| format!("{v:.2}"))
            .unwrap_or_else(|e| format!("— ({})", esc(&e.to_string())))
    };
    let yes = |b: Option<bool>| match b {
        Some(true) => "<span class=\"ok\">yes</span>".to_string(),
        Some(false) => "<span class=\"bad\">no</span>".to_string(),
        None => "—".to_string(),
    };
    vec![
        match &r.in_sun {
            Some(_) => format!("{} ({})", esc(&r.globe.label), crate::IN_SUN_NOTE),
            None => esc(&r.globe.label),
        },
        format!(
            "{:.2} / {:.2} / {:.2}",
            r.globe.tg_c, r.globe.ta_c, r.globe.va_m_s
        ),
        f(&r.mrt_iso_c),
        f(&r.mrt_mixed_c),
        r.ours_c
            .as_ref()
            .map(|(o, s)| format!("{o:.2} ± {}", uncertainty(*s, 2)))
            .unwrap_or_else(|e| esc(&e.to_string())),
        r.diff_iso_k.map_or("—".into(), |v| signed(v, 2)),
        r.diff_mixed_k.map_or("—".into(), |v| signed(v, 2)),
        yes(r.meets_required),
        yes(r.meets_desired),
    ]
}

fn validation_section(o: &mut String, d: &ReportData) {
    if d.validation.is_empty() {
        return;
    }
    o.push_str(
        "<h2>Validation against globe readings</h2><p>ISO 7726 requires ±2 K and desires ±0.2 K.</p>",
    );
    let rows: Vec<Vec<String>> = d.validation.iter().map(validation_row).collect();
    table(
        o,
        &[
            "location",
            "Tg / Ta (°C) / v (m/s)",
            "MRT ISO (°C)",
            "MRT mixed conv. (°C)",
            "mrtmap (°C)",
            "Δ ISO (K)",
            "Δ mixed (K)",
            "±2 K",
            "±0.2 K",
        ],
        &rows,
    );
}

fn points_section(o: &mut String, d: &ReportData) {
    if d.points.is_empty() {
        return;
    }
    o.push_str("<h2>Marked points: MRT and view factors</h2>");
    for p in &d.points {
        let name = p.name.clone().unwrap_or_default();
        o.push_str(&format!(
            "<h3>{} at {}: {} °C ± {} K</h3>",
            esc(&name),
            xyz(&p.xyz),
            num(&format!("point-{name}"), p.mrt_c, 2),
            uncertainty(p.std_error_k, 2)
        ));
        let rows: Vec<Vec<String>> = p
            .view_factors
            .iter()
            .filter(|v| v.view_factor > 0.0)
            .map(|v| {
                vec![
                    esc(&v.id),
                    esc(&v.label),
                    format!("{:.4}", v.view_factor),
                    format!("{:.2}", v.temperature_c),
                ]
            })
            .collect();
        table(o, &["surface / feature", "label", "F", "T (°C)"], &rows);
    }
}

/// A table of plain text cells (escaped here) under a heading, unless it has no rows.
fn plain_table<R: AsRef<[String]>>(o: &mut String, heading: &str, headers: &[&str], rows: &[R]) {
    if rows.is_empty() {
        return;
    }
    o.push_str(&format!("<h2>{heading}</h2>"));
    let rows: Vec<Vec<String>> = rows.iter().map(|r| r.as_ref().to_vec()).collect();
    plain_rows(o, headers, &rows);
}

/// A two-column what/value table whose values are text (left-aligned).
fn kv_table(o: &mut String, kv: &KeyValues) {
    if kv.is_empty() {
        return;
    }
    let mut t = String::new();
    plain_rows(&mut t, &["what", "value"], &key_value_rows(kv));
    o.push_str(&t.replacen("<table>", "<table class=\"kv\">", 1));
}

fn key_value_rows(kv: &KeyValues) -> Vec<Vec<String>> {
    kv.iter().map(|(k, v)| vec![k.clone(), v.clone()]).collect()
}

/// A person's comfort: what was assumed, how much of the floor is in each ISO 7730 category,
/// the worst asymmetry, the values at the marked points, and one map per quantity.
fn comfort_section(o: &mut String, d: &ReportData) {
    if d.comfort.is_empty() && d.comfort_maps.is_empty() {
        return;
    }
    o.push_str("<h2>Comfort of a person</h2>");
    kv_table(o, &d.comfort);
    if !d.comfort_points.is_empty() {
        let mut headers = vec!["point"];
        headers.extend(d.comfort_point_columns.iter().map(String::as_str));
        plain_rows(o, &headers, &d.comfort_points);
    }
    let b64 = base64::engine::general_purpose::STANDARD;
    for (title, png, csv) in &d.comfort_maps {
        o.push_str(&format!(
            "<h3>{}</h3><img alt=\"{}\" src=\"data:image/png;base64,{}\"><p>Grid values: <code>{}</code>.</p>",
            esc(title),
            esc(title),
            b64.encode(png),
            esc(csv)
        ));
    }
}

/// What the temperatures rest on: the absolute level (references or the camera's), the reference
/// readings with their residuals, and the frames' self-calibration.
fn level_section(o: &mut String, d: &ReportData) {
    if d.level.is_empty() {
        return;
    }
    o.push_str("<h2>What the temperatures rest on</h2>");
    kv_table(o, &d.level);
    let refs: Vec<Vec<String>> = d.references.iter().map(|r| r.to_vec()).collect();
    plain_rows(
        o,
        &[
            "reference",
            "reading: surface T (°C)",
            "ε",
            "the camera should read: radiant T (°C)",
            "camera (°C)",
            "corrected − should read (K)",
            "used",
        ],
        &refs,
    );
}

/// Where the coordinates are measured from: the room frame, its corners and walls.
fn room_section(o: &mut String, d: &ReportData) {
    if d.room_frame.is_empty() {
        return;
    }
    o.push_str(&format!(
        "<h2>Room coordinates</h2><p>{}</p>",
        esc(&d.room_frame)
    ));
    let corners: Vec<Vec<String>> = d.corners.iter().map(|r| r.to_vec()).collect();
    plain_rows(o, &["corner", "x (m)", "y (m)"], &corners);
    let walls: Vec<Vec<String>> = d.walls.iter().map(|r| r.to_vec()).collect();
    plain_rows(
        o,
        &["wall", "from corner", "to corner", "length (m)"],
        &walls,
    );
}

/// A table of plain text cells (escaped here), unless it has no rows.
fn plain_rows(o: &mut String, headers: &[&str], rows: &[Vec<String>]) {
    if rows.is_empty() {
        return;
    }
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|c| esc(c)).collect())
        .collect();
    table(o, headers, &cells);
}

/// The report as one HTML document.
pub fn render_html(d: &ReportData) -> String {
    let mut o = String::with_capacity(1 << 20);
    o.push_str(&format!(
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body><h1>{}</h1><p>Source: <code>{}</code></p>",
        esc(&d.title),
        esc(&d.title),
        esc(&d.source)
    ));
    if !d.made.is_empty() {
        o.push_str(&format!("<p class=\"made\">Made {}</p>", esc(&d.made)));
    }
    if !d.warnings.is_empty() {
        o.push_str("<h2>Warnings</h2>");
        for w in &d.warnings {
            o.push_str(&format!("<p class=\"warn\">{}</p>", esc(w)));
        }
    }
    room_section(&mut o, d);
    level_section(&mut o, d);
    for m in &d.maps {
        map_section(&mut o, m);
    }
    view3d_section(&mut o, d);
    comfort_section(&mut o, d);
    comparison_section(&mut o, d);
    validation_section(&mut o, d);
    points_section(&mut o, d);
    if !d.surfaces.is_empty() {
        o.push_str(
            "<p><small>Radiant T is what the thermal camera reads (set to ε = 1): the radiation leaving the \
             surface, emitted and reflected, which is what a person exchanges radiation with and what every MRT \
             here uses. Surface T is the surface's own temperature, what a contact thermometer reads (judge \
             condensation or down-draught by it): the radiant T less what the surface reflects, from its \
             emissivity ε and the irradiance the rest of the room gives it; its ± includes ε's.</small></p>",
        );
    }
    plain_table(
        &mut o,
        "Surfaces",
        &[
            "id",
            "kind",
            "radiant T (°C)",
            "± (K)",
            "ε",
            "surface T (°C, ± K)",
            "seen (by thermal texturing only; unseen)",
            "area (m²)",
        ],
        &d.surfaces,
    );
    plain_table(
        &mut o,
        "Features",
        &[
            "id",
            "on",
            "label",
            "radiant T (°C)",
            "ε",
            "surface T (°C, ± K)",
            "contrast (K)",
            "area (m²)",
        ],
        &d.features,
    );
    plain_table(
        &mut o,
        "Furniture (blocks part of the view)",
        &["id", "label", "size (m)", "T (°C)"],
        &d.furniture,
    );
    plain_table(
        &mut o,
        "Coverage and uncertainty",
        &["what", "value"],
        &key_value_rows(&d.coverage),
    );
    if !d.coverage_drawings.is_empty() {
        o.push_str(
            "<h3>What the scan saw of each surface</h3><p><small>Each surface's 15 cm texels as seen \
             facing it (walls upright): <span style=\"color:#5a8f3a\">■</span> seen, \
             <span style=\"color:#999\">■</span> filled in from the texels seen around it (next to a feature or an \
             edge, where blur is left out, or behind furniture), <span style=\"color:#d62728\">■</span> never seen (an \
             unseen patch: part of every MRT's ±).</small></p><div class=\"coverage\">",
        );
        for (caption, svg) in &d.coverage_drawings {
            o.push_str(&format!(
                "<figure style=\"display:inline-block;margin:4px 12px\">{svg}<figcaption>{}</figcaption></figure>",
                esc(caption)
            ));
        }
        o.push_str("</div>");
    }
    plain_table(
        &mut o,
        "Time per stage",
        &["stage", "seconds"],
        &key_value_rows(&d.timing),
    );
    if !d.parameters.is_empty() {
        o.push_str(&format!(
            "<h2>Parameters</h2><pre>{}</pre>",
            esc(&d.parameters)
        ));
    }
    o.push_str(&format!(
        "<p><small>Generated by mrtmap {}.</small></p></body></html>\n",
        env!("CARGO_PKG_VERSION")
    ));
    o
}
