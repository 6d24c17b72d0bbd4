//! Finding a chart: patch candidates ─► lattices ─► placed on each chart template in each
//! of the four in-plane rotations ─► the placement whose neutral patches are ordered by
//! lightness as their reflectances are (which any light keeps) and which covers the most
//! candidates wins. Or, from four corners the user gives, the rotation by the same rule.

use super::geometry::{quad_centre, quads_near, sort_corners, Homography};
use super::lateral_ca::{self, ChannelScales};
use super::lattice::{find_lattices, Lattice};
use super::load::Photo;
use super::pyramid::Level;
use super::refine::{refine, Start};
use super::segment::{find_blobs, Blob};
use super::{ChartTemplate, Detection, MIN_CONFIDENCE};
use crate::colorimetry::srgb_decode_f32;
use crate::error::{Error, Result};
use nalgebra::Matrix3;

/// Longer side (px) of the pyramid level searched first.
pub const DETECTION_SIZE: usize = 1000;
/// Most pixels of the finest pyramid level searched: a full-resolution level of a large
/// photo takes 24 bytes a pixel (3.6 GB at 150 Mpx) and a minute of search. At 8 Mpx a
/// chart a tenth of the photo's width is still 300 px wide, 25 px a patch of the SG.
const MAX_SEARCH_PIXELS: usize = 8_000_000;
/// Fewest blobs a lattice needs before it is placed on a template.
const MIN_LATTICE: usize = 6;
/// Smallest share of a template's patches a placement's lattice must cover.
const MIN_INLIER_SHARE: f64 = 0.1;

/// What the search saw, for the debug image when it fails.
#[derive(Debug, Clone, Default)]
pub struct SearchTrace {
    /// Patch candidates, centre and side in photo pixels.
    pub blobs: Vec<([f64; 2], f64)>,
    /// Best placement's outline (photo pixels) and confidence, even when rejected.
    pub best: Option<([[f64; 2]; 4], f64)>,
}

/// One placement of a lattice on a template.
#[derive(Debug, Clone)]
struct Candidate {
    template: usize,
    /// Chart → level coordinates.
    map: Homography,
    tau: f64,
    /// How grey the neutral patches are ([`greyness`]).
    greyness: f64,
    coverage: f64,
    /// Best score among the placements in the other three rotations.
    other_rotation_score: f64,
    fit_rms: f64,
    /// Share of the grid points in the ring just outside the chart that hold a blob.
    ring: f64,
    /// How much better the photo fits the patch grid here than shifted by half a patch
    /// ([`grid_support`]); measured only where the blobs alone do not reach
    /// [`MIN_CONFIDENCE`], else 0.
    support: f64,
}

impl Candidate {
    /// Patches found, in the neutrals' order, grey where the neutrals are (which tells the
    /// right way round from the wrong even where a shadow upsets the order), and nothing
    /// patch-like continuing the grid outside the chart (which a part of a larger chart
    /// has: six by four patches of the Digital SG, grey row included, otherwise read as a
    /// ColorChecker 24).
    fn score(&self) -> f64 {
        self.coverage + self.tau + self.greyness - self.ring
    }

    fn confidence(&self) -> f64 {
        let cov = (self.coverage / 0.6)
            .max(self.support / FULL_SUPPORT)
            .min(1.0);
        let order = self.tau.max(0.0);
        let margin = (0.5 + (self.score() - self.other_rotation_score)).clamp(0.0, 1.0);
        let fit = (1.0 - self.fit_rms / 0.25).clamp(0.0, 1.0);
        cov * order * margin * fit.sqrt()
    }
}

/// Finds one of `templates` in `photo`. Fails with a message that says so when no
/// placement reaches [`MIN_CONFIDENCE`].
pub fn detect(photo: &Photo, templates: &[ChartTemplate]) -> Result<Detection> {
    let (found, _) = detect_traced(photo, templates)?;
    found.ok_or_else(|| no_chart(photo, templates))
}

/// The error for a photo that shows none of `templates`.
pub(crate) fn no_chart(photo: &Photo, templates: &[ChartTemplate]) -> Error {
    let mut charts: Vec<String> = templates
        .iter()
        .map(|t| crate::chart::shown_chart_name(&t.name))
        .collect();
    charts.dedup();
    Error::invalid(format!(
        "{}: no chart found (looked for {}); give its corners with --corners x1,y1,…,x4,y4",
        photo.source,
        charts.join(", ")
    ))
}

/// [`detect`] that also returns what it saw.
pub fn detect_traced(
    photo: &Photo,
    templates: &[ChartTemplate],
) -> Result<(Option<Detection>, SearchTrace)> {
    detect_at(photo, templates, DETECTION_SIZE)
}

/// [`detect_traced`] searching first a level of about `size` px on its longer side (then
/// finer levels down to full resolution while nothing is found).
pub fn detect_at(
    photo: &Photo,
    templates: &[ChartTemplate],
    size: usize,
) -> Result<(Option<Detection>, SearchTrace)> {
    if templates.is_empty() {
        return Err(Error::invalid("no chart template to look for"));
    }
    let finest = finest_factor(photo.width, photo.height);
    let mut factor = Level::factor_for(photo.width, photo.height, size.max(1)).max(finest);
    let mut trace = SearchTrace::default();
    // A placement found by its support in the photo is kept aside while a finer level may
    // still find the chart by its patches (whose grid is the more exact).
    let mut extrapolated: Option<Detection> = None;
    let mut keep = |found: Option<(Detection, Start)>| -> Option<Detection> {
        match found? {
            (d, Start::Fitted) => Some(d),
            (d, Start::Extrapolated) => {
                if extrapolated
                    .as_ref()
                    .is_none_or(|e| d.confidence > e.confidence)
                {
                    extrapolated = Some(d);
                }
                None
            }
        }
    };
    let mut fringes = Fringes::default();
    loop {
        let level = fringes.align(Level::new(photo, factor));
        if let Some(found) = keep(search_traced(&level, factor as f64, templates, &mut trace)) {
            return Ok((
                Some(refined(photo, templates, found, finest, Start::Fitted)),
                trace,
            ));
        }
        // Small charts may need a finer level, down to the finest one searched.
        if factor <= finest {
            break;
        }
        factor = (factor / 2).max(finest);
    }
    // Charts whose patches are only a few pixels wide: the full-resolution photo enlarged.
    if factor == 1 && 4 * photo.width * photo.height <= MAX_SEARCH_PIXELS {
        let level = fringes.align(Level::new(photo, 1)).enlarged();
        if let Some(found) = keep(search_traced(&level, 0.5, templates, &mut trace)) {
            return Ok((
                Some(refined(photo, templates, found, finest, Start::Fitted)),
                trace,
            ));
        }
    }
    let found = extrapolated.map(|d| refined(photo, templates, d, finest, Start::Extrapolated));
    Ok((found, trace))
}

/// The lens's colour fringes, measured once (a relative magnification holds at every level)
/// and taken out of every level searched; they are measured and undone in the camera's own
/// RGB (see [`lateral_ca`]).
#[derive(Default)]
struct Fringes {
    scales: Option<ChannelScales>,
}

impl Fringes {
    /// `level` with the fringes taken out (measured on the first level given).
    fn align(&mut self, level: Level) -> Level {
        if self.scales.is_some_and(|s| s.is_negligible()) {
            return level;
        }
        let camera = lateral_ca::to_camera(&level);
        let scales = *self
            .scales
            .get_or_insert_with(|| lateral_ca::measure(&camera));
        if scales.is_negligible() {
            level
        } else {
            lateral_ca::to_display(&lateral_ca::undo(&camera, scales))
        }
    }
}

/// Finds every chart of `templates` in `photo` that no better placement overlaps, numbered
/// from left to right by their centres; empty when none reaches [`MIN_CONFIDENCE`]. The
/// levels are searched as [`detect_traced`] searches them, coarsest first; once charts are
/// found, a finer level is searched only while two or more charts are found (a photo of
/// several charts may hold smaller ones) or a lattice of patches lies outside them, so a
/// photo of one chart costs about what [`detect`] costs.
/// A placement found only by its support in the photo joins where no chart found by its
/// patches lies.
pub fn detect_all(
    photo: &Photo,
    templates: &[ChartTemplate],
) -> Result<(Vec<Detection>, SearchTrace)> {
    if templates.is_empty() {
        return Err(Error::invalid("no chart template to look for"));
    }
    let finest = finest_factor(photo.width, photo.height);
    let mut factor = Level::factor_for(photo.width, photo.height, DETECTION_SIZE).max(finest);
    let mut trace = SearchTrace::default();
    let mut fringes = Fringes::default();
    let mut found: Vec<Detection> = Vec::new();
    let mut extrapolated: Vec<Detection> = Vec::new();
    let mut keep = |placed: Vec<(Detection, Start)>, found: &mut Vec<Detection>| {
        for (d, start) in placed {
            match start {
                Start::Fitted => found.push(refined(photo, templates, d, finest, start)),
                Start::Extrapolated => extrapolated.push(d),
            }
        }
    };
    loop {
        let level = fringes.align(Level::new(photo, factor));
        let (placed, more) = search_all(&level, factor as f64, templates, &found, &mut trace);
        keep(placed, &mut found);
        if factor <= finest || (!found.is_empty() && !more) {
            break;
        }
        factor = (factor / 2).max(finest);
    }
    if found.is_empty() && factor == 1 && 4 * photo.width * photo.height <= MAX_SEARCH_PIXELS {
        let level = fringes.align(Level::new(photo, 1)).enlarged();
        let (placed, _) = search_all(&level, 0.5, templates, &found, &mut trace);
        keep(placed, &mut found);
    }
    extrapolated.sort_by(|a, b| b.confidence.total_cmp(&a.confidence));
    for d in extrapolated {
        if !found
            .iter()
            .any(|f| quads_near(&f.corners, &d.corners, 0.0))
        {
            found.push(refined(photo, templates, d, finest, Start::Extrapolated));
        }
    }
    found.sort_by(|a, b| {
        let (ca, cb) = (quad_centre(&a.corners), quad_centre(&b.corners));
        ca[0].total_cmp(&cb[0]).then(ca[1].total_cmp(&cb[1]))
    });
    Ok((found, trace))
}

/// Every confident placement on one level whose pixels are `scale` photo pixels wide that
/// overlaps neither a better one nor one of `found` (photo pixels), best first, each with
/// how its grid was placed; and whether a lattice of patches lies outside all of them.
fn search_all(
    level: &Level,
    scale: f64,
    templates: &[ChartTemplate],
    found: &[Detection],
    trace: &mut SearchTrace,
) -> (Vec<(Detection, Start)>, bool) {
    let blobs = find_blobs(level);
    let lattices = find_lattices(&blobs, MIN_LATTICE);
    let mut candidates: Vec<Candidate> = lattices
        .iter()
        .flat_map(|lattice| {
            templates
                .iter()
                .enumerate()
                .filter_map(|(ti, t)| place(level, &blobs, lattice, ti, t))
                .collect::<Vec<_>>()
        })
        .collect();
    weigh(level, scale, templates, &blobs, &mut candidates, trace);
    candidates.sort_by(|a, b| b.score().total_cmp(&a.score()));
    let outline = |c: &Candidate| {
        let map = c.map.scaled_output(scale);
        templates[c.template].corners().map(|p| map.apply(p))
    };
    if let Some(best) = candidates
        .iter()
        .max_by(|a, b| a.confidence().total_cmp(&b.confidence()))
    {
        let confidence = best.confidence();
        if trace.best.as_ref().is_none_or(|b| confidence >= b.1) {
            trace.best = Some((outline(best), confidence));
        }
    }
    let mut placed: Vec<(Detection, Start)> = Vec::new();
    for c in candidates
        .iter()
        .filter(|c| c.confidence() >= MIN_CONFIDENCE)
    {
        let corners = outline(c);
        let taken = found
            .iter()
            .chain(placed.iter().map(|p| &p.0))
            .any(|d| quads_near(&d.corners, &corners, 0.0));
        if taken {
            continue;
        }
        let start = if c.support > 0.0 {
            Start::Extrapolated
        } else {
            Start::Fitted
        };
        let detection = Detection {
            chart: templates[c.template].name.clone(),
            corners,
            homography: c.map.scaled_output(scale).to_rows(),
            confidence: c.confidence(),
        };
        placed.push((detection, start));
    }
    let charts: Vec<[[f64; 2]; 4]> = found
        .iter()
        .chain(placed.iter().map(|p| &p.0))
        .map(|d| d.corners)
        .collect();
    let outside: Vec<Blob> = blobs
        .iter()
        .filter(|b| {
            let p = [b.centre[0] * scale, b.centre[1] * scale];
            !charts.iter().any(|q| quads_near(q, &[p, p, p, p], 0.0))
        })
        .cloned()
        .collect();
    // A photo that shows several charts may hold smaller ones still, whose patches a coarse
    // level does not resolve (a Digital SG a tenth of the photo wide has patches of five
    // level pixels): it is searched finer.
    let more = charts.len() >= 2 || !find_lattices(&outside, MIN_LATTICE).is_empty();
    (placed, more)
}

/// `found` with its corners refined on the photo ([`refine`]).
fn refined(
    photo: &Photo,
    templates: &[ChartTemplate],
    found: Detection,
    finest: usize,
    start: Start,
) -> Detection {
    let Some(t) = templates.iter().find(|t| t.name == found.chart) else {
        return found;
    };
    let map = refine(photo, t, &found.map(), finest, start);
    Detection {
        corners: t.corners().map(|p| map.apply(p)),
        homography: map.to_rows(),
        ..found
    }
}

/// Searches one level whose pixels are `scale` photo pixels wide, noting what it saw in
/// `trace`; the detection when one reaches [`MIN_CONFIDENCE`], and whether its grid was
/// fitted to patches over the chart or extrapolated from a few of them.
fn search_traced(
    level: &Level,
    scale: f64,
    templates: &[ChartTemplate],
    trace: &mut SearchTrace,
) -> Option<(Detection, Start)> {
    let (mut candidates, blobs) = search_level(level, templates);
    weigh(level, scale, templates, &blobs, &mut candidates, trace);
    // The confident placement that scores best, else the most confident one (for the trace).
    let confident = candidates
        .iter()
        .filter(|c| c.confidence() >= MIN_CONFIDENCE)
        .max_by(|a, b| a.score().total_cmp(&b.score()));
    let c = match confident {
        Some(c) => c,
        None => candidates
            .iter()
            .max_by(|a, b| a.confidence().total_cmp(&b.confidence()))?,
    };
    let t = &templates[c.template];
    let map = c.map.scaled_output(scale);
    let corners = t.corners().map(|p| map.apply(p));
    let confidence = c.confidence();
    if trace.best.as_ref().is_none_or(|b| confidence >= b.1) {
        trace.best = Some((corners, confidence));
    }
    let start = if c.support > 0.0 {
        Start::Extrapolated
    } else {
        Start::Fitted
    };
    (confidence >= MIN_CONFIDENCE).then(|| {
        let found = Detection {
            chart: t.name.clone(),
            corners,
            homography: map.to_rows(),
            confidence,
        };
        (found, start)
    })
}

/// Notes a level's blobs (in photo pixels; the level's pixels are `scale` wide) in `trace`
/// when it placed candidates or nothing was noted yet; and for each candidate below
/// [`MIN_CONFIDENCE`] (too few patches segmented: a small or steep chart) lets the photo
/// itself say whether the grid sits on patches, and whether patches go on outside it.
fn weigh(
    level: &Level,
    scale: f64,
    templates: &[ChartTemplate],
    blobs: &[Blob],
    candidates: &mut [Candidate],
    trace: &mut SearchTrace,
) {
    if trace.blobs.is_empty() || !candidates.is_empty() {
        trace.blobs = blobs
            .iter()
            .map(|b| ([b.centre[0] * scale, b.centre[1] * scale], b.side() * scale))
            .collect();
    }
    for c in candidates.iter_mut() {
        if c.confidence() < MIN_CONFIDENCE {
            let t = &templates[c.template];
            c.support = grid_support(level, &t.patch_squares(), &c.map);
            let ring = grid_support(level, &ring_squares(t), &c.map);
            c.ring = c.ring.max((ring / FULL_SUPPORT).clamp(0.0, 1.0));
        }
    }
}

/// The smallest reduction factor the search goes down to: the level that keeps at most
/// [`MAX_SEARCH_PIXELS`] (full resolution for photos up to that size).
fn finest_factor(width: usize, height: usize) -> usize {
    let pixels = width as f64 * height as f64;
    (pixels / MAX_SEARCH_PIXELS as f64).sqrt().ceil().max(1.0) as usize
}

/// The best placement of each template on one level, and the level's blobs.
fn search_level(level: &Level, templates: &[ChartTemplate]) -> (Vec<Candidate>, Vec<Blob>) {
    let blobs = find_blobs(level);
    let lattices = find_lattices(&blobs, MIN_LATTICE);
    let mut best: Vec<Option<Candidate>> = vec![None; templates.len()];
    for lattice in &lattices {
        for (ti, t) in templates.iter().enumerate() {
            if let Some(c) = place(level, &blobs, lattice, ti, t) {
                if best[ti].as_ref().is_none_or(|b| c.score() > b.score()) {
                    best[ti] = Some(c);
                }
            }
        }
    }
    (best.into_iter().flatten().collect(), blobs)
}

/// Grid position (i, j) of a lattice → patch (column, row) of the chart for rotation `k`
/// (quarter turns) and shift `t`.
fn rotate(k: usize, p: [i32; 2]) -> [i32; 2] {
    match k {
        0 => p,
        1 => [p[1], -p[0]],
        2 => [-p[0], -p[1]],
        _ => [-p[1], p[0]],
    }
}

/// The lattice→chart-patch map as a matrix on homogeneous (i, j, 1).
fn rotation_matrix(k: usize, t: [i32; 2]) -> Matrix3<f64> {
    let (a, b, c, d) = match k {
        0 => (1.0, 0.0, 0.0, 1.0),
        1 => (0.0, 1.0, -1.0, 0.0),
        2 => (-1.0, 0.0, 0.0, -1.0),
        _ => (0.0, -1.0, 1.0, 0.0),
    };
    Matrix3::new(a, b, t[0] as f64, c, d, t[1] as f64, 0.0, 0.0, 1.0)
}

/// The best placement of `lattice` on template `t`, over rotations and shifts.
fn place(
    level: &Level,
    blobs: &[Blob],
    lattice: &Lattice,
    ti: usize,
    t: &ChartTemplate,
) -> Option<Candidate> {
    let n = t.patch_count() as f64;
    let (cols, rows) = (t.cols as i32, t.rows as i32);
    let half = t.patch_fraction / 2.0;
    // Chart coordinates → patch grid (column, row) as integers at patch centres.
    let chart_to_patch = Matrix3::new(1.0, 0.0, -half, 0.0, 1.0, -half, 0.0, 0.0, 1.0);
    let mut per_rotation: Vec<Option<Candidate>> = vec![None, None, None, None];
    for (k, slot) in per_rotation.iter_mut().enumerate() {
        let rotated: Vec<[i32; 2]> = lattice.members.iter().map(|m| rotate(k, m.1)).collect();
        let min_c = rotated.iter().map(|p| p[0]).min()?;
        let max_c = rotated.iter().map(|p| p[0]).max()?;
        let min_r = rotated.iter().map(|p| p[1]).min()?;
        let max_r = rotated.iter().map(|p| p[1]).max()?;
        for tc in (-max_c)..=(cols - 1 - min_c) {
            for tr in (-max_r)..=(rows - 1 - min_r) {
                let inside: Vec<usize> = (0..rotated.len())
                    .filter(|&m| {
                        let (c, r) = (rotated[m][0] + tc, rotated[m][1] + tr);
                        (0..cols).contains(&c) && (0..rows).contains(&r)
                    })
                    .collect();
                let inliers = inside.len();
                if inliers < MIN_LATTICE || (inliers as f64) < MIN_INLIER_SHARE * n {
                    continue;
                }
                let outside = rotated.len() - inliers;
                let coverage = inliers as f64 / (n + outside as f64);
                if slot.as_ref().is_some_and(|s| s.coverage > coverage + 0.3) {
                    continue;
                }
                // patch (c, r) → lattice (i, j) → level.
                let to_patch = rotation_matrix(k, [tc, tr]);
                let patch_to_lattice = to_patch.try_inverse()?;
                let map = Homography(lattice.map.0 * patch_to_lattice * chart_to_patch);
                let Some(neutral) = neutral_evidence(level, t, &map) else {
                    continue;
                };
                let fit_rms = {
                    let from: Vec<[f64; 2]> = inside
                        .iter()
                        .map(|&m| {
                            let p = lattice.members[m].1;
                            [p[0] as f64, p[1] as f64]
                        })
                        .collect();
                    let to: Vec<[f64; 2]> = inside
                        .iter()
                        .map(|&m| blobs[lattice.members[m].0].centre)
                        .collect();
                    let pitch = lattice_pitch(&lattice.map, &from);
                    lattice.map.rms_error(&from, &to) / pitch.max(1e-9)
                };
                let mut c = Candidate {
                    template: ti,
                    map,
                    tau: neutral.tau,
                    greyness: neutral.greyness,
                    coverage,
                    other_rotation_score: -1.0,
                    fit_rms,
                    ring: 0.0,
                    support: 0.0,
                };
                // The ring only lowers the score: measured only where it could still win.
                if slot.as_ref().is_some_and(|s| c.score() <= s.score()) {
                    continue;
                }
                // A blob cut by the photo's border is no evidence of a grid going on: the
                // background beside a chart at the edge is cut into patch-sized pieces.
                let cells = rotated
                    .iter()
                    .zip(&lattice.members)
                    .filter(|(_, m)| !blobs[m.0].may_touch_border(level.width, level.height))
                    .map(|(p, _)| (p[0] + tc, p[1] + tr));
                if lattice_goes_on(cells, cols, rows) {
                    continue;
                }
                c.ring = ring_share(blobs, t, &map);
                if slot.as_ref().is_none_or(|s| c.score() > s.score()) {
                    *slot = Some(c);
                }
            }
        }
    }
    let best_k = (0..4)
        .filter(|&k| per_rotation[k].is_some())
        .max_by(|&a, &b| {
            let sa = per_rotation[a].as_ref().map_or(f64::MIN, |c| c.score());
            let sb = per_rotation[b].as_ref().map_or(f64::MIN, |c| c.score());
            sa.total_cmp(&sb)
        })?;
    let other = (0..4)
        .filter(|&k| k != best_k)
        .filter_map(|k| per_rotation[k].as_ref().map(|c| c.score()))
        .fold(-1.0, f64::max);
    let mut best = per_rotation[best_k].take()?;
    best.other_rotation_score = other;
    Some(best)
}

/// The share of the grid points one step outside the chart's patch grid (the ring around
/// it) that lie within [`RING_SNAP`] of a blob's centre, mapped back through `map` (chart →
/// level). Near 0 for a whole chart on its background, near 1 for a part of a larger grid.
fn ring_share(blobs: &[Blob], t: &ChartTemplate, map: &Homography) -> f64 {
    let Some(back) = map.inverse() else {
        return 0.0;
    };
    let (cols, rows) = (t.cols as i32, t.rows as i32);
    let half = t.patch_fraction / 2.0;
    let mut hit = std::collections::HashSet::new();
    for b in blobs {
        let q = back.apply(b.centre);
        let (u, v) = (q[0] - half, q[1] - half);
        let (c, r) = (u.round(), v.round());
        if (u - c).hypot(v - r) > RING_SNAP {
            continue;
        }
        let (c, r) = (c as i32, r as i32);
        let on_ring = (-1..=cols).contains(&c)
            && (-1..=rows).contains(&r)
            && (c == -1 || c == cols || r == -1 || r == rows);
        if on_ring {
            hit.insert((c, r));
        }
    }
    hit.len() as f64 / (2 * (cols + rows) + 4) as f64
}

/// Whether the lattice a placement came from goes on past one of the chart's sides: the
/// line of cells one step beyond that side holds lattice members (`cells`: every member's
/// cell, in the template's columns and rows) in at least half its length, and two. A
/// chart's own lattice never does (its border lies there); a part of a larger grid does,
/// such as six by four patches of the ColorChecker Passport's other page beside its
/// ColorChecker 24, which otherwise reads as a second one. The members need not continue
/// patches found along the side: a page's dark patches are often missed. `cells` leaves out
/// members cut by the photo's border.
fn lattice_goes_on(cells: impl Iterator<Item = (i32, i32)>, cols: i32, rows: i32) -> bool {
    let cells: std::collections::HashSet<(i32, i32)> = cells.collect();
    let beyond = |line: &dyn Fn(i32) -> (i32, i32), n: i32| {
        let members = (0..n).filter(|&k| cells.contains(&line(k))).count();
        members >= 2 && 2 * members >= n as usize
    };
    beyond(&|r| (-1, r), rows)
        || beyond(&|r| (cols, r), rows)
        || beyond(&|c| (c, -1), cols)
        || beyond(&|c| (c, rows), cols)
}

/// Largest distance (in patch pitches) from a ring point to a blob that counts as a patch
/// continuing the grid there.
const RING_SNAP: f64 = 0.25;

/// Mean grid pitch (level px) of a lattice map around the given grid points.
fn lattice_pitch(map: &Homography, points: &[[f64; 2]]) -> f64 {
    let mut s = 0.0;
    for p in points {
        let a = map.apply(*p);
        let b = map.apply([p[0] + 1.0, p[1]]);
        let c = map.apply([p[0], p[1] + 1.0]);
        s += 0.5 * ((b[0] - a[0]).hypot(b[1] - a[1]) + (c[0] - a[0]).hypot(c[1] - a[1]));
    }
    s / points.len().max(1) as f64
}

/// Mean colour of the centre of every patch, sampled on `level` through `map` (chart →
/// level); `None` when a patch centre falls outside the level.
fn patch_colours(level: &Level, t: &ChartTemplate, map: &Homography) -> Option<Vec<[f32; 3]>> {
    let q = t.patch_fraction / 4.0;
    (0..t.patch_count())
        .map(|p| {
            let [cx, cy] = t.patch_centre(p);
            let centre = map.apply([cx, cy]);
            if !(centre[0] >= 0.0
                && centre[1] >= 0.0
                && centre[0] < level.width as f64
                && centre[1] < level.height as f64)
            {
                return None;
            }
            let mut sum = [0.0f32; 3];
            for dy in [-q, 0.0, q] {
                for dx in [-q, 0.0, q] {
                    let v = level.bilinear(map.apply([cx + dx, cy + dy]));
                    for c in 0..3 {
                        sum[c] += v[c] / 9.0;
                    }
                }
            }
            Some(sum)
        })
        .collect()
}

/// What the neutral patches of a placement say of it: their lightness order and how grey
/// they are, from one sampling of the patches ([`patch_colours`]).
#[derive(Debug, Clone, Copy)]
struct NeutralEvidence {
    /// Kendall's τ between the neutral patches' reflectances and their measured lightness
    /// ([`lightness_order`]).
    tau: f64,
    /// How much more alike in colour the neutral patches are than the chart's patches as a
    /// whole ([`greyness`]).
    greyness: f64,
}

/// [`NeutralEvidence`] of the placement `map` (chart → level) of `t`; `None` when a patch
/// lies outside the level or the chart has no pair of neutrals to order.
fn neutral_evidence(level: &Level, t: &ChartTemplate, map: &Homography) -> Option<NeutralEvidence> {
    let colours = patch_colours(level, t, map)?;
    Some(NeutralEvidence {
        tau: lightness_order(&colours, t)?,
        greyness: greyness(&colours, t),
    })
}

/// Kendall's τ between the neutral patches' reflectances and their measured lightness
/// (sum of the channels): +1 when the photo orders them as the chart does. Pairs whose
/// lightness differs by less than the quantisation (clipped or black) count as ties.
fn lightness_order(colours: &[[f32; 3]], t: &ChartTemplate) -> Option<f64> {
    let light: Vec<(f64, f64)> = t
        .neutrals
        .iter()
        .map(|&(p, r)| (r, colours[p].iter().map(|&v| v as f64).sum()))
        .collect();
    let (mut s, mut pairs) = (0.0, 0usize);
    for a in 0..light.len() {
        for b in a + 1..light.len() {
            let dr = light[a].0 - light[b].0;
            if dr.abs() < 0.02 * light[a].0.max(light[b].0) {
                continue;
            }
            pairs += 1;
            let dl = light[a].1 - light[b].1;
            if dl.abs() > 3.0 / 255.0 {
                s += (dr.signum() * dl.signum()) as f32 as f64;
            }
        }
    }
    (pairs > 0).then(|| s / pairs as f64)
}

/// 1 when the neutral patches share one colour (the light's), 0 when they differ in colour
/// as much as the chart's patches do: one minus the ratio of their off-axis shares, where a
/// set's off-axis share is the part of its linear RGB vectors' energy not along their
/// principal direction through the origin (1 − λ₁ / trace of the uncentred scatter matrix,
/// Jolliffe, *Principal Component Analysis*, 2002, §14.2.3). Unlike the lightness order it
/// holds in a shadow, which dims a patch without changing its colour.
fn greyness(colours: &[[f32; 3]], t: &ChartTemplate) -> f64 {
    let linear: Vec<nalgebra::Vector3<f64>> = colours
        .iter()
        .map(|c| nalgebra::Vector3::from(c.map(|v| f64::from(srgb_decode_f32(v)))))
        .collect();
    let off_axis = |patches: &mut dyn Iterator<Item = usize>| {
        let scatter: Matrix3<f64> = patches.map(|p| linear[p] * linear[p].transpose()).sum();
        let trace = scatter.trace();
        let largest = scatter.symmetric_eigenvalues().max();
        (trace > 0.0).then(|| 1.0 - largest / trace)
    };
    let neutrals = off_axis(&mut t.neutrals.iter().map(|n| n.0));
    let all = off_axis(&mut (0..colours.len()));
    match (neutrals, all) {
        (Some(n), Some(a)) if a > 1e-6 => (1.0 - n / a).clamp(0.0, 1.0),
        _ => 0.0,
    }
}

/// The chart's placement from four outer corners given in any order (photo pixels): the
/// corners are sorted and checked (inside the photo, convex), and of the four ways to lay
/// the chart on them the one whose sides fit the chart's aspect and whose neutral patches
/// are in lightness order is taken.
pub fn from_corners(
    photo: &Photo,
    template: &ChartTemplate,
    corners: &[[f64; 2]],
) -> Result<Detection> {
    Ok(
        corner_placements(photo, std::slice::from_ref(template), corners)?
            .remove(0)
            .1,
    )
}

/// [`from_corners`] for a photo that may show any of `templates`: each is laid on the
/// corners, and the one whose patches the rectified photo shows best is taken — the share
/// of the brightness variance in the patches' sampling squares that lies between patches
/// rather than within them (`template_fit`): a chart with another grid lays its squares
/// across patch edges. The fit of every template, best first, comes with it.
pub fn from_corners_any(
    photo: &Photo,
    templates: &[ChartTemplate],
    corners: &[[f64; 2]],
) -> Result<(Detection, Vec<(String, f64)>)> {
    let mut placed = corner_placements(photo, templates, corners)?;
    let fits = placed
        .iter()
        .map(|(fit, d)| (d.chart.clone(), *fit))
        .collect();
    Ok((placed.remove(0).1, fits))
}

/// Every template laid on the corners in its best orientation, with its fit; best first.
fn corner_placements(
    photo: &Photo,
    templates: &[ChartTemplate],
    corners: &[[f64; 2]],
) -> Result<Vec<(f64, Detection)>> {
    if templates.is_empty() {
        return Err(Error::invalid("no chart template to lay on the corners"));
    }
    let quad = sort_corners(corners, photo.width, photo.height)?;
    // The finest level searched: a foreshortened chart's patches may be a few pixels tall.
    let factor = finest_factor(photo.width, photo.height);
    let level = Level::new(photo, factor);
    let side = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let mut out = Vec::with_capacity(templates.len());
    for template in templates {
        let (w, h) = template.size();
        // Per orientation: the map, its neutral order, its fit.
        let mut ways = Vec::with_capacity(4);
        for s in 0..4 {
            let image: Vec<[f64; 2]> = (0..4).map(|k| quad[(s + k) % 4]).collect();
            let map = Homography::fit(&template.corners(), &image)?;
            let across = 0.5 * (side(image[0], image[1]) + side(image[2], image[3]));
            let down = 0.5 * (side(image[1], image[2]) + side(image[3], image[0]));
            let aspect_error = ((across / down) / (w / h)).ln().abs();
            let on_level = map.scaled_output(1.0 / factor as f64);
            let neutral =
                neutral_evidence(&level, template, &on_level).unwrap_or(NeutralEvidence {
                    tau: -1.0,
                    greyness: 0.0,
                });
            let fit = template_fit(&level, &template.patch_squares(), &on_level);
            ways.push((map, neutral, aspect_error, fit));
        }
        let best_fit = ways.iter().map(|w| w.3).fold(f64::NEG_INFINITY, f64::max);
        // Orientations that fit the grid clearly worse than the best are out of the running
        // (a quarter turn of a 6 × 4 grid); among the rest the neutrals' order and greyness
        // decide.
        let scores: Vec<f64> = ways
            .iter()
            .map(|(_, n, aspect, fit)| n.tau + n.greyness - 2.0 * aspect - 4.0 * (best_fit - fit))
            .collect();
        let chosen = (0..4)
            .max_by(|&a, &b| scores[a].total_cmp(&scores[b]))
            .ok_or_else(|| Error::invalid("no placement for the corners"))?;
        let other = (0..4)
            .filter(|&s| s != chosen)
            .map(|s| scores[s])
            .fold(-1.0, f64::max);
        let (map, neutral, _, fit) = ways.swap_remove(chosen);
        let confidence = neutral.tau.max(0.0) * (0.5 + scores[chosen] - other).clamp(0.0, 1.0);
        out.push((
            fit,
            Detection {
                chart: template.name.clone(),
                corners: template.corners().map(|p| map.apply(p)),
                homography: map.to_rows(),
                confidence,
            },
        ));
    }
    out.sort_by(|a, b| b.0.total_cmp(&a.0));
    Ok(out)
}

/// How well squares of a chart (chart coordinates) fit the photo through `map` (chart →
/// level): 5 × 5 points in each square, and the share of their brightness variance that
/// lies between the squares' means (the coefficient of determination of the partition
/// into squares, an analysis-of-variance R²). With the centre half of every patch
/// ([`ChartTemplate::patch_squares`]): near 1 when every square falls inside one flat
/// patch; low when squares straddle patch edges.
fn template_fit(level: &Level, squares: &[[[f64; 2]; 4]], map: &Homography) -> f64 {
    let mut values: Vec<Vec<f64>> = Vec::with_capacity(squares.len());
    for square in squares {
        let mut patch = Vec::with_capacity(25);
        for j in 0..5 {
            for i in 0..5 {
                let (a, b) = (i as f64 / 4.0, j as f64 / 4.0);
                let top = lerp(square[0], square[1], a);
                let bottom = lerp(square[3], square[2], a);
                let q = map.apply(lerp(top, bottom, b));
                if !(q[0] >= 0.0
                    && q[1] >= 0.0
                    && q[0] < level.width as f64
                    && q[1] < level.height as f64)
                {
                    continue;
                }
                patch.push(level.bilinear(q).iter().map(|&v| f64::from(v)).sum());
            }
        }
        values.push(patch);
    }
    let all: Vec<f64> = values.iter().flatten().copied().collect();
    if all.len() < 2 {
        return 0.0;
    }
    let grand = all.iter().sum::<f64>() / all.len() as f64;
    let total: f64 = all.iter().map(|v| (v - grand).powi(2)).sum();
    let within: f64 = values
        .iter()
        .filter(|p| !p.is_empty())
        .map(|p| {
            let m = p.iter().sum::<f64>() / p.len() as f64;
            p.iter().map(|v| (v - m).powi(2)).sum::<f64>()
        })
        .sum();
    if total <= 0.0 {
        return 0.0;
    }
    1.0 - within / total
}

/// A grid's support in the photo: [`template_fit`] of `squares` through `map` less the
/// best of the fits with the grid moved by half a patch pitch left, right, up or down.
/// Where the squares sit on a chart's patches they are flat (fit near 1) and moved by half
/// a pitch they straddle the patch edges (about 0.5 on a blurred Digital SG); on a flat or
/// textured background a grid fits as well moved as not (support near 0).
fn grid_support(level: &Level, squares: &[[[f64; 2]; 4]], map: &Homography) -> f64 {
    let here = template_fit(level, squares, map);
    let moved = [[0.5, 0.0], [-0.5, 0.0], [0.0, 0.5], [0.0, -0.5]]
        .iter()
        .map(|d| {
            let shift = Matrix3::new(1.0, 0.0, d[0], 0.0, 1.0, d[1], 0.0, 0.0, 1.0);
            template_fit(level, squares, &Homography(map.0 * shift))
        })
        .fold(f64::NEG_INFINITY, f64::max);
    here - moved
}

/// The centre halves of the cells one pitch outside the chart's patch grid (the ring that
/// [`ring_share`] counts blobs on): patches there mean a part of a larger chart.
fn ring_squares(t: &ChartTemplate) -> Vec<[[f64; 2]; 4]> {
    let (cols, rows) = (t.cols as i32, t.rows as i32);
    let h = t.patch_fraction / 4.0;
    let mut out = Vec::new();
    for r in -1..=rows {
        for c in -1..=cols {
            if c == -1 || c == cols || r == -1 || r == rows {
                let (x, y) = (
                    f64::from(c) + t.patch_fraction / 2.0,
                    f64::from(r) + t.patch_fraction / 2.0,
                );
                out.push([
                    [x - h, y - h],
                    [x + h, y - h],
                    [x + h, y + h],
                    [x - h, y + h],
                ]);
            }
        }
    }
    out
}

/// The grid support that counts as much as patches found on 60 % of the chart.
const FULL_SUPPORT: f64 = 0.25;

fn lerp(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::srgb_encode_f32;

    #[test]
    fn a_part_of_a_larger_grid_is_surrounded_by_patches() {
        // Issue 28: six by four patches of a Digital SG (its grey row among them) were read
        // as a ColorChecker 24; the blobs continuing the grid around them tell them apart.
        let t = ChartTemplate {
            name: "six_by_four".into(),
            rows: 4,
            cols: 6,
            patch_fraction: 0.84,
            feature_patches: (0..24).collect(),
            feature_names: Vec::new(),
            neutrals: Vec::new(),
        };
        let pitch = 20.0;
        let blob = |c: i32, r: i32| Blob {
            centre: [
                100.0 + pitch * (f64::from(c) + 0.42),
                80.0 + pitch * (f64::from(r) + 0.42),
            ],
            area: 280.0,
            colour: [0.5; 3],
            moments: [24.0, 0.0, 24.0],
        };
        let map = Homography(Matrix3::new(
            pitch, 0.0, 100.0, 0.0, pitch, 80.0, 0.0, 0.0, 1.0,
        ));
        let alone: Vec<Blob> = (0..4)
            .flat_map(|r| (0..6).map(move |c| blob(c, r)))
            .collect();
        assert_eq!(ring_share(&alone, &t, &map), 0.0);
        let within: Vec<Blob> = (-3..7)
            .flat_map(|r| (-4..10).map(move |c| blob(c, r)))
            .collect();
        assert_eq!(ring_share(&within, &t, &map), 1.0);
        // A chart at the edge of the larger grid: the ring's two sides inside it.
        let corner: Vec<Blob> = (0..7)
            .flat_map(|r| (0..10).map(move |c| blob(c, r)))
            .collect();
        let share = ring_share(&corner, &t, &map);
        assert!((share - 11.0 / 24.0).abs() < 1e-12, "{share}");
    }

    #[test]
    fn a_lattice_going_on_past_a_side_is_part_of_a_larger_grid() {
        let grid = |cols: std::ops::Range<i32>, rows: std::ops::Range<i32>| {
            rows.flat_map(move |r| cols.clone().map(move |c| (c, r)))
                .collect::<Vec<_>>()
        };
        // The chart's own lattice, some patches missed: it stops at its sides.
        let own: Vec<(i32, i32)> = grid(0..6, 0..4)
            .into_iter()
            .filter(|&(c, r)| (c + r) % 5 != 0)
            .collect();
        assert!(!lattice_goes_on(own.iter().copied(), 6, 4));
        // Six by four of a grid eight wide (the Passport's other page), at either end.
        assert!(lattice_goes_on(grid(0..8, 0..4).into_iter(), 6, 4));
        assert!(lattice_goes_on(grid(-2..6, 0..4).into_iter(), 6, 4));
        // Along a side whose own patches were partly missed, as a page's dark ones are.
        let missed = grid(0..8, 0..4)
            .into_iter()
            .filter(|&(c, r)| !(c == 5 && r != 1) && (c, r) != (7, 3));
        assert!(lattice_goes_on(missed, 6, 4));
        // One stray member beside a side is no grid going on.
        let stray = grid(0..6, 0..4).into_iter().chain([(6, 1), (2, -1)]);
        assert!(!lattice_goes_on(stray, 6, 4));
    }

    #[test]
    fn a_blob_cut_by_the_border_is_told_from_a_whole_one() {
        // A ColorChecker 24 at the top of a scene photo (colour experiment, CC24 under a
        // phosphor LED) was refused: two pieces of background cut by the top edge, in line
        // one step beyond its side, read as its grid going on.
        let rectangle = |centre: [f64; 2], w: f64, h: f64| Blob {
            centre,
            area: w * h,
            colour: [0.5; 3],
            moments: [w * w / 12.0, 0.0, h * h / 12.0],
        };
        let (width, height) = (1200, 900);
        // The pieces as segmented: 32 px tall, from the top row down.
        assert!(rectangle([700.5, 16.0], 74.0, 32.0).may_touch_border(width, height));
        assert!(rectangle([1190.0, 450.0], 20.0, 80.0).may_touch_border(width, height));
        assert!(rectangle([600.0, 880.0], 80.0, 40.0).may_touch_border(width, height));
        // Whole patches, near the edges and in the middle.
        assert!(!rectangle([60.0, 500.0], 80.0, 80.0).may_touch_border(width, height));
        assert!(!rectangle([600.0, 850.0], 80.0, 80.0).may_touch_border(width, height));
        assert!(!rectangle([600.0, 450.0], 80.0, 80.0).may_touch_border(width, height));
    }

    #[test]
    fn neutrals_are_grey_in_a_shadow_and_not_the_wrong_way_round() {
        // Issue 28: a ColorChecker 24 with a quarter of the light over its left half was
        // missed, its neutrals' lightness order upset; their colour is not.
        let chart =
            crate::chart::Chart::colorchecker24(&crate::spectral::Grid::SIMULATION).unwrap();
        let t = ChartTemplate::from_chart(&chart).unwrap();
        // A camera of three flat bands (blue below 490 nm, green to 580, red above) under
        // an equal-energy light, encoded: the neutral patches are grey.
        let wavelengths = chart.reflectances.wavelengths();
        let colours: Vec<[f32; 3]> = chart
            .reflectances
            .items()
            .iter()
            .map(|r| {
                let band = |lo: f64, hi: f64| {
                    let inside: Vec<f64> = wavelengths
                        .iter()
                        .zip(r)
                        .filter(|(w, _)| (lo..hi).contains(*w))
                        .map(|(_, v)| *v)
                        .collect();
                    srgb_encode_f32((inside.iter().sum::<f64>() / inside.len() as f64) as f32)
                };
                [band(580.0, 800.0), band(490.0, 580.0), band(300.0, 490.0)]
            })
            .collect();
        assert!(greyness(&colours, &t) > 0.95, "{}", greyness(&colours, &t));
        // The left half in a shadow leaving a quarter of the light (linear).
        let shadowed: Vec<[f32; 3]> = colours
            .iter()
            .enumerate()
            .map(|(p, c)| {
                if p % 6 < 3 {
                    c.map(|v| srgb_encode_f32(0.25 * srgb_decode_f32(v)))
                } else {
                    *c
                }
            })
            .collect();
        assert!(lightness_order(&shadowed, &t).unwrap() < 0.8);
        assert!(
            greyness(&shadowed, &t) > 0.95,
            "{}",
            greyness(&shadowed, &t)
        );
        // Turned half round, the neutrals' places hold the top row's colours.
        let turned: Vec<[f32; 3]> = (0..24).map(|p| colours[23 - p]).collect();
        assert!(greyness(&turned, &t) < 0.3, "{}", greyness(&turned, &t));
    }

    /// A level showing a grid of flat patches of alternating greys (pitch 10 px, gaps of 2
    /// px at 0.1) with its top-left patch corner at (20, 20); the rest is `background`.
    fn grid_level(background: f32) -> Level {
        let (w, h) = (160, 140);
        let plane: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i32 - 20, (i / w) as i32 - 20);
                if !(0..100).contains(&x) || !(0..80).contains(&y) {
                    return background;
                }
                let (c, r, u, v) = (x / 10, y / 10, x % 10, y % 10);
                if u >= 8 || v >= 8 {
                    0.1
                } else {
                    0.3 + 0.05 * ((c * 7 + r * 3) % 10) as f32
                }
            })
            .collect();
        Level {
            width: w,
            height: h,
            planes: [plane.clone(), plane.clone(), plane],
        }
    }

    #[test]
    fn a_grid_on_patches_is_supported_and_one_off_them_is_not() {
        // Issue 28: a small chart's blobs cover too little of it; the photo itself must
        // tell a grid on the patches from one on the background or between patches.
        let t = ChartTemplate {
            name: "ten_by_eight".into(),
            rows: 8,
            cols: 10,
            patch_fraction: 0.8,
            feature_patches: (0..80).collect(),
            feature_names: Vec::new(),
            neutrals: Vec::new(),
        };
        let at =
            |x: f64, y: f64| Homography(Matrix3::new(10.0, 0.0, x, 0.0, 10.0, y, 0.0, 0.0, 1.0));
        let level = grid_level(0.5);
        let on = grid_support(&level, &t.patch_squares(), &at(20.0, 20.0));
        assert!(on > 0.3, "on the patches: {on}");
        // Half a patch off: the squares straddle the edges and the gaps.
        let off = grid_support(&level, &t.patch_squares(), &at(25.0, 25.0));
        assert!(off < 0.0, "between the patches: {off}");
        // On the flat background beside the chart.
        let beside = grid_support(&level, &t.patch_squares(), &at(125.0, 55.0));
        assert!(beside.abs() < 0.05, "beside the chart: {beside}");
        // The ring of a whole chart on a flat background holds no patches; that of a
        // four-by-three part of it does.
        let ring = grid_support(&level, &ring_squares(&t), &at(20.0, 20.0));
        assert!(ring < 0.05, "ring of the whole chart: {ring}");
        let part = ChartTemplate {
            rows: 3,
            cols: 4,
            feature_patches: (0..12).collect(),
            ..t.clone()
        };
        let ring = grid_support(&level, &ring_squares(&part), &at(40.0, 40.0));
        assert!(ring > 0.3, "ring of a part: {ring}");
    }

    #[test]
    fn the_finest_level_searched_stays_small() {
        // Issue 15: a 30000×30000 photo without a chart aborted in the full-resolution
        // level; at 150 Mpx the search took 4.6 GB and a minute.
        assert_eq!(finest_factor(4000, 2000), 1);
        assert_eq!(finest_factor(15_000, 10_000), 5);
        for (w, h) in [(15_000, 10_000), (30_000, 30_000), (12_345, 678)] {
            let f = finest_factor(w, h);
            assert!(
                (w / f) * (h / f) <= MAX_SEARCH_PIXELS,
                "{w}×{h}: factor {f}"
            );
            assert!(f == 1 || (w / (f - 1)) * (h / (f - 1)) > MAX_SEARCH_PIXELS);
        }
    }
}
