//! The one patch sampler, shared by the virtual camera and by photos: which part of a patch
//! is read ([`SAMPLING_FRACTION`]) and the robust statistic that turns its pixels into a
//! feature ([`robust_mean`]). Simulated and real features differ only by what the pixels
//! show, never by how they were averaged.

/// Sampled side of a patch over the patch's side: the thesis samples 14×14 px of a 24×24 px
/// patch, centred (section 3.1.7); other sizes keep the proportion.
pub const SAMPLING_FRACTION: f64 = 14.0 / 24.0;

/// Share of pixels trimmed from each end of the lightness order.
const TRIM: f64 = 0.1;

/// Outliers lie beyond this many robust standard deviations of the median lightness.
const OUTLIER_SIGMAS: f32 = 4.0;

/// Consistency factor of the median absolute deviation for normally distributed values
/// (Rousseeuw & Croux 1993): σ ≈ 1.4826 · MAD.
const MAD_TO_SIGMA: f32 = 1.4826;

/// Lightness margin (encoded, 0…1) always kept, so a noise-free patch keeps every pixel.
const OUTLIER_FLOOR: f32 = 6.0 / 255.0;

/// Reusable buffers for [`robust_mean`], so a loop over many patches allocates nothing.
#[derive(Debug, Clone, Default)]
pub struct SampleBuffers {
    /// The pixels of the patch being sampled (encoded RGB, 0…1).
    pub pixels: Vec<[f32; 3]>,
    /// Each pixel's lightness order key (high 32 bits) and index (low 32 bits), sorted.
    order: Vec<u64>,
}

impl SampleBuffers {
    /// Buffers holding `pixels` (encoded RGB, 0…1), ready for [`robust_mean`].
    pub fn with_pixels(pixels: Vec<[f32; 3]>) -> SampleBuffers {
        SampleBuffers {
            pixels,
            order: Vec::new(),
        }
    }
}

/// A pixel's lightness, R + G + B.
fn lightness(v: &[f32; 3]) -> f32 {
    v[0] + v[1] + v[2]
}

/// An unsigned key in the order of [`f32::total_cmp`] (IEEE 754 totalOrder): negative
/// values have every bit flipped, the others only the sign bit.
fn order_key(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// The mean and standard deviation (encoded, 0…1) of the pixels in `buffers.pixels` after
/// dropping lightness outliers (beyond 4 robust standard deviations of the median, e.g.
/// specular glints, dust or clipped pixels) and trimming a tenth of the rest from each end
/// of the lightness order (a trimmed mean; Wilcox 2012, *Introduction to Robust Estimation*,
/// ch. 3). Lightness is R + G + B; pixels of equal lightness keep their order. An empty set
/// gives zeros.
///
/// The pixels are put in lightness order once (a sort of packed keys); the median absolute
/// deviation is then the `n/2`-th step of a walk outwards from the median (deviations grow
/// monotonically both ways), and the inliers are one contiguous run of that order.
pub fn robust_mean(buffers: &mut SampleBuffers) -> ([f64; 3], [f64; 3]) {
    let SampleBuffers { pixels, order } = buffers;
    let n = pixels.len();
    if n == 0 {
        return ([0.0; 3], [0.0; 3]);
    }
    // Patches hold far fewer than 2³² pixels (photos read at most tens of thousands).
    debug_assert!(n <= u32::MAX as usize);
    order.clear();
    order.extend(
        pixels
            .iter()
            .enumerate()
            .map(|(i, v)| u64::from(order_key(lightness(v))) << 32 | i as u64),
    );
    order.sort_unstable();
    let pixel = |k: usize| &pixels[(order[k] & 0xffff_ffff) as usize];
    let deviation = |k: usize, median: f32| (lightness(pixel(k)) - median).abs();
    let median = lightness(pixel(n / 2));
    // The (n/2)-th smallest deviation, 0-based: merge the two runs leaving the median.
    let (mut below, mut above) = (n / 2, n / 2);
    let mut mad = 0.0f32;
    for _ in 0..=n / 2 {
        let left = (below > 0).then(|| deviation(below - 1, median));
        let right = (above < n).then(|| deviation(above, median));
        match (left, right) {
            (Some(l), Some(r)) if l < r => (mad, below) = (l, below - 1),
            (Some(l), None) => (mad, below) = (l, below - 1),
            (_, Some(r)) => (mad, above) = (r, above + 1),
            (None, None) => break,
        }
    }
    let limit = OUTLIER_SIGMAS * MAD_TO_SIGMA * mad + OUTLIER_FLOOR;
    let mut first = 0;
    while deviation(first, median) > limit {
        first += 1;
    }
    let mut end = n;
    while deviation(end - 1, median) > limit {
        end -= 1;
    }
    let cut = ((end - first) as f64 * TRIM) as usize;
    let core = first + cut..end - cut;
    let k = core.len() as f64;
    let mut mean = [0.0f64; 3];
    for v in core.clone().map(pixel) {
        for c in 0..3 {
            mean[c] += v[c] as f64;
        }
    }
    mean = mean.map(|s| s / k);
    let mut var = [0.0f64; 3];
    for v in core.map(pixel) {
        for c in 0..3 {
            var[c] += (v[c] as f64 - mean[c]).powi(2);
        }
    }
    (mean, var.map(|s| (s / k).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mean_of(pixels: Vec<[f32; 3]>) -> ([f64; 3], [f64; 3]) {
        robust_mean(&mut SampleBuffers::with_pixels(pixels))
    }

    #[test]
    fn glints_are_dropped_and_symmetric_noise_kept() {
        let mut v: Vec<[f32; 3]> = (0..100)
            .map(|i| {
                let d = ((i % 10) as f32 - 4.5) / 255.0;
                [0.4 + d, 0.3 + d, 0.2 + d]
            })
            .collect();
        v.extend(std::iter::repeat_n([0.99, 0.99, 0.99], 8));
        let (mean, _) = mean_of(v);
        assert!((mean[0] - 0.4).abs() < 1e-3, "{mean:?}");
        assert!((mean[2] - 0.2).abs() < 1e-3, "{mean:?}");
    }

    #[test]
    fn a_flat_patch_gives_its_value_and_no_spread() {
        let (mean, std) = mean_of(vec![[0.25, 0.5, 0.75]; 196]);
        assert_eq!(mean, [0.25, 0.5, 0.75]);
        assert_eq!(std, [0.0; 3]);
    }

    #[test]
    fn the_trimmed_mean_of_a_ramp_is_its_centre() {
        // 0, 1, …, 99 (× 1/300 in each channel): trimming 10 from each end keeps 10…89,
        // mean 49.5, standard deviation √((80² − 1)/12).
        let v: Vec<[f32; 3]> = (0..100).map(|i| [i as f32 / 300.0; 3]).collect();
        let (mean, std) = mean_of(v);
        assert!((mean[1] - 49.5 / 300.0).abs() < 1e-6, "{mean:?}");
        let expected = ((80.0f64 * 80.0 - 1.0) / 12.0).sqrt() / 300.0;
        assert!((std[1] - expected).abs() < 1e-6, "{std:?}");
    }

    #[test]
    fn no_pixels_give_zeros() {
        assert_eq!(mean_of(Vec::new()), ([0.0; 3], [0.0; 3]));
    }

    /// The definition written out directly (a stable sort, the median absolute deviation by
    /// selection, a filter, a trim): the fast version must give the same bits.
    fn direct(mut values: Vec<[f32; 3]>) -> ([f64; 3], [f64; 3]) {
        values.sort_by(|a, b| lightness(a).total_cmp(&lightness(b)));
        let median = lightness(&values[values.len() / 2]);
        let mut dev: Vec<f32> = values
            .iter()
            .map(|v| (lightness(v) - median).abs())
            .collect();
        let mid = dev.len() / 2;
        let mad = *dev.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
        let limit = OUTLIER_SIGMAS * MAD_TO_SIGMA * mad + OUTLIER_FLOOR;
        let inliers: Vec<[f32; 3]> = values
            .into_iter()
            .filter(|v| (lightness(v) - median).abs() <= limit)
            .collect();
        let cut = (inliers.len() as f64 * TRIM) as usize;
        let core = &inliers[cut..inliers.len() - cut];
        let k = core.len() as f64;
        let mean: [f64; 3] =
            std::array::from_fn(|c| core.iter().map(|v| v[c] as f64).sum::<f64>() / k);
        let var: [f64; 3] = std::array::from_fn(|c| {
            core.iter()
                .map(|v| (v[c] as f64 - mean[c]).powi(2))
                .sum::<f64>()
        });
        (mean, var.map(|s| (s / k).sqrt()))
    }

    proptest::proptest! {
        #[test]
        fn the_fast_robust_mean_equals_the_definition(
            levels in proptest::collection::vec((0u8..=255, 0u8..=255, 0u8..=255), 1..300),
            glints in 0usize..20,
        ) {
            // 8-bit levels, so that many pixels share a lightness (ties keep their order).
            let mut pixels: Vec<[f32; 3]> = levels
                .iter()
                .map(|&(r, g, b)| [r, g, b].map(|v| f32::from(v) / 255.0))
                .collect();
            pixels.extend(std::iter::repeat_n([1.0, 1.0, 1.0], glints));
            let fast = robust_mean(&mut SampleBuffers::with_pixels(pixels.clone()));
            proptest::prop_assert_eq!(fast, direct(pixels));
        }
    }

    #[test]
    fn order_keys_follow_total_order() {
        let xs = [-1.5f32, -0.0, 0.0, 1e-30, 0.5, 3.0, f32::INFINITY];
        for w in xs.windows(2) {
            assert!(order_key(w[0]) < order_key(w[1]), "{w:?}");
        }
    }
}
