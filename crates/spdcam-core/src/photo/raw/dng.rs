//! Writing a DNG (Adobe, *Digital Negative Specification* 1.6): one uncompressed 16-bit
//! colour-filter mosaic in IFD 0 (`NewSubFileType` 0, `PhotometricInterpretation` CFA
//! 32803), with its black and white levels, CFA pattern, two `ColorMatrix` tags with their
//! calibration illuminants, `AsShotNeutral` and the EXIF exposure (TIFF/EP puts it in
//! IFD 0); where given, `ForwardMatrix1/2`, `AnalogBalance` and lens-shading gain maps
//! (`OpcodeList2`), as cameras and raw converters write them. The virtual camera writes its photos this way (`spdcam render -o photo.dng`), so
//! that tests have raw photos of a known light; any DNG reader opens them.
//!
//! The virtual camera's exposure is relative: it meters the chart and scales its raw
//! values to that, whatever the light's level. Told the light's illuminance on the chart,
//! [`virtual_exposure`] writes the EXIF exposure that ISO 12232:2019's saturation-based
//! speed gives those raw values: the sensor is rated ISO [`VIRTUAL_ISO`] by saturation
//! under the light photographed, the lens is at [`VIRTUAL_F_NUMBER`], and the exposure
//! time is what puts a perfect white diffuser at the green raw value the photo has
//! ([`Exposure::for_raw_value`]). A reader that takes the EXIF ISO as the saturation speed
//! and the green photosites as luminance ([`Exposure::luminance_from_raw`]) reads the
//! light's level back. A real camera's ISO is rated under one daylight illuminant, so
//! under another light its green's share of luminance moves what such a reader finds
//! (docs/raw.md); the virtual camera's rating follows the light, so that its files test
//! the reading itself.

use super::colour::{illuminant_cct, CalibratedMatrix, RawColour};
use super::opcodes::{gain_map_list, GainMap};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::photo::Exposure;
use crate::raster::{CfaPattern, Mosaic};
use crate::spectral::Spd;
use nalgebra::Matrix3;
use std::io::Cursor;
use tiff::encoder::{colortype, Rational, SRational, TiffEncoder};
use tiff::tags::Tag;

/// The black level written: an offset, as real sensors have, so that read noise below black
/// survives.
pub const DNG_BLACK: u16 = 256;
/// The white level written (a 14-bit sensor).
pub const DNG_WHITE: u16 = 16383;
/// The aperture the virtual camera's DNGs are exposed at (f-number).
pub const VIRTUAL_F_NUMBER: f64 = 4.0;
/// The virtual sensor's ISO 12232:2019 saturation-based speed: its white level is reached at
/// the focal-plane exposure 78 / 100 = 0.78 lux·s of the light photographed.
pub const VIRTUAL_ISO: f64 = 100.0;
/// Denominator of the matrices' signed rationals.
const MATRIX_DENOMINATOR: i32 = 10_000;

/// What a DNG holds beside the mosaic.
#[derive(Debug, Clone)]
pub struct DngMetadata {
    /// The camera's name (`UniqueCameraModel`, `Model`).
    pub camera: String,
    /// `ColorMatrix1` and `ColorMatrix2`: XYZ → camera under their illuminants, given by
    /// EXIF `LightSource` code (17 = A, 21 = D65).
    pub matrices: [(u16, Matrix3<f64>); 2],
    /// The camera's neutral as shot (raw RGB of a white surface, any scale).
    pub as_shot_neutral: [f64; 3],
    /// The exposure, when known.
    pub exposure: Option<Exposure>,
    /// `ForwardMatrix1` and `ForwardMatrix2` (white-balanced camera RGB → XYZ at D50), for
    /// the same illuminants as `matrices`.
    pub forward_matrices: Option<[Matrix3<f64>; 2]>,
    /// `AnalogBalance`: gains applied to each channel before the values were stored.
    pub analog_balance: Option<[f64; 3]>,
    /// Lens-shading gain maps, written as `OpcodeList2`.
    pub gain_maps: Vec<GainMap>,
}

/// An UNDEFINED (type 7) TIFF value: bytes whose meaning the tag defines, as `OpcodeList2`.
struct Undefined<'a>(&'a [u8]);

impl tiff::encoder::TiffValue for Undefined<'_> {
    const BYTE_LEN: u8 = 1;
    const FIELD_TYPE: tiff::tags::Type = tiff::tags::Type::UNDEFINED;
    fn count(&self) -> usize {
        self.0.len()
    }
    fn data(&self) -> std::borrow::Cow<'_, [u8]> {
        std::borrow::Cow::Borrowed(self.0)
    }
}

/// A 3 × 3 matrix as a DNG's nine signed rationals, row by row.
fn matrix_rationals(matrix: &Matrix3<f64>) -> Vec<SRational> {
    // nalgebra iterates column by column: the transpose's order is the rows'.
    matrix
        .transpose()
        .iter()
        .map(|&v| SRational {
            n: (v * MATRIX_DENOMINATOR as f64).round() as i32,
            d: MATRIX_DENOMINATOR,
        })
        .collect()
}

/// The DNG file of `mosaic` (normalised raw, 1 = full scale; quantised to
/// [`DNG_BLACK`]…[`DNG_WHITE`]) with `meta`.
pub fn encode_dng(mosaic: &Mosaic, meta: &DngMetadata) -> Result<Vec<u8>> {
    let fail = |e: tiff::TiffError| Error::invalid(format!("cannot write the DNG: {e}"));
    let (w, h) = (mosaic.width, mosaic.height);
    let width = u32::try_from(w).map_err(|_| Error::invalid("the mosaic is too wide for a DNG"))?;
    let height =
        u32::try_from(h).map_err(|_| Error::invalid("the mosaic is too tall for a DNG"))?;
    let span = f32::from(DNG_WHITE - DNG_BLACK);
    let values: Vec<u16> = mosaic
        .data
        .iter()
        .map(|&v| {
            (f32::from(DNG_BLACK) + v * span)
                .round()
                .clamp(0.0, f32::from(DNG_WHITE)) as u16
        })
        .collect();
    let neutral_max = meta.as_shot_neutral.iter().cloned().fold(0.0, f64::max);
    if !(neutral_max > 0.0
        && meta
            .as_shot_neutral
            .iter()
            .all(|v| v.is_finite() && *v > 0.0))
    {
        return Err(Error::invalid(
            "the as-shot neutral must be positive in every channel",
        ));
    }
    let mut bytes = Cursor::new(Vec::new());
    let mut tiff = TiffEncoder::new(&mut bytes).map_err(fail)?;
    let mut image = tiff
        .new_image::<colortype::Gray16>(width, height)
        .map_err(fail)?;
    let dir = image.encoder();
    let cfa = cfa_pattern(mosaic.pattern);
    dir.write_tag(Tag::NewSubfileType, 0u32).map_err(fail)?;
    dir.write_tag(Tag::PhotometricInterpretation, 32803u16)
        .map_err(fail)?;
    dir.write_tag(Tag::Make, "spdcam").map_err(fail)?;
    dir.write_tag(Tag::Unknown(272), meta.camera.as_str())
        .map_err(fail)?; // Model
    dir.write_tag(Tag::Unknown(274), 1u16).map_err(fail)?; // Orientation: upright
    dir.write_tag(Tag::Unknown(33421), &[2u16, 2][..])
        .map_err(fail)?; // CFARepeatPatternDim
    dir.write_tag(Tag::Unknown(33422), &cfa[..]).map_err(fail)?; // CFAPattern
    dir.write_tag(Tag::Unknown(50706), &[1u8, 4, 0, 0][..])
        .map_err(fail)?; // DNGVersion
    dir.write_tag(Tag::Unknown(50707), &[1u8, 1, 0, 0][..])
        .map_err(fail)?; // DNGBackwardVersion
    let unique = format!("spdcam {}", meta.camera);
    dir.write_tag(Tag::Unknown(50708), unique.as_str())
        .map_err(fail)?; // UniqueCameraModel
    dir.write_tag(Tag::Unknown(50710), &[0u8, 1, 2][..])
        .map_err(fail)?; // CFAPlaneColor
    dir.write_tag(Tag::Unknown(50711), 1u16).map_err(fail)?; // CFALayout: rectangular
    dir.write_tag(Tag::Unknown(50714), u32::from(DNG_BLACK))
        .map_err(fail)?; // BlackLevel
    dir.write_tag(Tag::Unknown(50717), u32::from(DNG_WHITE))
        .map_err(fail)?; // WhiteLevel
    for (k, (illuminant, matrix)) in meta.matrices.iter().enumerate() {
        // ColorMatrix1/2 and CalibrationIlluminant1/2.
        dir.write_tag(
            Tag::Unknown(50721 + k as u16),
            &matrix_rationals(matrix)[..],
        )
        .map_err(fail)?;
        dir.write_tag(Tag::Unknown(50778 + k as u16), *illuminant)
            .map_err(fail)?;
    }
    for (k, matrix) in meta.forward_matrices.iter().flatten().enumerate() {
        // ForwardMatrix1/2.
        dir.write_tag(
            Tag::Unknown(50964 + k as u16),
            &matrix_rationals(matrix)[..],
        )
        .map_err(fail)?;
    }
    if let Some(balance) = meta.analog_balance {
        let gains: Vec<Rational> = balance
            .iter()
            .map(|&v| Rational {
                n: (v * 1_000_000.0).round().clamp(1.0, f64::from(u32::MAX)) as u32,
                d: 1_000_000,
            })
            .collect();
        dir.write_tag(Tag::Unknown(50727), &gains[..])
            .map_err(fail)?; // AnalogBalance
    }
    if !meta.gain_maps.is_empty() {
        let list = gain_map_list(&meta.gain_maps);
        dir.write_tag(Tag::Unknown(51009), Undefined(&list))
            .map_err(fail)?; // OpcodeList2
    }
    let neutral: Vec<Rational> = meta
        .as_shot_neutral
        .iter()
        .map(|&v| Rational {
            n: ((v / neutral_max) * 1_000_000.0).round().max(1.0) as u32,
            d: 1_000_000,
        })
        .collect();
    dir.write_tag(Tag::Unknown(50728), &neutral[..])
        .map_err(fail)?; // AsShotNeutral
    if let Some(e) = &meta.exposure {
        let time = exif_rational(e.exposure_time_s).ok_or_else(|| {
            Error::invalid(format!(
                "the exposure time {} s cannot be written as an EXIF rational",
                e.exposure_time_s
            ))
        })?;
        let f_number = Rational {
            n: (e.f_number * 100.0).round() as u32,
            d: 100,
        };
        dir.write_tag(Tag::Unknown(33434), time).map_err(fail)?; // ExposureTime
        dir.write_tag(Tag::Unknown(33437), f_number).map_err(fail)?; // FNumber
        dir.write_tag(
            Tag::Unknown(34855),
            e.iso.round().clamp(1.0, 65535.0) as u16,
        )
        .map_err(fail)?; // ISOSpeedRatings
    }
    image.write_data(&values).map_err(fail)?;
    Ok(bytes.into_inner())
}

/// The DNG of `mosaic` as `camera` took it under `spd` (`spdcam render … -o x.dng`): the
/// camera's matrices fitted under A and D65, its exact neutral under the light as shot,
/// `exposure` when given.
pub fn virtual_camera_dng(
    camera: &Camera,
    spd: &Spd,
    mosaic: &Mosaic,
    exposure: Option<Exposure>,
) -> Result<Vec<u8>> {
    let meta = DngMetadata {
        camera: camera.camera_name().to_string(),
        matrices: camera.dng_colour_matrices()?,
        as_shot_neutral: camera.neutral_under(spd)?,
        exposure,
        forward_matrices: None,
        analog_balance: None,
        gain_maps: Vec::new(),
    };
    encode_dng(mosaic, &meta)
}

/// The colour calibration the virtual camera's DNGs carry ([`virtual_camera_dng`]): its
/// matrices fitted under A and D65, as a raw reader takes them
/// ([`RawColour::light_xy`] gives the light a neutral shows through them).
pub fn virtual_raw_colour(camera: &Camera) -> Result<RawColour> {
    let matrices = camera
        .dng_colour_matrices()?
        .iter()
        .map(|&(code, matrix)| {
            let (name, cct_k) = illuminant_cct(code).ok_or_else(|| {
                Error::invalid(format!("calibration illuminant code {code} has no CCT"))
            })?;
            Ok(CalibratedMatrix::new(name, cct_k, matrix))
        })
        .collect::<Result<Vec<_>>>()?;
    RawColour::new(matrices, None)
}

/// The EXIF exposure of a photo `camera` took of its chart under `spd` lighting the chart
/// at `illuminance_lux`, with its raw values scaled by `scale` ([`Camera::exposed_chart_at`]
/// gives a photo's): f/[`VIRTUAL_F_NUMBER`], ISO [`VIRTUAL_ISO`] as the sensor's
/// saturation-based speed under `spd`, and the time at which a perfect white diffuser
/// (luminance E/π) reads its green raw value at `scale`
/// ([`Exposure::for_raw_value`]; the module documentation says why). An error for an
/// illuminance that is not finite and positive, or a light the camera's green does not see.
pub fn virtual_exposure(
    camera: &Camera,
    spd: &Spd,
    scale: f32,
    illuminance_lux: f64,
) -> Result<Exposure> {
    if !(illuminance_lux.is_finite() && illuminance_lux > 0.0) {
        return Err(Error::invalid(format!(
            "the illuminance {illuminance_lux} lx must be finite and above zero"
        )));
    }
    let green = camera.exposed_white(spd, scale)?[1];
    let luminance = illuminance_lux / std::f64::consts::PI;
    let exposure = Exposure::for_raw_value(VIRTUAL_F_NUMBER, VIRTUAL_ISO, luminance, green)
        .ok_or_else(|| Error::invalid("the light gives this camera no green signal"))?;
    match exif_rational(exposure.exposure_time_s) {
        Some(_) => Ok(exposure),
        None => Err(Error::invalid(format!(
            "{illuminance_lux} lx at this photo's raw level (ISO {VIRTUAL_ISO}, \
             f/{VIRTUAL_F_NUMBER}) needs an exposure time of {} s, which EXIF cannot hold",
            exposure.exposure_time_s
        ))),
    }
}

/// A positive value as an EXIF rational of at least 9 significant digits where it fits
/// (the largest power-of-ten denominator up to 10⁹ that keeps the numerator in 32 bits);
/// `None` when it is not finite and positive or lies outside 10⁻⁹…4·10⁹.
fn exif_rational(v: f64) -> Option<Rational> {
    if !(v.is_finite() && v > 0.0) {
        return None;
    }
    let mut d: u32 = 1_000_000_000;
    while d > 1 && v * f64::from(d) > f64::from(u32::MAX) {
        d /= 10;
    }
    let n = (v * f64::from(d)).round();
    (n >= 1.0 && n <= f64::from(u32::MAX)).then_some(Rational { n: n as u32, d })
}

/// The `CFAPattern` bytes (0 red, 1 green, 2 blue) of a 2×2 layout, row-major.
fn cfa_pattern(pattern: CfaPattern) -> [u8; 4] {
    [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(x, y)| pattern.channel_at(x, y) as u8)
}

#[cfg(test)]
mod tests {
    use super::exif_rational;

    #[test]
    fn exposure_times_keep_nine_digits_as_exif_rationals() {
        let r = exif_rational(0.003_401_5).unwrap();
        assert_eq!((r.n, r.d), (3_401_500, 1_000_000_000));
        // 5000 s: the denominator steps down until the numerator fits 32 bits.
        let r = exif_rational(5000.0).unwrap();
        assert_eq!((r.n, r.d), (500_000_000, 100_000));
        let r = exif_rational(1e-9).unwrap();
        assert_eq!((r.n, r.d), (1, 1_000_000_000));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-11, 1e10] {
            assert!(exif_rational(bad).is_none(), "{bad}");
        }
    }
}
