//! Reading a raw file with rawler into a [`RawMosaic`]: the active area's photosites, black
//! and white levels, colour-filter layout, orientation, colour matrices, as-shot neutral and
//! EXIF exposure. rawler panics on some damaged files; the panic is caught here and becomes
//! an error naming the file.

use super::colour::{illuminant_cct, CalibratedMatrix, RawColour};
use super::opcodes::OpcodeList;
use super::{CfaTile, RawMosaic};
use crate::error::{Error, Result};
use crate::limits;
use crate::photo::Exposure;
use nalgebra::Matrix3;
use rawler::decoders::{Orientation, RawDecodeParams, WellKnownIFD};
use rawler::formats::tiff::IFD;
use rawler::rawimage::{RawImageData, RawPhotometricInterpretation};
use rawler::rawsource::RawSource;
use rawler::tags::DngTag;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::rc::Rc;

/// Whether the file's first bytes (at least 12) are those of a raw format whose container
/// is not TIFF (CR3, RAF, ORF, RW2); TIFF-based raw files (DNG, CR2, NEF, ARW, PEF, …)
/// are told from ordinary TIFF images by trying rawler first.
pub fn looks_like_raw(head: &[u8]) -> bool {
    let cr3 = head.len() >= 12 && &head[4..8] == b"ftyp" && &head[8..11] == b"crx";
    cr3 || head.starts_with(b"FUJIFILM")
        || head.starts_with(b"IIRO")
        || head.starts_with(b"IIRS")
        || head.starts_with(b"MMOR")
        || head.starts_with(b"IIU\0")
}

/// Decodes the raw file `bytes` (named `source` in messages). The largest image a
/// TIFF-structured file claims is checked against [`limits::IMAGE_PIXELS`] before the
/// decoder allocates it, the decoded photosite count again after; any panic inside the
/// decoder becomes an error.
pub fn decode(bytes: &[u8], source: &str) -> Result<RawMosaic> {
    match decode_known(bytes, source)? {
        Ok(mosaic) => Ok(mosaic),
        Err(unknown) => Err(Error::Image {
            context: source.to_string(),
            message: cannot_decode(&unknown),
        }),
    }
}

/// What to tell a person whose raw file the decoder refused with `why`: a format or
/// compression it does not read (GoPro's VC-5 DNGs, a camera it names but does not know) is
/// said as such; anything else, a file whose camera cannot even be read among them, is most
/// likely a damaged or truncated copy.
fn cannot_decode(why: &str) -> String {
    let develop = "develop it to JPEG or TIFF in a raw converter and give spdcam that";
    let unknown_camera = why.contains("No decoder found") && !why.contains("make: ''");
    if why.contains("Unsupported") || unknown_camera {
        format!(
            "cannot decode this raw file: the raw decoder does not read its format or \
             compression ({why}); {develop}"
        )
    } else {
        format!(
            "cannot decode this raw file ({why}); is it damaged or truncated? A raw file \
             must be copied whole from the camera; or {develop}"
        )
    }
}

/// Whether a panic at `file` (its source path) happened inside the raw decoder's crate.
fn in_raw_decoder(file: &str) -> bool {
    file.split(['/', '\\'])
        .any(|part| part.starts_with("rawler-") || part == "rawler")
}

/// Keeps the raw decoder's panics off standard error: they are caught and become an error
/// naming the file ([`decode`]), and rawler panics once per worker on some damaged files,
/// which printed thousands of lines before that one error. Other panics are reported as
/// before. Installed once, the first time a raw file is decoded.
fn quiet_raw_decoder_panics() {
    static INSTALL: std::sync::Once = std::sync::Once::new();
    INSTALL.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !info.location().is_some_and(|l| in_raw_decoder(l.file())) {
                previous(info);
            }
        }));
    });
}

/// [`decode`] for a file that may be an ordinary TIFF image: `None` when rawler knows no
/// raw format in it (the file is read once, not once to ask and again to decode).
pub fn decode_if_raw(bytes: &[u8], source: &str) -> Result<Option<RawMosaic>> {
    Ok(decode_known(bytes, source)?.ok())
}

/// The mosaic of a file rawler knows as raw; `Ok(Err(why))` when it knows no raw format in
/// it; an error for a raw file it cannot decode or that is beyond the limits.
fn decode_known(bytes: &[u8], source: &str) -> Result<std::result::Result<RawMosaic, String>> {
    let fail = |message: String| Error::Image {
        context: source.to_string(),
        message,
    };
    quiet_raw_decoder_panics();
    let file = RawSource::new_from_slice(bytes);
    let decoder = match catch_unwind(AssertUnwindSafe(|| rawler::get_decoder(&file))) {
        Ok(Ok(decoder)) => decoder,
        Ok(Err(e)) => return Ok(Err(e.to_string())),
        Err(_) => return Ok(Err("the decoder failed reading its header".into())),
    };
    let max_pixels = limits::IMAGE_PIXELS.value()?;
    if let Some(claimed) = super::header::largest_claimed_pixels(bytes) {
        limits::IMAGE_PIXELS.check_against(
            claimed,
            max_pixels,
            &format!("{source} (an image of {claimed} pixels, as the file claims)"),
        )?;
    }
    let decoded = catch_unwind(AssertUnwindSafe(|| {
        let params = RawDecodeParams::default();
        let image = decoder.raw_image(&file, &params, false)?;
        let exif = decoder.raw_metadata(&file, &params).ok().map(|m| m.exif);
        // A DNG's own tags beyond what rawler reads (none for other formats).
        let root = decoder.ifd(WellKnownIFD::Root).ok().flatten();
        let raw_ifd = decoder.ifd(WellKnownIFD::Raw).ok().flatten();
        Ok::<_, rawler::RawlerError>((image, exif, DngTags { root, raw_ifd }))
    }));
    let (mut image, exif, dng) = match decoded {
        Ok(Ok(decoded)) => decoded,
        Ok(Err(e)) => return Err(fail(cannot_decode(&e.to_string()))),
        Err(_) => {
            return Err(fail(
                "the raw decoder failed on this file (damaged or truncated?); copy it whole \
                 from the camera again, or develop it to JPEG or TIFF in a raw converter and \
                 give spdcam that"
                    .into(),
            ))
        }
    };
    let pixels = limits::product(&[image.width as u64, image.height as u64]);
    limits::IMAGE_PIXELS.check_against(
        pixels,
        max_pixels,
        &format!("{source} ({}×{} photosites)", image.width, image.height),
    )?;
    let channels = image.cpp;
    let cfa = match (&image.photometric, channels) {
        (RawPhotometricInterpretation::Cfa(config), 1) => Some(config.cfa.clone()),
        (RawPhotometricInterpretation::LinearRaw, 3) => None,
        (RawPhotometricInterpretation::BlackIsZero, 1) => {
            return Err(fail(
                "this raw file is monochrome; a chart's colours need a colour sensor".into(),
            ))
        }
        _ => {
            return Err(fail(format!(
                "this raw file's layout ({channels} values per photosite, {:?}) is not one \
                 spdcam reads",
                image.photometric
            )))
        }
    };
    let (x0, y0, width, height) = match image.active_area {
        Some(r) => (r.p.x, r.p.y, r.d.w, r.d.h),
        None => (0, 0, image.width, image.height),
    };
    if x0 + width > image.width || y0 + height > image.height {
        return Err(fail(
            "the raw file's active area lies outside its image".into(),
        ));
    }
    let cfa = cfa.map(|pattern| {
        let colours = (0..pattern.height)
            .flat_map(|r| (0..pattern.width).map(move |c| (r, c)))
            .map(|(r, c)| pattern.color_at(r + y0, c + x0) as u8)
            .collect();
        CfaTile {
            width: pattern.width,
            height: pattern.height,
            colours,
        }
    });
    let stride = image.width * channels;
    let crop = |all: &[u16]| -> Vec<u16> {
        (y0..y0 + height)
            .flat_map(|y| {
                all[y * stride + x0 * channels..y * stride + (x0 + width) * channels]
                    .iter()
                    .copied()
            })
            .collect()
    };
    let mut white = image.whitelevel.as_vec();
    // The decoded values are kept as they are when the active area is the whole image.
    let whole = (x0, y0, width, height) == (0, 0, image.width, image.height);
    let data = std::mem::replace(&mut image.data, RawImageData::Integer(Vec::new()));
    let (values, scale) = match data {
        RawImageData::Integer(all) if all.len() == stride * image.height => {
            (if whole { all } else { crop(&all) }, 1.0)
        }
        RawImageData::Float(all) if all.len() == stride * image.height => {
            // Floating-point DNGs store 0…white; kept as 16-bit steps of the white level.
            let top = white.iter().cloned().fold(1.0f32, f32::max);
            let scale = 65535.0 / top;
            let ints: Vec<u16> = all
                .iter()
                .map(|v| (v * scale).round().clamp(0.0, 65535.0) as u16)
                .collect();
            (crop(&ints), scale)
        }
        _ => return Err(fail("the raw image's values do not fill its size".into())),
    };
    white.iter_mut().for_each(|w| *w *= scale);
    let white = match white.as_slice() {
        [w] => [*w; 3],
        [r, g, b, ..] => [*r, *g, *b],
        _ => return Err(fail("the raw file gives no white level".into())),
    };
    let black = image
        .blacklevel
        .as_vec()
        .iter()
        .map(|b| b * scale)
        .collect();
    let mut matrices = Vec::new();
    for (illuminant, flat) in &image.color_matrix {
        let Some((name, cct_k)) = illuminant_cct(*illuminant as u16) else {
            continue;
        };
        if flat.len() < 9 {
            continue;
        }
        let m: Vec<f64> = flat[..9].iter().map(|&v| v as f64).collect();
        let mut matrix = CalibratedMatrix::new(name, cct_k, Matrix3::from_row_slice(&m));
        // The DNG's CameraCalibration and ForwardMatrix of the same calibration illuminant.
        if let Some(k) = dng.calibration_index(*illuminant as u16) {
            if let Some(cc) =
                dng.matrix(&[DngTag::CameraCalibration1, DngTag::CameraCalibration2][k])
            {
                matrix.camera_calibration = cc;
            }
            matrix.forward = dng.matrix(&[DngTag::ForwardMatrix1, DngTag::ForwardMatrix2][k]);
        }
        matrices.push(matrix);
    }
    let wb = image.wb_coeffs;
    let as_shot_neutral = (wb[..3].iter().all(|v| v.is_finite() && *v > 0.0))
        .then(|| [wb[1] / wb[0], 1.0, wb[1] / wb[2]].map(|v| v as f64));
    let mut colour = RawColour::new(matrices, as_shot_neutral).map_err(|e| fail(e.to_string()))?;
    if let Some(balance) = dng.values(DngTag::AnalogBalance, 3) {
        colour = colour.with_analog_balance([balance[0], balance[1], balance[2]]);
    }
    let opcodes = match dng.bytes(DngTag::OpcodeList2) {
        Some(bytes) => OpcodeList::parse(bytes).map_err(|e| fail(e.to_string()))?,
        None => OpcodeList::default(),
    };
    let exposure = exif.and_then(|exif| {
        let number = |r: Option<rawler::formats::tiff::Rational>| {
            r.filter(|r| r.d != 0).map(|r| r.n as f64 / r.d as f64)
        };
        let f_number = number(exif.fnumber)?;
        let exposure_time_s = number(exif.exposure_time)?;
        let iso = exif
            .iso_speed_ratings
            .map(f64::from)
            .or(exif.iso_speed.map(f64::from))?;
        Exposure::new(f_number, exposure_time_s, iso)
    });
    let mut mosaic = RawMosaic {
        camera: format!("{} {}", image.clean_make, image.clean_model)
            .trim()
            .to_string(),
        width,
        height,
        channels,
        cfa,
        black,
        black_tile: (image.blacklevel.width, image.blacklevel.height),
        white,
        colour,
        orientation: orientation_code(image.orientation),
        exposure,
        gain_maps_applied: 0,
        opcodes_skipped: opcodes.skipped,
        values,
    };
    mosaic.validate().map_err(|e| fail(e.to_string()))?;
    for map in &opcodes.gain_maps {
        map.apply(&mut mosaic);
    }
    mosaic.gain_maps_applied = opcodes.gain_maps.len();
    Ok(Ok(mosaic))
}

/// A DNG's image file directories as rawler read them: IFD 0 (the camera profile's tags)
/// and the raw image's (its opcode lists); both `None` for other formats.
struct DngTags {
    root: Option<Rc<IFD>>,
    raw_ifd: Option<Rc<IFD>>,
}

impl DngTags {
    /// The tag's entry: in IFD 0, else in the raw image's IFD.
    fn entry(&self, tag: DngTag) -> Option<&rawler::formats::tiff::Entry> {
        [&self.root, &self.raw_ifd]
            .into_iter()
            .flatten()
            .find_map(|ifd| ifd.get_entry(tag))
    }

    /// The tag's first `n` values as numbers, when it holds at least `n` finite ones.
    fn values(&self, tag: DngTag, n: usize) -> Option<Vec<f64>> {
        let entry = self.entry(tag)?;
        let v: Vec<f64> = (0..n)
            .map(|i| entry.value.get_f32(i).ok().flatten().map(f64::from))
            .collect::<Option<_>>()?;
        v.iter().all(|x| x.is_finite()).then_some(v)
    }

    /// A 3 × 3 matrix tag (row-major), when the file gives one.
    fn matrix(&self, tag: &DngTag) -> Option<Matrix3<f64>> {
        self.values(*tag, 9).map(|v| Matrix3::from_row_slice(&v))
    }

    /// The bytes of an UNDEFINED (or BYTE) tag.
    fn bytes(&self, tag: DngTag) -> Option<&[u8]> {
        match &self.entry(tag)?.value {
            rawler::formats::tiff::Value::Undefined(b) | rawler::formats::tiff::Value::Byte(b) => {
                Some(b)
            }
            _ => None,
        }
    }

    /// Which calibration illuminant (0 or 1) has EXIF light-source code `code`.
    fn calibration_index(&self, code: u16) -> Option<usize> {
        [
            DngTag::CalibrationIlluminant1,
            DngTag::CalibrationIlluminant2,
        ]
        .into_iter()
        .position(|tag| {
            self.entry(tag)
                .and_then(|e| e.value.get_u16(0).ok().flatten())
                == Some(code)
        })
    }
}

/// The EXIF orientation code of rawler's orientation.
fn orientation_code(orientation: Orientation) -> u16 {
    match orientation {
        Orientation::HorizontalFlip => 2,
        Orientation::Rotate180 => 3,
        Orientation::VerticalFlip => 4,
        Orientation::Transpose => 5,
        Orientation::Rotate90 => 6,
        Orientation::Transverse => 7,
        Orientation::Rotate270 => 8,
        Orientation::Normal | Orientation::Unknown => 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_decoders_panics_are_told_by_their_source_path() {
        // Where rawler 0.8 panicked on damaged public test files (a 6 kB NEF, a 12 kB RW2).
        let registry = "/home/u/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f";
        assert!(in_raw_decoder(&format!(
            "{registry}/rawler-0.8.0/src/pumps.rs"
        )));
        assert!(in_raw_decoder(&format!(
            "{registry}/rawler-0.8.0/src/decoders/rw2/v4decompressor.rs"
        )));
        assert!(in_raw_decoder(r"C:\deps\rawler\src\bits.rs"));
        assert!(!in_raw_decoder(
            "crates/spdcam-core/src/photo/raw/decode.rs"
        ));
        assert!(!in_raw_decoder(&format!(
            "{registry}/rawloader-0.37.1/src/lib.rs"
        )));
        assert!(!in_raw_decoder(&format!(
            "{registry}/rayon-core-1.12.1/src/job.rs"
        )));
    }

    #[test]
    fn an_unsupported_format_is_not_called_damaged() {
        // rawler's words for a GoPro VC-5 DNG and for a camera it does not know.
        for why in [
            "Failed to decode image, possibly corrupt image: TODO: Unsupported DNG compression",
            "Error: No decoder found, model 'X1', make: 'Newmaker', mode: ''",
        ] {
            let message = cannot_decode(why);
            assert!(message.contains("does not read its format"), "{message}");
            assert!(!message.contains("damaged"), "{message}");
            assert!(message.contains(why));
        }
        // A cut file and one whose camera cannot be read (a CR3 of 128 kB) are damaged.
        for why in [
            "I/O error: subview(): Offset 5575128+334859 is behind EOF",
            "Error: No decoder found, model '', make: '', mode: ''",
        ] {
            let cut = cannot_decode(why);
            assert!(cut.contains("damaged or truncated"), "{cut}");
            assert!(cut.contains("raw converter"), "{cut}");
        }
    }
}
