//! The room's outline on the floor plan, robust to how the walk went.
//!
//! 1. Wall lines: the points of vertical surfaces in the upper half of the room (walls reach the
//!    ceiling, most furniture does not), seen from above, vote with their normals' directions (a
//!    Hough transform on the normals); each direction's points vote for an offset; each peak is a
//!    line, refitted to the middle of its points (a far wall is fused as thick as the depth noise
//!    there). Lines of noise are sparse or thick and are dropped, and so are lines made of the
//!    spread of stronger walls (their points nearly all among those walls' points). A wall seen
//!    briefly, at a grazing angle or only above furniture still gives a line.
//! 2. Where the room is: the floor and ceiling points seen, on a 5 cm raster.
//! 3. The plane is cut into cells by every line (and, along each wall direction, by the floor and
//!    ceiling's extreme extent, for a wall never seen); a cell is the room's when most of its
//!    inside (15 cm from its edges, past the floor points scattered beyond a wall) was seen as
//!    floor or ceiling. The kept cells' boundary is the loop of walls, counter-clockwise;
//!    its corners are the lines' intersections. Spurious lines inside the room (a tall cupboard's
//!    side, a wall's shadow) cut cells that are kept on both sides and drop out; lines outside it
//!    bound cells that are empty. The loop closes whenever the floor or ceiling was seen. Walls
//!    shorter than 30 cm (slivers where lines cross near a corner) are removed by extending their
//!    neighbours, and so are walls under 1 m whose line has less than 30 % of the point density of
//!    both neighbours when those meet within 50 cm (a corner hidden behind furniture, cut off by
//!    a slanted line of depth noise).
//! 4. Each observed wall's line is fitted again to its points at every height, normals within 80°
//!    (`refine_walls`), and the corners are where the refitted lines meet.

use mrtmap_geometry::nalgebra::{Point2, Vector2};
use mrtmap_geometry::shape2d::line_intersection;

/// A wall line on the floor plan: the points `q` with `n·q = rho`; `n` points into the room once
/// the line is on the outline.
#[derive(Clone, Debug)]
pub struct WallLine {
    /// Unit normal.
    pub n: Vector2<f64>,
    /// Offset along the normal (m).
    pub rho: f64,
    /// The wall points (indices into the points given) on the line.
    pub points: Vec<usize>,
    /// Placed at the edge of the floor and ceiling seen, not from wall points.
    pub inferred: bool,
    /// Its points per 10 cm of the length along which it was seen.
    pub density: f64,
    /// The median distance of its points from it (m).
    pub thickness: f64,
}

impl WallLine {
    fn direction(&self) -> Vector2<f64> {
        Vector2::new(-self.n.y, self.n.x)
    }

    fn distance(&self, q: &Point2<f64>) -> f64 {
        self.n.dot(&q.coords) - self.rho
    }
}

/// The outline: walls in order counter-clockwise seen from above.
#[derive(Clone, Debug)]
pub struct Outline {
    /// Every line found (walls and others).
    pub lines: Vec<WallLine>,
    /// The line of each wall, in order around the room.
    pub walls: Vec<usize>,
    /// Corner `k`, where wall `k − 1` meets wall `k`.
    pub corners: Vec<Point2<f64>>,
    /// Each wall's inward unit normal.
    pub normals: Vec<Vector2<f64>>,
}

/// Why no outline.
#[derive(Clone, Debug, PartialEq)]
pub enum OutlineError {
    /// Too few wall points or no floor or ceiling seen.
    NothingSeen,
    /// The kept cells reach the edge of the search area (never with a floor or ceiling seen):
    /// the part of the boundary that is not a wall, from one point to another.
    Open(Point2<f64>, Point2<f64>),
}

/// Settings of the outline search.
#[derive(Clone, Copy, Debug)]
pub struct OutlineParams {
    /// Points within this distance of a line's offset peak start its fit, and lie on it at least
    /// this far (m; more on a thick wall).
    pub band_m: f64,
    /// Normals within this angle of a line's normal vote for it (degrees).
    pub normal_deg: f64,
    /// A line needs this many points…
    pub min_points: usize,
    /// …along at least this length (m).
    pub min_length_m: f64,
    /// Lines closer than this in angle (degrees) and offset (m) are one line.
    pub merge_deg: f64,
    /// See `merge_deg`.
    pub merge_m: f64,
    /// Raster cell for the floor and ceiling seen (m).
    pub cell_m: f64,
}

impl Default for OutlineParams {
    fn default() -> Self {
        Self {
            band_m: 0.08,
            normal_deg: 20.0,
            min_points: 80,
            min_length_m: 0.3,
            merge_deg: 6.0,
            merge_m: 0.15,
            cell_m: 0.05,
        }
    }
}

/// A cell is the room's when at least this share of it was seen as floor or ceiling: beyond the
/// walls next to nothing is seen (a lower share let thin slivers of noise in on 30 s walks).
const KEEP_SHARE: f64 = 0.5;

/// Floor and ceiling points scatter this far (m) beyond a wall with the depth noise (10–15 cm
/// beyond a bay window's front wall 4 m away): a cell is judged on its part at least this far
/// inside its edges (on the whole cell when it is thinner), so that a thin cell beyond a wall is
/// not taken for the room's.
const SPILL_M: f64 = 0.15;

/// A line with at least this share of the densest line's points per length is a wall whatever
/// its thickness, and its direction may carry an inferred wall.
const STRONG_DENSITY: f64 = 0.3;

/// How far from a wall line its points are sought when the line is refined (m).
const WIDE_M: f64 = 0.3;

fn wrap_deg(a: f64) -> f64 {
    a.rem_euclid(360.0)
}

fn angle_diff_deg(a: f64, b: f64) -> f64 {
    let d = wrap_deg(a - b);
    d.min(360.0 - d)
}

/// A line through `pts` robust to a minority off it: total least squares, then again on the points
/// within 2.5 robust standard deviations of the first fit (at least 1 cm).
fn fit_line(pts: &[Point2<f64>], n0: &Vector2<f64>) -> Option<(Vector2<f64>, f64)> {
    let (n, rho) = fit_line_tls(pts, None, n0)?;
    Some(
        trimmed_fit(pts, None, (n, rho), (0.01, f64::INFINITY))
            .map_or((n, rho), |(n, rho, _)| (n, rho)),
    )
}

/// The line `(n, rho)` refitted to the points of `pts` within 2.5 robust standard deviations of
/// their median distance from it (the cut clamped to `clamp`), each weighted by `weights` when
/// given, and the cut.
fn trimmed_fit(
    pts: &[Point2<f64>],
    weights: Option<&[f64]>,
    (n, rho): (Vector2<f64>, f64),
    clamp: (f64, f64),
) -> Option<(Vector2<f64>, f64, f64)> {
    if pts.is_empty() {
        return None;
    }
    let dist = |q: &Point2<f64>| n.dot(&q.coords) - rho;
    let mut r: Vec<f64> = pts.iter().map(dist).collect();
    r.sort_by(f64::total_cmp);
    let med = r[r.len() / 2];
    let mut dev: Vec<f64> = r.iter().map(|x| (x - med).abs()).collect();
    dev.sort_by(f64::total_cmp);
    let cut = (2.5 * 1.4826 * dev[dev.len() / 2]).clamp(clamp.0, clamp.1);
    let keep: Vec<usize> = (0..pts.len())
        .filter(|&i| (dist(&pts[i]) - med).abs() <= cut)
        .collect();
    let near: Vec<Point2<f64>> = keep.iter().map(|&i| pts[i]).collect();
    let w: Option<Vec<f64>> = weights.map(|w| keep.iter().map(|&i| w[i]).collect());
    let (n, rho) = fit_line_tls(&near, w.as_deref(), &n)?;
    Some((n, rho, cut))
}

/// Total least squares line through `pts` (each weighted by `weights` when given), its normal
/// oriented like `n0`.
fn fit_line_tls(
    pts: &[Point2<f64>],
    weights: Option<&[f64]>,
    n0: &Vector2<f64>,
) -> Option<(Vector2<f64>, f64)> {
    if pts.len() < 2 {
        return None;
    }
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    let total: f64 = (0..pts.len()).map(w).sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let c = pts
        .iter()
        .enumerate()
        .fold(Vector2::zeros(), |a, (i, q)| a + q.coords * w(i))
        / total;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (i, q) in pts.iter().enumerate() {
        let d = q.coords - c;
        sxx += w(i) * d.x * d.x;
        sxy += w(i) * d.x * d.y;
        syy += w(i) * d.y * d.y;
    }
    // The direction of least spread: the eigenvector of the smaller eigenvalue.
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy); // direction of largest spread
    let mut n = Vector2::new(-theta.sin(), theta.cos());
    if n.dot(n0) < 0.0 {
        n = -n;
    }
    Some((n, n.dot(&c)))
}

/// The points' extent along a line in 10 cm bins: the occupied length (bins with two points or
/// more, in runs of at least `min_len`) and which points lie in those runs.
fn runs_along(
    line: &WallLine,
    pts: &[Point2<f64>],
    idx: &[usize],
    min_len: f64,
) -> (f64, Vec<usize>) {
    if idx.is_empty() {
        return (0.0, Vec::new());
    }
    let d = line.direction();
    let s: Vec<f64> = idx.iter().map(|&i| d.dot(&pts[i].coords)).collect();
    let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let bins = (((hi - lo) / 0.1).floor() as usize + 1).min(200_000);
    let bin = |v: f64| (((v - lo) / 0.1) as usize).min(bins - 1);
    let mut count = vec![0usize; bins];
    for v in &s {
        count[bin(*v)] += 1;
    }
    // Runs of occupied bins with gaps of at most 30 cm.
    let mut keep = vec![false; bins];
    let mut total = 0.0;
    let mut b = 0;
    while b < bins {
        if count[b] < 2 {
            b += 1;
            continue;
        }
        let (start, mut end, mut gap, mut occupied) = (b, b, 0, 0usize);
        let mut c = b;
        while c < bins && gap <= 3 {
            if count[c] >= 2 {
                end = c;
                gap = 0;
                occupied += 1;
            } else {
                gap += 1;
            }
            c += 1;
        }
        if (end - start + 1) as f64 * 0.1 >= min_len {
            keep[start..=end].iter_mut().for_each(|k| *k = true);
            total += occupied as f64 * 0.1;
        }
        b = end + 1;
    }
    let kept = idx
        .iter()
        .zip(&s)
        .filter(|(_, v)| keep[bin(**v)])
        .map(|(i, _)| *i)
        .collect();
    (total, kept)
}

/// Wall lines from points on the floor plan with their (horizontal, unit) normals: a Hough
/// transform on the normals' directions ([`direction_peak`]), then on the offsets along each
/// direction ([`lines_facing`]); weak lines and the spread of strong ones are dropped.
pub fn wall_lines(
    pts: &[Point2<f64>],
    normals: &[Vector2<f64>],
    p: &OutlineParams,
) -> Vec<WallLine> {
    let angle: Vec<f64> = normals
        .iter()
        .map(|n| wrap_deg(n.y.atan2(n.x).to_degrees()))
        .collect();
    let mut free = vec![true; pts.len()];
    let mut exhausted = [false; 360];
    let mut lines: Vec<WallLine> = Vec::new();
    for _ in 0..64 {
        let Some(peak) = direction_peak(&angle, &free, &exhausted, p.min_points) else {
            break;
        };
        let near: Vec<usize> = (0..pts.len())
            .filter(|&i| free[i] && angle_diff_deg(angle[i], peak as f64 + 0.5) <= p.normal_deg)
            .collect();
        // The direction: the mean of the near normals.
        let mean = near
            .iter()
            .fold(Vector2::zeros(), |a, &i| a + normals[i])
            .try_normalize(1e-9)
            .unwrap_or_else(|| {
                let r = (peak as f64 + 0.5).to_radians();
                Vector2::new(r.cos(), r.sin())
            });
        let found = lines_facing((pts, normals), &near, &mean, &mut free, p);
        if found.is_empty() {
            for k in 0..7 {
                exhausted[(peak + 360 + k - 3) % 360] = true;
            }
        }
        lines.extend(found);
        // Points of this direction on no line are spent either way.
        for &i in &near {
            if angle_diff_deg(angle[i], peak as f64 + 0.5) <= 3.5 {
                free[i] = false;
            }
        }
    }
    // Noise (the blended normals where walls meet the ceiling, clutter) makes weak lines: a wall
    // has at least a twentieth of the points of the best-seen wall, and where it was seen its
    // points are dense (a fused cloud has one point per voxel of surface seen, however briefly)
    // and, unless very dense, thin. Measured on 60 s and 30 s walks: walls 30–150 points per
    // 10 cm with a median distance from their line of 1–8 cm; noise lines at most 22 points per
    // 10 cm, and those above a tenth of the densest wall's 9–15 cm thick.
    let strongest = lines.iter().map(|l| l.points.len()).max().unwrap_or(0);
    let densest = lines.iter().map(|l| l.density).fold(0.0, f64::max);
    lines.retain(|l| {
        l.points.len() * 20 >= strongest
            && (l.density >= STRONG_DENSITY * densest
                || (l.density >= 0.1 * densest && l.thickness <= 0.1))
    });
    drop_spread(merge_lines(lines, pts, p), pts)
}

/// The direction (1° bin) most free points face, summed over ±3°, among those not exhausted;
/// `None` when fewer than `min_points` face any.
fn direction_peak(
    angle: &[f64],
    free: &[bool],
    exhausted: &[bool; 360],
    min_points: usize,
) -> Option<usize> {
    let mut hist = [0usize; 360];
    for (i, a) in angle.iter().enumerate() {
        if free[i] {
            hist[(*a as usize).min(359)] += 1;
        }
    }
    let score = |b: usize| (0..7).map(|k| hist[(b + 360 + k - 3) % 360]).sum::<usize>();
    (0..360)
        .filter(|&b| !exhausted[b])
        .max_by_key(|&b| (score(b), std::cmp::Reverse(b)))
        .filter(|&peak| score(peak) >= min_points)
}

/// The lines facing `mean` among the points `near`: peaks of their offsets along it (2 cm bins)
/// in turn, each placed by [`place_line`]; the points of each line found stop being free.
fn lines_facing(
    (pts, normals): (&[Point2<f64>], &[Vector2<f64>]),
    near: &[usize],
    mean: &Vector2<f64>,
    free: &mut [bool],
    p: &OutlineParams,
) -> Vec<WallLine> {
    let rho: Vec<f64> = near.iter().map(|&i| mean.dot(&pts[i].coords)).collect();
    let lo = rho.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = rho.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let nb = (((hi - lo) / 0.02).floor() as usize + 1).min(100_000);
    let mut rh = vec![0usize; nb];
    for r in &rho {
        rh[(((r - lo) / 0.02) as usize).min(nb - 1)] += 1;
    }
    let half = (p.band_m / 0.02).round() as usize;
    let window = |b: usize| {
        rh[b.saturating_sub(half)..(b + half + 1).min(nb)]
            .iter()
            .sum::<usize>()
    };
    let mut used = vec![false; nb];
    let mut lines = Vec::new();
    while let Some(b) = (0..nb)
        .filter(|&b| !used[b])
        .max_by_key(|&b| (window(b), std::cmp::Reverse(b)))
    {
        if window(b) < p.min_points {
            break;
        }
        used[b.saturating_sub(2 * half)..(b + 2 * half + 1).min(nb)]
            .iter_mut()
            .for_each(|u| *u = true);
        let r0 = lo + (b as f64 + 0.5) * 0.02;
        let q: Vec<Point2<f64>> = near
            .iter()
            .zip(&rho)
            .filter(|(_, r)| (**r - r0).abs() <= p.band_m)
            .map(|(i, _)| pts[*i])
            .collect();
        let Some((n, rho_fit)) = fit_line(&q, mean) else {
            continue;
        };
        if let Some(line) = place_line(n, rho_fit, (pts, normals), free, p) {
            lines.push(line);
        }
    }
    lines
}

/// A line started at normal `n` and offset `rho`, placed in the middle of its points and given
/// them (they stop being free); `None` when too few or too short runs of points support it.
///
/// A fused wall seen from afar is as thick as the depth noise there (25 cm and more): the line is
/// the middle of its points within 30 cm, found by trimming at 2.5 robust standard deviations
/// and refitting; its points lie within that spread.
fn place_line(
    n: Vector2<f64>,
    rho: f64,
    (pts, normals): (&[Point2<f64>], &[Vector2<f64>]),
    free: &mut [bool],
    p: &OutlineParams,
) -> Option<WallLine> {
    let mut line = WallLine {
        n,
        rho,
        points: Vec::new(),
        inferred: false,
        density: 0.0,
        thickness: 0.0,
    };
    let cos_n = p.normal_deg.to_radians().cos();
    // The free points within `width` of a line whose normals agree with it.
    let within = |line: &WallLine, width: f64, free: &[bool]| -> Vec<usize> {
        (0..pts.len())
            .filter(|&i| {
                free[i] && line.distance(&pts[i]).abs() <= width && normals[i].dot(&line.n) >= cos_n
            })
            .collect()
    };
    let mut band = p.band_m;
    for _ in 0..3 {
        let near = within(&line, WIDE_M, free);
        if near.len() < p.min_points {
            break;
        }
        let q: Vec<Point2<f64>> = near.iter().map(|&i| pts[i]).collect();
        let Some((n, rho, cut)) = trimmed_fit(&q, None, (line.n, line.rho), (0.02, WIDE_M)) else {
            break;
        };
        band = cut.max(p.band_m);
        line.n = n;
        line.rho = rho;
    }
    // Its points: near the line with agreeing normals, in runs along it.
    let cand = within(&line, band, free);
    let (length, kept) = runs_along(&line, pts, &cand, p.min_length_m);
    if kept.len() < p.min_points || length < p.min_length_m {
        return None;
    }
    for &i in &kept {
        free[i] = false;
    }
    line.density = kept.len() as f64 / (length / 0.1);
    let mut r: Vec<f64> = kept.iter().map(|&i| line.distance(&pts[i]).abs()).collect();
    r.sort_by(f64::total_cmp);
    line.thickness = r[r.len() / 2];
    line.points = kept;
    Some(line)
}

/// A point of a line lies among the points of stronger lines when one of theirs is this close (m).
const SPREAD_M: f64 = 0.05;
/// A line with at least this share of its points among stronger lines' is their spread.
const SPREAD_SHARE: f64 = 0.9;

/// Lines that are the spread of stronger (denser) ones: a thick fused wall
/// leaves points beyond its line's band, and its blended normals at corners, which can make a
/// line of their own a few degrees off it, even across a corner (bay window, walk 1: 1,366 points,
/// 9 cm thick, 12° off the wall, from one wall's spread to the next). Nearly all such a line's
/// points (96–99 % measured) lie within [`SPREAD_M`] of a stronger line's points; a wall of its
/// own has points there only near its corners (57–63 % of a 0.8 m bay wall seen thick, under
/// 10 % of longer walls). Such lines are dropped.
fn drop_spread(lines: Vec<WallLine>, pts: &[Point2<f64>]) -> Vec<WallLine> {
    let key = |q: &Point2<f64>| {
        (
            (q.x / SPREAD_M).floor() as i64,
            (q.y / SPREAD_M).floor() as i64,
        )
    };
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    // Densest first: a line of spread can hold more points than a short wall it crosses.
    let mut order: Vec<usize> = (0..lines.len()).collect();
    order.sort_by(|&a, &b| lines[b].density.total_cmp(&lines[a].density));
    let mut keep = vec![false; lines.len()];
    for (rank, &k) in order.iter().enumerate() {
        let line = &lines[k];
        let among = line
            .points
            .iter()
            .filter(|&&i| {
                let (cx, cy) = key(&pts[i]);
                (-1..=1).any(|dx| {
                    (-1..=1).any(|dy| {
                        grid.get(&(cx + dx, cy + dy)).is_some_and(|v| {
                            v.iter()
                                .any(|&j| (pts[j] - pts[i]).norm_squared() <= SPREAD_M * SPREAD_M)
                        })
                    })
                })
            })
            .count();
        if rank > 0 && among as f64 >= SPREAD_SHARE * line.points.len() as f64 {
            continue;
        }
        for &i in &line.points {
            grid.entry(key(&pts[i])).or_default().push(i);
        }
        keep[k] = true;
    }
    lines
        .into_iter()
        .zip(keep)
        .filter_map(|(l, k)| k.then_some(l))
        .collect()
}

/// Lines that are one wall found twice (within `merge_deg` and `merge_m`, facing the same way):
/// merged and refitted.
fn merge_lines(mut lines: Vec<WallLine>, pts: &[Point2<f64>], p: &OutlineParams) -> Vec<WallLine> {
    lines.sort_by_key(|l| std::cmp::Reverse(l.points.len()));
    let mut out: Vec<WallLine> = Vec::new();
    for l in lines {
        let centre = l
            .points
            .iter()
            .fold(Vector2::zeros(), |a, &i| a + pts[i].coords)
            / l.points.len().max(1) as f64;
        let same = out.iter_mut().find(|m| {
            m.n.dot(&l.n) >= p.merge_deg.to_radians().cos()
                && m.distance(&Point2::from(centre)).abs() <= p.merge_m
        });
        match same {
            Some(m) => {
                m.points.extend(l.points);
                let q: Vec<Point2<f64>> = m.points.iter().map(|&i| pts[i]).collect();
                if let Some((n, rho)) = fit_line(&q, &m.n) {
                    m.n = n;
                    m.rho = rho;
                }
            }
            None => out.push(l),
        }
    }
    out
}

/// Where floor or ceiling was seen: a raster of `cell_m` over the area, closed (gaps of one cell
/// filled).
struct Seen {
    origin: Point2<f64>,
    cell: f64,
    w: usize,
    h: usize,
    seen: Vec<bool>,
}

/// The index of the cell holding `q` on a raster of `w` × `h` cells of side `cell` from `origin`.
fn cell_index(
    q: &Point2<f64>,
    origin: &Point2<f64>,
    cell: f64,
    w: usize,
    h: usize,
) -> Option<usize> {
    let (x, y) = (
        ((q.x - origin.x) / cell).floor(),
        ((q.y - origin.y) / cell).floor(),
    );
    (x >= 0.0 && y >= 0.0 && (x as usize) < w && (y as usize) < h)
        .then(|| y as usize * w + x as usize)
}

impl Seen {
    fn new(evidence: &[Point2<f64>], lo: Point2<f64>, hi: Point2<f64>, cell: f64) -> Self {
        let w = (((hi.x - lo.x) / cell).ceil() as usize).clamp(1, 4000);
        let h = (((hi.y - lo.y) / cell).ceil() as usize).clamp(1, 4000);
        let mut seen = vec![false; w * h];
        for c in evidence
            .iter()
            .filter_map(|q| cell_index(q, &lo, cell, w, h))
        {
            seen[c] = true;
        }
        let grow = |s: &[bool], value: bool| {
            let mut out = s.to_vec();
            for y in 0..h {
                for x in 0..w {
                    if s[y * w + x] == value {
                        continue;
                    }
                    let hit = (y.saturating_sub(1)..(y + 2).min(h)).any(|yy| {
                        (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| s[yy * w + xx] == value)
                    });
                    if hit {
                        out[y * w + x] = value;
                    }
                }
            }
            out
        };
        let seen = grow(&grow(&seen, true), false);
        Self {
            origin: lo,
            cell,
            w,
            h,
            seen,
        }
    }

    /// The points of `evidence` in cells holding at least a quarter of the median non-empty cell's
    /// count.
    fn dense(&self, evidence: &[Point2<f64>]) -> Vec<Point2<f64>> {
        let cell = |q: &Point2<f64>| cell_index(q, &self.origin, self.cell, self.w, self.h);
        let mut count = vec![0usize; self.w * self.h];
        for q in evidence {
            if let Some(c) = cell(q) {
                count[c] += 1;
            }
        }
        let mut full: Vec<usize> = count.iter().copied().filter(|&n| n > 0).collect();
        full.sort_unstable();
        let median = full.get(full.len() / 2).copied().unwrap_or(0);
        evidence
            .iter()
            .filter(|q| cell(q).is_some_and(|c| 4 * count[c] >= median))
            .copied()
            .collect()
    }

    /// The share of the raster cells whose centres lie in the convex polygon `poly`, at least
    /// `margin` inside each of its edges, that were seen, and how many there were.
    fn share(&self, poly: &[Point2<f64>], margin: f64) -> (f64, usize) {
        let (mut lo, mut hi) = (poly[0], poly[0]);
        for q in poly {
            lo = lo.inf(q);
            hi = hi.sup(q);
        }
        let x0 = (((lo.x - self.origin.x) / self.cell).floor().max(0.0)) as usize;
        let y0 = (((lo.y - self.origin.y) / self.cell).floor().max(0.0)) as usize;
        let x1 = ((((hi.x - self.origin.x) / self.cell).ceil().max(0.0)) as usize).min(self.w);
        let y1 = ((((hi.y - self.origin.y) / self.cell).ceil().max(0.0)) as usize).min(self.h);
        let (mut total, mut seen) = (0usize, 0usize);
        for y in y0..y1 {
            for x in x0..x1 {
                let c = Point2::new(
                    self.origin.x + (x as f64 + 0.5) * self.cell,
                    self.origin.y + (y as f64 + 0.5) * self.cell,
                );
                if inside_convex_by(&c, poly, margin) {
                    total += 1;
                    seen += self.seen[y * self.w + x] as usize;
                }
            }
        }
        (seen as f64 / total.max(1) as f64, total)
    }
}

/// Whether `q` lies inside the counter-clockwise convex polygon, at least `margin` from each of
/// its edges' lines.
fn inside_convex_by(q: &Point2<f64>, poly: &[Point2<f64>], margin: f64) -> bool {
    (0..poly.len()).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let e = b - a;
        e.perp(&(q - a)) >= margin * e.norm()
    })
}

/// A cell of the arrangement: a convex counter-clockwise polygon, the line of each edge (edge `i`
/// from vertex `i` to `i + 1`; `None` for the search area's edge) and the cell's side of every
/// line.
#[derive(Clone, Debug)]
struct Cell {
    poly: Vec<Point2<f64>>,
    edge_line: Vec<Option<usize>>,
    side: Vec<bool>,
}

/// The part of a cell on the side of `line` where `distance ≥ 0` (`keep_positive`) or `≤ 0`; the
/// new edge is labelled with the line.
fn clip_cell(cell: &Cell, line: &WallLine, k: usize, keep_positive: bool) -> Option<Cell> {
    let sgn = if keep_positive { 1.0 } else { -1.0 };
    let d: Vec<f64> = cell.poly.iter().map(|q| sgn * line.distance(q)).collect();
    let n = cell.poly.len();
    let (mut poly, mut labels) = (Vec::new(), Vec::new());
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b) = (cell.poly[i], cell.poly[j]);
        if d[i] >= 0.0 {
            poly.push(a);
            labels.push(cell.edge_line[i]);
        }
        if (d[i] >= 0.0) != (d[j] >= 0.0) {
            let t = d[i] / (d[i] - d[j]);
            poly.push(a + (b - a) * t);
            // Entering the kept side continues edge i; leaving it runs along the line.
            labels.push(if d[i] >= 0.0 {
                Some(k)
            } else {
                cell.edge_line[i]
            });
        }
    }
    // Remove repeated vertices (an edge of zero length).
    let mut out_p: Vec<Point2<f64>> = Vec::with_capacity(poly.len());
    let mut out_l = Vec::with_capacity(poly.len());
    for (q, l) in poly.iter().zip(&labels) {
        if out_p
            .last()
            .is_some_and(|last: &Point2<f64>| (q - last).norm() < 1e-9)
        {
            *out_l.last_mut().expect("a label per vertex") = *l;
            continue;
        }
        out_p.push(*q);
        out_l.push(*l);
    }
    while out_p.len() > 1 && (out_p[0] - out_p[out_p.len() - 1]).norm() < 1e-9 {
        out_p.pop();
        out_l.pop();
    }
    if out_p.len() < 3 || mrtmap_geometry::polygon::signed_area(&out_p) < 1e-6 {
        return None;
    }
    let mut side = cell.side.clone();
    side[k] = keep_positive;
    Some(Cell {
        poly: out_p,
        edge_line: out_l,
        side,
    })
}

/// The room's outline from wall lines and where floor or ceiling was seen (`evidence`, points on
/// the floor plan). Adds, along each wall direction, lines at the evidence's extreme extent where
/// no wall was found there ([`infer_lines`]); cuts the evidence's box by every line
/// ([`Arrangement`]); keeps the cells the evidence fills and, of them, the connected region with
/// the largest area; walks its boundary into walls ([`loop_walls`]) and drops slivers.
pub fn outline(
    mut lines: Vec<WallLine>,
    evidence: &[Point2<f64>],
    p: &OutlineParams,
) -> Result<Outline, OutlineError> {
    if evidence.len() < 10 || lines.is_empty() {
        return Err(OutlineError::NothingSeen);
    }
    let (mut lo, mut hi) = (evidence[0], evidence[0]);
    for q in evidence {
        lo = lo.inf(q);
        hi = hi.sup(q);
    }
    let margin = Vector2::new(0.5, 0.5);
    let (lo, hi) = (lo - margin, hi + margin);
    let seen = Seen::new(evidence, lo, hi, p.cell_m);
    infer_lines(&mut lines, &seen.dense(evidence), p);
    let arrangement = Arrangement::new(&lines, lo, hi);
    let keep: Vec<bool> = arrangement
        .cells
        .iter()
        .map(|c| {
            let (share, total) = match seen.share(&c.poly, SPILL_M) {
                (_, 0) => seen.share(&c.poly, 0.0),
                inner => inner,
            };
            total > 0 && share >= KEEP_SHARE
        })
        .collect();
    let region = arrangement
        .largest_region(&keep)
        .ok_or(OutlineError::NothingSeen)?;
    let edges = arrangement.boundary(&region);
    let outer = chain(&edges)
        .into_iter()
        .max_by(|a, b| loop_area(a, &edges).total_cmp(&loop_area(b, &edges)))
        .ok_or(OutlineError::NothingSeen)?;
    let mut walls = loop_walls(&outer, &edges)?;
    drop_short_walls(&mut walls, &lines, p.min_length_m);
    if walls.len() < 3 {
        return Err(OutlineError::NothingSeen);
    }
    let normals = walls
        .iter()
        .map(|w| {
            let d = (w.end - w.start).normalize();
            Vector2::new(-d.y, d.x)
        })
        .collect();
    Ok(Outline {
        walls: walls.iter().map(|w| w.line).collect(),
        corners: walls.iter().map(|w| w.start).collect(),
        normals,
        lines,
    })
}

/// Adds inferred lines: along each well-seen line's normal (and its opposite), the extreme of the
/// evidence in well-filled raster cells (`dense`; the depth noise of a far wall scatters a few
/// floor points beyond it, the floor seen ends densely at the wall), where no line lies there.
/// Only the directions of well-seen walls: a weak line's direction would cut a corner off.
fn infer_lines(lines: &mut Vec<WallLine>, dense: &[Point2<f64>], p: &OutlineParams) {
    let found = lines.len();
    let densest = lines.iter().map(|l| l.density).fold(0.0, f64::max);
    for k in 0..found {
        if lines[k].density < STRONG_DENSITY * densest {
            continue;
        }
        for sgn in [1.0, -1.0] {
            let n = lines[k].n * sgn;
            let mut proj: Vec<f64> = dense.iter().map(|q| n.dot(&q.coords)).collect();
            if proj.is_empty() {
                continue;
            }
            proj.sort_by(f64::total_cmp);
            let rho = proj[proj.len() / 1000];
            let covered = lines.iter().any(|l| {
                l.n.dot(&n) >= (2.0 * p.merge_deg).to_radians().cos()
                    && (l.rho - rho).abs() <= 2.0 * p.merge_m
            });
            if !covered {
                lines.push(WallLine {
                    n,
                    rho,
                    points: Vec::new(),
                    inferred: true,
                    density: 0.0,
                    thickness: 0.0,
                });
            }
        }
    }
}

/// The cells the lines cut a box into, each known by its side of every line.
struct Arrangement {
    cells: Vec<Cell>,
    /// A cell's index by its sides.
    index: std::collections::HashMap<Vec<bool>, usize>,
}

/// A connected set of kept cells: each cell's region (`usize::MAX` for none) and the largest's.
struct Region {
    of_cell: Vec<usize>,
    root: usize,
}

/// A directed edge of a region's boundary, on wall line `line` (`None`: the search box's edge).
#[derive(Clone, Copy, Debug)]
struct BoundaryEdge {
    from: Point2<f64>,
    to: Point2<f64>,
    line: Option<usize>,
}

/// One wall of the outline's loop: on wall line `line`, from `start` to `end`.
#[derive(Clone, Copy, Debug)]
struct LoopWall {
    line: usize,
    start: Point2<f64>,
    end: Point2<f64>,
}

impl Arrangement {
    /// The box `lo`–`hi` cut by every line.
    fn new(lines: &[WallLine], lo: Point2<f64>, hi: Point2<f64>) -> Self {
        let mut cells = vec![Cell {
            poly: vec![lo, Point2::new(hi.x, lo.y), hi, Point2::new(lo.x, hi.y)],
            edge_line: vec![None; 4],
            side: vec![false; lines.len()],
        }];
        for (k, line) in lines.iter().enumerate() {
            cells = cells
                .iter()
                .flat_map(|c| [clip_cell(c, line, k, true), clip_cell(c, line, k, false)])
                .flatten()
                .collect();
        }
        let index = cells
            .iter()
            .enumerate()
            .map(|(i, c)| (c.side.clone(), i))
            .collect();
        Self { cells, index }
    }

    /// The cell across line `k` from cell `i`.
    fn neighbour(&self, i: usize, k: usize) -> Option<usize> {
        let mut s = self.cells[i].side.clone();
        s[k] = !s[k];
        self.index.get(&s).copied()
    }

    /// The connected kept cells with the largest area; `None` when none is kept.
    fn largest_region(&self, keep: &[bool]) -> Option<Region> {
        let cells = &self.cells;
        let mut comp = vec![usize::MAX; cells.len()];
        let mut best: Option<(f64, usize)> = None;
        for start in 0..cells.len() {
            if !keep[start] || comp[start] != usize::MAX {
                continue;
            }
            let (mut stack, mut area) = (vec![start], 0.0);
            comp[start] = start;
            while let Some(i) = stack.pop() {
                area += mrtmap_geometry::polygon::signed_area(&cells[i].poly);
                for k in cells[i].edge_line.iter().flatten() {
                    if let Some(j) = self.neighbour(i, *k)
                        && keep[j]
                        && comp[j] == usize::MAX
                    {
                        comp[j] = start;
                        stack.push(j);
                    }
                }
            }
            if best.is_none_or(|b| area > b.0) {
                best = Some((area, start));
            }
        }
        best.map(|(_, root)| Region {
            of_cell: comp,
            root,
        })
    }

    /// The region's boundary: each of its cells' edges whose neighbour across is not in it.
    fn boundary(&self, region: &Region) -> Vec<BoundaryEdge> {
        let inside = |i: usize| region.of_cell[i] == region.root;
        let mut edges = Vec::new();
        for (i, c) in self.cells.iter().enumerate() {
            if !inside(i) {
                continue;
            }
            for e in 0..c.poly.len() {
                let outside = match c.edge_line[e] {
                    None => true,
                    Some(k) => self.neighbour(i, k).is_none_or(|j| !inside(j)),
                };
                if outside {
                    edges.push(BoundaryEdge {
                        from: c.poly[e],
                        to: c.poly[(e + 1) % c.poly.len()],
                        line: c.edge_line[e],
                    });
                }
            }
        }
        edges
    }
}

/// The walls of a boundary loop: consecutive edges on one line merged; an edge on the search
/// box's frame (no wall line) means the outline does not close.
fn loop_walls(outer: &[usize], edges: &[BoundaryEdge]) -> Result<Vec<LoopWall>, OutlineError> {
    let mut runs: Vec<BoundaryEdge> = Vec::new();
    for &e in outer {
        let edge = edges[e];
        match runs.last_mut() {
            Some(last) if last.line == edge.line => last.to = edge.to,
            _ => runs.push(edge),
        }
    }
    if runs.len() > 1 && runs[0].line == runs[runs.len() - 1].line {
        let last = runs.pop().expect("more than one");
        runs[0].from = last.from;
    }
    runs.into_iter()
        .map(|r| match r.line {
            Some(line) => Ok(LoopWall {
                line,
                start: r.from,
                end: r.to,
            }),
            None => Err(OutlineError::Open(r.from, r.to)),
        })
        .collect()
}

/// A wall's line is placed anew from its wall's points at every height between its corners with
/// normals within this angle of the wall's: the lines are found from the points in the upper part
/// of the room whose normals lie within 20° of the wall's (furniture and noise make lines of their
/// own lower down), but on a thick fused wall those lie on its inner side. L-shaped walk 6: the
/// window wall's upper points with normals within 20° lie 13–15 mm inside at its west end and
/// 1 mm outside at its east end; its line was 7–16 mm inside along the window; refitted,
/// 6–8 mm.
const REFIT_NORMAL_DEG: f64 = 80.0;
/// Points this close to a wall's corners (m) are left out of its refit (the next wall's points).
const REFIT_END_M: f64 = 0.15;
/// A refit turning a line by more than this (degrees) or moving its walls' ends by more than
/// [`REFIT_MAX_MOVE_M`] is not taken: the refit corrects the few centimetres by which the points
/// with agreeing normals sit inside a thick wall, and a larger disagreement is the cloud bent at
/// other heights (T-shaped walk 1: a 3 m wall fused 2–6 cm inward below 1.5 m over half its
/// length; refitted, one end moved 5 cm and the node in front of it went from 0.143 to 0.333 K).
const REFIT_MAX_DEG: f64 = 2.0;
/// See [`REFIT_MAX_DEG`].
const REFIT_MAX_MOVE_M: f64 = 0.025;

/// Places each observed wall's line anew from the points `pts` (with their normals) of vertical
/// surfaces at every height along its wall (see [`REFIT_NORMAL_DEG`]), then the corners where the
/// lines meet.
pub fn refine_walls(
    o: &mut Outline,
    pts: &[Point2<f64>],
    normals: &[Vector2<f64>],
    weights: &[f64],
    p: &OutlineParams,
) {
    let n = o.walls.len();
    let cos_n = REFIT_NORMAL_DEG.to_radians().cos();
    let mut lines = o.walls.clone();
    lines.sort_unstable();
    lines.dedup();
    for l in lines {
        if o.lines[l].inferred {
            continue;
        }
        // This line's walls, as (start, end, inward normal).
        let spans: Vec<(Point2<f64>, Point2<f64>, Vector2<f64>)> = (0..n)
            .filter(|&k| o.walls[k] == l)
            .map(|k| (o.corners[k], o.corners[(k + 1) % n], o.normals[k]))
            .collect();
        let on_span = |q: &Point2<f64>, nq: &Vector2<f64>| {
            spans.iter().any(|(a, b, inward)| {
                let len = (b - a).norm();
                let s = (q - a).dot(&((b - a) / len.max(1e-9)));
                s >= REFIT_END_M && s <= len - REFIT_END_M && nq.dot(inward) >= cos_n
            })
        };
        let old = (o.lines[l].n, o.lines[l].rho);
        let mut fit = old;
        for _ in 0..3 {
            let idx: Vec<usize> = (0..pts.len())
                .filter(|&i| {
                    (fit.0.dot(&pts[i].coords) - fit.1).abs() <= WIDE_M
                        && on_span(&pts[i], &normals[i])
                })
                .collect();
            if idx.len() < p.min_points {
                break;
            }
            let q: Vec<Point2<f64>> = idx.iter().map(|&i| pts[i]).collect();
            let w: Vec<f64> = idx.iter().map(|&i| weights[i]).collect();
            let Some((nn, rho, _)) = trimmed_fit(&q, Some(&w), fit, (0.02, WIDE_M)) else {
                break;
            };
            fit = (nn, rho);
        }
        let moved = spans
            .iter()
            .flat_map(|(a, b, _)| [a, b])
            .fold(0.0f64, |m, q| m.max((fit.0.dot(&q.coords) - fit.1).abs()));
        if fit.0.dot(&old.0).clamp(-1.0, 1.0).acos().to_degrees() <= REFIT_MAX_DEG
            && moved <= REFIT_MAX_MOVE_M
        {
            o.lines[l].n = fit.0;
            o.lines[l].rho = fit.1;
        }
    }
    let corners: Vec<Point2<f64>> = (0..n)
        .map(|k| {
            meet(&o.lines[o.walls[(k + n - 1) % n]], &o.lines[o.walls[k]]).unwrap_or(o.corners[k])
        })
        .collect();
    o.normals = (0..n)
        .map(|k| {
            let d = (corners[(k + 1) % n] - corners[k]).normalize();
            Vector2::new(-d.y, d.x)
        })
        .collect();
    o.corners = corners;
}

/// Where lines `a` and `b` meet, unless they are within 20° of parallel.
fn meet(a: &WallLine, b: &WallLine) -> Option<Point2<f64>> {
    if a.direction().dot(&b.direction()).abs() > 20f64.to_radians().cos() {
        return None;
    }
    line_intersection(
        &Point2::from(a.n * a.rho),
        &a.direction(),
        &Point2::from(b.n * b.rho),
        &b.direction(),
    )
}

/// A wall shorter than this (m) whose line has under [`WEAK_DENSITY_SHARE`] of the point density of
/// both its neighbours is noise, not a wall, when its neighbours meet within [`WEAK_MEET_M`] of its
/// middle: a corner hidden behind furniture, seen only through the depth noise around it, cut
/// off by a slanted line (L-shaped walk 13: 0.45 m, 18 points per 10 cm against 91 and 101 for
/// the walls beside it, 9 cm thick against 2–5 cm, pushing the corner 20 cm out).
const WEAK_MAX_M: f64 = 1.0;
/// See [`WEAK_MAX_M`].
const WEAK_DENSITY_SHARE: f64 = 0.3;
/// See [`WEAK_MAX_M`].
const WEAK_MEET_M: f64 = 0.5;

/// Walls shorter than `min_m` (slivers where lines of noise cross near a corner) are removed:
/// the walls on either side are extended to meet, or, when those are parallel (a step), the
/// weaker of them goes too and the stronger meets the next. So are short walls of weak lines
/// between two well-seen walls that meet near them (see [`WEAK_MAX_M`]).
fn drop_short_walls(walls: &mut Vec<LoopWall>, lines: &[WallLine], min_m: f64) {
    let support = |k: usize| {
        if lines[k].inferred {
            0
        } else {
            lines[k].points.len()
        }
    };
    let weak = |walls: &[LoopWall], i: usize| {
        let n = walls.len();
        let (w, prev, next) = (&walls[i], &walls[(i + n - 1) % n], &walls[(i + 1) % n]);
        let (l, lp, ln) = (&lines[w.line], &lines[prev.line], &lines[next.line]);
        let mid = w.start + (w.end - w.start) / 2.0;
        !l.inferred
            && !lp.inferred
            && !ln.inferred
            && (w.end - w.start).norm() < WEAK_MAX_M
            && l.density < WEAK_DENSITY_SHARE * lp.density.min(ln.density)
            && meet(lp, ln).is_some_and(|c| (c - mid).norm() < WEAK_MEET_M)
    };
    while walls.len() > 3 {
        let n = walls.len();
        let Some(i) = (0..n)
            .filter(|&i| (walls[i].end - walls[i].start).norm() < min_m || weak(walls, i))
            .min_by(|&a, &b| {
                (walls[a].end - walls[a].start)
                    .norm()
                    .total_cmp(&(walls[b].end - walls[b].start).norm())
            })
        else {
            break;
        };
        let (prev, next) = ((i + n - 1) % n, (i + 1) % n);
        let (lp, ln) = (walls[prev].line, walls[next].line);
        let mid = walls[i].start + (walls[i].end - walls[i].start) / 2.0;
        if let Some(c) = meet(&lines[lp], &lines[ln])
            && (c - mid).norm() < 1.0
        {
            walls[prev].end = c;
            walls[next].start = c;
            walls.remove(i);
            continue;
        }
        // A step: drop the short wall and its weaker neighbour.
        let (weak, strong) = if support(lp) < support(ln) {
            (prev, next)
        } else {
            (next, prev)
        };
        let beyond = if weak == prev {
            (prev + n - 1) % n
        } else {
            (next + 1) % n
        };
        let Some(c) = meet(&lines[walls[strong].line], &lines[walls[beyond].line]) else {
            break;
        };
        if weak == prev {
            walls[beyond].end = c;
            walls[strong].start = c;
        } else {
            walls[strong].end = c;
            walls[beyond].start = c;
        }
        let (a, b) = if i > weak { (i, weak) } else { (weak, i) };
        walls.remove(a);
        walls.remove(b);
        // The loop may now hold one line twice in a row: merge such neighbours.
        let mut k = 0;
        while walls.len() > 3 && k < walls.len() {
            let j = (k + 1) % walls.len();
            if walls[k].line == walls[j].line {
                walls[k].end = walls[j].end;
                walls.remove(j);
            } else {
                k += 1;
            }
        }
    }
}

/// Chains directed edges into loops by matching each edge's end with another's start.
fn chain(edges: &[BoundaryEdge]) -> Vec<Vec<usize>> {
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut lp = vec![start];
        let mut cur = start;
        loop {
            let end = edges[cur].to;
            let next = (0..edges.len())
                .filter(|&j| !used[j] || j == start)
                .min_by(|&a, &b| {
                    (edges[a].from - end)
                        .norm()
                        .total_cmp(&(edges[b].from - end).norm())
                });
            match next {
                Some(j) if (edges[j].from - end).norm() < 1e-6 => {
                    if j == start {
                        loops.push(lp);
                        break;
                    }
                    used[j] = true;
                    lp.push(j);
                    cur = j;
                }
                _ => break,
            }
        }
    }
    loops
}

fn loop_area(lp: &[usize], edges: &[BoundaryEdge]) -> f64 {
    let pts: Vec<Point2<f64>> = lp.iter().map(|&e| edges[e].from).collect();
    mrtmap_geometry::polygon::signed_area(&pts)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wall points, their normals, and floor points.
    type Fixture = (Vec<Point2<f64>>, Vec<Vector2<f64>>, Vec<Point2<f64>>);

    /// Points every 3 cm along the polygon's edges (normals into the room) and filling it.
    fn room(poly: &[[f64; 2]], skip_wall: Option<usize>) -> Fixture {
        let (mut pts, mut nrm) = (Vec::new(), Vec::new());
        let n = poly.len();
        for k in 0..n {
            if Some(k) == skip_wall {
                continue;
            }
            let (a, b) = (Point2::from(poly[k]), Point2::from(poly[(k + 1) % n]));
            let d = (b - a).normalize();
            let inward = Vector2::new(-d.y, d.x);
            let steps = ((b - a).norm() / 0.03) as usize;
            for s in 0..steps {
                for layer in 0..8 {
                    pts.push(
                        a + (b - a) * (s as f64 / steps as f64)
                            + inward * (0.004 * (layer as f64 - 3.5)),
                    );
                    nrm.push(inward);
                }
            }
        }
        let p2: Vec<Point2<f64>> = poly.iter().map(|q| Point2::from(*q)).collect();
        let mut ev = Vec::new();
        for i in -10..310 {
            for j in -10..260 {
                let q = Point2::new(i as f64 * 0.02, j as f64 * 0.02);
                if mrtmap_geometry::polygon::point_in_polygon_fast(&q, &p2) {
                    ev.push(q);
                }
            }
        }
        (pts, nrm, ev)
    }

    const L: [[f64; 2]; 6] = [
        [0.0, 0.0],
        [6.0, 0.0],
        [6.0, 2.5],
        [3.5, 2.5],
        [3.5, 5.0],
        [0.0, 5.0],
    ];

    fn corners_match(o: &Outline, truth: &[[f64; 2]], tol: f64) {
        assert_eq!(o.corners.len(), truth.len(), "corners {:?}", o.corners);
        for t in truth {
            let near = o
                .corners
                .iter()
                .map(|c| (c - Point2::from(*t)).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(near < tol, "no corner near {t:?}: {:?}", o.corners);
        }
    }

    #[test]
    fn an_l_shaped_room_closes_with_six_walls() {
        let (pts, nrm, ev) = room(&L, None);
        let p = OutlineParams::default();
        let lines = wall_lines(&pts, &nrm, &p);
        let o = outline(lines, &ev, &p).expect("an outline");
        corners_match(&o, &L, 0.01);
        assert!(o.walls.iter().all(|&w| !o.lines[w].inferred));
        // Counter-clockwise, normals into the room.
        assert!(mrtmap_geometry::polygon::signed_area(&o.corners) > 0.0);
    }

    #[test]
    fn a_wall_never_seen_is_inferred_from_the_floor() {
        let (pts, nrm, ev) = room(&L, Some(1));
        let p = OutlineParams::default();
        let o = outline(wall_lines(&pts, &nrm, &p), &ev, &p).expect("an outline");
        // The inferred wall lies at the floor seen, here on a 2 cm grid: within a few
        // centimetres of the truth.
        corners_match(&o, &L, 0.05);
        let inferred: Vec<usize> = o
            .walls
            .iter()
            .copied()
            .filter(|&w| o.lines[w].inferred)
            .collect();
        assert_eq!(inferred.len(), 1);
    }

    #[test]
    fn a_line_inside_the_room_is_not_a_wall() {
        let (mut pts, mut nrm, ev) = room(&L, None);
        // A tall cupboard's side across the long leg.
        for s in 0..60 {
            for layer in 0..8 {
                pts.push(Point2::new(
                    2.0 + 0.004 * layer as f64,
                    0.5 + s as f64 * 0.03,
                ));
                nrm.push(Vector2::new(1.0, 0.0));
            }
        }
        let p = OutlineParams::default();
        let o = outline(wall_lines(&pts, &nrm, &p), &ev, &p).expect("an outline");
        corners_match(&o, &L, 0.01);
    }

    #[test]
    fn a_weak_slanted_line_across_a_hidden_corner_is_not_a_wall() {
        // The corner (0, 5) hidden behind a bookcase: the north wall seen only to x = 0.4, floor
        // noise seen 20 cm beyond the corner, and a sparse, thick slanted line from (0.4, 5.0) to
        // (0, 5.2) through it (L-shaped walk 13: 18 points per 10 cm against 91-101 beside it).
        let mut seen = L.to_vec();
        seen.splice(5..6, [[0.4, 5.0], [0.0, 5.2]]);
        let (wall_pts, wall_nrm, _) = room(&L, None);
        let (_, _, ev) = room(&seen, None);
        let (mut pts, mut nrm) = (Vec::new(), Vec::new());
        for (q, n) in wall_pts.iter().zip(&wall_nrm) {
            if q.y > 4.9 && q.x < 0.4 {
                continue; // the hidden part of the north wall
            }
            // Three passes over the walls: well-seen walls are dense.
            for _ in 0..3 {
                pts.push(*q);
                nrm.push(*n);
            }
        }
        let (a, b) = (Point2::new(0.4, 5.0), Point2::new(0.0, 5.2));
        let d = (b - a).normalize();
        let inward = Vector2::new(d.y, -d.x);
        // Its points scattered along 1.8 m of the line (past the corner and into the room's
        // noise): 17 per 10 cm against 80 on the walls, 4 cm from the line.
        for s in 0..75 {
            for off in [-0.06, -0.02, 0.02, 0.06] {
                pts.push(a + (b - a) * (-1.5 + 4.0 * s as f64 / 75.0) + inward * off);
                nrm.push(inward);
            }
        }
        let p = OutlineParams::default();
        let lines = wall_lines(&pts, &nrm, &p);
        assert!(
            lines
                .iter()
                .any(|l| l.n.dot(&inward).abs() > 0.95 && l.distance(&a).abs() < 0.05),
            "the slanted line is found: {:?}",
            lines
                .iter()
                .map(|l| (l.n, l.rho, l.density, l.thickness))
                .collect::<Vec<_>>()
        );
        let o = outline(lines, &ev, &p).expect("an outline");
        corners_match(&o, &L, 0.03);
    }

    /// A line through `pts` as `wall_lines` gives it (normal `n`, through `q`, `density` points
    /// per 10 cm).
    fn line_of(
        n: Vector2<f64>,
        q: Point2<f64>,
        points: std::ops::Range<usize>,
        density: f64,
    ) -> WallLine {
        WallLine {
            n,
            rho: n.dot(&q.coords),
            points: points.collect(),
            inferred: false,
            density,
            thickness: 0.02,
        }
    }

    #[test]
    fn a_wall_s_spread_is_not_a_line_of_its_own() {
        // A wall along y = 0 (x from 0 to 3 m, 1 cm thick), a wall meeting it at a right angle
        // at x = 3, and a 0.8 m wall at 50° from its start, 6 cm thick (a bay window's side).
        // Two lines of spread: 3 cm beyond the wall over its length, and 4 cm beyond both the
        // wall and the slanted wall, with more points than the slanted wall but sparser (bay
        // window walk 3: checked by number of points, that line hid the slanted wall).
        let mut pts = Vec::new();
        for i in 0..300 {
            for off in [-0.005, 0.0, 0.005] {
                pts.push(Point2::new(i as f64 * 0.01, off));
            }
        }
        let wall = 0..pts.len();
        for i in 0..300 {
            pts.push(Point2::new(i as f64 * 0.01, -0.03));
        }
        let spread = wall.end..pts.len();
        for i in 0..200 {
            pts.push(Point2::new(3.0, i as f64 * 0.01));
        }
        let side = spread.end..pts.len();
        let d = Vector2::new(50f64.to_radians().cos(), -50f64.to_radians().sin());
        let n_slant = Vector2::new(-d.y, d.x);
        for i in 0..80 {
            for off in [-0.03, 0.0, 0.03] {
                pts.push(Point2::origin() + d * (i as f64 * 0.01) + n_slant * off);
            }
        }
        let slant = side.end..pts.len();
        for i in 0..80 {
            pts.push(Point2::origin() + d * (i as f64 * 0.01) - n_slant * 0.07);
        }
        for i in 0..300 {
            pts.push(Point2::new(i as f64 * 0.01, -0.04));
        }
        let crossing = slant.end..pts.len();
        assert!(crossing.len() > slant.len());
        let y = Vector2::new(0.0, 1.0);
        let lines = vec![
            line_of(y, Point2::origin(), wall, 100.0),
            line_of(Vector2::new(-1.0, 0.0), Point2::new(3.0, 0.0), side, 100.0),
            line_of(y, Point2::new(0.0, -0.04), crossing, 30.0),
            line_of(n_slant, Point2::origin(), slant, 80.0),
            line_of(y, Point2::new(0.0, -0.03), spread, 30.0),
        ];
        let kept = drop_spread(lines, &pts);
        let densities: Vec<f64> = kept.iter().map(|l| l.density).collect();
        assert_eq!(densities, [100.0, 100.0, 80.0]);
    }

    #[test]
    fn a_bay_window_closes_although_the_floor_seen_spills_past_its_front_wall() {
        // A 5 x 4 m room with a trapezoidal bay 0.6 m deep on its south wall (the bay window
        // room of bench/rooms), and floor points seen up to 20 cm beyond the bay's front wall
        // (the depth noise 4 m away): the cell beyond the front wall between the bay's slanted
        // walls is thin, and 54 % of it holds floor points (kept as the room's when judged on
        // the whole cell).
        let bay = [
            [0.5, 0.6],
            [2.0, 0.6],
            [2.5, 0.0],
            [3.5, 0.0],
            [4.0, 0.6],
            [5.5, 0.6],
            [5.5, 4.6],
            [0.5, 4.6],
        ];
        let (pts, nrm, mut ev) = room(&bay, None);
        // Beyond the front wall, between the slanted walls' lines, floor points as the bay
        // window walk 1 saw them: per 5 cm of depth, 0.91, 0.55, 0.13 and 0.02 times the density
        // inside the room (about 11 points per 5 cm raster cell; here a 1 cm grid, each point
        // kept with that share of 11/25, in a fixed pseudo-random pattern).
        let share = [0.91, 0.55, 0.13, 0.02];
        let mut state = 12345u64;
        for i in 200..400 {
            for j in -20..0 {
                let q = Point2::new(i as f64 * 0.01, j as f64 * 0.01);
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                let between = q.y > -1.2 * (q.x - 2.5) && q.y > 1.2 * (q.x - 3.5);
                if between && u < share[((-j - 1) / 5) as usize] * 11.0 / 25.0 {
                    ev.push(q);
                }
            }
        }
        let p = OutlineParams::default();
        let o = outline(wall_lines(&pts, &nrm, &p), &ev, &p).expect("an outline");
        corners_match(&o, &bay, 0.02);
    }

    /// The y of the outline's corners on the south wall (y near 0).
    fn south_corners(o: &Outline) -> Vec<f64> {
        o.corners
            .iter()
            .filter(|c| c.y.abs() < 0.1)
            .map(|c| c.y)
            .collect()
    }

    #[test]
    fn a_thick_wall_is_placed_at_the_middle_of_all_its_points() {
        // The south wall fused thick: the points on its inner side have normals facing the room,
        // those on its outer side normals 40° off (as a noisy far wall's do). The lines are found
        // from normals within 20°, so the line lies on the inner side; the refit takes the
        // wall's middle, unless that moves the wall more than [`REFIT_MAX_MOVE_M`].
        let tilted = Vector2::new(40f64.to_radians().sin(), 40f64.to_radians().cos());
        // (half the thickness in cm, where the refit leaves the wall's corners (m)).
        for (half, expect) in [(4, 0.0), (6, 0.03)] {
            let (mut pts, mut nrm, ev) = room(&L, Some(0));
            for s in 0..200 {
                for layer in -half..=half {
                    pts.push(Point2::new(0.03 * s as f64, 0.01 * layer as f64));
                    nrm.push(if layer >= 0 { Vector2::y() } else { tilted });
                }
            }
            let p = OutlineParams::default();
            let mut o = outline(wall_lines(&pts, &nrm, &p), &ev, &p).expect("an outline");
            let before = south_corners(&o);
            assert_eq!(before.len(), 2, "corners {:?}", o.corners);
            let inner = 0.005 * half as f64;
            assert!(
                before.iter().all(|y| (y - inner).abs() < 0.003),
                "the line from agreeing normals lies in the inner half: {before:?}"
            );
            refine_walls(&mut o, &pts, &nrm, &vec![1.0; pts.len()], &p);
            assert!(
                south_corners(&o).iter().all(|y| (y - expect).abs() < 0.003),
                "refitted ({half} cm): {:?}",
                south_corners(&o)
            );
            corners_match(&o, &L, 0.031);
            assert!(mrtmap_geometry::polygon::signed_area(&o.corners) > 0.0);
            for k in 0..o.corners.len() {
                let d = o.corners[(k + 1) % o.corners.len()] - o.corners[k];
                assert!(o.normals[k].dot(&d).abs() < 1e-9 && o.normals[k].perp(&d) < 0.0);
            }
        }
    }

    #[test]
    fn a_wall_is_placed_by_its_measurements_not_by_its_sparsely_seen_points() {
        // The south wall at y = 0 fused as a fused cloud holds a noisy far wall: three layers seen
        // 40 times each about the surface, and the depth noise's long far tail, five layers
        // behind it (2–6 cm outside the room) seen once each. Counted as points the tail pulls
        // the wall out; weighted by what each point stands for it stays within 2 mm.
        let (mut pts, mut nrm, ev) = room(&L, Some(0));
        let mut w = vec![1.0; pts.len()];
        for s in 0..200 {
            for layer in -6..=1 {
                pts.push(Point2::new(0.03 * s as f64, 0.01 * layer as f64));
                nrm.push(Vector2::y());
                w.push(if layer >= -1 { 40.0 } else { 1.0 });
            }
        }
        let p = OutlineParams::default();
        let placed = |w: &[f64]| {
            let mut o = outline(wall_lines(&pts, &nrm, &p), &ev, &p).expect("an outline");
            refine_walls(&mut o, &pts, &nrm, w, &p);
            let y = south_corners(&o);
            assert_eq!(y.len(), 2, "corners {:?}", o.corners);
            y
        };
        let counted = placed(&vec![1.0; pts.len()]);
        assert!(
            counted.iter().all(|y| *y < -0.01),
            "counted as points, the tail pulls the wall out: {counted:?}"
        );
        let weighted = placed(&w);
        assert!(
            weighted.iter().all(|y| y.abs() < 0.002),
            "weighted by observations: {weighted:?}"
        );
    }

    #[test]
    fn nothing_seen_is_an_error() {
        let p = OutlineParams::default();
        assert_eq!(
            outline(Vec::new(), &[], &p).unwrap_err(),
            OutlineError::NothingSeen
        );
    }
}
