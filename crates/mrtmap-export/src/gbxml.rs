//! gbXML 6.01 (the newest schema a package registry ships, `xgbxml` on PyPI): a Campus with one
//! Building and one Space, the scene's surfaces as Surfaces (walls with an opening
//! `ExteriorWall`, other walls `InteriorWall`, `InteriorFloor`, `Ceiling`), windows and doors as
//! Openings, one Construction per surface kind (the schema requires one; a scan knows no layers).
//!
//! The schema has no place for a measured surface temperature and refuses attributes it does not
//! declare, so the measurements go in each Surface's and Opening's `Description`, as one line of
//! `key=value` pairs separated by `; ` after the word `mrtmap:`:
//! `mrtmap: temperature_c=18.8; temperature_std_k=0.1; emissivity=1; observed_fraction=0.72;
//! label=exterior wall`; a surface's features that are not openings (lights, paintings) follow as
//! `feature=ID|LABEL|TEMPERATURE_C|AREA_M2`. The Space's Description carries the level's ±.
//! Polygons are wound counter-clockwise seen from outside, as gbXML asks.

use std::fmt::Write;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_geometry::polygon::area_3d;
use mrtmap_radiation::{RadiantScene, Surface, SurfaceKind};
use mrtmap_report::mesh::{oriented, outward_normal};

use crate::{Identifiers, Opening, num, opening};

/// Escapes text for XML content and attribute values.
pub fn xml_escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c if (c as u32) < 0x20 && !matches!(c, '\n' | '\t' | '\r') => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

fn poly_loop(out: &mut String, indent: &str, p: &[Point3<f64>]) {
    let _ = writeln!(out, "{indent}<PlanarGeometry>");
    let _ = writeln!(out, "{indent}  <PolyLoop>");
    for q in p {
        let _ = writeln!(
            out,
            "{indent}    <CartesianPoint><Coordinate>{}</Coordinate><Coordinate>{}</Coordinate><Coordinate>{}</Coordinate></CartesianPoint>",
            num(q.x, 6),
            num(q.y, 6),
            num(q.z, 6)
        );
    }
    let _ = writeln!(out, "{indent}  </PolyLoop>");
    let _ = writeln!(out, "{indent}</PlanarGeometry>");
}

fn describe(
    t_c: f64,
    std_k: Option<f64>,
    emissivity: f64,
    surface: Option<(f64, f64)>,
    label: &str,
) -> String {
    let mut d = format!("mrtmap: temperature_c={}", num(t_c, 3));
    if let Some(s) = std_k {
        let _ = write!(d, "; temperature_std_k={}", num(s, 3));
    }
    let _ = write!(d, "; emissivity={}", num(emissivity, 3));
    if let Some((t, s)) = surface {
        let _ = write!(
            d,
            "; surface_temperature_c={}; surface_temperature_std_k={}",
            num(t, 3),
            num(s, 3)
        );
    }
    let _ = write!(d, "; label={}", label.replace(';', ","));
    d
}

/// The room's volume (m³) from its surfaces wound outward (divergence theorem); a scene that is not
/// closed gives a meaningless number.
pub fn room_volume(scene: &RadiantScene) -> f64 {
    // The divergence theorem needs a closed room: one without a floor or a ceiling (an open scene
    // file) is taken as the prism of its floor outline up to its highest point instead (the
    // theorem gave 27.2 m³ for the example office without its ceiling, which holds 40.8).
    let has = |k: SurfaceKind| scene.surfaces.iter().any(|s| s.kind == k);
    if !(has(SurfaceKind::Floor) && has(SurfaceKind::Ceiling)) {
        return mrtmap_radiation::RoomBounds::of_scene(scene).map_or(0.0, |b| {
            mrtmap_geometry::polygon::signed_area(&b.frame.floor_uv).abs() * b.ceiling_m
        });
    }
    scene
        .surfaces
        .iter()
        .map(|s| {
            let p = oriented(&s.polygon, &outward_normal(scene, s));
            let n = mrtmap_geometry::polygon::newell_normal(&p);
            let a = 0.5 * n.norm();
            let c = mrtmap_geometry::polygon::centroid(&p);
            if a > 0.0 {
                c.coords.dot(&(n / n.norm())) * a / 3.0
            } else {
                0.0
            }
        })
        .sum()
}

/// The floor's area (m²): the surfaces of kind floor.
pub fn floor_area(scene: &RadiantScene) -> f64 {
    scene
        .surfaces
        .iter()
        .filter(|s| s.kind == SurfaceKind::Floor)
        .map(|s| area_3d(&s.polygon))
        .sum()
}

/// One surface as a gbXML Surface in `space`, with its windows and doors as Openings and its other
/// features in its Description.
fn surface_xml(
    o: &mut String,
    scene: &RadiantScene,
    s: &Surface,
    ids: &mut Identifiers,
    space: &str,
) {
    let out = outward_normal(scene, s);
    let ty = match s.kind {
        SurfaceKind::Floor => "InteriorFloor",
        SurfaceKind::Ceiling => "Ceiling",
        _ if s.features.iter().any(|f| opening(&f.label).is_some()) => "ExteriorWall",
        _ => "InteriorWall",
    };
    let mut d = describe(
        s.temperature.celsius(),
        s.temperature_std_k,
        s.emissivity,
        s.surface_temperature.map(|(t, e)| (t.celsius(), e)),
        &s.label,
    );
    if let Some(f) = s.observed_fraction {
        let _ = write!(d, "; observed_fraction={}", num(f, 3));
    }
    for f in s.features.iter().filter(|f| opening(&f.label).is_none()) {
        let _ = write!(
            d,
            "; feature={}|{}|{}|{}",
            f.id.replace([';', '|'], "_"),
            f.label.replace([';', '|'], "_"),
            num(f.temperature.celsius(), 3),
            num(area_3d(&f.polygon), 4)
        );
    }
    let _ = writeln!(
        o,
        "    <Surface id=\"{}\" surfaceType=\"{ty}\" constructionIdRef=\"mrtmap-{}\">",
        ids.make(&s.id),
        s.kind.as_str()
    );
    let _ = writeln!(o, "      <Name>{}</Name>", xml_escape(&s.id));
    let _ = writeln!(o, "      <Description>{}</Description>", xml_escape(&d));
    let _ = writeln!(o, "      <AdjacentSpaceId spaceIdRef=\"{space}\"/>");
    poly_loop(o, "      ", &oriented(&s.polygon, &out));
    for f in &s.features {
        let kind = match opening(&f.label) {
            None => continue,
            Some(Opening::Door) => "NonSlidingDoor",
            Some(Opening::Window) if s.kind == SurfaceKind::Ceiling => "FixedSkylight",
            Some(Opening::Window) => "FixedWindow",
        };
        let _ = writeln!(
            o,
            "      <Opening id=\"{}\" openingType=\"{kind}\">",
            ids.make(&f.id)
        );
        let _ = writeln!(o, "        <Name>{}</Name>", xml_escape(&f.id));
        let _ = writeln!(
            o,
            "        <Description>{}</Description>",
            xml_escape(&describe(
                f.temperature.celsius(),
                f.temperature_std_k,
                f.emissivity,
                f.surface_temperature.map(|(t, e)| (t.celsius(), e)),
                &f.label
            ))
        );
        poly_loop(o, "        ", &oriented(&f.polygon, &out));
        let _ = writeln!(o, "      </Opening>");
    }
    let _ = writeln!(o, "    </Surface>");
}

/// The scene as a gbXML 6.01 document named `name`, in metres and °C.
pub fn write(scene: &RadiantScene, name: &str) -> String {
    let mut ids = Identifiers::default();
    for k in ["floor", "ceiling", "wall", "other"] {
        ids.make(&format!("mrtmap-{k}"));
    }
    let campus = ids.make("campus");
    let building = ids.make("building");
    let space = ids.make(&format!("{name}_space"));
    let floor_m2 = floor_area(scene);
    let mut o = String::new();
    o.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    o.push_str(
        "<gbXML xmlns=\"http://www.gbxml.org/schema\" version=\"6.01\" useSIUnitsForResults=\"true\" \
         temperatureUnit=\"C\" lengthUnit=\"Meters\" areaUnit=\"SquareMeters\" volumeUnit=\"CubicMeters\">\n",
    );
    let _ = writeln!(o, "  <Campus id=\"{campus}\">");
    let _ = writeln!(o, "    <Name>{}</Name>", xml_escape(name));
    let _ = writeln!(
        o,
        "    <Building id=\"{building}\" buildingType=\"Office\">"
    );
    let _ = writeln!(o, "      <Name>{}</Name>", xml_escape(name));
    let _ = writeln!(o, "      <Area>{}</Area>", num(floor_m2, 4));
    let _ = writeln!(o, "      <Space id=\"{space}\">");
    let _ = writeln!(o, "        <Name>{}</Name>", xml_escape(name));
    let _ = writeln!(
        o,
        "        <Description>mrtmap: measured room; temperature_level_std_k={}; furniture={}</Description>",
        num(scene.temperature_level_std_k, 3),
        scene.occluders.len()
    );
    let _ = writeln!(o, "        <Area>{}</Area>", num(floor_m2, 4));
    let _ = writeln!(o, "        <Volume>{}</Volume>", num(room_volume(scene), 4));
    let _ = writeln!(o, "      </Space>");
    let _ = writeln!(o, "    </Building>");
    for s in &scene.surfaces {
        surface_xml(&mut o, scene, s, &mut ids, &space);
    }
    let _ = writeln!(o, "  </Campus>");
    let mut kinds: Vec<&str> = scene.surfaces.iter().map(|s| s.kind.as_str()).collect();
    kinds.sort_unstable();
    kinds.dedup();
    for k in kinds {
        let _ = writeln!(
            o,
            "  <Construction id=\"mrtmap-{k}\"><Name>{k} as scanned (layers unknown)</Name></Construction>"
        );
    }
    o.push_str("</gbXML>\n");
    o
}
