//! Render speed (issue targets): a full 1709×1212 render with noise, Menon and aberration
//! (≤ 50 ms), a dataset-sized render of 96 patches of 24 px (≤ 1 ms), and noise-free
//! patch-level features (≥ 100,000 per second). Each line prints the median time and its
//! ratio against the target. Baselines of the same run: the previous noise and colour stages
//! (scalar: one ziggurat normal per pixel from a xoshiro256++ stream, one pixel at a time
//! through the colour matrix and table; kept in this file) timed on the same planes, giving
//! the render with the previous stages; and, when python3 with numpy and colour-demosaicing
//! is present, the same 1709×1212 pipeline in numpy (`tools/baseline_render.py`;
//! `SPDCAM_PYTHON` picks the interpreter).

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Poisson, StandardNormal};
use rayon::prelude::*;
use spdcam_core::builtin;
use spdcam_core::camera::colour::ColourTransform;
use spdcam_core::camera::noise::{self, NoiseParams};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, Layout};
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::raster::RgbImage;
use spdcam_core::seed;
use spdcam_core::spectral::{Grid, SpectralSet};
use std::time::{Duration, Instant};

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn time_it(runs: usize, mut f: impl FnMut()) -> Duration {
    f();
    median(
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed()
            })
            .collect(),
    )
}

fn main() {
    let grid = Grid::SIMULATION;
    let set = builtin::CAMERAS[0].load().expect("built-in camera");
    let nikon = Sensitivities::new("nikon_d5100_npl", &set, &grid).expect("camera");
    let d65 = StandardIlluminant::D65.spd(&grid).expect("D65");
    let config = CameraConfig::default();

    // 1. The thesis's photo size.
    let big = Chart::colorchecker24(&grid)
        .and_then(|c| c.with_layout(Layout::fit(4, 6, 1709, 1212, 0.1, 0.3)?))
        .expect("chart");
    let camera = Camera::new(&nikon, big, config, &grid).expect("camera");
    let light = camera.light(&d65).expect("light");
    let mut buffers = camera.buffers();
    let mut seed = 0;
    let full = time_it(15, || {
        seed += 1;
        camera.render_into(&light, seed, &mut buffers, None);
    });
    report(
        "full render 1709×1212 (noise, Menon, aberration)",
        full,
        Duration::from_millis(50),
    );
    // The same render with the previous noise and colour stages: each stage timed on the
    // planes it works on (the noise-free mosaic, the aberrated image), then swapped in.
    let quiet = Camera::new(
        &nikon,
        camera.chart().clone(),
        CameraConfig {
            noise: None,
            ..config
        },
        &grid,
    )
    .expect("camera");
    let stages = quiet.render(&d65, 1, true).expect("render").stages;
    let clean = stages.cfa.expect("mosaic").data;
    let aberrated = stages.aberrated.expect("aberrated image");
    let params = config.noise.expect("noise");
    let mut plane = clean.clone();
    let width = camera.chart().layout.width;
    let noise_new = time_it(15, || {
        plane.copy_from_slice(&clean);
        seed += 1;
        noise::add_noise(&mut plane, width, &params, seed);
    });
    let noise_old = time_it(15, || {
        plane.copy_from_slice(&clean);
        seed += 1;
        previous_noise(&mut plane, width, &params, seed);
    });
    let transform =
        ColourTransform::new(camera.correction_matrix(), config.colour.bit_depth).expect("colour");
    let mut image = aberrated.clone();
    let colour_new = time_it(15, || {
        image.clone_from(&aberrated);
        transform.apply(&mut image);
    });
    let colour_old = time_it(15, || {
        image.clone_from(&aberrated);
        previous_colour(&transform, &mut image);
    });
    let previous = full + noise_old + colour_old - noise_new - colour_new;
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "  noise stage {:.1} ms (previous {:.1} ms, {:.1}×), colour stage {:.1} ms (previous \
         {:.1} ms, {:.1}×)",
        ms(noise_new),
        ms(noise_old),
        noise_old.as_secs_f64() / noise_new.as_secs_f64(),
        ms(colour_new),
        ms(colour_old),
        colour_old.as_secs_f64() / colour_new.as_secs_f64()
    );
    println!(
        "  with the previous noise and colour stages: {:.1} ms → {:.2}× faster now",
        ms(previous),
        previous.as_secs_f64() / full.as_secs_f64()
    );
    if let Some(baseline) = numpy_baseline() {
        println!(
            "  numpy + colour-demosaicing baseline, same run: {:.0} ms → spdcam is {:.1}× faster",
            baseline.as_secs_f64() * 1e3,
            baseline.as_secs_f64() / full.as_secs_f64()
        );
    } else {
        println!("  (numpy baseline skipped: python3 with numpy and colour-demosaicing not found)");
    }

    // 2. Dataset-sized: 96 patches of 24 px (8×12), single thread.
    let refl = SpectralSet::on_grid(
        &grid,
        (0..96).map(|i| format!("p{i}")).collect(),
        (0..96)
            .map(|i| {
                (0..grid.count)
                    .map(|b| 0.05 + 0.9 * (((i * 7 + b) % 23) as f64 / 22.0))
                    .collect()
            })
            .collect(),
    )
    .expect("reflectances");
    let sg = Chart::from_reflectances("synthetic96", &refl, 8, 12, &grid).expect("chart");
    let camera = Camera::new(&nikon, sg, config, &grid).expect("camera");
    let light = camera.light(&d65).expect("light");
    let mut buffers = camera.buffers();
    let small = time_it(300, || {
        seed += 1;
        camera.render_into(&light, seed, &mut buffers, None);
        std::hint::black_box(camera.features(&buffers.image));
    });
    report(
        "dataset render 288×192, 96 patches, full image + features",
        small,
        Duration::from_millis(1),
    );
    let mut features = Vec::with_capacity(288);
    let features_only = time_it(300, || {
        seed += 1;
        features.clear();
        camera.render_features_into(&light, seed, &mut buffers, &mut features);
        std::hint::black_box(&features);
    });
    report(
        "dataset render 288×192, 96 patches, features only",
        features_only,
        Duration::from_millis(1),
    );

    // 3. Noise-free patch-level features.
    let mut raw = Vec::new();
    let mut out = Vec::with_capacity(288);
    let n = 20_000;
    let fast = time_it(5, || {
        for _ in 0..n {
            out.clear();
            camera.features_fast(&light, &mut raw, &mut out);
            std::hint::black_box(&out);
        }
    }) / n;
    report(
        "patch-level features, 96 patches (one thread)",
        fast,
        Duration::from_micros(10),
    );
    println!(
        "  = {:.0} renders/s on one thread",
        1.0 / fast.as_secs_f64()
    );
}

fn report(what: &str, time: Duration, target: Duration) {
    println!(
        "{what}: {:.3} ms (target {:.3} ms, ratio {:.2} of target)",
        time.as_secs_f64() * 1e3,
        target.as_secs_f64() * 1e3,
        time.as_secs_f64() / target.as_secs_f64()
    );
}

/// The previous noise stage: per pixel, one ziggurat normal (rand_distr's `StandardNormal`)
/// from a xoshiro256++ stream per band of 16 rows, Poisson shot noise below 64 electrons.
fn previous_noise(data: &mut [f32], width: usize, params: &NoiseParams, seed: u64) {
    let range = params.signal_range_adu() as f32;
    let gain = params.gain_adu_per_e as f32;
    let read = params.read_noise_e as f32;
    let black = params.black_level_adu as f32;
    let full = params.full_scale_adu() as f32;
    let process = |(band, rows): (usize, &mut [f32])| {
        let mut rng = SmallRng::seed_from_u64(seed::derive(seed, band as u64));
        for v in rows.iter_mut() {
            let mean_e = (*v * range / gain).max(0.0);
            let electrons = if mean_e > 64.0 {
                let z: f32 = rng.sample(StandardNormal);
                mean_e + z * (mean_e + read * read).sqrt()
            } else {
                let shot = if mean_e > 0.0 {
                    Poisson::new(mean_e)
                        .map(|p| p.sample(&mut rng))
                        .unwrap_or(mean_e)
                } else {
                    0.0
                };
                let z: f32 = rng.sample(StandardNormal);
                shot + z * read
            };
            let adu = ((black + electrons * gain + 0.5).max(0.0) as u32 as f32).min(full);
            *v = (adu - black) / range;
        }
    };
    let chunk = 16 * width.max(1);
    if data.len() > 200_000 {
        data.par_chunks_mut(chunk).enumerate().for_each(process);
    } else {
        data.chunks_mut(chunk).enumerate().for_each(process);
    }
}

/// The previous colour stage: one pixel at a time through the matrix, the table and the
/// quantisation.
fn previous_colour(transform: &ColourTransform, image: &mut RgbImage) {
    let [r, g, b] = &mut image.planes;
    let one = |((r, g), b): ((&mut [f32], &mut [f32]), &mut [f32])| {
        for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
            let lin = transform.to_linear_srgb([*r, *g, *b]);
            *r = transform.quantise(transform.encode(lin[0]));
            *g = transform.quantise(transform.encode(lin[1]));
            *b = transform.quantise(transform.encode(lin[2]));
        }
    };
    r.par_chunks_mut(16384)
        .zip(g.par_chunks_mut(16384))
        .zip(b.par_chunks_mut(16384))
        .for_each(one);
}

/// Times `tools/baseline_render.py` (numpy + colour-demosaicing) if python3 (or
/// `$SPDCAM_PYTHON`) can run it.
fn numpy_baseline() -> Option<Duration> {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/baseline_render.py"
    );
    let python = std::env::var("SPDCAM_PYTHON").unwrap_or_else(|_| "python3".into());
    let out = std::process::Command::new(python)
        .arg(script)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let secs: f64 = text.lines().last()?.trim().parse().ok()?;
    Some(Duration::from_secs_f64(secs))
}
