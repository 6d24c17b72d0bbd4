use spdcam_core::camera::demosaic::*;
use spdcam_core::camera::noise::*;
use spdcam_core::camera::white_balance::*;
use spdcam_core::camera::*;
use spdcam_core::raster::*;
use std::time::Instant;
fn main() {
    for (w, h) in [(288usize, 192usize), (1709, 1212)] {
        let mut m = Mosaic::new(w, h, CfaPattern::Rggb);
        for (i, v) in m.data.iter_mut().enumerate() {
            *v = ((i % 97) as f32) / 100.0;
        }
        let reps = if w < 1000 { 200 } else { 10 };
        let t = Instant::now();
        for s in 0..reps {
            add_noise(&mut m.data, w, &NoiseParams::THESIS, s);
        }
        println!(
            "{w}x{h} noise {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let mut img = RgbImage::new(w, h);
        for meth in DemosaicMethod::ALL {
            let t = Instant::now();
            for _ in 0..reps {
                demosaic_into(&m, meth, &mut img);
            }
            println!(
                "{w}x{h} {meth:?} {:.3} ms",
                t.elapsed().as_secs_f64() * 1e3 / reps as f64
            );
        }
        let wb = WhiteBalance::default();
        let t = Instant::now();
        for _ in 0..reps {
            std::hint::black_box(wb.gains(&img));
        }
        println!(
            "{w}x{h} wb gains {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let t = Instant::now();
        for _ in 0..reps {
            white_balance::apply_gains(&mut img, [1.01, 1.0, 0.99]);
        }
        println!(
            "{w}x{h} wb apply {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let mut scratch = Vec::new();
        let t = Instant::now();
        for _ in 0..reps {
            aberration::LateralAberration::THESIS.apply(&mut img, &mut scratch);
        }
        println!(
            "{w}x{h} aberration {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let ct = colour::ColourTransform::new(Some(nalgebra::Matrix3::identity()), 8).unwrap();
        let t = Instant::now();
        for _ in 0..reps {
            let mut i2 = img.clone();
            ct.apply(&mut i2);
        }
        println!(
            "{w}x{h} colour(+clone) {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
    }
}
