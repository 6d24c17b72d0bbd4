//! What the 24-megapixel photo benchmarks share (`spdcam-core`'s photo bench and `spdcam`'s
//! photo_estimate and raw_estimate benches include this file by path): the photo and the timing.

use std::time::{Duration, Instant};

/// The size the benchmarks enlarge their photo to: 24 megapixels.
pub const WIDTH: u32 = 6000;
/// See [`WIDTH`].
pub const HEIGHT: u32 = 4000;

/// `photo` enlarged to [`WIDTH`] × [`HEIGHT`] and JPEG-encoded at quality 92, as a camera
/// writes it.
pub fn enlarged_jpeg(photo: &image::DynamicImage) -> Vec<u8> {
    let big = photo
        .resize_exact(WIDTH, HEIGHT, image::imageops::FilterType::Triangle)
        .to_rgb8();
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 92)
        .encode(big.as_raw(), WIDTH, HEIGHT, image::ExtendedColorType::Rgb8)
        .expect("encode");
    jpeg
}

/// The median time of `runs` calls of `f`, after one call to warm up.
pub fn median(runs: usize, mut f: impl FnMut()) -> Duration {
    f();
    let mut t: Vec<Duration> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed()
        })
        .collect();
    t.sort();
    t[t.len() / 2]
}
