//! Reading photos: JPEG, PNG (8/16-bit), TIFF, with the EXIF orientation applied, into one
//! compact buffer of encoded sRGB values (8 or 16 bits per channel, as the file had).

use crate::error::{Error, Result};
use image::{DynamicImage, ImageDecoder, ImageReader};
use std::io::{BufRead, Cursor, Seek};
use std::path::Path;

/// Smallest width and height of a photo that can show a chart.
pub const MIN_PHOTO_SIDE: usize = 16;
/// Largest memory the decoder may allocate (a 50-megapixel 16-bit RGBA photo needs 400 MB).
const MAX_DECODE_BYTES: u64 = 1 << 30;

/// The pixels of a photo, interleaved RGB, as the file stored them.
#[derive(Debug, Clone, PartialEq)]
enum Pixels {
    Rgb8(Vec<u8>),
    Rgb16(Vec<u16>),
}

/// A decoded photo, upright (EXIF orientation applied): encoded sRGB, 8 or 16 bits per
/// channel, interleaved, without any conversion that would multiply its size.
#[derive(Debug, Clone, PartialEq)]
pub struct Photo {
    /// Where the photo came from (file path or a name), for messages.
    pub source: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    pixels: Pixels,
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
            pixels,
        })
    }

    /// A photo from a decoded image (any colour type; alpha is dropped, grey becomes RGB).
    pub fn from_image(source: &str, image: DynamicImage) -> Result<Photo> {
        let (w, h) = (image.width() as usize, image.height() as usize);
        match image {
            DynamicImage::ImageRgb8(b) => Photo::from_rgb8(source, w, h, b.into_raw()),
            DynamicImage::ImageRgb16(b) => Photo::from_rgb16(source, w, h, b.into_raw()),
            DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgba16(_)
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

/// Reads a photo file (JPEG, PNG 8/16-bit, TIFF; format from the content), applying its
/// EXIF orientation.
pub fn load_photo(path: &Path) -> Result<Photo> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    decode(std::io::BufReader::new(file), &path.display().to_string())
}

/// Decodes a photo held in memory; `source` names it in messages.
pub fn decode_photo(bytes: &[u8], source: &str) -> Result<Photo> {
    decode(Cursor::new(bytes), source)
}

fn decode<R: BufRead + Seek>(reader: R, source: &str) -> Result<Photo> {
    let image_error = |message: String| Error::Image {
        context: source.to_string(),
        message,
    };
    let mut reader = ImageReader::new(reader)
        .with_guessed_format()
        .map_err(|e| image_error(format!("cannot read: {e}")))?;
    if reader.format().is_none() {
        return Err(image_error(
            "not an image in a supported format (JPEG, PNG, TIFF)".into(),
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    reader.limits(limits);
    let mut decoder = reader
        .into_decoder()
        .map_err(|e| image_error(format!("cannot decode: {e}")))?;
    let orientation = decoder
        .orientation()
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    let mut image = DynamicImage::from_decoder(decoder)
        .map_err(|e| image_error(format!("cannot decode (damaged or truncated?): {e}")))?;
    image.apply_orientation(orientation);
    Photo::from_image(source, image)
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
