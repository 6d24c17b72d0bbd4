//! The held-out virtual photos the trust protocols use: the split's lamps through its
//! held-out cameras with the randomised in-camera stage, clean and made bad three ways
//! (patches in another order, the right half lit by another lamp, glare).

use crate::error::{EvalError, Result};
use crate::held_out::{on_grid, randomised_cameras, HeldOutPhotos, Setup};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::chart::Chart;
use spdcam_core::colorimetry::{srgb_decode, srgb_encode};
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::seed;
use spdcam_infer::Model;

/// Share of the chart's mean linear level the glare adds at its brightest corner.
pub const GLARE_LEVEL: f64 = 0.4;
/// Width (standard deviation, chart widths) of the glare's fall-off from that corner.
pub const GLARE_WIDTH: f64 = 0.35;

/// Feature rows with their true SPDs (peak 1, on the model's grid).
#[derive(Clone)]
pub struct Rows {
    /// Feature rows, one per photo.
    pub features: Vec<Vec<f64>>,
    /// Their true SPDs.
    pub truths: Vec<Vec<f64>>,
}

/// Held-out virtual photos of the lamps `part` of the split: clean, and the same shots made
/// bad three ways (patches in another order, the right half lit by another lamp, glare).
pub struct Shots {
    /// The photos as taken.
    pub clean: Rows,
    /// The same photos with the patches in a random order (a chart the model does not read).
    pub wrong_chart: Vec<Vec<f64>>,
    /// The right half of the chart lit by the next lamp of the split.
    pub half_lit: Vec<Vec<f64>>,
    /// The same two lights, each half of the chart exposed and white-balanced for its own
    /// light (two photos joined, or a camera that balances each region): every neutral patch
    /// stays grey, so only the coloured patches tell.
    pub half_balanced: Vec<Vec<f64>>,
    /// Per photo, how far apart its two lights are: the mean absolute change (feature
    /// units, 0–255) of the right half's coloured patches between [`Shots::half_balanced`]
    /// and the photo lit by its first lamp alone.
    pub balanced_change: Vec<f64>,
    /// Veiling glare from a lamp beside the chart ([`GLARE_LEVEL`], [`GLARE_WIDTH`]).
    pub glare: Vec<Vec<f64>>,
}

impl HeldOutPhotos {
    /// The lamps of `part`, `shots` photos each through the held-out cameras with the
    /// randomised in-camera stage (exposure, white balance, tone, JPEG, gradient).
    pub fn shots(
        &self,
        setup: &Setup,
        chart: &Chart,
        model: &Model,
        part: LampPart,
    ) -> Result<Shots> {
        let ids = setup
            .library
            .positions(setup.split.lamps(part), "the split's lamps")?;
        if ids.len() < 2 {
            return Err(EvalError::invalid(
                "the split names fewer than two lamps for this part",
            ));
        }
        let stream = seed::derive(self.seed, part as u64);
        let randomisation = randomised_cameras(&setup.cameras, stream, chart)?;
        let truth = on_grid(&setup.library, &model.grid())?;
        let cols = chart.layout.cols;
        let right: Vec<bool> = (0..chart.reflectances.len())
            .map(|p| 2 * (p % cols) >= cols)
            .collect();
        let glare_gain = glare(chart);
        let mut rng = SmallRng::seed_from_u64(seed::derive(stream, 0x5752_4f4e_4700_0001));
        let mut out = Shots {
            clean: Rows {
                features: Vec::new(),
                truths: Vec::new(),
            },
            wrong_chart: Vec::new(),
            half_lit: Vec::new(),
            half_balanced: Vec::new(),
            balanced_change: Vec::new(),
            glare: Vec::new(),
        };
        let neutral: Vec<bool> = {
            let mut n = vec![false; chart.feature_patches.len()];
            for (f, _) in chart.neutral_features() {
                n[f] = true;
            }
            n
        };
        let coloured_right: Vec<usize> = (0..chart.feature_patches.len())
            .filter(|&f| right[chart.feature_patches[f]] && !neutral[f])
            .collect();
        let (mut raw, mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (j, &i) in ids.iter().enumerate() {
            let other = ids[(j + 1) % ids.len()];
            for k in 0..self.shots {
                let (camera, ic) = randomisation.draw(stream, j as u64 * self.shots + k);
                a.clear();
                b.clear();
                c.clear();
                let light = camera.light(&setup.library.spds[i])?;
                let other_light = camera.light(&setup.library.spds[other])?;
                camera.features_fast_with(ic.as_ref(), &light, &mut raw, &mut a);
                camera.features_fast_two_lights(
                    ic.as_ref(),
                    &light,
                    &other_light,
                    &right,
                    &mut raw,
                    &mut b,
                );
                camera.features_fast_with(ic.as_ref(), &other_light, &mut raw, &mut c);
                let clean: Vec<f64> = a.iter().map(|&v| f64::from(v)).collect();
                let half: Vec<f64> = b.iter().map(|&v| f64::from(v)).collect();
                let balanced: Vec<f64> = chart
                    .feature_patches
                    .iter()
                    .enumerate()
                    .flat_map(|(f, &p)| {
                        let from = if right[p] { &c } else { &a };
                        from[3 * f..3 * f + 3].iter().map(|&v| f64::from(v))
                    })
                    .collect();
                let mut order: Vec<usize> = (0..chart.feature_patches.len()).collect();
                order.shuffle(&mut rng);
                let wrong: Vec<f64> = order
                    .iter()
                    .flat_map(|&p| clean[3 * p..3 * p + 3].to_vec())
                    .collect();
                let mean_linear =
                    clean.iter().map(|&v| srgb_decode(v / 255.0)).sum::<f64>() / clean.len() as f64;
                let glared: Vec<f64> = clean
                    .iter()
                    .enumerate()
                    .map(|(f, &v)| {
                        let lin =
                            srgb_decode(v / 255.0) + GLARE_LEVEL * mean_linear * glare_gain[f / 3];
                        255.0 * srgb_encode(lin.min(1.0))
                    })
                    .collect();
                let change = coloured_right
                    .iter()
                    .flat_map(|&f| (3 * f..3 * f + 3).map(|v| (balanced[v] - clean[v]).abs()))
                    .sum::<f64>()
                    / (3 * coloured_right.len()).max(1) as f64;
                out.clean.features.push(clean);
                out.clean.truths.push(truth[i].clone());
                out.wrong_chart.push(wrong);
                out.half_lit.push(half);
                out.balanced_change.push(change);
                out.half_balanced.push(balanced);
                out.glare.push(glared);
            }
        }
        Ok(out)
    }
}

/// Per feature patch of `chart`: the relative glare, 1 at the top-left corner falling off
/// as a Gaussian of [`GLARE_WIDTH`] chart widths (a lamp beside the chart, out of frame).
fn glare(chart: &Chart) -> Vec<f64> {
    let (rows, cols) = (chart.layout.rows as f64, chart.layout.cols as f64);
    chart
        .feature_patches
        .iter()
        .map(|&p| {
            let x = ((p % chart.layout.cols) as f64 + 0.5) / cols;
            let y = ((p / chart.layout.cols) as f64 + 0.5) / rows * rows / cols;
            (-(x * x + y * y) / (2.0 * GLARE_WIDTH * GLARE_WIDTH)).exp()
        })
        .collect()
}
