//! The scene stage: the light as it falls on the chart. Real photos are rarely evenly lit;
//! a lamp off to one side brightens one edge of the chart, which the model must not read as
//! a change of colour.

/// Uneven lighting: the light's relative gain on a region is `1 + gradient[0]·x +
/// gradient[1]·y`, with x, y the region centre's position across the chart's patch grid
/// from −½ (left, top) to +½ (right, bottom); [0, 0] = even lighting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnevenLighting {
    /// The gain's slope across (x) and down (y) the chart.
    pub gradient: [f64; 2],
}

impl UnevenLighting {
    /// Multiplies each region's raw value by the gain at its centre (never below 0);
    /// `centres` holds each region's (x, y) position from −½ to ½ (the background sits at
    /// the centre).
    pub fn apply(&self, raw: &mut [[f32; 3]], centres: &[[f32; 2]]) {
        if self.gradient == [0.0, 0.0] {
            return;
        }
        let [gx, gy] = self.gradient.map(|g| g as f32);
        for (v, [x, y]) in raw.iter_mut().zip(centres) {
            let gain = (1.0 + gx * x + gy * y).max(0.0);
            *v = v.map(|c| c * gain);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gain_is_linear_across_the_chart_and_even_lighting_changes_nothing() {
        let centres = [[-0.5, 0.0], [0.5, 0.0], [0.0, 0.5]];
        let mut raw = [[1.0f32, 2.0, 4.0]; 3];
        UnevenLighting {
            gradient: [0.4, -1.0],
        }
        .apply(&mut raw, &centres);
        assert_eq!(raw[0], [0.8, 1.6, 3.2]);
        assert_eq!(raw[1], [1.2, 2.4, 4.8]);
        assert_eq!(raw[2], [0.5, 1.0, 2.0]);
        let mut even = [[1.0f32, 2.0, 4.0]; 3];
        UnevenLighting { gradient: [0.0; 2] }.apply(&mut even, &centres);
        assert_eq!(even, [[1.0, 2.0, 4.0]; 3]);
    }
}
