//! Synthetic photos of several charts at several places, each under its own light (or one
//! light at different levels, a chart in shadow): the photos the light at several places
//! is tested and measured on. Each chart is laid and painted as [`super::scene`] lays one;
//! the photo has one exposure (metered on the first chart under its light) and one white
//! balance, as a camera takes one photo, so the charts' levels compare as the lights'.

use super::geometry::quads_near;
use super::pocket::{case_dark, check_case_shadow, Case};
use super::scene::{
    chart_white, check_placement, check_scene_size, check_width_share, develop_whole, lay, paint,
    quad_area, Laid, SceneOptions, Seen,
};
use crate::camera::{self, Camera};
use crate::error::{Error, Result};
use crate::imageio;
use crate::raster::{Mosaic, RgbImage};
use crate::spectral::Spd;
use rand::rngs::SmallRng;
use rand::SeedableRng;

/// Most charts one scene holds.
pub const MAX_PLACES: usize = 8;

/// Draws of a chart's random placement before the scene is given up as too full.
const PLACEMENT_TRIES: usize = 200;

/// One chart of a scene of several.
#[derive(Debug, Clone)]
pub struct ScenePlace<'a> {
    /// The camera photographing this chart: the photo's camera with this chart (every
    /// place's camera must share the first one's sensor and settings, which develop the
    /// photo).
    pub camera: &'a Camera,
    /// The light on this chart.
    pub light: &'a Spd,
    /// The light's level against the SPD as given (0.5: half as bright, as in a shadow).
    pub level: f64,
    /// Where and how the chart lies: the chart's fields of [`SceneOptions`] (its share of
    /// the width, centre, rotation, tilt or perspective, shadow); the photo's fields are
    /// those given to [`photograph_places`].
    pub placing: SceneOptions,
    /// The chart held in a ColorChecker Passport's case, open flat beside its other page:
    /// the camera photographing that page (its chart from
    /// [`PassportPage::chart`](super::pocket::PassportPage::chart)); `None`: the chart alone.
    pub case: Option<&'a Camera>,
}

/// What is true about one chart of a scene of several.
#[derive(Debug, Clone)]
pub struct PlaceTruth {
    /// The chart's name.
    pub chart: String,
    /// Outer corners of its patch grid in the photo: the chart's TL, TR, BR, BL.
    pub corners: [[f64; 2]; 4],
    /// Patch side in photo pixels (the mean over the chart).
    pub patch_px: f64,
    /// Each feature patch as a flat, noise-free, unblurred patch would show at its centre
    /// (encoded sRGB, 0–255).
    pub expected_features: Vec<f32>,
    /// The light's luminance on the chart relative to the first chart's (1 for the first).
    pub relative_illuminance: f64,
}

/// A synthetic photo of several charts and what is true about each.
#[derive(Debug, Clone)]
pub struct PlacesPhoto {
    /// The JPEG file's bytes.
    pub jpeg: Vec<u8>,
    /// Per chart, in the order given.
    pub places: Vec<PlaceTruth>,
    /// The sensor's mosaic before any processing, for a raw file (`None` for a
    /// three-sensor camera).
    pub mosaic: Option<Mosaic>,
}

/// Photographs the charts of `places` in one scene `seed` of `options`' size, lens and JPEG
/// settings: each chart laid where its placing says (random places drawn again until no
/// two charts overlap), lit by its light at its level, the photo exposed for the first.
pub fn photograph_places(
    places: &[ScenePlace],
    seed: u64,
    options: &SceneOptions,
) -> Result<PlacesPhoto> {
    let Some(first) = places.first() else {
        return Err(Error::invalid("a scene needs at least one chart"));
    };
    if places.len() > MAX_PLACES {
        return Err(Error::invalid(format!(
            "{} charts in one scene: at most {MAX_PLACES}",
            places.len()
        )));
    }
    let (w, h) = (options.width, options.height);
    check_scene_size(w, h)?;
    for (k, place) in places.iter().enumerate() {
        check_width_share(place.placing.width_share)?;
        check_placement(&place.placing)?;
        if place.case.is_some() {
            check_case_shadow(place.placing.shadow, k + 1)?;
        }
        if !(place.level.is_finite() && place.level > 0.0) {
            return Err(Error::invalid(format!(
                "chart {}: the light's level {} must be above 0",
                k + 1,
                place.level
            )));
        }
    }
    let mut rng = SmallRng::seed_from_u64(seed);
    let (laid, cases) = lay_apart(places, &mut rng, options)?;
    let mut scale = None;
    let mut exposed = Vec::with_capacity(places.len());
    let mut pages = Vec::with_capacity(places.len());
    for place in places {
        let lit = Spd::new(
            *place.light.grid(),
            place.light.iter().map(|v| v * place.level).collect(),
        )?;
        let (one, s) = place.camera.exposed_chart_at(&[&lit], scale)?;
        scale = Some(s);
        exposed.push(one);
        pages.push(match place.case {
            Some(page) => Some(page.exposed_chart_at(&[&lit], scale)?.0),
            None => None,
        });
    }
    let mut scene = RgbImage::new(w, h);
    scene.planes =
        super::scene::background(&mut rng, w, h, chart_white(first.camera, &exposed[0][0]));
    for (k, (place, laid)) in places.iter().zip(&laid).enumerate() {
        if let (Some(page), Some(case), Some(page_exposed)) = (place.case, &cases[k], &pages[k]) {
            case.paint_frame(&mut scene, case_dark(page, &page_exposed[0]));
            paint(&mut scene, page, &case.page, page_exposed, None);
        }
        let exposed = &exposed[k];
        paint(
            &mut scene,
            place.camera,
            laid,
            exposed,
            place.placing.shadow,
        );
    }
    let glow = options.glow.map(|g| {
        let patches = first.camera.chart().reflectances.len();
        let mean = camera::patch_mean(&exposed[0][0], patches);
        (g, laid[0].corners[0], laid[0].grid_width_px(), mean)
    });
    let (developed, vignetting, quality) =
        develop_whole(first.camera, &mut scene, &mut rng, seed, options, glow)?;
    let seen = Seen {
        developer: first.camera,
        vignetting,
        glow,
        gains: developed.white_balance_gains,
        size: (w, h),
    };
    let reference = luminance(first.light) * first.level;
    let truths = places
        .iter()
        .zip(&laid)
        .zip(&exposed)
        .map(|((place, laid), exposed)| PlaceTruth {
            chart: place.camera.chart().name.clone(),
            corners: laid.corners,
            patch_px: laid.patch_px,
            expected_features: seen.features(place.camera, laid, exposed, place.placing.shadow),
            relative_illuminance: luminance(place.light) * place.level / reference,
        })
        .collect();
    Ok(PlacesPhoto {
        jpeg: imageio::encode_jpeg(&developed.image, quality)?,
        places: truths,
        mosaic: developed.mosaic,
    })
}

/// Σ S(λ)·ȳ(λ) of `spd` on its grid, enough to compare two lights' luminance (CIE 1931 2°).
fn luminance(spd: &Spd) -> f64 {
    crate::colorimetry::Observer::cie1931(spd.grid())
        .map(|o| o.cmf(1).iter().zip(spd.iter()).map(|(v, s)| v * s).sum())
        .unwrap_or(f64::NAN)
}

/// Every place's chart laid in the photo (with its case, if held in one), none overlapping
/// another (with a gap of a tenth of the smaller one's size): random placements are drawn
/// again; fixed ones that overlap, or a case that does not fit the photo, are an error
/// naming them.
fn lay_apart(
    places: &[ScenePlace],
    rng: &mut SmallRng,
    options: &SceneOptions,
) -> Result<(Vec<Laid>, Vec<Option<Case>>)> {
    let mut laid: Vec<Laid> = Vec::with_capacity(places.len());
    let mut cases: Vec<Option<Case>> = Vec::with_capacity(places.len());
    for (k, place) in places.iter().enumerate() {
        let placing = SceneOptions {
            width: options.width,
            height: options.height,
            ..place.placing.clone()
        };
        let fixed = placing.centre.is_some();
        let mut tries = 0;
        loop {
            let mut candidate = lay(place.camera, rng, &placing)?;
            let case = place
                .case
                .map(|page| Case::around(&candidate, page.chart()));
            if let Some(case) = &case {
                candidate.outline = case.outline;
                if !inside(&case.outline, options) {
                    if fixed || tries >= PLACEMENT_TRIES {
                        return Err(Error::invalid(format!(
                            "chart {}: its Passport case does not fit the photo; place it \
                             further in or make it smaller",
                            k + 1
                        )));
                    }
                    tries += 1;
                    continue;
                }
            }
            match laid.iter().position(|other| overlap(other, &candidate)) {
                None => {
                    laid.push(candidate);
                    cases.push(case);
                    break;
                }
                Some(j) if fixed || tries >= PLACEMENT_TRIES => {
                    return Err(Error::invalid(format!(
                        "charts {} and {} of the scene overlap; place them apart or make them \
                         smaller",
                        j + 1,
                        k + 1
                    )))
                }
                Some(_) => tries += 1,
            }
        }
    }
    Ok((laid, cases))
}

/// Whether `outline` lies inside the photo of `options`' size, 4 px from its edges.
fn inside(outline: &[[f64; 2]; 4], options: &SceneOptions) -> bool {
    let (w, h) = (options.width as f64, options.height as f64);
    outline
        .iter()
        .all(|p| p[0] > 4.0 && p[1] > 4.0 && p[0] < w - 4.0 && p[1] < h - 4.0)
}

/// Whether two laid charts' outlines (their canvases, border included, or their cases) come
/// nearer than a tenth of the smaller one's size.
fn overlap(a: &Laid, b: &Laid) -> bool {
    let (pa, pb) = (a.outline, b.outline);
    let gap = 0.1 * quad_area(&pa).min(quad_area(&pb)).sqrt();
    quads_near(&pa, &pb, gap)
}
