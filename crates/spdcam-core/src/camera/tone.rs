//! The image processor's rendering after the colour matrix, as a JPEG camera does it:
//! colour saturation, a highlight shoulder, a tone curve beyond the sRGB gamma, a contrast
//! S-curve, and the JPEG's quantisation of flat patches. Every parameter's neutral value
//! leaves the sRGB encoding alone.

use super::colour::ColourTransform;

/// Rec. 709 / sRGB luminance weights of linear R, G, B.
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// The rendering's parameters (see [`super::in_camera::InCamera`] for their ranges).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToneRendering {
    /// Colour saturation in linear sRGB about the luminance (1 = unchanged).
    pub saturation: f64,
    /// Linear values above `1 − shoulder` roll off smoothly towards 1 (0 = hard clip).
    pub shoulder: f64,
    /// Power on linear values before encoding (1 = the sRGB curve alone).
    pub gamma: f64,
    /// S-curve on encoded values `y + contrast·y(1−y)(2y−1)` (0 = none).
    pub contrast: f64,
    /// JPEG quality (1–100) whose DC quantisation steps round each pixel; `None`: no JPEG.
    pub jpeg_quality: Option<u8>,
    /// Black floor on encoded values: `floor + (1 − floor)·y` (0 = none).
    pub floor: f64,
}

impl ToneRendering {
    /// Linear sRGB (from the colour matrix) → encoded sRGB on 0…1, unquantised.
    pub fn encode(&self, colour: &ColourTransform, linear: [f32; 3]) -> [f32; 3] {
        let mut v = linear;
        if self.saturation != 1.0 {
            let y = LUMA[0] * v[0] + LUMA[1] * v[1] + LUMA[2] * v[2];
            let s = self.saturation as f32;
            v = v.map(|x| y + s * (x - y));
        }
        let knee = 1.0 - self.shoulder as f32;
        let width = self.shoulder as f32;
        let gamma = self.gamma as f32;
        let c = self.contrast as f32;
        let floor = self.floor as f32;
        let encoded = v.map(|x| {
            let mut x = x.max(0.0);
            if width > 0.0 && x > knee {
                x = knee + width * (1.0 - (-(x - knee) / width).exp());
            }
            x = x.min(1.0);
            if gamma != 1.0 {
                x = x.powf(gamma);
            }
            let y = colour.encode(x);
            let y = (y + c * y * (1.0 - y) * (2.0 * y - 1.0)).clamp(0.0, 1.0);
            floor + (1.0 - floor) * y
        });
        match self.jpeg_quality {
            Some(q) => jpeg_quantise(encoded, q),
            None => encoded,
        }
    }
}

/// libjpeg's quality scaling of a base table entry: the quantisation step.
fn jpeg_step(base: u32, quality: u8) -> f32 {
    let q = u32::from(quality.clamp(1, 100));
    let scale = if q < 50 { 5000 / q } else { 200 - 2 * q };
    ((base * scale + 50) / 100).clamp(1, 255) as f32
}

/// Rounds an encoded pixel's JFIF Y, Cb, Cr (8-bit units) to the DC quantisation steps of
/// `quality` divided by 8 (the DC coefficient of an 8×8 block is 8 × its mean), then back.
pub fn jpeg_quantise(rgb: [f32; 3], quality: u8) -> [f32; 3] {
    // Standard tables' DC entries (ITU-T T.81 Annex K): luminance 16, chrominance 17.
    let (sy, sc) = (jpeg_step(16, quality) / 8.0, jpeg_step(17, quality) / 8.0);
    let [r, g, b] = rgb.map(|v| v * 255.0);
    let y = 0.299 * r + 0.587 * g + 0.114 * b;
    let cb = -0.168_736 * r - 0.331_264 * g + 0.5 * b;
    let cr = 0.5 * r - 0.418_688 * g - 0.081_312 * b;
    let round = |v: f32, s: f32| (v / s).round() * s;
    let (y, cb, cr) = (round(y, sy), round(cb, sc), round(cr, sc));
    [
        y + 1.402 * cr,
        y - 0.344_136 * cb - 0.714_136 * cr,
        y + 1.772 * cb,
    ]
    .map(|v| (v / 255.0).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jpeg_steps_follow_libjpeg_scaling() {
        assert_eq!(jpeg_step(16, 50), 16.0);
        assert_eq!(jpeg_step(16, 75), 8.0);
        assert_eq!(jpeg_step(16, 100), 1.0);
        assert_eq!(jpeg_step(17, 10), 85.0);
    }
}
