//! The thermal corners' numbering tied to the colour image's, and the first extrinsic.
//!
//! A plain checkerboard is numbered from what each camera sees: a quarter turn apart, or shifted
//! on a partly visible board.
//!
//! 1. The quarter turn ([`quarter_turns`]): for each pair posed by both cameras alone, the turn of
//!    the thermal numbering that makes the thermal camera's rotation relative to the colour
//!    camera smallest.
//! 2. The first extrinsic from the pairs that show the whole board in both images (their
//!    numbering is fixed once turned): the median of their offsets ([`median_offset`]) and the
//!    mean of their rotations near the medoid ([`mean_whole_rotation`]).
//! 3. The shift ([`tie_shifts`]): of every shift of a pair's thermal numbering, the one whose
//!    corners lie nearest where the colour view of the board, carried through the first
//!    extrinsic, puts them; a pair whose best shift is too far off or not clearly better than the
//!    next is rejected.

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use super::joint::PairStatus;
use super::mono::MonoResult;
use super::view_error;
use crate::CalibError;
use crate::board::Board;
use crate::detect::{Corner, Detection};

/// Relabels corners by k quarter turns then a shift that brings the smallest labels to (0, 0);
/// returns the new corners and the board-frame isometry S with X_new = S · X_old.
fn relabel(corners: &[Corner], k: u32, board: &Board) -> (Vec<Corner>, Isometry3<f64>) {
    let rot = |i: i32, j: i32| match k % 4 {
        0 => (i, j),
        1 => (-j, i),
        2 => (-i, -j),
        _ => (j, -i),
    };
    let turned: Vec<(i32, i32)> = corners.iter().map(|c| rot(c.i, c.j)).collect();
    let mi = turned.iter().map(|t| t.0).min().unwrap_or(0);
    let mj = turned.iter().map(|t| t.1).min().unwrap_or(0);
    let out = corners
        .iter()
        .zip(&turned)
        .map(|(c, t)| Corner {
            i: t.0 - mi,
            j: t.1 - mj,
            ..*c
        })
        .collect();
    let s = Isometry3::from_parts(
        Translation3::new(
            -mi as f64 * board.square_m,
            -mj as f64 * board.square_m,
            0.0,
        ),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), k as f64 * std::f64::consts::FRAC_PI_2),
    );
    (out, s)
}

/// The corners with their labels shifted by (`di`, `dj`).
fn shift(corners: &[Corner], di: i32, dj: i32) -> Vec<Corner> {
    corners
        .iter()
        .map(|c| Corner {
            i: c.i + di,
            j: c.j + dj,
            ..*c
        })
        .collect()
}

/// The board-frame isometry of a label shift by (`di`, `dj`) squares.
fn board_shift(board: &Board, di: i32, dj: i32) -> Isometry3<f64> {
    Isometry3::translation(di as f64 * board.square_m, dj as f64 * board.square_m, 0.0)
}

/// The median (the upper one of an even count; 0 when empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() { 0.0 } else { v[v.len() / 2] }
}

/// The mean of rotations (their quaternions summed on one hemisphere, normalised).
fn mean_rotation(q: &[UnitQuaternion<f64>]) -> UnitQuaternion<f64> {
    let Some(q0) = q.first() else {
        return UnitQuaternion::identity();
    };
    let mut acc = Quaternion::new(0.0, 0.0, 0.0, 0.0);
    for x in q {
        let s = if x.coords.dot(&q0.coords) < 0.0 {
            -1.0
        } else {
            1.0
        };
        acc += x.into_inner() * s;
    }
    UnitQuaternion::from_quaternion(acc)
}

/// A pair whose thermal corners were turned to the colour corners' orientation.
pub(super) struct Cand {
    k: usize,
    th: Vec<Corner>,
    /// colour camera_from_board.
    tc: Isometry3<f64>,
    /// thermal camera_from_board, in the turned numbering.
    tt: Isometry3<f64>,
}

/// Ties thermal labels to the colour labels, the quarter turn first: the turn that makes the
/// thermal camera's rotation relative to the colour camera smallest.
pub(super) fn quarter_turns(
    board: &Board,
    th_dets: &[Option<Detection>],
    rgb_alone: &MonoResult,
    thermal_alone: &MonoResult,
) -> Vec<Cand> {
    let mut cands = Vec::new();
    for (k, dt) in th_dets.iter().enumerate() {
        let (Some(tc), Some(tt), Some(dt)) =
            (rgb_alone.poses[k], thermal_alone.poses[k], dt.as_ref())
        else {
            continue;
        };
        let best = (0..4)
            .map(|q| {
                let (c, s) = relabel(&dt.corners, q, board);
                let tt2 = tt * s.inverse();
                let e = tt2 * tc.inverse();
                (e.rotation.angle(), c, tt2)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, c, tt2)) = best {
            cands.push(Cand {
                k,
                th: c,
                tc,
                tt: tt2,
            });
        }
    }
    cands
}

/// Whether a detection holds every inner corner of the board.
pub(super) fn full(board: &Board, d: &Option<Detection>) -> bool {
    d.as_ref().is_some_and(|d| {
        let (w, h) = d.extent();
        d.corners.len() == board.corners()
            && ((w, h) == (board.cols as i32, board.rows as i32)
                || (w, h) == (board.rows as i32, board.cols as i32))
    })
}

/// The thermal camera's position relative to the colour camera: the median over the pairs that
/// show the whole board in both images (their numbering is not ambiguous up to a shift).
pub(super) fn median_offset(
    board: &Board,
    cands: &[Cand],
    rgb_dets: &[Option<Detection>],
    th_dets: &[Option<Detection>],
) -> Result<Vector3<f64>, CalibError> {
    let ts: Vec<Vector3<f64>> = cands
        .iter()
        .filter(|c| full(board, &rgb_dets[c.k]) && full(board, &th_dets[c.k]))
        .map(|c| (c.tt * c.tc.inverse()).translation.vector)
        .collect();
    if ts.is_empty() {
        return Err(CalibError::NoCompletePair {
            cols: board.cols,
            rows: board.rows,
        });
    }
    Ok(Vector3::new(
        median(ts.iter().map(|t| t.x).collect()),
        median(ts.iter().map(|t| t.y).collect()),
        median(ts.iter().map(|t| t.z).collect()),
    ))
}

/// The pairs tied: index, colour camera_from_board, thermal_from_colour.
pub(super) type Tied = Vec<(usize, Isometry3<f64>, Isometry3<f64>)>;

/// The thermal camera's rotation relative to the colour camera from the pairs that show the whole
/// board in both images: the mean of those within 3° of their medoid (the one nearest all
/// others), so that a mismatched pair does not turn it.
pub(super) fn mean_whole_rotation(
    cands: &[Cand],
    whole: &dyn Fn(usize) -> bool,
) -> UnitQuaternion<f64> {
    let q: Vec<UnitQuaternion<f64>> = cands
        .iter()
        .filter(|c| whole(c.k))
        .map(|c| (c.tt * c.tc.inverse()).rotation)
        .collect();
    let spread = |a: &UnitQuaternion<f64>| q.iter().map(|b| a.angle_to(b)).sum::<f64>();
    let Some(medoid) = q.iter().min_by(|a, b| spread(a).total_cmp(&spread(b))) else {
        return UnitQuaternion::identity();
    };
    let near: Vec<UnitQuaternion<f64>> = q
        .iter()
        .filter(|r| r.angle_to(medoid) < 3f64.to_radians())
        .copied()
        .collect();
    mean_rotation(&near)
}

/// The largest error (in squares of the board as the thermal camera sees it) at which a thermal
/// numbering predicted from the colour view and the other pairs' extrinsic is accepted: a
/// neighbouring numbering lies one square away.
const TIE_SQUARES: f64 = 0.35;

/// Ties each candidate's thermal numbering to the colour one: of every shift of the board's
/// numbering, the one whose corners lie nearest where the colour camera's view of the board puts
/// them in the thermal image (through `e0`, the extrinsic of the pairs showing the whole board).
/// A pair whose best numbering is more than `TIE_SQUARES` of a square off, or not clearly better
/// than the next, is rejected with both distances.
pub(super) fn tie_shifts(
    board: &Board,
    cands: &[Cand],
    e0: &Isometry3<f64>,
    thermal: &PinholeCamera,
    whole: &dyn Fn(usize) -> bool,
    status: &mut [PairStatus],
) -> (Tied, Vec<Option<Vec<Corner>>>) {
    let mut used = Vec::new();
    let mut th_labels: Vec<Option<Vec<Corner>>> = vec![None; status.len()];
    let reach = (board.cols as i32).max(board.rows as i32);
    for cand in cands {
        let predicted = e0 * cand.tc;
        let mut tries: Vec<(f64, i32, i32)> = Vec::new();
        for di in -reach..=reach {
            for dj in -reach..=reach {
                // The colour numbering of a partly seen board starts where its view does, so
                // the thermal labels may run beyond it either way.
                let c = shift(&cand.th, di, dj);
                tries.push((view_error(thermal, &predicted, board, &c).rms_px, di, dj));
            }
        }
        tries.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(&(mut d, mut di, mut dj)) = tries.first() else {
            continue;
        };
        let mut next = tries.get(1).map_or(f64::INFINITY, |t| t.0);
        // The board's square as the thermal camera sees it at this pair's distance.
        let z = predicted.translation.vector.z.max(1e-3);
        let square_px = thermal.fx * board.square_m / z;
        // A pair whose both images show the whole board needs no shift (its numbering is fixed
        // once turned): kept unless it lies two squares off, for the fit's outlier test to judge.
        let (limit, ratio) = if whole(cand.k) {
            d = view_error(thermal, &predicted, board, &cand.th).rms_px;
            (di, dj, next) = (0, 0, f64::INFINITY);
            (2.0 * square_px, 0.0)
        } else {
            (TIE_SQUARES * square_px, 2.0)
        };
        if d > limit || next < ratio * d {
            status[cand.k] = PairStatus::Rejected(format!(
                "the thermal corners cannot be matched to the colour corners: the best numbering lies {d:.1} px from where the colour view and the other pairs put the board (the next {next:.1} px; accepted: under {limit:.1} px and half the next)"
            ));
            continue;
        }
        let tt = cand.tt * board_shift(board, di, dj).inverse();
        used.push((cand.k, cand.tc, tt * cand.tc.inverse()));
        th_labels[cand.k] = Some(shift(&cand.th, di, dj));
    }
    (used, th_labels)
}
