//! The emission shapes real lamps are made of, each a function of wavelength with a peak
//! height of 1: the spectrum of a single LED (Ohno 2005), a phosphor's broad band (Gaussian
//! in photon energy), an atomic or ionic emission line as the spectroradiometer records it,
//! and a filament (Planck's law with a smooth transmission filter).

use crate::cie_illuminant::planck_radiance;

/// hc in eV·nm: photon energy E = [`HC_EV_NM`] / λ.
pub const HC_EV_NM: f64 = 1_239.841_984;

/// One emission shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A single LED, Ohno's model: S(λ) = (g + 2g⁵)/3 with g = exp(−((λ − λ₀)/Δλ)²), λ₀ the
    /// peak and Δλ its half spectral width (Y. Ohno, "Spectral design considerations for
    /// white LED color rendering", Optical Engineering 44(11), 111302, 2005, eq. 1).
    LedOhno2005 {
        /// λ₀, the peak wavelength (nm).
        peak_nm: f64,
        /// Δλ, half the spectral width (nm).
        half_width_nm: f64,
    },
    /// A phosphor's emission band (Ce³⁺, Eu²⁺, Mn²⁺ …): a Gaussian in photon energy,
    /// exp(−(E − E₀)²/(2σ²)), as the configurational-coordinate model of a broad
    /// d→f band gives (G. Blasse, B. C. Grabmaier, *Luminescent Materials*, Springer 1994,
    /// ch. 2); on a wavelength axis it has the long tail towards the red that phosphors show.
    PhosphorBand {
        /// The peak wavelength (nm), hc/E₀.
        peak_nm: f64,
        /// σ, the band's standard deviation in photon energy (eV).
        sigma_ev: f64,
    },
    /// An emission line (atomic lines of discharges, the narrow f→f lines of rare-earth
    /// phosphors) as a spectroradiometer of Gaussian bandpass records it:
    /// exp(−(λ − λ₀)²/(2σ²)).
    Line {
        /// λ₀, the line's wavelength (nm).
        centre_nm: f64,
        /// σ, the recorded bandpass's standard deviation (nm).
        sigma_nm: f64,
    },
    /// A filament: Planck's law at `cct_k` times a smooth filter
    /// exp(a·x + b·x²), x = (λ − 580 nm)/200 nm (a dimmer, a coated or dichroic
    /// reflector, a blue daylight filter), scaled so its largest value on 380–780 nm is 1.
    Filament {
        /// The filament's temperature (K).
        cct_k: f64,
        /// a, the filter's linear term (positive: more red).
        tilt: f64,
        /// b, the filter's quadratic term.
        curve: f64,
    },
}

impl Shape {
    /// The shape at `nm` (peak height 1 for the LED, band and line; the filament unscaled).
    pub fn value(&self, nm: f64) -> f64 {
        match *self {
            Shape::LedOhno2005 {
                peak_nm,
                half_width_nm,
            } => {
                let g = (-((nm - peak_nm) / half_width_nm).powi(2)).exp();
                (g + 2.0 * g.powi(5)) / 3.0
            }
            Shape::PhosphorBand { peak_nm, sigma_ev } => {
                let d = HC_EV_NM / nm - HC_EV_NM / peak_nm;
                (-d * d / (2.0 * sigma_ev * sigma_ev)).exp()
            }
            Shape::Line {
                centre_nm,
                sigma_nm,
            } => (-(nm - centre_nm).powi(2) / (2.0 * sigma_nm * sigma_nm)).exp(),
            Shape::Filament { cct_k, tilt, curve } => {
                let x = (nm - 580.0) / 200.0;
                planck_radiance(nm, cct_k) * (tilt * x + curve * x * x).exp()
            }
        }
    }

    /// The shape sampled at `wavelengths`; a filament is scaled to a maximum of 1 there.
    pub fn sample(&self, wavelengths: &[f64]) -> Vec<f64> {
        let mut v: Vec<f64> = wavelengths.iter().map(|&nm| self.value(nm)).collect();
        if matches!(self, Shape::Filament { .. }) {
            let max = v.iter().cloned().fold(0.0, f64::max);
            if max > 0.0 && max.is_finite() {
                v.iter_mut().for_each(|x| *x /= max);
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ohno_led_by_hand() {
        // Peak 550 nm, half width 50 nm, at 575 nm: g = exp(−(25/50)²) = 0.778801,
        // (g + 2g⁵)/3 = 0.4506035.
        let led = Shape::LedOhno2005 {
            peak_nm: 550.0,
            half_width_nm: 50.0,
        };
        assert!((led.value(575.0) - 0.450_603_459).abs() < 1e-9);
        assert_eq!(led.value(550.0), 1.0);
    }

    #[test]
    fn phosphor_band_is_gaussian_in_energy_with_a_red_tail() {
        let band = Shape::PhosphorBand {
            peak_nm: 560.0,
            sigma_ev: 0.15,
        };
        assert_eq!(band.value(560.0), 1.0);
        // One σ away in energy: E = E₀ ∓ 0.15 eV.
        let e0 = HC_EV_NM / 560.0;
        let red = HC_EV_NM / (e0 - 0.15);
        let blue = HC_EV_NM / (e0 + 0.15);
        assert!((band.value(red) - (-0.5f64).exp()).abs() < 1e-12);
        assert!((band.value(blue) - (-0.5f64).exp()).abs() < 1e-12);
        assert!(red - 560.0 > 560.0 - blue);
    }

    #[test]
    fn filament_without_filter_is_planck() {
        let wl: Vec<f64> = (0..81).map(|k| 380.0 + 5.0 * k as f64).collect();
        let f = Shape::Filament {
            cct_k: 2856.0,
            tilt: 0.0,
            curve: 0.0,
        }
        .sample(&wl);
        let p: Vec<f64> = wl.iter().map(|&nm| planck_radiance(nm, 2856.0)).collect();
        let pmax = p.iter().cloned().fold(0.0, f64::max);
        for (a, b) in f.iter().zip(&p) {
            assert!((a - b / pmax).abs() < 1e-12);
        }
        // Below 3,000 K the maximum on 380–780 nm is at 780 nm.
        assert!((f[80] - 1.0).abs() < 1e-12);
    }
}
