//! What an element of a room is, from its label: the one vocabulary that the emissivities, the
//! sun, the exports, the simulator and the advice read.
//!
//! A label is free text (a detector's word, a person's); [`ElementKind::of_label`] turns it into a
//! kind by the first alias of [`LABEL_ALIASES`] that the label contains, in the table's order
//! (any case). Longer phrases come first, so that "roof light" is glazing and not a light, and
//! "glass door" is a glazed door and not a plain one. Nothing else in mrtmap compares label text:
//! every decision that depends on what an element is goes through this table.

use serde::{Deserialize, Serialize};

/// Which glazing an element is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GlazingKind {
    /// A window in a wall (also plain "glazing", "glass").
    Window,
    /// A skylight, roof light or roof window in a ceiling or roof.
    Skylight,
    /// A glazed (glass) door or French window.
    Door,
    /// A curtain wall or glass wall.
    CurtainWall,
}

/// What an element of a room is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementKind {
    /// Glazing: the sun and the sky come through it (SolarCal's f_svv and f_bes), its emissivity
    /// is glass's, a depth camera's near-infrared passes through it, and the exports make it an
    /// aperture.
    Glazing(GlazingKind),
    /// A mirror: glass in the long-wave, opaque to the sun.
    Mirror,
    /// A radiator, heater or convector.
    Radiator,
    /// A radiant (heating or cooling) panel.
    RadiantPanel,
    /// A light fitting.
    Light,
    /// A painting or picture.
    Painting,
    /// An opaque door.
    Door,
    /// A desk.
    Desk,
    /// None of the above.
    Other,
}

/// The label segmentation gives a feature that neither a rule nor a mask names.
pub const UNLABELLED: &str = "unlabelled";

/// Whether a label says nothing of what its element is (blank, or [`UNLABELLED`]).
pub fn says_nothing(label: &str) -> bool {
    let t = label.trim();
    t.is_empty() || t.eq_ignore_ascii_case(UNLABELLED)
}

/// The aliases of each kind, looked for in a label (lower case) in this order: the first one the
/// label contains decides.
pub const LABEL_ALIASES: &[(&str, ElementKind)] = &[
    ("mirror", ElementKind::Mirror),
    ("glazed door", ElementKind::Glazing(GlazingKind::Door)),
    ("glass door", ElementKind::Glazing(GlazingKind::Door)),
    ("french window", ElementKind::Glazing(GlazingKind::Door)),
    ("patio door", ElementKind::Glazing(GlazingKind::Door)),
    ("skylight", ElementKind::Glazing(GlazingKind::Skylight)),
    ("sky light", ElementKind::Glazing(GlazingKind::Skylight)),
    ("roof light", ElementKind::Glazing(GlazingKind::Skylight)),
    ("rooflight", ElementKind::Glazing(GlazingKind::Skylight)),
    ("roof window", ElementKind::Glazing(GlazingKind::Skylight)),
    ("roof glazing", ElementKind::Glazing(GlazingKind::Skylight)),
    ("lantern light", ElementKind::Glazing(GlazingKind::Skylight)),
    (
        "curtain wall",
        ElementKind::Glazing(GlazingKind::CurtainWall),
    ),
    ("glass wall", ElementKind::Glazing(GlazingKind::CurtainWall)),
    ("window", ElementKind::Glazing(GlazingKind::Window)),
    ("glazing", ElementKind::Glazing(GlazingKind::Window)),
    ("glazed", ElementKind::Glazing(GlazingKind::Window)),
    ("glass", ElementKind::Glazing(GlazingKind::Window)),
    ("radiant panel", ElementKind::RadiantPanel),
    ("radiator", ElementKind::Radiator),
    ("heater", ElementKind::Radiator),
    ("convector", ElementKind::Radiator),
    ("panel", ElementKind::RadiantPanel),
    ("light", ElementKind::Light),
    ("lamp", ElementKind::Light),
    ("luminaire", ElementKind::Light),
    ("painting", ElementKind::Painting),
    ("picture", ElementKind::Painting),
    ("door", ElementKind::Door),
    ("desk", ElementKind::Desk),
];

impl ElementKind {
    /// The kind a label names (any case); [`ElementKind::Other`] when it names none.
    pub fn of_label(label: &str) -> Self {
        let l = label.to_lowercase();
        LABEL_ALIASES
            .iter()
            .find(|(alias, _)| l.contains(alias))
            .map_or(Self::Other, |(_, k)| *k)
    }

    /// Glazing the sun comes through.
    pub fn is_glazing(self) -> bool {
        matches!(self, Self::Glazing(_))
    }

    /// Glass in the long-wave (glazing or a mirror): its emissivity is glass's, and a depth
    /// camera's near-infrared passes through it or is mirrored.
    pub fn is_glass(self) -> bool {
        matches!(self, Self::Glazing(_) | Self::Mirror)
    }

    /// A door, glazed or not.
    pub fn is_door(self) -> bool {
        matches!(self, Self::Door | Self::Glazing(GlazingKind::Door))
    }

    /// Its name in files and messages ("window", "skylight", "glazed door", …).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Glazing(GlazingKind::Window) => "window",
            Self::Glazing(GlazingKind::Skylight) => "skylight",
            Self::Glazing(GlazingKind::Door) => "glazed door",
            Self::Glazing(GlazingKind::CurtainWall) => "curtain wall",
            Self::Mirror => "mirror",
            Self::Radiator => "radiator",
            Self::RadiantPanel => "radiant panel",
            Self::Light => "light",
            Self::Painting => "painting",
            Self::Door => "door",
            Self::Desk => "desk",
            Self::Other => "other",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_their_kinds() {
        use ElementKind as K;
        use GlazingKind as G;
        for (label, kind) in [
            ("window", K::Glazing(G::Window)),
            ("Window-1", K::Glazing(G::Window)),
            ("skylight", K::Glazing(G::Skylight)),
            ("Roof Light", K::Glazing(G::Skylight)),
            ("roof window", K::Glazing(G::Skylight)),
            ("glazed door", K::Glazing(G::Door)),
            ("glass door", K::Glazing(G::Door)),
            ("curtain wall", K::Glazing(G::CurtainWall)),
            ("glazing", K::Glazing(G::Window)),
            ("mirror", K::Mirror),
            ("radiator", K::Radiator),
            ("radiant panel", K::RadiantPanel),
            ("recessed light", K::Light),
            ("painting", K::Painting),
            ("door", K::Door),
            ("desk", K::Desk),
            ("exterior wall", K::Other),
            ("unlabelled", K::Other),
        ] {
            assert_eq!(ElementKind::of_label(label), kind, "{label}");
        }
        // Every glazing lets the sun in; a mirror is glass but no glazing; a glazed door is both
        // glazing and a door.
        assert!(ElementKind::of_label("skylight").is_glazing());
        assert!(!ElementKind::of_label("mirror").is_glazing());
        assert!(ElementKind::of_label("mirror").is_glass());
        let d = ElementKind::of_label("glass door");
        assert!(d.is_glazing() && d.is_door());
        assert!(!ElementKind::of_label("door").is_glazing());
    }

    /// Each alias names the kind it stands beside: no alias is hidden by an earlier, shorter one.
    #[test]
    fn no_alias_is_shadowed() {
        for (alias, kind) in LABEL_ALIASES {
            assert_eq!(ElementKind::of_label(alias), *kind, "{alias}");
        }
    }
}
