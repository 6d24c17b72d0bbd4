//! What a colour meter shows for coloured light: the dominant (or complementary) wavelength
//! and the excitation purity on the CIE 1931 chromaticity diagram, and the peak wavelength.
//!
//! CIE 015:2018 §9.1: the dominant wavelength λ_d of a colour stimulus is the wavelength of
//! the monochromatic stimulus that, additively mixed with a specified achromatic stimulus (the
//! white point), matches it — on the (x, y) diagram, where the straight line from the white
//! point through the stimulus meets the spectral locus. When the line meets the line of
//! purples instead, the stimulus has no dominant wavelength but a complementary one, λ_c,
//! where the line extended backwards through the white point meets the spectral locus. The
//! excitation purity is p_e = (y − y_n)/(y_b − y_n) (or with x), i.e. the distance of the
//! stimulus from the white point over that of the boundary point (on the spectral locus or
//! the line of purples) along the same line.
//!
//! The spectral locus is the CIE 1931 2° observer's at 1 nm over 360–780 nm, closed by the
//! line of purples from 780 to 360 nm, as colour-science's `colour.dominant_wavelength` and
//! `colour.excitation_purity` take it; unlike colour-science, which reports the nearest
//! tabulated wavelength, the wavelength here is interpolated along the locus segment hit.
//! The default white point is the equi-energy illuminant E (x = y = 1/3), the usual choice
//! for light sources (CIE 015:2018 §9.1 leaves the achromatic stimulus to the user).

use super::spectrum::{observer_2deg, LightSpectrum, QUALITY_GRID};
use crate::colorimetry::xyz_to_xy;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// The chromaticity of the equi-energy illuminant E, x = y = 1/3: the default white point of
/// the dominant wavelength of a light.
pub const ILLUMINANT_E_XY: [f64; 2] = [1.0 / 3.0, 1.0 / 3.0];

/// A chromaticity this close to the white point (in x, y) has no hue to name.
const AT_WHITE: f64 = 1e-9;

/// The dominant or complementary wavelength of a colour stimulus and its excitation purity
/// (CIE 015:2018 §9.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DominantWavelength {
    /// The dominant wavelength λ_d in nm or, when `complementary`, the complementary
    /// wavelength λ_c.
    pub wavelength_nm: f64,
    /// Whether the line from the white point through the stimulus meets the line of purples:
    /// the stimulus is purple and `wavelength_nm` is its complementary wavelength.
    pub complementary: bool,
    /// Excitation purity p_e, 0 at the white point, 1 on the spectral locus or the line of
    /// purples.
    pub excitation_purity: f64,
    /// Where the line from the white point through the stimulus meets the boundary of the
    /// diagram (spectral locus or line of purples), CIE 1931 (x, y).
    pub boundary_xy: [f64; 2],
}

impl DominantWavelength {
    /// The wavelength with colour-science's sign convention: the dominant wavelength, or the
    /// complementary wavelength negated for a purple.
    pub fn signed_nm(&self) -> f64 {
        if self.complementary {
            -self.wavelength_nm
        } else {
            self.wavelength_nm
        }
    }
}

/// The spectral locus (x, y) at each wavelength of [`QUALITY_GRID`], built once.
fn spectral_locus() -> &'static [[f64; 2]] {
    static LOCUS: OnceLock<Vec<[f64; 2]>> = OnceLock::new();
    LOCUS.get_or_init(|| {
        let obs = observer_2deg();
        (0..QUALITY_GRID.count)
            .map(|i| xyz_to_xy([obs.cmf(0)[i], obs.cmf(1)[i], obs.cmf(2)[i]]))
            .collect()
    })
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Where the ray `origin + t·dir` (t > 0) first meets the closed boundary of the diagram:
/// (t, segment index, position 0–1 along the segment). Segment i joins locus points i and
/// i + 1; the last one, from the last locus point back to the first, is the line of purples.
fn first_hit(origin: [f64; 2], dir: [f64; 2]) -> Option<(f64, usize, f64)> {
    let locus = spectral_locus();
    let n = locus.len();
    let mut best: Option<(f64, usize, f64)> = None;
    for i in 0..n {
        let (a, b) = (locus[i], locus[(i + 1) % n]);
        let edge = [b[0] - a[0], b[1] - a[1]];
        let denom = cross(dir, edge);
        if denom.abs() < 1e-300 {
            continue;
        }
        let w = [a[0] - origin[0], a[1] - origin[1]];
        let t = cross(w, edge) / denom;
        let s = cross(w, dir) / denom;
        if t > 0.0 && (0.0..=1.0).contains(&s) && best.is_none_or(|(bt, _, _)| t < bt) {
            best = Some((t, i, s));
        }
    }
    best
}

/// Whether `xy` lies strictly inside the diagram (spectral locus closed by the line of
/// purples), by the even–odd rule.
fn inside_locus(xy: [f64; 2]) -> bool {
    let locus = spectral_locus();
    let n = locus.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (locus[i], locus[(i + 1) % n]);
        if (a[1] > xy[1]) != (b[1] > xy[1]) {
            let x = a[0] + (xy[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if xy[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The dominant (or complementary) wavelength and excitation purity of chromaticity `xy`
/// relative to the white point `white_xy` (CIE 1931 2°, CIE 015:2018 §9.1; see the module
/// documentation). Errors on non-finite input, on a white point outside the spectral locus,
/// and on a stimulus at the white point, which has no hue and so no dominant wavelength.
///
/// ```
/// use spdcam_core::quality::dominant::{dominant_wavelength, ILLUMINANT_E_XY};
///
/// // A saturated orange-red relative to D65: dominant wavelength about 616 nm.
/// let d = dominant_wavelength([0.54369557, 0.32107944], [0.3127, 0.3290])?;
/// assert!((d.wavelength_nm - 616.0).abs() < 0.5 && !d.complementary);
/// // A magenta relative to E: no dominant wavelength, a complementary one in the green.
/// let p = dominant_wavelength([0.40, 0.20], ILLUMINANT_E_XY)?;
/// assert!(p.complementary && p.signed_nm() < -490.0 && p.signed_nm() > -570.0);
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn dominant_wavelength(xy: [f64; 2], white_xy: [f64; 2]) -> Result<DominantWavelength> {
    if !(xy.iter().chain(&white_xy).all(|v| v.is_finite())) {
        return Err(Error::invalid(format!(
            "dominant wavelength of chromaticity ({}, {}) against white ({}, {}): the \
             coordinates must be finite numbers",
            xy[0], xy[1], white_xy[0], white_xy[1]
        )));
    }
    if !inside_locus(white_xy) {
        return Err(Error::invalid(format!(
            "white point ({}, {}) lies outside the CIE 1931 spectral locus; give the \
             chromaticity of a real white, e.g. illuminant E (1/3, 1/3) or D65 (0.3127, 0.3290)",
            white_xy[0], white_xy[1]
        )));
    }
    let dir = [xy[0] - white_xy[0], xy[1] - white_xy[1]];
    let distance = dir[0].hypot(dir[1]);
    if distance < AT_WHITE {
        return Err(Error::invalid(format!(
            "chromaticity ({}, {}) is the white point itself: it has no hue, so no dominant \
             wavelength (its excitation purity is 0)",
            xy[0], xy[1]
        )));
    }
    let locus = spectral_locus();
    let purple_segment = locus.len() - 1;
    let wavelength_at = |segment: usize, s: f64| {
        QUALITY_GRID.start_nm + (segment as f64 + s) * QUALITY_GRID.step_nm
    };
    // The white point is inside the closed boundary, so every ray from it leaves it once.
    let (t, segment, s) = first_hit(white_xy, dir).expect("a ray from inside meets the boundary");
    let boundary_xy = [white_xy[0] + t * dir[0], white_xy[1] + t * dir[1]];
    let excitation_purity = 1.0 / t;
    if segment != purple_segment {
        return Ok(DominantWavelength {
            wavelength_nm: wavelength_at(segment, s),
            complementary: false,
            excitation_purity,
            boundary_xy,
        });
    }
    let (_, back_segment, back_s) =
        first_hit(white_xy, [-dir[0], -dir[1]]).expect("a ray from inside meets the boundary");
    Ok(DominantWavelength {
        wavelength_nm: wavelength_at(back_segment, back_s),
        complementary: true,
        excitation_purity,
        boundary_xy,
    })
}

/// The dominant (or complementary) wavelength and excitation purity of a light relative to
/// `white_xy` ([`ILLUMINANT_E_XY`] is the usual choice), from its CIE 1931 2° chromaticity;
/// see [`dominant_wavelength`].
pub fn dominant_wavelength_of(
    light: &LightSpectrum,
    white_xy: [f64; 2],
) -> Result<DominantWavelength> {
    dominant_wavelength(xyz_to_xy(light.xyz()), white_xy)
}

/// The wavelength of the SPD's maximum, in nm, to the 1 nm of [`QUALITY_GRID`] (the input
/// resampled as [`LightSpectrum`] does), within 360–780 nm; the first of equal maxima.
pub fn peak_wavelength_nm(light: &LightSpectrum) -> f64 {
    let values = light.values();
    let i = values
        .iter()
        .enumerate()
        .fold(0, |best, (i, v)| if *v > values[best] { i } else { best });
    QUALITY_GRID.start_nm + i as f64 * QUALITY_GRID.step_nm
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(nm: usize) -> LightSpectrum {
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[nm - 360] = 1.0;
        LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap()
    }

    #[test]
    fn a_monochromatic_line_is_its_own_dominant_wavelength_at_full_purity() {
        for nm in [450, 480, 520, 555, 580, 610, 650] {
            let d = dominant_wavelength_of(&line(nm), ILLUMINANT_E_XY).unwrap();
            assert!(!d.complementary, "{nm}: {d:?}");
            assert!((d.wavelength_nm - nm as f64).abs() < 1e-6, "{nm}: {d:?}");
            assert!((d.excitation_purity - 1.0).abs() < 1e-9, "{nm}: {d:?}");
            assert_eq!(peak_wavelength_nm(&line(nm)), nm as f64);
        }
    }

    #[test]
    fn a_purple_has_a_complementary_wavelength() {
        // Equal parts of a 450 nm and a 650 nm line: purple. The line from E through it meets
        // the line of purples, and backwards the spectral locus in the green.
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[450 - 360] = 1.0;
        v[650 - 360] = 1.0;
        let light = LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap();
        let d = dominant_wavelength_of(&light, ILLUMINANT_E_XY).unwrap();
        assert!(d.complementary, "{d:?}");
        assert!(d.signed_nm() < 0.0 && (495.0..570.0).contains(&d.wavelength_nm));
        assert!(
            d.excitation_purity > 0.0 && d.excitation_purity < 1.0,
            "{d:?}"
        );
        // Halfway between the white point and the boundary point: purity one half.
        let w = ILLUMINANT_E_XY;
        let b = d.boundary_xy;
        let mid = [(w[0] + b[0]) / 2.0, (w[1] + b[1]) / 2.0];
        let half = dominant_wavelength(mid, w).unwrap();
        assert!((half.excitation_purity - 0.5).abs() < 1e-12, "{half:?}");
        assert_eq!(half.wavelength_nm, d.wavelength_nm);
    }

    #[test]
    fn meaningless_questions_are_errors() {
        let e = dominant_wavelength(ILLUMINANT_E_XY, ILLUMINANT_E_XY).unwrap_err();
        assert!(e.to_string().contains("no dominant wavelength"), "{e}");
        let e = dominant_wavelength([0.4, 0.4], [0.9, 0.9]).unwrap_err();
        assert!(e.to_string().contains("white point (0.9, 0.9)"), "{e}");
        let e = dominant_wavelength([f64::NAN, 0.4], ILLUMINANT_E_XY).unwrap_err();
        assert!(e.to_string().contains("finite"), "{e}");
    }
}
