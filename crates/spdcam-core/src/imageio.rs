//! Writing rendered images as PNG (atomically) or JPEG.

use crate::error::{Error, Result};
use crate::fsio;
use crate::raster::{Mosaic, RgbImage};
use image::{ImageBuffer, ImageEncoder, Luma, Rgb};
use std::path::Path;

/// An RGB image with values on 0…1 (clipped) as 8-bit RGB.
fn to_rgb8(image: &RgbImage) -> ImageBuffer<Rgb<u8>, Vec<u8>> {
    let (w, h) = (image.width as u32, image.height as u32);
    ImageBuffer::from_fn(w, h, |x, y| {
        Rgb(image
            .pixel(x as usize, y as usize)
            .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
    })
}

/// Encodes an RGB image with values on 0…1 (clipped) as an 8- or 16-bit PNG.
pub fn encode_png(image: &RgbImage, bit_depth: u32) -> Result<Vec<u8>> {
    let (w, h) = (image.width as u32, image.height as u32);
    let mut bytes = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
    let result = match bit_depth {
        8 => encoder.write_image(
            to_rgb8(image).as_raw(),
            w,
            h,
            image::ExtendedColorType::Rgb8,
        ),
        16 => {
            let buf = ImageBuffer::<Rgb<u16>, _>::from_fn(w, h, |x, y| {
                Rgb(image
                    .pixel(x as usize, y as usize)
                    .map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16))
            });
            let raw: Vec<u8> = buf.as_raw().iter().flat_map(|v| v.to_ne_bytes()).collect();
            encoder.write_image(&raw, w, h, image::ExtendedColorType::Rgb16)
        }
        other => {
            return Err(Error::invalid(format!(
                "PNG bit depth {other} is not 8 or 16"
            )))
        }
    };
    result.map_err(|e| Error::Image {
        context: "PNG encoding".into(),
        message: e.to_string(),
    })?;
    Ok(bytes)
}

/// Encodes an RGB image with values on 0…1 (clipped) as an 8-bit JPEG of `quality` (1–100).
pub fn encode_jpeg(image: &RgbImage, quality: u8) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, quality.clamp(1, 100))
        .write_image(
            to_rgb8(image).as_raw(),
            image.width as u32,
            image.height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Image {
            context: "JPEG encoding".into(),
            message: e.to_string(),
        })?;
    Ok(bytes)
}

/// Writes an RGB image (0…1) as PNG at `path`, atomically.
pub fn write_png(path: &Path, image: &RgbImage, bit_depth: u32) -> Result<()> {
    fsio::write_atomic(path, &encode_png(image, bit_depth)?)
}

/// Writes a raw mosaic (0…1, clipped) as a 16-bit greyscale PNG, atomically.
pub fn write_mosaic_png(path: &Path, mosaic: &Mosaic) -> Result<()> {
    let (w, h) = (mosaic.width as u32, mosaic.height as u32);
    let buf = ImageBuffer::<Luma<u16>, _>::from_fn(w, h, |x, y| {
        Luma([(mosaic.get(x as usize, y as usize).clamp(0.0, 1.0) * 65535.0).round() as u16])
    });
    let raw: Vec<u8> = buf.as_raw().iter().flat_map(|v| v.to_ne_bytes()).collect();
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&raw, w, h, image::ExtendedColorType::L16)
        .map_err(|e| Error::Image {
            context: format!("PNG encoding of {}", path.display()),
            message: e.to_string(),
        })?;
    fsio::write_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_8_and_16_bit() {
        let mut img = RgbImage::new(3, 2);
        img.planes[0] = vec![0.0, 0.5, 1.0, 0.25, 0.75, 2.0];
        img.planes[2] = vec![1.0; 6];
        for depth in [8, 16] {
            let bytes = encode_png(&img, depth).unwrap();
            let decoded = image::load_from_memory(&bytes).unwrap().to_rgb16();
            assert_eq!(decoded.dimensions(), (3, 2));
            let px = decoded.get_pixel(1, 0);
            let levels = if depth == 8 { 255.0 } else { 65535.0 };
            let expect = (0.5f64 * levels).round() / levels;
            assert!((px[0] as f64 / 65535.0 - expect).abs() < 1e-4);
            assert_eq!(decoded.get_pixel(2, 1)[0], 65535);
            assert_eq!(px[2], 65535);
        }
    }
}
