//! The optics stage: what the lens does to the light before the sensor. Veiling glare is
//! here; lateral chromatic aberration ([`super::aberration`]) belongs to the same box but
//! runs on the white-balanced image, where the thesis put it (section 3.1.5).

use super::patch_mean;

/// Veiling glare (ISO 18844): stray light scattered inside the lens adds a share of the
/// scene's mean level to every region, lifting dark patches most.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VeilingGlare {
    /// Each region's raw value gains this share of the mean raw value of the chart's
    /// patches (0 = none).
    pub share: f64,
}

impl VeilingGlare {
    /// Adds the glare to the raw region values in place; `patches` is the number of chart
    /// patches (the regions before the background).
    pub fn apply(&self, raw: &mut [[f32; 3]], patches: usize) {
        if self.share > 0.0 {
            let mean = patch_mean(raw, patches);
            let f = self.share as f32;
            raw.iter_mut()
                .for_each(|v| *v = std::array::from_fn(|c| v[c] + f * mean[c]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glare_adds_a_share_of_the_patch_mean_to_every_region() {
        // Two patches (mean 0.5, 1, 0.25) and the background.
        let mut raw = [[0.0f32, 1.0, 0.5], [1.0, 1.0, 0.0], [0.2, 0.2, 0.2]];
        VeilingGlare { share: 0.5 }.apply(&mut raw, 2);
        assert_eq!(
            raw,
            [[0.25, 1.5, 0.625], [1.25, 1.5, 0.125], [0.45, 0.7, 0.325]]
        );
    }
}
