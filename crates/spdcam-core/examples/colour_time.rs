use spdcam_core::camera::colour::ColourTransform;
use spdcam_core::raster::RgbImage;
use std::time::Instant;
fn main() {
    let ct = ColourTransform::new(Some(nalgebra::Matrix3::identity()), 8).unwrap();
    let mut img = RgbImage::new(288, 192);
    for c in 0..3 {
        for (i, v) in img.planes[c].iter_mut().enumerate() {
            *v = ((i * (c + 3)) % 1000) as f32 / 1000.0;
        }
    }
    let reps = 300;
    let t = Instant::now();
    for _ in 0..reps {
        let mut i2 = img.clone();
        ct.apply(&mut i2);
        std::hint::black_box(&i2);
    }
    println!(
        "apply {:.3} ms",
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    );
    let t = Instant::now();
    for _ in 0..reps {
        let mut s = 0.0f32;
        for v in &img.planes[0] {
            s += ct.encode(*v);
        }
        std::hint::black_box(s);
    }
    println!(
        "encode only plane {:.3} ms",
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    );
    let t = Instant::now();
    for _ in 0..reps {
        let mut s = 0.0f32;
        for v in &img.planes[0] {
            s += ct.quantise(*v);
        }
        std::hint::black_box(s);
    }
    println!(
        "quantise only plane {:.3} ms",
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    );
    let t = Instant::now();
    for _ in 0..reps {
        let mut s = 0.0f32;
        for v in &img.planes[0] {
            s += v.powi(6);
        }
        std::hint::black_box(s);
    }
    println!(
        "powi6 plane {:.3} ms",
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    );
}
