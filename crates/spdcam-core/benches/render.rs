//! Render speed (issue targets): a full 1709×1212 render with noise, Menon and aberration
//! (≤ 100 ms), a dataset-sized render of 96 patches of 24 px (≤ 1 ms), and noise-free
//! patch-level features (≥ 100,000 per second). Each line prints the median time and its
//! ratio against the target; when python3 with numpy and colour-demosaicing is present, the
//! same 1709×1212 pipeline in numpy (`tools/baseline_render.py`) runs as the baseline of the
//! same run and the speed-up over it is printed (`SPDCAM_PYTHON` picks the interpreter).

use spdcam_core::builtin;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, Layout};
use spdcam_core::illuminant::StandardIlluminant;
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
        Duration::from_millis(100),
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
