//! Reading photos: JPEG, PNG (8/16-bit), TIFF, with the EXIF orientation applied, into one
//! compact buffer of encoded sRGB values (8 or 16 bits per channel, as the file had); and
//! camera raw files ([`super::raw`]), whose encoded pixels are a preview to find the chart
//! in, the linear mosaic held beside them.

use super::exposure::Exposure;
use super::raw::{self, RawMosaic};
use crate::advice::{Advice, CORRUPT, TRUNCATED};
use crate::error::{Error, Result};
use crate::{fsio, limits};
use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader};
use std::io::Cursor;
use std::path::Path;
use std::sync::Arc;

/// Smallest width and height of a photo that can show a chart.
pub const MIN_PHOTO_SIDE: usize = 16;
/// Bytes the decoder may allocate per pixel allowed by [`limits::IMAGE_PIXELS`]: a 16-bit
/// RGBA pixel; a safety net behind the pixel count checked from the header.
const DECODE_BYTES_PER_PIXEL: u64 = 8;
/// Bytes of a 16-bit RGB pixel, the widest a photo is kept in.
const RGB16_BYTES: u64 = 6;

/// The pixels of a photo, interleaved RGB, as the file stored them.
#[derive(Debug, Clone, PartialEq)]
enum Pixels {
    Rgb8(Vec<u8>),
    Rgb16(Vec<u16>),
}

/// A decoded photo, upright (EXIF orientation applied): encoded sRGB, 8 or 16 bits per
/// channel, interleaved, without any conversion that would multiply its size. A raw photo
/// holds its linear mosaic beside them ([`Photo::raw`]); its encoded pixels are then the
/// preview the chart is found in, and its patches are read on the mosaic.
#[derive(Debug, Clone, PartialEq)]
pub struct Photo {
    /// Where the photo came from (file path or a name), for messages.
    pub source: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// What the decoder noticed but could decode past, e.g. a truncated file.
    pub warnings: Vec<String>,
    /// The camera's exposure from the file's EXIF, when it gives aperture, time and ISO.
    pub exposure: Option<Exposure>,
    pixels: Pixels,
    raw: Option<Arc<RawMosaic>>,
}

impl Photo {
    /// A photo from interleaved 8-bit RGB.
    pub fn from_rgb8(source: &str, width: usize, height: usize, data: Vec<u8>) -> Result<Photo> {
        Photo::checked(source, width, height, data.len(), Pixels::Rgb8(data))
    }

    /// A photo from interleaved 16-bit RGB.
    pub fn from_rgb16(source: &str, width: usize, height: usize, data: Vec<u16>) -> Result<Photo> {
        Photo::checked(source, width, height, data.len(), Pixels::Rgb16(data))
    }

    fn checked(
        source: &str,
        width: usize,
        height: usize,
        len: usize,
        pixels: Pixels,
    ) -> Result<Photo> {
        if len != width * height * 3 {
            return Err(Error::invalid(format!(
                "{source}: {len} values do not fill a {width}×{height} RGB image"
            )));
        }
        if width < MIN_PHOTO_SIDE || height < MIN_PHOTO_SIDE {
            return Err(Error::invalid(format!(
                "{source}: the photo is {width}×{height} px; a chart needs at least \
                 {MIN_PHOTO_SIDE}×{MIN_PHOTO_SIDE}"
            )));
        }
        Ok(Photo {
            source: source.to_string(),
            width,
            height,
            warnings: Vec::new(),
            exposure: None,
            pixels,
            raw: None,
        })
    }

    /// A raw photo: the preview of `mosaic` ([`RawMosaic::preview`]) with the mosaic kept
    /// beside it.
    pub fn from_raw(source: &str, mosaic: RawMosaic) -> Result<Photo> {
        let mut photo = mosaic.preview(source)?;
        photo.raw = Some(Arc::new(mosaic));
        Ok(photo)
    }

    /// The linear mosaic of a raw photo; `None` for an encoded one.
    pub fn raw(&self) -> Option<&RawMosaic> {
        self.raw.as_deref()
    }

    /// A photo from a decoded image (any colour type; alpha is dropped, grey becomes RGB).
    /// RGBA is turned into RGB in place, so that a large photo is not held twice.
    pub fn from_image(source: &str, image: DynamicImage) -> Result<Photo> {
        let (w, h) = (image.width() as usize, image.height() as usize);
        match image {
            DynamicImage::ImageRgb8(b) => Photo::from_rgb8(source, w, h, b.into_raw()),
            DynamicImage::ImageRgb16(b) => Photo::from_rgb16(source, w, h, b.into_raw()),
            DynamicImage::ImageRgba8(b) => Photo::from_rgb8(source, w, h, drop_alpha(b.into_raw())),
            DynamicImage::ImageRgba16(b) => {
                Photo::from_rgb16(source, w, h, drop_alpha(b.into_raw()))
            }
            DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgb32F(_)
            | DynamicImage::ImageRgba32F(_) => {
                Photo::from_rgb16(source, w, h, image.to_rgb16().into_raw())
            }
            other => Photo::from_rgb8(source, w, h, other.to_rgb8().into_raw()),
        }
    }

    /// The stored values, interleaved RGB row by row, when they have 8 bits per channel
    /// (e.g. to hand the decoded photo to another program).
    pub fn rgb8(&self) -> Option<&[u8]> {
        match &self.pixels {
            Pixels::Rgb8(d) => Some(d),
            Pixels::Rgb16(_) => None,
        }
    }

    /// The stored values, interleaved RGB row by row, when they have 16 bits per channel.
    pub fn rgb16(&self) -> Option<&[u16]> {
        match &self.pixels {
            Pixels::Rgb8(_) => None,
            Pixels::Rgb16(d) => Some(d),
        }
    }

    /// Bits per channel of the stored values (8 or 16).
    pub fn bit_depth(&self) -> u32 {
        match self.pixels {
            Pixels::Rgb8(_) => 8,
            Pixels::Rgb16(_) => 16,
        }
    }

    /// Encoded value (0…1) at or above which a channel counts as clipped.
    pub fn clip_level(&self) -> f32 {
        match self.pixels {
            Pixels::Rgb8(_) => 254.5 / 255.0,
            Pixels::Rgb16(_) => 65400.0 / 65535.0,
        }
    }

    /// Encoded sRGB (0…1) of pixel (`x`, `y`).
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        let i = 3 * (y * self.width + x);
        match &self.pixels {
            Pixels::Rgb8(d) => [d[i], d[i + 1], d[i + 2]].map(|v| v as f32 * (1.0 / 255.0)),
            Pixels::Rgb16(d) => [d[i], d[i + 1], d[i + 2]].map(|v| v as f32 * (1.0 / 65535.0)),
        }
    }

    /// Sums of encoded values (0…1 scale) over row `y`, columns `x0..x1`, per channel.
    #[inline]
    pub(crate) fn row_sum(&self, y: usize, x0: usize, x1: usize) -> [f32; 3] {
        let (a, b) = (3 * (y * self.width + x0), 3 * (y * self.width + x1));
        let mut s = [0u32; 3];
        match &self.pixels {
            Pixels::Rgb8(d) => {
                for px in d[a..b].chunks_exact(3) {
                    s[0] += px[0] as u32;
                    s[1] += px[1] as u32;
                    s[2] += px[2] as u32;
                }
                s.map(|v| v as f32 * (1.0 / 255.0))
            }
            Pixels::Rgb16(d) => {
                let mut s = [0u64; 3];
                for px in d[a..b].chunks_exact(3) {
                    s[0] += px[0] as u64;
                    s[1] += px[1] as u64;
                    s[2] += px[2] as u64;
                }
                s.map(|v| v as f32 * (1.0 / 65535.0))
            }
        }
    }
}

/// Interleaved RGBA values as interleaved RGB, in the same buffer.
fn drop_alpha<T: Copy>(mut rgba: Vec<T>) -> Vec<T> {
    let pixels = rgba.len() / 4;
    for i in 0..pixels {
        for c in 0..3 {
            rgba[3 * i + c] = rgba[4 * i + c];
        }
    }
    rgba.truncate(3 * pixels);
    rgba.shrink_to_fit();
    rgba
}

/// Reads a photo (JPEG, PNG 8/16-bit, TIFF; format from the content) from a file, a pipe
/// or a device, at most [`limits::PHOTO_BYTES`] of it, applying its EXIF orientation. Its
/// first bytes are checked for the signature of one of those formats before the rest is
/// read, so that anything else (`/dev/zero`, a CSV) is refused at once.
pub fn load_photo(path: &Path) -> Result<Photo> {
    let source = path.display().to_string();
    let bytes =
        fsio::read_limited_checked(
            path,
            &limits::PHOTO_BYTES,
            12,
            |head| match fsio::image_format(head) {
                Some(_) => Ok(()),
                None if raw::looks_like_raw(head) => Ok(()),
                None => Err(Error::Image {
                    context: source.clone(),
                    message: format!(
                        "not a JPEG, PNG, TIFF or camera raw image ({}); spdcam reads \
                     photos in those formats",
                        describe_head(head)
                    ),
                }),
            },
        )?;
    decode_photo(&bytes, &source)
}

/// The first bytes of a file for a message: that it is empty, else up to 8 bytes in hex.
fn describe_head(head: &[u8]) -> String {
    if head.is_empty() {
        return "it is empty".into();
    }
    let shown: Vec<String> = head.iter().take(8).map(|b| format!("{b:02X}")).collect();
    format!("it starts with the bytes {}", shown.join(" "))
}

/// Decodes a photo held in memory; `source` names it in messages. The pixel count is read
/// from the header and checked against [`limits::IMAGE_PIXELS`] before any pixel is
/// decoded; a JPEG that ends before its end-of-image marker decodes with a warning. A
/// camera raw file (told by its signature, or a TIFF the raw decoder knows a camera for)
/// becomes a raw photo ([`Photo::from_raw`]).
pub fn decode_photo(bytes: &[u8], source: &str) -> Result<Photo> {
    // DNG and most raw formats are TIFF files: the raw decoder is asked whether it knows
    // the file; an ordinary TIFF image goes to the image decoder.
    if raw::looks_like_raw(bytes) {
        return Photo::from_raw(source, raw::decode(bytes, source)?);
    }
    if fsio::image_format(bytes) == Some("TIFF") {
        if let Some(mosaic) = raw::decode_if_raw(bytes, source)? {
            return Photo::from_raw(source, mosaic);
        }
    }
    decode_encoded(bytes, source)
}

/// Decodes an encoded (JPEG, PNG, TIFF) photo held in memory.
fn decode_encoded(bytes: &[u8], source: &str) -> Result<Photo> {
    let image_error = |message: String| Error::Image {
        context: source.to_string(),
        message,
    };
    let mut reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| image_error(format!("cannot read: {e}")))?;
    let Some(format) = reader.format() else {
        return Err(image_error(
            "not an image in a supported format (JPEG, PNG, TIFF)".into(),
        ));
    };
    let max_pixels = limits::IMAGE_PIXELS.value()?;
    let mut decode_limits = image::Limits::default();
    decode_limits.max_alloc = Some(max_pixels.saturating_mul(DECODE_BYTES_PER_PIXEL));
    reader.limits(decode_limits);
    let mut decoder = reader
        .into_decoder()
        .map_err(|e| image_error(format!("cannot decode: {e}")))?;
    let (w, h) = decoder.dimensions();
    let pixels = limits::product(&[w.into(), h.into()]);
    // Pixels wider than 16-bit RGB (alpha, floats) count as as many 16-bit RGB pixels as
    // their bytes fill, so that the limit bounds the decoded bytes too.
    let weighted = decoder.total_bytes().div_ceil(RGB16_BYTES);
    let context = if weighted > pixels {
        format!(
            "{source} ({w}×{h} px of {:?}, counted as 16-bit RGB pixels)",
            decoder.color_type()
        )
    } else {
        format!("{source} ({w}×{h} px)")
    };
    limits::IMAGE_PIXELS.check_against(pixels.max(weighted), max_pixels, &context)?;
    let orientation = decoder
        .orientation()
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    let exposure = decoder
        .exif_metadata()
        .ok()
        .flatten()
        .and_then(Exposure::from_exif);
    let end = if format == ImageFormat::Jpeg {
        jpeg_end(bytes)
    } else {
        JpegEnd::Complete
    };
    let mut image = DynamicImage::from_decoder(decoder).map_err(|e| {
        image_error(match end {
            JpegEnd::Truncated => format!("cannot decode: {e} ({TRUNCATED})"),
            JpegEnd::Corrupt => format!("cannot decode: {e} ({CORRUPT})"),
            JpegEnd::Complete => format!("cannot decode (damaged or truncated?): {e}"),
        })
    })?;
    image.apply_orientation(orientation);
    let mut photo = Photo::from_image(source, image)?;
    photo.exposure = exposure;
    match end {
        JpegEnd::Truncated => photo.warnings.push(Advice::TruncatedJpeg.to_string()),
        JpegEnd::Corrupt => photo.warnings.push(Advice::CorruptJpeg.to_string()),
        JpegEnd::Complete => {}
    }
    Ok(photo)
}

/// How a JPEG stream ends, judged from its markers (ITU-T T.81, B.1.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JpegEnd {
    /// The marker segments lead to the end-of-image marker (`FF D9`); anything after it
    /// (as some phones append) is ignored.
    Complete,
    /// The data ends before the end-of-image marker: the file was cut.
    Truncated,
    /// The marker segments do not lead to the end-of-image marker though the file holds
    /// one after its image data: a damaged byte (a flipped bit) broke a marker or a
    /// segment's length.
    Corrupt,
}

/// How the JPEG stream `bytes` ends ([`JpegEnd`]); not a JPEG counts as complete.
pub fn jpeg_end(bytes: &[u8]) -> JpegEnd {
    const EOI: [u8; 2] = [0xFF, 0xD9];
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return JpegEnd::Complete;
    }
    match walk_jpeg_markers(bytes) {
        Ok(()) => JpegEnd::Complete,
        // Entropy-coded data never holds FF D9 (a 0xFF is followed by 0x00 or a restart
        // code), so an end-of-image marker after the first scan's start is the real end.
        Err(Some(scan)) if bytes[scan..].windows(2).any(|w| w == EOI) => JpegEnd::Corrupt,
        Err(None) if bytes.ends_with(&EOI) => JpegEnd::Corrupt,
        Err(_) => JpegEnd::Truncated,
    }
}

/// Walks the marker segments of a JPEG stream, skipping each segment by its length and the
/// entropy-coded data after each start-of-scan: `Ok` on reaching the end-of-image marker,
/// else `Err` with where the first scan's data begins, when one was reached.
fn walk_jpeg_markers(bytes: &[u8]) -> std::result::Result<(), Option<usize>> {
    let mut i = 2;
    let mut first_scan = None;
    loop {
        // A marker: one or more 0xFF fill bytes, then its code; anything else where a
        // marker belongs means the structure is broken.
        if bytes.get(i) != Some(&0xFF) {
            return Err(first_scan);
        }
        while i < bytes.len() && bytes[i] == 0xFF {
            i += 1;
        }
        let Some(&code) = bytes.get(i) else {
            return Err(first_scan);
        };
        i += 1;
        match code {
            0xD9 => return Ok(()),
            0x01 | 0xD0..=0xD7 => continue,
            _ => {}
        }
        let Some(len) = bytes
            .get(i..i + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
        else {
            return Err(first_scan);
        };
        i += len as usize;
        if i > bytes.len() {
            return Err(first_scan);
        }
        if code == 0xDA {
            first_scan.get_or_insert(i);
            // Entropy-coded data: ends at the first 0xFF not followed by 0x00 (stuffing) or
            // a restart marker.
            loop {
                match bytes.get(i..i + 2) {
                    None => return Err(first_scan),
                    Some([0xFF, next]) if *next != 0x00 && !(0xD0..=0xD7).contains(next) => break,
                    _ => i += 1,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_png_keeps_its_depth_and_values() {
        let img = image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(20, 18, |x, y| {
            image::Rgb([x as u16 * 1000, y as u16 * 3000, 65535])
        });
        let mut bytes = Vec::new();
        DynamicImage::ImageRgb16(img)
            .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
            .unwrap();
        let p = decode_photo(&bytes, "t.png").unwrap();
        assert_eq!((p.width, p.height, p.bit_depth()), (20, 18, 16));
        let v = p.pixel(3, 2);
        assert!((v[0] - 3000.0 / 65535.0).abs() < 1e-6 && (v[2] - 1.0).abs() < 1e-6);
        let values = p.rgb16().unwrap();
        assert_eq!(&values[3 * (2 * 20 + 3)..][..3], &[3000, 6000, 65535]);
        assert!(p.rgb8().is_none());
    }

    #[test]
    fn an_ordinary_tiff_is_read_as_an_image_not_a_raw_file() {
        // A TIFF goes through the raw decoder first (DNG and most raw formats are TIFFs),
        // which knows no camera in it: it is decoded as the image it is.
        let img = image::ImageBuffer::<image::Rgb<u8>, _>::from_fn(40, 30, |x, y| {
            image::Rgb([(x * 6) as u8, (y * 8) as u8, 200])
        });
        let mut bytes = Vec::new();
        DynamicImage::ImageRgb8(img)
            .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Tiff)
            .unwrap();
        assert!(raw::decode_if_raw(&bytes, "t.tif").unwrap().is_none());
        let p = decode_photo(&bytes, "t.tif").unwrap();
        assert_eq!((p.width, p.height, p.bit_depth()), (40, 30, 8));
        assert!(p.raw().is_none());
        assert_eq!(&p.rgb8().unwrap()[3 * (2 * 40 + 3)..][..3], &[18, 16, 200]);
    }

    fn jpeg_of(width: u32, height: u32) -> Vec<u8> {
        let img = image::ImageBuffer::<image::Rgb<u8>, _>::from_fn(width, height, |x, y| {
            image::Rgb([(x * 7) as u8, (y * 5) as u8, ((x + y) * 3) as u8])
        });
        let mut bytes = Vec::new();
        DynamicImage::ImageRgb8(img)
            .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Jpeg)
            .unwrap();
        bytes
    }

    #[test]
    fn truncated_jpegs_decode_with_a_warning() {
        // Issue 15: JPEGs cut at 90 % and 99 % decoded without a word.
        let bytes = jpeg_of(64, 48);
        assert_eq!(jpeg_end(&bytes), JpegEnd::Complete);
        assert!(decode_photo(&bytes, "whole.jpg")
            .unwrap()
            .warnings
            .is_empty());
        for percent in [50, 90, 99] {
            let cut = &bytes[..bytes.len() * percent / 100];
            assert_eq!(jpeg_end(cut), JpegEnd::Truncated, "{percent} %");
            if let Ok(photo) = decode_photo(cut, "cut.jpg") {
                assert!(
                    photo.warnings.iter().any(|w| w.contains("truncated")),
                    "{percent} %: {:?}",
                    photo.warnings
                );
            }
        }
        // Data after the end-of-image marker (as some phones append) is not truncation.
        let mut trailing = bytes.clone();
        trailing.extend_from_slice(b"extra data");
        assert_eq!(jpeg_end(&trailing), JpegEnd::Complete);
    }

    /// A PNG declaring `width × height` RGB pixels whose image data is one empty zlib
    /// stream: a few dozen bytes that ask for gigabytes.
    fn png_bomb(width: u32, height: u32) -> Vec<u8> {
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut chunk = |kind: &[u8], body: &[u8]| {
            let mut typed = kind.to_vec();
            typed.extend_from_slice(body);
            png.extend_from_slice(&(body.len() as u32).to_be_bytes());
            png.extend_from_slice(&typed);
            png.extend_from_slice(&crc32(&typed).to_be_bytes());
        };
        let mut header = Vec::new();
        header.extend_from_slice(&width.to_be_bytes());
        header.extend_from_slice(&height.to_be_bytes());
        header.extend_from_slice(&[8, 2, 0, 0, 0]);
        chunk(b"IHDR", &header);
        // zlib header, one final stored block of no bytes, Adler-32 of nothing (RFC 1950/1951).
        chunk(
            b"IDAT",
            &[0x78, 0x01, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0, 0, 0, 1],
        );
        chunk(b"IEND", &[]);
        png
    }

    /// CRC-32 (ISO 3309, as PNG uses), bit by bit.
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = 0xFFFF_FFFFu32;
        for &b in bytes {
            crc ^= b as u32;
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    #[test]
    fn decompression_bombs_are_refused_from_the_header() {
        // Issue 15: a PNG declaring 20000×20000 took 12.5 GB; 30000×30000 aborted.
        for (w, h) in [(20_000, 20_000), (30_000, 30_000), (200_000, 1000)] {
            let e = decode_photo(&png_bomb(w, h), "bomb.png")
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("bomb.png") && e.contains("SPDCAM_MAX_IMAGE_PIXELS"),
                "{w}×{h}: {e}"
            );
        }
        // Under the limit, the same header reaches the decoder, which finds no image data.
        let e = decode_photo(&png_bomb(100, 100), "small.png").unwrap_err();
        assert!(!e.to_string().contains("SPDCAM_MAX_IMAGE_PIXELS"), "{e}");
    }

    #[test]
    fn alpha_is_dropped_in_place_keeping_the_colours() {
        let img = image::ImageBuffer::<image::Rgba<u16>, _>::from_fn(17, 16, |x, y| {
            image::Rgba([x as u16 * 100, y as u16 * 200, 7, 123])
        });
        let mut bytes = Vec::new();
        DynamicImage::ImageRgba16(img)
            .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
            .unwrap();
        let p = decode_photo(&bytes, "alpha.png").unwrap();
        assert_eq!(p.bit_depth(), 16);
        let v = p.pixel(16, 15);
        let expect = [1600.0, 3000.0, 7.0].map(|x: f32| x / 65535.0);
        for c in 0..3 {
            assert!((v[c] - expect[c]).abs() < 1e-7, "{v:?}");
        }
        assert_eq!(
            drop_alpha(vec![1u8, 2, 3, 4, 5, 6, 7, 8]),
            [1, 2, 3, 5, 6, 7]
        );
    }

    #[test]
    fn garbage_and_tiny_images_are_clear_errors() {
        let e = decode_photo(b"hello, this is text", "notes.txt").unwrap_err();
        assert!(e.to_string().contains("notes.txt"), "{e}");
        let mut bytes = Vec::new();
        DynamicImage::new_rgb8(1, 1)
            .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
            .unwrap();
        let e = decode_photo(&bytes, "dot.png").unwrap_err().to_string();
        assert!(e.contains("1×1"), "{e}");
    }
}
