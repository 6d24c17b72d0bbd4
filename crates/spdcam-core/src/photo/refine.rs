//! Sub-pixel placement of a found chart: the grid fitted to the patch candidates' centroids
//! is off by a few per cent of a patch side (blobs trimmed by their edges, merged or
//! missing ones). Its four corners are moved, by a Nelder–Mead search, to where the
//! chart's patch edges are sharpest: the contrast between pairs of points a small distance
//! inside and outside every edge of every patch ([`edge_contrast`]). Each pair straddles
//! its edge symmetrically at the best placement, so the fit has no pull towards a smaller
//! or larger grid (as the variance within patch squares has: shrunk squares hold fewer
//! edge pixels). The distance starts wide, for a wide basin, and ends a fiftieth of a pitch,
//! where each pair reads the brightness gradient across its edge.

use super::geometry::Homography;
use super::lateral_ca::to_camera;
use super::load::Photo;
use super::pyramid::Level;
use super::ChartTemplate;
use crate::minimise::nelder_mead;

/// Patch pitch (level px) the refinement works at: coarser levels for large charts keep
/// the work per evaluation small; finer would add nothing but noise.
const WORKING_PITCH_PX: f64 = 32.0;
/// Smallest patch pitch (photo px) refined: below it the edges are a few pixels of blur,
/// demosaicing and JPEG blocks. On the detection protocol's photos (docs/detection.md),
/// with the lens's colour fringes taken out of the search, refining from 12 px on brought
/// the ColorChecker 24 at 1/15 of the width (18 px) from 5.9 % of a patch side to 2.9 %
/// and the SG at 1/8 (14 px) from 4.4 % to 3.7 %; from 7 px on, the SG at 1/12 (9.5 px)
/// from 3.5 % to 2.0 % (seed 1) and 3.4 % to 1.9 % (seed 2), at 1/15 (7.6 px) from 3.5 %
/// to 3.2 % and 3.9 % to 3.7 %.
const MIN_PITCH_PX: f64 = 7.0;
/// Points along each edge of a patch.
const EDGE_POINTS: usize = 5;
/// First step of the search, in patch pitches per corner coordinate (each later pass takes
/// a third of the one before).
const FIRST_STEP: f64 = 0.08;
/// Objective evaluations of the search: a sixth for the shift, the rest shared by the
/// three passes over the corners.
const EVALUATIONS: usize = 2000;
/// A corner moved farther than this (in pitches) means the search left the chart: the
/// placement it started from is kept. A third of a pitch, well short of the next patch:
/// on the detection protocol's Digital SG at 1/15 of the width (seed 2), a bound of 0.15
/// turned back two searches from grids 0.8–1 px off (7 px pitch), and 0.3 brought that
/// bucket's mean corner error from 3.7 % to 2.8 % of a patch side.
const MOST_MOVEMENT: f64 = 0.3;

/// Where a placement to refine comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Start {
    /// A grid fitted to patch candidates over most of the chart: refined only where the
    /// patches are at least [`MIN_PITCH_PX`] apart.
    Fitted,
    /// A grid extrapolated from patch candidates on a small part of the chart (found by its
    /// support in the photo): refined at any size.
    /// On the detection protocol's Digital SG at 1/8 of the width the mean corner error
    /// fell from 8.9 % to 3.6 % of a patch side.
    Extrapolated,
}
/// Distance of the point pairs from the edges in the first passes, in pitches: as wide as
/// the basin should be.
const WIDE_PAIRS: f64 = 0.15;
/// Distance of the point pairs from the edges in the middle pass, in level pixels (at most
/// half the gap between patches): about twice the width of a blurred edge, between the
/// wide basin of the first pass and the last pass's edge itself.
const MIDDLE_PAIRS_PX: f64 = 2.0;
/// Distance of the point pairs from the edges in the last pass, in pitches (at most half
/// the gap): pairs this close read the brightness gradient across each edge rather than
/// the contrast between a patch and what lies a pixel beyond it. Chosen on the detection
/// protocol's seed 3 (20 photos per bucket; seeds 1 and 2 are those reported) against the
/// earlier 1 level pixel: the Digital SG at 1/15 of the width 2.4 → 1.3 % of a patch side,
/// at 70° tilt 1.3 → 0.9 %, at 1/4 0.51 → 0.40 %; the ColorChecker 24 at 1/4 0.53 →
/// 0.43 %, under 25 % light 1.07 → 0.95 %, at 70° tilt 1.02 → 1.30 %. 0.03 pitches gave
/// the SG at 1/15 1.6 %; a fixed 0.15 level px, better for the SG, left the ColorChecker
/// 24 at 70° at 2.1–2.4 %.
const NARROW_PAIRS: f64 = 0.02;

/// Mean squared difference of the green channel between points `delta` (chart units, patch
/// pitches) inside and outside each patch's four edges, [`EDGE_POINTS`] pairs per edge,
/// through `map` (chart → level); pairs with a point off the level are left out. The
/// level is in the camera's own RGB ([`to_camera`]), and its green is read, because lateral
/// chromatic aberration moves the red and blue images of an edge (radially, by up to a
/// pixel or two at the frame's edge) but leaves green where the lens puts it, while the
/// photo's green mixes in red and blue through the camera's colour matrix. On the
/// detection protocol's ColorChecker 24 at 1/12 of the width (seed 7's three photos),
/// reading the photo's green left the corners 1–3 px off; the camera's green, 0.1–0.5 px.
fn edge_contrast(level: &Level, t: &ChartTemplate, map: &Homography, delta: f64) -> f64 {
    let inside_level = |q: [f64; 2]| {
        q[0] >= 0.0 && q[1] >= 0.0 && q[0] < level.width as f64 && q[1] < level.height as f64
    };
    let f = t.patch_fraction;
    let (mut sum, mut n) = (0.0, 0usize);
    for p in 0..t.patch_count() {
        let [cx, cy] = t.patch_centre(p);
        let (x0, y0) = (cx - f / 2.0, cy - f / 2.0);
        for k in 0..EDGE_POINTS {
            let along = f * (k as f64 + 0.5) / EDGE_POINTS as f64;
            // (inside, outside) for the top, bottom, left and right edges.
            let pairs = [
                ([x0 + along, y0 + delta], [x0 + along, y0 - delta]),
                ([x0 + along, y0 + f - delta], [x0 + along, y0 + f + delta]),
                ([x0 + delta, y0 + along], [x0 - delta, y0 + along]),
                ([x0 + f - delta, y0 + along], [x0 + f + delta, y0 + along]),
            ];
            for (a, b) in pairs {
                let (qa, qb) = (map.apply(a), map.apply(b));
                if inside_level(qa) && inside_level(qb) {
                    let (a, b) = (level.bilinear_channel(qa, 1), level.bilinear_channel(qb, 1));
                    sum += f64::from(a - b).powi(2);
                    n += 1;
                }
            }
        }
    }
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// `map` (chart → photo pixels) with its four corners moved to where `t`'s patch edges are
/// sharpest in `photo`; `map` itself when a fitted grid's patches are under
/// [`MIN_PITCH_PX`] apart, or the search finds nothing better or wanders off the chart.
/// `finest` is the smallest reduction factor the photo may be read at.
pub(super) fn refine(
    photo: &Photo,
    t: &ChartTemplate,
    map: &Homography,
    finest: usize,
    start: Start,
) -> Homography {
    let chart_corners = t.corners();
    let corners = chart_corners.map(|p| map.apply(p));
    if corners.iter().flatten().any(|v| !v.is_finite()) {
        return *map;
    }
    let (w, h) = t.size();
    let area = quad_area(&corners);
    let pitch = (area / (w * h)).sqrt();
    let min_pitch = match start {
        Start::Fitted => MIN_PITCH_PX,
        Start::Extrapolated => 0.0,
    };
    if !(pitch.is_finite() && pitch > 0.0 && pitch >= min_pitch) {
        return *map;
    }
    let factor = ((pitch / WORKING_PITCH_PX).floor() as usize)
        .max(finest)
        .max(1);
    let scale = factor as f64;
    // The chart's bounding box and a pitch around it, in level pixels.
    let lo = |k: usize| corners.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min);
    let hi = |k: usize| {
        corners
            .iter()
            .map(|c| c[k])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let origin = [0, 1].map(|k| ((lo(k) - pitch) / scale).floor().max(0.0) as usize);
    let end = [0, 1].map(|k| ((hi(k) + pitch) / scale).ceil().max(0.0) as usize);
    let size = [0, 1].map(|k| end[k].saturating_sub(origin[k]));
    let level = to_camera(&Level::window(photo, factor, origin, size));
    if level.width < 2 || level.height < 2 {
        return *map;
    }
    let to_level = |p: [f64; 2]| [0, 1].map(|k| p[k] / scale - origin[k] as f64);
    let start = corners.map(to_level);
    let step = pitch / scale;
    let placed = |x: &[f64; 8]| -> Option<Homography> {
        let moved: Vec<[f64; 2]> = (0..4)
            .map(|k| {
                [
                    start[k][0] + step * x[2 * k],
                    start[k][1] + step * x[2 * k + 1],
                ]
            })
            .collect();
        Homography::fit(&chart_corners, &moved).ok()
    };
    let gap = (1.0 - t.patch_fraction) / 2.0;
    let objective = |x: &[f64; 8], delta: f64| match placed(x) {
        Some(m) => -edge_contrast(&level, t, &m, delta),
        None => 0.0,
    };
    // The chart's shift first, with wide pairs; then the four corners, with a shrinking
    // simplex restarted where it collapsed and pairs narrowed to the gap.
    let (shift, _) = nelder_mead(
        &mut |v: &[f64; 2]| {
            objective(
                &[v[0], v[1], v[0], v[1], v[0], v[1], v[0], v[1]],
                WIDE_PAIRS,
            )
        },
        [0.0; 2],
        FIRST_STEP,
        EVALUATIONS / 6,
    );
    let mut best = [0, 1, 0, 1, 0, 1, 0, 1].map(|k| shift[k]);
    let narrow = gap.min(NARROW_PAIRS);
    let passes = [
        (FIRST_STEP, WIDE_PAIRS),
        (FIRST_STEP / 3.0, gap.min(MIDDLE_PAIRS_PX / step)),
        (FIRST_STEP / 9.0, narrow),
    ];
    for (first_step, delta) in passes {
        best = nelder_mead(
            &mut |x| objective(x, delta),
            best,
            first_step,
            EVALUATIONS / 4,
        )
        .0;
    }
    let before = objective(&[0.0; 8], narrow);
    let value = objective(&best, narrow);
    let moved_most = (0..4)
        .map(|k| best[2 * k].hypot(best[2 * k + 1]))
        .fold(0.0, f64::max);
    if value >= before || moved_most > MOST_MOVEMENT {
        return *map;
    }
    let Some(on_level) = placed(&best) else {
        return *map;
    };
    // Level → photo: add the window's origin, then scale.
    let refined_corners = chart_corners.map(|p| {
        let q = on_level.apply(p);
        [0, 1].map(|k| (q[k] + origin[k] as f64) * scale)
    });
    Homography::fit(&chart_corners, &refined_corners).unwrap_or(*map)
}

/// Area of a quadrilateral (shoelace formula).
fn quad_area(q: &[[f64; 2]; 4]) -> f64 {
    0.5 * (0..4)
        .map(|k| q[k][0] * q[(k + 1) % 4][1] - q[(k + 1) % 4][0] * q[k][1])
        .sum::<f64>()
        .abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photo::COLORCHECKER24_PATCH_FRACTION;

    fn template(cols: usize, rows: usize) -> ChartTemplate {
        ChartTemplate {
            name: "grid".into(),
            rows,
            cols,
            patch_fraction: COLORCHECKER24_PATCH_FRACTION,
            feature_patches: (0..rows * cols).collect(),
            feature_names: Vec::new(),
            neutrals: Vec::new(),
        }
    }

    /// A photo of `t` (patches of varied green, dark gaps, grey background) through `map`,
    /// each pixel the mean of 4 × 4 points inside it.
    fn photo_of(t: &ChartTemplate, map: &Homography, (w, h): (usize, usize)) -> Photo {
        let back = map.inverse().unwrap();
        let (cw, ch) = t.size();
        let pitch_gap = 1.0 - t.patch_fraction;
        let mut data = Vec::with_capacity(3 * w * h);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f64; 3];
                for sy in 0..4 {
                    for sx in 0..4 {
                        let p = [
                            x as f64 + (sx as f64 + 0.5) / 4.0,
                            y as f64 + (sy as f64 + 0.5) / 4.0,
                        ];
                        let q = back.apply(p);
                        let v = if q[0] < -pitch_gap
                            || q[1] < -pitch_gap
                            || q[0] > cw + pitch_gap
                            || q[1] > ch + pitch_gap
                        {
                            [120.0, 120.0, 120.0]
                        } else {
                            let (c, r) = (q[0].floor(), q[1].floor());
                            let inside = q[0] >= 0.0
                                && q[1] >= 0.0
                                && q[0] - c < t.patch_fraction
                                && q[1] - r < t.patch_fraction
                                && (c as usize) < t.cols
                                && (r as usize) < t.rows;
                            if inside {
                                let k = (r as usize * t.cols + c as usize) as f64;
                                let g = 40.0 + (k * 97.0) % 200.0;
                                [255.0 - g, g, 60.0 + (k * 53.0) % 180.0]
                            } else {
                                [20.0, 20.0, 20.0]
                            }
                        };
                        for c in 0..3 {
                            sum[c] += v[c] / 16.0;
                        }
                    }
                }
                data.extend(sum.map(|v| v.round() as u8));
            }
        }
        Photo::from_rgb8("grid.png", w, h, data).unwrap()
    }

    fn corner_error(t: &ChartTemplate, a: &Homography, b: &Homography) -> f64 {
        t.corners()
            .iter()
            .map(|&p| {
                let (u, v) = (a.apply(p), b.apply(p));
                (u[0] - v[0]).hypot(u[1] - v[1])
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_placement_off_by_a_tenth_of_a_patch_is_brought_onto_the_patches() {
        let t = template(6, 4);
        let truth_corners = [[52.3, 40.7], [251.9, 55.2], [243.4, 190.6], [47.8, 171.1]];
        let truth = Homography::fit(&t.corners(), &truth_corners).unwrap();
        let photo = photo_of(&t, &truth, (300, 230));
        let pitch = 200.0 / t.size().0;
        let off: Vec<[f64; 2]> = truth_corners
            .iter()
            .zip([[0.1, -0.05], [0.08, 0.06], [-0.04, 0.1], [0.1, 0.0]])
            .map(|(c, d)| [c[0] + d[0] * pitch, c[1] + d[1] * pitch])
            .collect();
        let start = Homography::fit(&t.corners(), &off).unwrap();
        assert!(corner_error(&t, &start, &truth) > 0.08 * pitch);
        let refined = refine(&photo, &t, &start, 1, Start::Fitted);
        let error = corner_error(&t, &refined, &truth);
        assert!(
            error < 0.02 * pitch,
            "worst corner {error:.2} px off, pitch {pitch:.1} px"
        );
        // The true placement fits better than the one it started from, and is kept.
        let level = Level::new(&photo, 1);
        let gap = (1.0 - t.patch_fraction) / 2.0;
        assert!(edge_contrast(&level, &t, &truth, gap) > edge_contrast(&level, &t, &start, gap));
        let again = refine(&photo, &t, &truth, 1, Start::Fitted);
        assert!(corner_error(&t, &again, &truth) < 0.02 * pitch);
    }

    #[test]
    fn a_fine_grid_with_gaps_under_half_a_pixel_is_refined() {
        // A Digital SG's grid (14 × 10, narrow gaps) with patches 7.5 px apart, as at 1/15
        // of a 1600 px photo: its gaps are under half a pixel wide.
        let t = ChartTemplate {
            patch_fraction: crate::photo::COLORCHECKER_SG_PATCH_FRACTION,
            ..template(14, 10)
        };
        let pitch = 7.5;
        let truth_corners = [
            [20.3, 15.6],
            [20.3 + 14.0 * pitch, 17.1],
            [21.9 + 14.0 * pitch, 16.4 + 10.0 * pitch],
            [19.2, 15.1 + 10.0 * pitch],
        ];
        let truth = Homography::fit(&t.corners(), &truth_corners).unwrap();
        let photo = photo_of(&t, &truth, (150, 110));
        let off: Vec<[f64; 2]> = truth_corners
            .iter()
            .zip([[0.06, -0.04], [-0.05, 0.06], [0.05, 0.05], [-0.06, 0.0]])
            .map(|(c, d)| [c[0] + d[0] * pitch, c[1] + d[1] * pitch])
            .collect();
        let start = Homography::fit(&t.corners(), &off).unwrap();
        let refined = refine(&photo, &t, &start, 1, Start::Fitted);
        let error = corner_error(&t, &refined, &truth);
        assert!(corner_error(&t, &start, &truth) > 0.07 * pitch);
        // Noise-free and sharp, the last pass's narrow pairs read a gradient that bilinear
        // interpolation makes flat within a pixel: 0.03 of a pitch here (pairs half the
        // gap wide: 0.016); on blurred, noisy photos they place such grids best (see
        // `NARROW_PAIRS`).
        assert!(
            error < 0.04 * pitch,
            "worst corner {error:.2} px off, pitch {pitch:.1} px"
        );
    }

    #[test]
    fn a_placement_off_the_photo_is_kept_as_it_is() {
        let t = template(6, 4);
        let photo = Photo::from_rgb8("flat.png", 64, 64, vec![128; 3 * 64 * 64]).unwrap();
        let far = Homography::fit(
            &t.corners(),
            &[
                [500.0, 500.0],
                [700.0, 500.0],
                [700.0, 640.0],
                [500.0, 640.0],
            ],
        )
        .unwrap();
        assert_eq!(refine(&photo, &t, &far, 1, Start::Fitted), far);
    }
}
