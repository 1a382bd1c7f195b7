//! `[emissivity]`: the surfaces' long-wave emissivities, overriding the table's by label or id.

use mrtmap_radiation::RadiantScene;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// `[emissivity]`: the surfaces' long-wave emissivities, where the table's by label are not wanted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmissivitySection {
    /// The standard uncertainty of each emissivity.
    pub std: f64,
    /// Emissivity of elements whose label contains the key (case-insensitive; the longest key
    /// that matches wins).
    pub by_label: std::collections::BTreeMap<String, f64>,
    /// Emissivity of one surface or feature, by id.
    pub by_id: std::collections::BTreeMap<String, f64>,
}

impl Default for EmissivitySection {
    fn default() -> Self {
        Self {
            std: mrtmap_radiation::grey::EMISSIVITY_STD,
            by_label: Default::default(),
            by_id: Default::default(),
        }
    }
}

impl EmissivitySection {
    /// Every value is an emissivity (0 < ε ≤ 1), the standard uncertainty within 0…0.5.
    pub fn check(&self) -> Result<()> {
        if !(self.std.is_finite() && (0.0..=0.5).contains(&self.std)) {
            return Err(Error::setting(
                format!("[emissivity] std = {}", self.std),
                "must be between 0 and 0.5",
            ));
        }
        for (table, map) in [("by_label", &self.by_label), ("by_id", &self.by_id)] {
            if let Some((k, v)) = map.iter().find(|(_, v)| !(**v > 0.0 && **v <= 1.0)) {
                return Err(Error::setting(
                    format!("[emissivity] {table}.{k} = {v}"),
                    "is not an emissivity: give a value above 0 and at most 1",
                ));
            }
        }
        Ok(())
    }

    /// The emissivity of the element `id` labelled `label` (of kind `kind` for a surface).
    pub fn of(&self, id: &str, label: &str, kind: Option<mrtmap_radiation::SurfaceKind>) -> f64 {
        if let Some(e) = self.by_id.get(id) {
            return *e;
        }
        let l = label.to_lowercase();
        self.by_label
            .iter()
            .filter(|(k, _)| l.contains(&k.to_lowercase()))
            .max_by_key(|(k, _)| k.len())
            .map_or_else(
                || mrtmap_radiation::grey::default_emissivity(label, kind),
                |(_, e)| *e,
            )
    }

    /// The first element of `scene` that one of this section's entries names (by id or label)
    /// whose emissivity in the scene is another: (its id, the scene's, this section's). The
    /// emissivities are applied when the room is segmented, where the camera's radiant
    /// temperatures become surface temperatures; a scene segmented without them cannot take them
    /// afterwards.
    pub fn disagrees_with(&self, scene: &RadiantScene) -> Option<(String, f64, f64)> {
        let named = |id: &str, label: &str| {
            let l = label.to_lowercase();
            self.by_id.contains_key(id)
                || self.by_label.keys().any(|k| l.contains(&k.to_lowercase()))
        };
        let mut elements: Vec<(&str, &str, Option<mrtmap_radiation::SurfaceKind>, f64)> =
            Vec::new();
        for s in &scene.surfaces {
            elements.push((&s.id, &s.label, Some(s.kind), s.emissivity));
            for f in &s.features {
                elements.push((&f.id, &f.label, None, f.emissivity));
            }
        }
        for o in &scene.occluders {
            elements.push((&o.id, &o.label, None, o.emissivity));
        }
        elements.into_iter().find_map(|(id, label, kind, e)| {
            let want = self.of(id, label, kind);
            (named(id, label) && (want - e).abs() > 1e-9).then(|| (id.to_string(), e, want))
        })
    }

    /// Sets every surface's, feature's and occluder's emissivity in `scene` and marks its
    /// temperatures as radiant (what the camera read). Returns the entries that matched nothing
    /// in the scene (`by_id.window-99`, `by_label.windw`), for a warning: a misspelt one changed
    /// nothing without a word.
    pub fn apply(&self, scene: &mut RadiantScene) -> Vec<String> {
        let mut elements: Vec<(String, String)> = Vec::new();
        for s in &mut scene.surfaces {
            s.emissivity = self.of(&s.id, &s.label, Some(s.kind));
            elements.push((s.id.clone(), s.label.to_lowercase()));
            for f in &mut s.features {
                f.emissivity = self.of(&f.id, &f.label, None);
                elements.push((f.id.clone(), f.label.to_lowercase()));
            }
        }
        for o in &mut scene.occluders {
            o.emissivity = self.of(&o.id, &o.label, None);
            elements.push((o.id.clone(), o.label.to_lowercase()));
        }
        scene.temperatures = Some(mrtmap_radiation::TemperatureKind::Radiant);
        let ids = self
            .by_id
            .keys()
            .filter(|k| !elements.iter().any(|(id, _)| id == *k))
            .map(|k| format!("by_id.{k}"));
        let labels = self
            .by_label
            .keys()
            .filter(|k| !elements.iter().any(|(_, l)| l.contains(&k.to_lowercase())))
            .map(|k| format!("by_label.{k}"));
        ids.chain(labels).collect()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Entries that match nothing are returned for a warning (a misspelt id or label changed
    /// nothing without a word); those that match are used and not returned.
    #[test]
    fn entries_matching_nothing_are_named() {
        let mut scene = mrtmap_radiation::example_office();
        let window = scene
            .surfaces
            .iter()
            .flat_map(|s| &s.features)
            .find(|f| f.label.to_lowercase().contains("window"))
            .map(|f| f.id.clone())
            .unwrap();
        let mut e = EmissivitySection::default();
        e.by_id.insert(window.clone(), 0.5);
        e.by_id.insert("window-99".into(), 0.9);
        e.by_label.insert("windw".into(), 0.5);
        e.by_label.insert("Wall".into(), 0.92);
        let unmatched = e.apply(&mut scene);
        assert_eq!(unmatched, vec!["by_id.window-99", "by_label.windw"]);
        let w = scene
            .surfaces
            .iter()
            .flat_map(|s| &s.features)
            .find(|f| f.id == window);
        assert_eq!(w.unwrap().emissivity, 0.5);
    }
}
