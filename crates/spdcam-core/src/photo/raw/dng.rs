//! Writing a DNG (Adobe, *Digital Negative Specification* 1.6): one uncompressed 16-bit
//! colour-filter mosaic in IFD 0 (`NewSubFileType` 0, `PhotometricInterpretation` CFA
//! 32803), with its black and white levels, CFA pattern, two `ColorMatrix` tags with their
//! calibration illuminants, `AsShotNeutral` and the EXIF exposure (TIFF/EP puts it in
//! IFD 0). The virtual camera writes its photos this way (`spdcam render -o photo.dng`), so
//! that tests have raw photos of a known light; any DNG reader opens them.

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
        let rationals: Vec<SRational> = matrix
            .transpose()
            .iter()
            .map(|&v| SRational {
                n: (v * MATRIX_DENOMINATOR as f64).round() as i32,
                d: MATRIX_DENOMINATOR,
            })
            .collect();
        // ColorMatrix1/2 (row-major: the transpose of nalgebra's column order) and
        // CalibrationIlluminant1/2.
        dir.write_tag(Tag::Unknown(50721 + k as u16), &rationals[..])
            .map_err(fail)?;
        dir.write_tag(Tag::Unknown(50778 + k as u16), *illuminant)
            .map_err(fail)?;
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
        let time = Rational {
            n: (e.exposure_time_s * 1_000_000.0).round().max(1.0) as u32,
            d: 1_000_000,
        };
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
    };
    encode_dng(mosaic, &meta)
}

/// The `CFAPattern` bytes (0 red, 1 green, 2 blue) of a 2×2 layout, row-major.
fn cfa_pattern(pattern: CfaPattern) -> [u8; 4] {
    [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(x, y)| pattern.channel_at(x, y) as u8)
}
