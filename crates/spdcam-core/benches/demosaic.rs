//! Demosaicing speed: every method on a full sensor frame (1709×1212, split over threads) and
//! on a dataset-sized image (288×192, one thread).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use spdcam_core::camera::demosaic::{demosaic_into, DemosaicMethod};
use spdcam_core::raster::{CfaPattern, Mosaic, RgbImage};

/// A smooth scene with a little deterministic grain, behind an RGGB filter.
fn mosaic(width: usize, height: usize) -> Mosaic {
    let mut m = Mosaic::new(width, height, CfaPattern::Rggb);
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for y in 0..height {
        for x in 0..width {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let grain = (state >> 40) as f32 / (1u64 << 24) as f32;
            let (xf, yf) = (x as f32, y as f32);
            let scene = 0.5 + 0.3 * (0.013 * xf + 0.007 * yf).sin() * (0.011 * yf).cos();
            m.data[y * width + x] = scene + 0.05 * grain;
        }
    }
    m
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("demosaic");
    for (width, height) in [(1709, 1212), (288, 192)] {
        let input = mosaic(width, height);
        let mut out = RgbImage::new(width, height);
        for method in DemosaicMethod::ALL {
            group.bench_function(format!("{}/{width}x{height}", method.name()), |b| {
                b.iter(|| demosaic_into(black_box(&input), method, &mut out))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
