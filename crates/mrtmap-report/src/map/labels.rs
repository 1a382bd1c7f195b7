//! Labels placed without overlap. Every label, mark and corner number takes a pixel box; a label
//! whose own spot is taken moves to the nearest free spot around its anchor (rings of growing
//! radius, wider than tall, as text is) and, when it moved far, a thin leader line joins it to
//! what it names. Labels that find no free spot inside the plot are drawn at their anchor.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{FONT_FAMILY, de};
use crate::ReportError;

/// A pixel box (x0, y0, x1, y1) taken by a label or a mark.
pub(super) type PixelBox = (i32, i32, i32, i32);

/// A label moved further than this from its anchor gets a leader line (px).
const LEADER_PX: f64 = 26.0;

/// The boxes taken so far, inside the plot's pixel area.
pub(super) struct Placer {
    placed: Vec<PixelBox>,
    area: PixelBox,
}

/// Text to place near a spot.
pub(super) struct Label {
    /// The pixel it names.
    pub anchor: (i32, i32),
    /// The text.
    pub text: String,
}

/// The box of a `w`×`h` label centred at `c`.
pub(super) fn centred_box(c: (i32, i32), w: i32, h: i32) -> PixelBox {
    (c.0 - w / 2, c.1 - h / 2, c.0 + w / 2, c.1 + h / 2)
}

/// The width of `text` in the 12 px label font (DejaVu Sans averages about half an em per
/// character in lower case).
pub(super) fn text_width(text: &str) -> i32 {
    (text.chars().count() as f64 * 6.2).ceil() as i32 + 6
}

/// Height of a label box (px).
pub(super) const LABEL_H: i32 = 16;

impl Placer {
    /// Nothing placed yet; labels must stay inside `area`.
    pub fn new(area: PixelBox) -> Self {
        Self {
            placed: Vec::new(),
            area,
        }
    }

    /// Takes a box.
    pub fn reserve(&mut self, b: PixelBox) {
        self.placed.push(b);
    }

    /// Whether `b` lies inside the plot and overlaps nothing placed.
    pub fn is_clear(&self, b: PixelBox) -> bool {
        let inside =
            b.0 >= self.area.0 && b.1 >= self.area.1 && b.2 <= self.area.2 && b.3 <= self.area.3;
        inside
            && self
                .placed
                .iter()
                .all(|p| b.2 < p.0 || b.0 > p.2 || b.3 < p.1 || b.1 > p.3)
    }

    /// The centre of the nearest free `w`×`h` box around `anchor`, if any.
    pub fn find(&self, anchor: (i32, i32), w: i32, h: i32) -> Option<(i32, i32)> {
        let rings = [0.0, 12.0, 20.0, 30.0, 42.0, 56.0, 72.0, 90.0, 110.0, 135.0];
        rings.iter().find_map(|&r| {
            let steps = if r == 0.0 { 1 } else { 24 };
            (0..steps).find_map(|k| {
                // Start below-right of the anchor's right side, go round.
                let a = std::f64::consts::TAU * k as f64 / steps as f64;
                let c = (
                    anchor.0 + (r * 1.8 * a.cos()).round() as i32,
                    anchor.1 - (r * a.sin()).round() as i32,
                );
                self.is_clear(centred_box(c, w + 4, h + 2)).then_some(c)
            })
        })
    }
}

/// Draws `label` at the nearest free spot (with a leader line when it moved far) and takes its box.
pub(super) fn draw_label<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    placer: &mut Placer,
    label: Label,
) -> Result<(), ReportError> {
    let (w, h) = (text_width(&label.text), LABEL_H);
    let c = placer.find(label.anchor, w, h).unwrap_or(label.anchor);
    let b = centred_box(c, w + 4, h + 2);
    placer.reserve(b);
    let (dx, dy) = (
        f64::from(c.0 - label.anchor.0),
        f64::from(c.1 - label.anchor.1),
    );
    if dx.hypot(dy) > LEADER_PX {
        // From the anchor to the nearest point of the label's box.
        let to = (
            label.anchor.0.clamp(b.0, b.2),
            label.anchor.1.clamp(b.1, b.3),
        );
        let grey = RGBColor(60, 60, 60);
        root.draw(&PathElement::new(
            vec![label.anchor, to],
            grey.stroke_width(1),
        ))
        .map_err(de)?;
        root.draw(&Circle::new(label.anchor, 2, grey.filled()))
            .map_err(de)?;
    }
    root.draw(&Rectangle::new(
        [(c.0 - w / 2, c.1 - h / 2), (c.0 + w / 2, c.1 + h / 2)],
        WHITE.mix(0.8).filled(),
    ))
    .map_err(de)?;
    root.draw(&Text::new(
        label.text,
        c,
        (FONT_FAMILY, 12)
            .into_font()
            .color(&RGBColor(20, 20, 20))
            .pos(Pos::new(HPos::Center, VPos::Center)),
    ))
    .map_err(de)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_taken_spot_moves_the_label_to_a_free_one_nearby() {
        let mut p = Placer::new((0, 0, 400, 400));
        let first = p.find((200, 200), 60, 16).unwrap();
        assert_eq!(first, (200, 200));
        p.reserve(centred_box(first, 64, 18));
        let second = p.find((200, 200), 60, 16).unwrap();
        assert_ne!(second, first);
        assert!(p.is_clear(centred_box(second, 64, 18)));
        let d = f64::from(second.0 - 200).hypot(f64::from(second.1 - 200));
        assert!(d < 60.0, "moved {d} px");
    }

    #[test]
    fn labels_stay_inside_the_plot() {
        let p = Placer::new((0, 0, 100, 100));
        let c = p.find((2, 2), 40, 16).unwrap();
        let b = centred_box(c, 44, 18);
        assert!(b.0 >= 0 && b.1 >= 0 && b.2 <= 100 && b.3 <= 100, "{b:?}");
        assert_eq!(p.find((50, 50), 400, 16), None);
    }
}
