//! How a photo was exposed, from its EXIF (CIPA DC-008-2019 tags), and the scene luminance
//! that implies — the basis of spdcam's approximate absolute levels (illuminance, PPFD,
//! melanopic EDI).
//!
//! The photometric chain is ISO 12232:2019's standard output sensitivity (SOS): a camera
//! set to ISO S renders the focal-plane exposure H_m = 10 / S lux·s as the output value 118
//! of 255 in 8-bit sRGB — linear 0.18 of the output's white. The focal-plane exposure of a
//! scene area of luminance L (cd/m²) is H = q · L · t / N² (ISO 12232 annex, ISO 2720) with
//! q = 0.65 for a typical lens (transmission, vignetting and the cos⁴ fall-off at the
//! centre). An area rendered at linear value y, with the output taken as linear in
//! exposure, therefore had L = (y / 0.18) · (10 / S) · N² / (q · t).
//!
//! Cameras' tone curves are not linear, their ISO ratings are within about a third of a
//! stop of SOS, and lenses vignette: the result is approximate (tens of per cent), which
//! every output saying it repeats.
//!
//! A raw file's values are the sensor's, before any tone curve: for them the chain is ISO
//! 12232:2019's saturation-based speed instead. A sensor of saturation speed S_sat reaches
//! its white level (the maximum unclipped value) at the focal-plane exposure
//! H_sat = 78 / S_sat lux·s; the 78 puts an 18 % grey metered by a reflected-light meter at
//! 18 %/√2 ≈ 12.7 % of saturation, half a stop of headroom above a 100 % white diffuser. A
//! raw value is linear in exposure, so an area read at v of the white level (black
//! subtracted) had H = v · 78 / S and L = v · (78 / S) · N² / (q · t)
//! ([`Exposure::luminance_from_raw`]). The EXIF ISO is taken as S_sat: a camera rated by
//! SOS, by noise or with extra headroom, or a raw channel that is not the luminance, moves
//! the result.

use exif::{In, Reader, Tag, Value};
use serde::Serialize;

/// The linear output value of ISO 12232's SOS reference exposure (118/255 in sRGB).
pub const SOS_LINEAR_VALUE: f64 = 0.18;
/// The focal-plane exposure (lux·s) that ISO S renders at [`SOS_LINEAR_VALUE`] is this / S.
pub const SOS_EXPOSURE_CONSTANT: f64 = 10.0;
/// ISO 12232:2019 saturation-based speed: a sensor of speed S saturates (reaches its white
/// level) at the focal-plane exposure H_sat = this / S lux·s.
pub const SATURATION_EXPOSURE_CONSTANT: f64 = 78.0;
/// The lens factor q of H = q · L · t / N² (ISO 12232, ISO 2720: π/4 · transmission 0.9 ·
/// vignetting 0.98 · cos⁴ 10° ≈ 0.65).
pub const LENS_FACTOR: f64 = 0.65;

/// The exposure of a photo as its EXIF gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Exposure {
    /// The lens aperture N (f-number).
    pub f_number: f64,
    /// The exposure time t, seconds.
    pub exposure_time_s: f64,
    /// The ISO setting S (PhotographicSensitivity, or the recommended exposure index when
    /// that reads 65535).
    pub iso: f64,
}

impl Exposure {
    /// The exposure from raw EXIF (the TIFF structure a JPEG's APP1 segment or a PNG's eXIf
    /// chunk holds); `None` when it cannot be read or lacks a positive aperture, time or
    /// ISO. The aperture and time fall back to their APEX tags (ApertureValue,
    /// ShutterSpeedValue: N = 2^(Av/2), t = 2^(−Tv)).
    pub fn from_exif(raw: Vec<u8>) -> Option<Exposure> {
        let exif = Reader::new().read_raw(raw).ok()?;
        let number = |tag: Tag| -> Option<f64> {
            let field = exif.get_field(tag, In::PRIMARY)?;
            let v = match &field.value {
                Value::Rational(v) => v.first()?.to_f64(),
                Value::SRational(v) => v.first()?.to_f64(),
                other => f64::from(other.get_uint(0)?),
            };
            v.is_finite().then_some(v)
        };
        let positive = |v: f64| v > 0.0;
        let f_number = number(Tag::FNumber)
            .filter(|&v| positive(v))
            .or_else(|| number(Tag::ApertureValue).map(|av| 2f64.powf(av / 2.0)))?;
        let exposure_time_s = number(Tag::ExposureTime)
            .filter(|&v| positive(v))
            .or_else(|| number(Tag::ShutterSpeedValue).map(|tv| 2f64.powf(-tv)))?;
        let iso = match number(Tag::PhotographicSensitivity) {
            Some(v) if v > 0.0 && v < 65535.0 => Some(v),
            _ => number(Tag::RecommendedExposureIndex)
                .or_else(|| number(Tag::ISOSpeed))
                .filter(|&v| positive(v)),
        }?;
        Exposure::new(f_number, exposure_time_s, iso)
    }

    /// The exposure of aperture `f_number`, time `exposure_time_s` and ISO `iso`; `None`
    /// unless all three are finite and positive (a raw file's EXIF as its decoder reads it).
    pub fn new(f_number: f64, exposure_time_s: f64, iso: f64) -> Option<Exposure> {
        [f_number, exposure_time_s, iso]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
            .then_some(Exposure {
                f_number,
                exposure_time_s,
                iso,
            })
    }

    /// The luminance (cd/m²) of a scene area the photo renders at linear value `y` (0–1 of
    /// the output's white; e.g. sRGB-decoded luminance), by the SOS relation of the module
    /// documentation.
    pub fn luminance(&self, y: f64) -> f64 {
        (y / SOS_LINEAR_VALUE) * (SOS_EXPOSURE_CONSTANT / self.iso) * self.f_number.powi(2)
            / (LENS_FACTOR * self.exposure_time_s)
    }

    /// The luminance (cd/m²) of a scene area a raw file reads at `v` of the sensor's white
    /// level (black subtracted; linear, before any development), with the EXIF ISO taken
    /// as the sensor's ISO 12232 saturation-based speed: L = v · (78 / S) · N² / (q · t)
    /// (module documentation).
    pub fn luminance_from_raw(&self, v: f64) -> f64 {
        v * (SATURATION_EXPOSURE_CONSTANT / self.iso) * self.f_number.powi(2)
            / (LENS_FACTOR * self.exposure_time_s)
    }

    /// The exposure at aperture `f_number` on a sensor of saturation speed `iso` that reads
    /// a scene area of `luminance` (cd/m²) at `v` of the white level: its time is
    /// t = v · (78 / S) · N² / (q · L), so that [`Exposure::luminance_from_raw`] of `v`
    /// gives `luminance` back. `None` unless every input is finite and positive.
    pub fn for_raw_value(f_number: f64, iso: f64, luminance: f64, v: f64) -> Option<Exposure> {
        if !(luminance.is_finite() && luminance > 0.0 && v.is_finite() && v > 0.0) {
            return None;
        }
        let time =
            v * (SATURATION_EXPOSURE_CONSTANT / iso) * f_number.powi(2) / (LENS_FACTOR * luminance);
        Exposure::new(f_number, time, iso)
    }

    /// `f/4, 1/60 s, ISO 400`.
    pub fn label(&self) -> String {
        let t = if self.exposure_time_s < 1.0 {
            format!("1/{:.0} s", 1.0 / self.exposure_time_s)
        } else {
            format!("{} s", self.exposure_time_s)
        };
        format!("f/{}, {t}, ISO {:.0}", self.f_number, self.iso)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use exif::experimental::Writer;
    use exif::{Field, Rational};
    use std::io::Cursor;

    /// Raw EXIF (TIFF) holding `fields` in the primary image's IFD.
    pub(crate) fn raw_exif(fields: &[Field]) -> Vec<u8> {
        let mut writer = Writer::new();
        for f in fields {
            writer.push_field(f);
        }
        let mut out = Cursor::new(Vec::new());
        writer.write(&mut out, false).unwrap();
        out.into_inner()
    }

    fn field(tag: Tag, value: Value) -> Field {
        Field {
            tag,
            ifd_num: In::PRIMARY,
            value,
        }
    }

    fn rational(num: u32, denom: u32) -> Value {
        Value::Rational(vec![Rational { num, denom }])
    }

    #[test]
    fn aperture_time_and_iso_are_read() {
        let raw = raw_exif(&[
            field(Tag::FNumber, rational(56, 10)),
            field(Tag::ExposureTime, rational(1, 125)),
            field(Tag::PhotographicSensitivity, Value::Short(vec![400])),
        ]);
        let e = Exposure::from_exif(raw).unwrap();
        assert_eq!(
            e,
            Exposure {
                f_number: 5.6,
                exposure_time_s: 0.008,
                iso: 400.0
            }
        );
        assert_eq!(e.label(), "f/5.6, 1/125 s, ISO 400");
    }

    #[test]
    fn apex_values_and_the_exposure_index_stand_in() {
        // Av 4 → f/4, Tv 6 → 1/64 s; ISO 65535 means "higher": the exposure index counts.
        let raw = raw_exif(&[
            field(Tag::ApertureValue, rational(4, 1)),
            field(
                Tag::ShutterSpeedValue,
                Value::SRational(vec![exif::SRational { num: 6, denom: 1 }]),
            ),
            field(Tag::PhotographicSensitivity, Value::Short(vec![65535])),
            field(Tag::RecommendedExposureIndex, Value::Long(vec![102_400])),
        ]);
        let e = Exposure::from_exif(raw).unwrap();
        assert!((e.f_number - 4.0).abs() < 1e-12);
        assert!((e.exposure_time_s - 1.0 / 64.0).abs() < 1e-15);
        assert_eq!(e.iso, 102_400.0);
    }

    #[test]
    fn incomplete_or_damaged_exif_gives_none() {
        let raw = raw_exif(&[
            field(Tag::FNumber, rational(4, 1)),
            field(Tag::PhotographicSensitivity, Value::Short(vec![100])),
        ]);
        assert_eq!(Exposure::from_exif(raw), None, "no exposure time");
        let raw = raw_exif(&[
            field(Tag::FNumber, rational(0, 1)),
            field(Tag::ExposureTime, rational(1, 60)),
            field(Tag::PhotographicSensitivity, Value::Short(vec![100])),
        ]);
        assert_eq!(Exposure::from_exif(raw), None, "f/0");
        assert_eq!(Exposure::from_exif(b"II*\0garbage".to_vec()), None);
        assert_eq!(Exposure::from_exif(Vec::new()), None);
    }

    #[test]
    fn luminance_by_hand() {
        // ISO 100, 1/100 s, f/4: the SOS grey (y = 0.18) had L = 10/100 · 16 / (0.65 · 0.01)
        // = 246.15 cd/m²; twice the output value means twice the luminance.
        let e = Exposure {
            f_number: 4.0,
            exposure_time_s: 0.01,
            iso: 100.0,
        };
        assert!((e.luminance(0.18) - 0.1 * 16.0 / 0.0065).abs() < 1e-9);
        assert!((e.luminance(0.36) - 2.0 * e.luminance(0.18)).abs() < 1e-9);
        // A raw file: at the white level (v = 1) ISO 100 saturated at H = 78/100 lux·s, so
        // L = 0.78 · 16 / (0.65 · 0.01) = 1920 cd/m²; half the raw value, half the light.
        assert!((e.luminance_from_raw(1.0) - 0.78 * 16.0 / 0.0065).abs() < 1e-9);
        assert!((e.luminance_from_raw(0.25) - 480.0).abs() < 1e-9);
    }

    #[test]
    fn the_raw_exposure_for_a_luminance_reads_it_back() {
        let e = Exposure::for_raw_value(4.0, 100.0, 318.31, 0.4).unwrap();
        assert_eq!((e.f_number, e.iso), (4.0, 100.0));
        // t = 0.4 · 0.78 · 16 / (0.65 · 318.31) = 24.1 ms.
        assert!((e.exposure_time_s - 0.4 * 0.78 * 16.0 / (0.65 * 318.31)).abs() < 1e-12);
        assert!((e.luminance_from_raw(0.4) / 318.31 - 1.0).abs() < 1e-12);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Exposure::for_raw_value(4.0, 100.0, bad, 0.4).is_none());
            assert!(Exposure::for_raw_value(4.0, 100.0, 318.31, bad).is_none());
            assert!(Exposure::for_raw_value(bad, 100.0, 318.31, 0.4).is_none());
            assert!(Exposure::for_raw_value(4.0, bad, 318.31, 0.4).is_none());
        }
    }
}
