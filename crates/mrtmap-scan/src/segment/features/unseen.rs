//! Unseen patches: the raster texels the scan never saw, each with the temperatures it may have.
//!
//! 1. A raster texel is never seen when under one in [`SEEN_ONE_IN`] of its analysis texels on
//!    the surface were observed and it lies mostly outside every feature's outline (where the feature's
//!    temperature applies).
//! 2. Never-seen texels are grouped into 8-connected patches.
//! 3. Each patch is bounded by the temperatures seen within [`UNSEEN_SURROUNDINGS_M`] of it
//!    (else anywhere on the surface), as departures from the background model, placed on the
//!    background over the patch: a stratified wall's gradient is known.
//! 4. A feature bounds a patch only when the patch touches its outline, and only where the
//!    feature may continue ([`Reach`]: its box, open on the sides beyond which no background was
//!    seen); a touching patch is split by the features that may cover each of its texels.

use mrtmap_geometry::nalgebra::Point2;
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_physics::ZERO_CELSIUS_K;
use mrtmap_radiation::UnseenPatch;

use super::background::Background;
use super::grid::Grid;

/// A raster texel is seen when at least one in this many of its analysis texels on the surface
/// were observed (a quarter): the raster averages those it has and fills the others, and those
/// the scan never saw are unseen patches.
pub(super) const SEEN_ONE_IN: usize = 4;

/// Where a feature may continue into what the scan did not see: the box of its outline, open
/// (unbounded) on each side beyond which the scan saw no background. A window or a radiator is a
/// rectangle: seen with wall above it, it does not continue upwards, whatever lies beside it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reach {
    /// The outline's box.
    lo: Point2<f64>,
    hi: Point2<f64>,
    /// The box the feature may fill: `lo`/`hi`, infinite on its open sides.
    may_lo: Point2<f64>,
    may_hi: Point2<f64>,
    /// The temperatures seen inside its outline, as departures from the background (K).
    range_k: Option<(f64, f64)>,
}

/// How far beyond a feature's side the scan must have seen background for the side to be its
/// end (m): one raster texel.
const REACH_PROBE_M: f64 = 0.15;

impl Reach {
    /// The reach of the feature outlined by `poly` on the surface of `g` with background `bg`.
    pub(super) fn of(g: &Grid, poly: &[Point2<f64>], bg: &Background) -> Self {
        let (mut lo, mut hi) = (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for q in poly {
            lo = lo.inf(q);
            hi = hi.sup(q);
        }
        // A side is open when the strip just beyond it, on the surface, was mostly not seen; a
        // side on the surface's edge is closed.
        let open = |within: &dyn Fn(&Point2<f64>) -> bool| {
            let (mut n, mut seen) = (0usize, 0usize);
            for c in (0..g.nx * g.ny).filter(|&c| g.inside[c]) {
                if within(&g.centre_of(c)) {
                    n += 1;
                    seen += usize::from(g.observed(c));
                }
            }
            n > 0 && seen * 2 < n
        };
        let w = REACH_PROBE_M;
        let along_y = |q: &Point2<f64>| (lo.y..=hi.y).contains(&q.y);
        let along_x = |q: &Point2<f64>| (lo.x..=hi.x).contains(&q.x);
        let (mut may_lo, mut may_hi) = (lo, hi);
        if open(&|q| along_y(q) && q.x < lo.x && q.x >= lo.x - w) {
            may_lo.x = f64::NEG_INFINITY;
        }
        if open(&|q| along_y(q) && q.x > hi.x && q.x <= hi.x + w) {
            may_hi.x = f64::INFINITY;
        }
        if open(&|q| along_x(q) && q.y < lo.y && q.y >= lo.y - w) {
            may_lo.y = f64::NEG_INFINITY;
        }
        if open(&|q| along_x(q) && q.y > hi.y && q.y <= hi.y + w) {
            may_hi.y = f64::INFINITY;
        }
        let (mut t_lo, mut t_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in (0..g.nx * g.ny).filter(|&c| g.inside[c] && g.observed(c)) {
            let q = g.centre_of(c);
            if q.x >= lo.x
                && q.x <= hi.x
                && q.y >= lo.y
                && q.y <= hi.y
                && point_in_polygon_fast(&q, poly)
            {
                let t = g.kelvin(c) - bg.a - bg.b * q.y;
                t_lo = t_lo.min(t);
                t_hi = t_hi.max(t);
            }
        }
        Self {
            lo,
            hi,
            may_lo,
            may_hi,
            range_k: (t_lo <= t_hi).then_some((t_lo, t_hi)),
        }
    }

    /// The distance from `q` to the outline's box (m; the larger of the two axes').
    fn distance(&self, q: &Point2<f64>) -> f64 {
        let dx = (self.lo.x - q.x).max(q.x - self.hi.x).max(0.0);
        let dy = (self.lo.y - q.y).max(q.y - self.hi.y).max(0.0);
        dx.max(dy)
    }

    /// Whether the feature may cover `q` (within `margin` of its reach).
    fn may_hold(&self, q: &Point2<f64>, margin: f64) -> bool {
        q.x >= self.may_lo.x - margin
            && q.x <= self.may_hi.x + margin
            && q.y >= self.may_lo.y - margin
            && q.y <= self.may_hi.y + margin
    }
}

/// The 8-connected patch of `unseen` raster texels (`cols` × `rows`) holding `start`, marked in
/// `done`, in index order.
fn grow_patch(
    start: usize,
    unseen: &[bool],
    done: &mut [bool],
    (cols, rows): (usize, usize),
) -> Vec<usize> {
    let mut texels = vec![start];
    done[start] = true;
    let mut next = 0;
    while next < texels.len() {
        let r = texels[next];
        next += 1;
        let (col, row) = (r % cols, r / cols);
        for rr in row.saturating_sub(1)..(row + 2).min(rows) {
            for cc in col.saturating_sub(1)..(col + 2).min(cols) {
                let q = rr * cols + cc;
                if unseen[q] && !done[q] {
                    done[q] = true;
                    texels.push(q);
                }
            }
        }
    }
    texels.sort_unstable();
    texels
}

/// The analysis texels of raster texel `r` (`k` × `k` of them, `cols` raster texels per row).
fn raster_cells(g: &Grid, k: usize, cols: usize, r: usize) -> impl Iterator<Item = usize> + '_ {
    let (col, row) = (r % cols, r / cols);
    (row * k..((row + 1) * k).min(g.ny))
        .flat_map(move |j| (col * k..((col + 1) * k).min(g.nx)).map(move |i| j * g.nx + i))
}

/// Whether the scan never saw a raster texel of analysis texels `cells`: under a quarter of
/// those on the surface observed, and mostly outside every feature's outline (`in_feature`).
fn never_seen(g: &Grid, cells: impl Iterator<Item = usize>, in_feature: &[bool]) -> bool {
    let (mut inside, mut seen, mut feature) = (0usize, 0usize, 0usize);
    for c in cells.filter(|&c| g.inside[c]) {
        inside += 1;
        seen += usize::from(g.observed(c));
        feature += usize::from(in_feature[c]);
    }
    inside > 0 && seen * SEEN_ONE_IN < inside && feature * 2 < inside
}

/// The box, in analysis texels `[i0, j0, i1, j1)`, of raster texels `texels` (`k` × `k` analysis
/// texels each, `cols` per row), grown by `ring` analysis texels and clipped to the grid.
fn patch_box(g: &Grid, texels: &[usize], k: usize, cols: usize, ring: usize) -> [usize; 4] {
    let (mut i0, mut j0, mut i1, mut j1) = (usize::MAX, usize::MAX, 0, 0);
    for &r in texels {
        let (col, row) = (r % cols, r / cols);
        i0 = i0.min(col * k);
        j0 = j0.min(row * k);
        i1 = i1.max(((col + 1) * k).min(g.nx));
        j1 = j1.max(((row + 1) * k).min(g.ny));
    }
    [
        i0.saturating_sub(ring),
        j0.saturating_sub(ring),
        (i1 + ring).min(g.nx),
        (j1 + ring).min(g.ny),
    ]
}

/// How far around an unseen patch the seen texels bound its temperature (m).
const UNSEEN_SURROUNDINGS_M: f64 = 0.5;

/// The raster's texels (`k` × `k` analysis texels each, `cols` × `rows`) that the scan never saw
/// (under a quarter of their analysis texels observed, and mostly outside every feature's outline
/// `in_feature`, where the feature's temperature applies), grouped into 8-connected patches, each
/// with the range of the temperatures seen within [`UNSEEN_SURROUNDINGS_M`] of it, else anywhere
/// on the surface, as departures from the background model `bg` placed on the background over
/// the patch (a stratified wall's gradient is known; a 20 s radiant-ceiling walk's unseen wall
/// patches took its whole 2 K span as possible). A feature's temperatures bound a patch only when the patch touches its outline
/// (a window or a panel may continue into what was not seen); a feature whose edge was seen, with
/// background beyond it, ends there, and its cells and their blur (`near_feature`) are left out:
/// a 20 s office walk's 1.3 m² unseen patch of wall 0.4 m from the window's seen edge took the
/// window's 11.4 °C as possible and stated ±1.45 K at the node beside it, where the error was
/// 0.14 K. A touching patch is split by the features that may cover each of its texels (their
/// [`Reach`]): each part is bounded by the background seen around the patch and by those
/// features' own temperatures.
pub(super) fn unseen_patches(
    g: &Grid,
    (in_feature, near_feature): (&[bool], &[bool]),
    reaches: &[Reach],
    bg: &Background,
    k: usize,
    (cols, rows): (usize, usize),
    on_surface: &[bool],
) -> Vec<UnseenPatch> {
    let cells_of = |r: usize| raster_cells(g, k, cols, r);
    let unseen: Vec<bool> = (0..cols * rows)
        .map(|r| on_surface[r] && never_seen(g, cells_of(r), in_feature))
        .collect();
    // Temperatures seen are taken relative to the surface's background model (a wall's vertical
    // gradient), and the range is placed on the background over the patch: a patch on a
    // stratified wall follows the gradient as its neighbours do, and what is uncertain is how
    // far it strays from it.
    let bg_at = |c: usize| bg.a + bg.b * g.centre_of(c).y;
    let observed_range = |cells: &mut dyn Iterator<Item = usize>, features: bool| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in cells.filter(|&c| g.inside[c] && g.observed(c) && (features || !near_feature[c])) {
            let t = g.kelvin(c) - bg_at(c);
            lo = lo.min(t);
            hi = hi.max(t);
        }
        (lo <= hi).then_some((lo, hi))
    };
    let ring = (UNSEEN_SURROUNDINGS_M / g.t).ceil() as usize;
    let mut done = vec![false; cols * rows];
    let mut out = Vec::new();
    for start in 0..cols * rows {
        if !unseen[start] || done[start] {
            continue;
        }
        let texels = grow_patch(start, &unseen, &mut done, (cols, rows));
        let [i0, j0, i1, j1] = patch_box(g, &texels, k, cols, ring);
        // Does the patch touch a feature's outline (one within a raster texel of an unseen
        // cell of it: the patch's texels start where a raster texel is mostly unseen)?
        let reach = k + 1;
        let unseen_cells = || {
            texels
                .iter()
                .flat_map(|&r| cells_of(r))
                .filter(|&c| !g.observed(c))
        };
        let touches = unseen_cells().any(|c| {
            let (i, j) = (c % g.nx, c / g.nx);
            (j.saturating_sub(reach)..(j + reach + 1).min(g.ny)).any(|jj| {
                (i.saturating_sub(reach)..(i + reach + 1).min(g.nx))
                    .any(|ii| in_feature[jj * g.nx + ii])
            })
        });
        // Which features it touches, and where in it they may continue: within each one's
        // reach (its box, open on the sides beyond which no background was seen).
        let near_m = reach as f64 * g.t;
        let touching: Vec<&Reach> = if touches {
            reaches
                .iter()
                .filter(|f| unseen_cells().any(|c| f.distance(&g.centre_of(c)) <= near_m))
                .collect()
        } else {
            Vec::new()
        };
        let half_texel = 0.5 * k as f64 * g.t;
        let raster_centre = |r: usize| {
            Point2::new(
                g.lo.x + ((r % cols) as f64 + 0.5) * k as f64 * g.t,
                g.lo.y + ((r / cols) as f64 + 0.5) * k as f64 * g.t,
            )
        };
        // The patch's texels grouped by the touching features that may cover them: each group
        // is bounded by the background seen around the patch and by those features' own
        // temperatures (a texel beside a window but above a radiator may be the window, not
        // the radiator).
        let mut groups: std::collections::BTreeMap<Vec<usize>, Vec<usize>> =
            std::collections::BTreeMap::new();
        for &r in &texels {
            let q = raster_centre(r);
            let by = (0..touching.len()).filter(|&i| touching[i].may_hold(&q, half_texel));
            groups.entry(by.collect()).or_default().push(r);
        }
        let around = |features: bool| {
            observed_range(
                &mut (j0..j1).flat_map(|j| (i0..i1).map(move |i| j * g.nx + i)),
                features,
            )
        };
        let background = around(false)
            .or_else(|| around(true))
            .or_else(|| observed_range(&mut (0..g.nx * g.ny), true));
        for (by, part) in groups {
            let range = by
                .iter()
                .filter_map(|&i| touching[i].range_k)
                .chain(background)
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
            // The background over the part's own cells.
            let (n, sum) = part
                .iter()
                .flat_map(|&r| cells_of(r))
                .filter(|&c| g.inside[c])
                .fold((0usize, 0.0), |(n, s), c| (n + 1, s + bg_at(c)));
            let base = if n > 0 { sum / n as f64 } else { bg.a };
            if let Some((lo, hi)) = range {
                out.push(UnseenPatch {
                    texels: part,
                    range_c: [base + lo - ZERO_CELSIUS_K, base + hi - ZERO_CELSIUS_K],
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::features::testing::analyse_seen;
    use mrtmap_geometry::nalgebra::Point3;

    /// A 4 × 2.5 m wall at 18 °C with a 30 °C panel (x 1…2, z 1…2) and two holes the walk never
    /// saw: one 0.6 m square by the panel (from x `a_from`), one far from it (x 3.2…3.8,
    /// z 0.2…0.6). Each is an unseen patch covering its hole, bounded by what was seen around it:
    /// the second is pinned near 18 °C; the panel's 30 °C may continue into the first when the
    /// hole touches the panel (`a_from` 2.0), not when the panel's edge was seen with wall beyond
    /// it (`a_from` 2.3). The panel is seen, so none of its texels is unseen.
    #[test]
    fn unseen_holes_become_patches_bounded_by_their_surroundings() {
        for (a_from, touches) in [(2.0, true), (2.3, false)] {
            unseen_holes_by_a_panel(a_from, touches);
        }
    }

    fn unseen_holes_by_a_panel(a_from: f64, touches: bool) {
        let hole_a =
            |x: f64, z: f64| (a_from..a_from + 0.6).contains(&x) && (1.2..1.8).contains(&z);
        let hole_b = |x: f64, z: f64| (3.2..3.8).contains(&x) && (0.2..0.6).contains(&z);
        let panel = |x: f64, z: f64| (1.0..2.0).contains(&x) && (1.0..2.0).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| {
                (!(hole_a(x, z) || hole_b(x, z))).then_some(if panel(x, z) { 30.0 } else { 18.0 })
            },
            false,
        );
        assert_eq!(a.features.len(), 1, "the panel: {:?}", a.dropped);
        let r = a.raster.as_ref().expect("a raster");
        assert_eq!(r.unseen.len(), 2, "{:?}", r.unseen);
        let centre = |t: usize| {
            use mrtmap_geometry::nalgebra::Vector3;
            let (c, row) = ((t % r.cols) as f64 + 0.5, (t / r.cols) as f64 + 0.5);
            let p = Point3::from(r.origin)
                + Vector3::from(r.u) * (c * r.texel_m)
                + Vector3::from(r.v) * (row * r.texel_m);
            (p.x, p.z)
        };
        for patch in &r.unseen {
            let (x, z) = centre(patch.texels[0]);
            let area = patch.texels.len() as f64 * r.texel_m * r.texel_m;
            let near_panel = x < 3.0;
            let hole_area = if near_panel { 0.36 } else { 0.24 };
            assert!(
                area >= 0.5 * hole_area && area <= 1.6 * hole_area,
                "patch at ({x:.2}, {z:.2}): {area:.2} m² for a {hole_area} m² hole"
            );
            for &t in &patch.texels {
                let (x, z) = centre(t);
                assert!(!panel(x, z), "a panel texel ({x:.2}, {z:.2}) is not unseen");
            }
            let [lo, hi] = patch.range_c;
            assert!((lo - 18.0).abs() < 0.3, "{:?}", patch.range_c);
            if near_panel && touches {
                assert!(
                    hi > 29.0,
                    "the panel's 30 °C is beside it: {:?}",
                    patch.range_c
                );
            } else {
                assert!(
                    hi < 18.5,
                    "only the wall's 18 °C around it: {:?}",
                    patch.range_c
                );
            }
        }
        // The host's temperature no longer carries the unseen share: the raster's patches do.
        assert!(a.temperature_std_k < 0.05, "{}", a.temperature_std_k);
    }

    /// A 4 × 2.5 m wall at 18 °C with a 45 °C radiator (x 1…2, z 0.15…0.75) whose right end
    /// the walk never saw, nor the wall beside and above it (x 2…3.6, z 0…2.3: 3.7 m²). The
    /// radiator may continue to the right, not upwards (wall was seen above it): only the band
    /// beside it may be 45 °C; the rest of the hole is bounded by the wall (the L-shaped room's
    /// 20 s walks let a 4–4.9 m² patch beside its radiator and window be anything from 9.5 to
    /// 45 °C, and stated ±6.3 K where the error was 1 K).
    #[test]
    fn an_unseen_patch_may_be_a_feature_only_where_the_feature_may_continue() {
        let hole = |x: f64, z: f64| (2.0..3.6).contains(&x) && z < 2.3;
        let radiator = |x: f64, z: f64| (1.0..2.0).contains(&x) && (0.15..0.75).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| (!hole(x, z)).then_some(if radiator(x, z) { 45.0 } else { 18.0 }),
            false,
        );
        assert_eq!(a.features.len(), 1, "the radiator: {:?}", a.dropped);
        let r = a.raster.as_ref().expect("a raster");
        let z_of = |t: usize| r.origin[2] + r.v[2] * ((t / r.cols) as f64 + 0.5) * r.texel_m;
        let area = |p: &UnseenPatch| p.texels.len() as f64 * r.texel_m * r.texel_m;
        let hot: Vec<&UnseenPatch> = r.unseen.iter().filter(|p| p.range_c[1] > 44.0).collect();
        let plain: Vec<&UnseenPatch> = r.unseen.iter().filter(|p| p.range_c[1] < 18.5).collect();
        assert_eq!(hot.len() + plain.len(), r.unseen.len(), "{:?}", r.unseen);
        let hot_m2: f64 = hot.iter().map(|p| area(p)).sum();
        let plain_m2: f64 = plain.iter().map(|p| area(p)).sum();
        assert!((0.5..1.6).contains(&hot_m2), "{hot_m2:.2} m² may be 45 °C");
        assert!(plain_m2 > 2.2, "{plain_m2:.2} m² bounded by the wall");
        for p in &hot {
            for &t in &p.texels {
                let z = z_of(t);
                assert!((0.0..0.95).contains(&z), "a texel at z {z:.2} may be 45 °C");
            }
        }
    }

    /// A wall stratified by 0.8 K/m (18 °C at the floor, 20 °C at 2.5 m) with a 0.6 m hole the
    /// walk never saw at mid-height: the seen surroundings span 1.3 K of height, but the wall's
    /// gradient is known, so the patch is bounded by how far the wall strays from it (nowhere
    /// here), placed on the gradient at the hole.
    #[test]
    fn an_unseen_patch_on_a_stratified_wall_follows_its_gradient() {
        let hole = |x: f64, z: f64| (1.7..2.3).contains(&x) && (0.95..1.55).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| (!hole(x, z)).then_some(18.0 + 0.8 * z),
            true,
        );
        let r = a.raster.as_ref().expect("a raster");
        assert_eq!(r.unseen.len(), 1, "{:?}", r.unseen);
        let [lo, hi] = r.unseen[0].range_c;
        assert!(hi - lo < 0.1, "{:?}", r.unseen[0].range_c);
        // The hole's middle (z 1.25 m) is at 19.0 °C.
        assert!(
            ((lo + hi) / 2.0 - 19.0).abs() < 0.1,
            "{:?}",
            r.unseen[0].range_c
        );
    }
}
