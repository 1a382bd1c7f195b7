//! Radiance scene description (`.rad`): each surface, feature and furniture face as `polygon`s with
//! a material of its own. A scan measures temperatures, not reflectances, so the materials are
//! the usual defaults by kind (grey `plastic`: floor 0.2, walls 0.5, ceiling 0.8, furniture 0.35;
//! windows `glass` of transmissivity 0.88, i.e. 96 % transmittance); edit them for a daylight
//! study. Each object's measured temperature is in a comment above it. A surface with features is
//! written as the triangles of its outline with the features cut out, so no two polygons overlap;
//! polygons are wound counter-clockwise seen from inside the room (their normals face the room).

use std::fmt::Write;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_radiation::RadiantScene;
use mrtmap_report::mesh::{
    MeshPart, PartRole, oriented, outline_triangles, outward_normal, scene_mesh,
};

use crate::{Identifiers, is_glazing, num};

fn reflectance(p: &MeshPart) -> f64 {
    match (p.role, p.detail.as_str()) {
        (PartRole::Furniture, _) => 0.35,
        (PartRole::Surface, "floor") => 0.2,
        (PartRole::Surface, "ceiling") => 0.8,
        _ => 0.5,
    }
}

fn polygon(o: &mut String, material: &str, id: &str, p: &[Point3<f64>]) {
    let _ = writeln!(o, "{material} polygon {id}\n0\n0\n{}", 3 * p.len());
    for q in p {
        let _ = writeln!(o, "  {} {} {}", num(q.x, 6), num(q.y, 6), num(q.z, 6));
    }
    o.push('\n');
}

/// `text` on one line: a line break in a label would end the comment and leave the rest of the
/// label where Radiance reads primitives.
fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The comment above an object: its id, what it is, its radiant temperature, ± and area, and its
/// emissivity and surface temperature where the scene gives one.
fn comment(p: &MeshPart) -> String {
    let mut what = format!("# {} ({}", one_line(&p.id), p.role.as_str());
    if !p.label.is_empty() {
        let _ = write!(what, ", {}", one_line(&p.label));
    }
    let _ = write!(what, "): {} °C", num(p.temperature_c, 2));
    if let Some(s) = p.temperature_std_k {
        let _ = write!(what, " ± {} K", num(s, 2));
    }
    if let Some((t, s)) = p.surface_temperature {
        let _ = write!(
            what,
            " radiant; emissivity {}, surface {} °C ± {} K",
            num(p.emissivity, 2),
            num(t, 2),
            num(s, 2)
        );
    }
    let _ = writeln!(what, ", {} m²", num(p.area_m2, 3));
    what
}

/// The scene as Radiance primitives, named after `name` in the header.
pub fn write(scene: &RadiantScene, name: &str) -> String {
    let mut ids = Identifiers::default();
    let mut o = format!(
        "# {}: a room measured by mrtmap ({} surfaces, {} furniture); metres, the scene's frame (z up)\n\
         # materials are default reflectances by kind (a scan measures temperatures, not reflectances)\n\n",
        one_line(name),
        scene.surfaces.len(),
        scene.occluders.len()
    );
    for p in scene_mesh(scene) {
        let id = ids.make(&p.id);
        let material = format!("{id}_mat");
        o.push_str(&comment(&p));
        if p.role == PartRole::Feature && is_glazing(&p.label) {
            let _ = writeln!(o, "void glass {material}\n0\n0\n3 0.88 0.88 0.88\n");
        } else {
            let r = num(reflectance(&p), 3);
            let _ = writeln!(o, "void plastic {material}\n0\n0\n5 {r} {r} {r} 0 0\n");
        }
        let surface = scene.surfaces.iter().find(|s| s.id == p.id);
        match surface.filter(|_| p.role == PartRole::Surface) {
            // The outline, facing the room; with features, its triangles around them.
            Some(s) => {
                let inward = -outward_normal(scene, s);
                if s.features.is_empty() {
                    polygon(&mut o, &material, &id, &oriented(&s.polygon, &inward));
                    continue;
                }
                let (pts, tris) = outline_triangles(s);
                for (k, t) in tris.iter().enumerate() {
                    let tri = [pts[t[0]], pts[t[1]], pts[t[2]]];
                    polygon(
                        &mut o,
                        &material,
                        &format!("{id}.{k}"),
                        &oriented(&tri, &inward),
                    );
                }
            }
            // Features and furniture as the mesh has them (features facing the room).
            None => {
                for (k, t) in p.triangles.iter().enumerate() {
                    let v = |i: u32| Point3::from(p.positions[i as usize]);
                    let tri = if p.role == PartRole::Feature {
                        [v(t[0]), v(t[2]), v(t[1])]
                    } else {
                        [v(t[0]), v(t[1]), v(t[2])]
                    };
                    polygon(&mut o, &material, &format!("{id}.{k}"), &tri);
                }
            }
        }
    }
    o
}
