//! Dataset generation speed (issue targets): 10,000 samples of the 96-patch ColorChecker SG
//! through the full camera in ≤ 10 s (≥ 1,000 samples/s) and ≥ 100,000 samples/s on the fast
//! path, measured in memory (no disk), with and without Parquet encoding, and the fast path
//! written to disk by `Generator::run` (files rendered, compressed and written in parallel;
//! goal ≥ 100,000 samples/s and ≤ 150 bytes a sample) against the previous writer in the same
//! run (files rendered in turn, each encoded uncompressed with DOUBLE SPDs and weights on one
//! writer thread). Ratios are printed against the targets and against the thesis's own
//! generator (7,193 images in 55 min, 2.18 samples/s). A per-stage timing of one
//! full-pipeline sample on one thread follows.
//!
//! Uses the thesis set-up (Canon EOS 5D Mark II + BW486, SG 96) from `$SPDCAM_DATA` or
//! `../shared/data`; falls back to the built-in Nikon D5100 on the ColorChecker 24.

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::demosaic;
use spdcam_core::camera::sensor::{self, Sensitivities, SpectralResponse};
use spdcam_core::camera::white_balance;
use spdcam_core::camera::{noise, Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::dataset::{
    self, FileFormat, GenerateOptions, Generator, Pipeline, SampleBatch, DEFAULT_CHUNK_SIZE,
};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::Grid;
use std::hint::black_box;
use std::time::{Duration, Instant};

const THESIS_SAMPLES_PER_S: f64 = 7193.0 / (55.0 * 60.0);

struct SetUp {
    camera: Camera,
    sensitivities: Sensitivities,
    lighting: Lighting,
    label: String,
}

fn set_up(grid: &Grid) -> SetUp {
    let root = spdcam_test_data::measured_data_dir();
    let data_dir = DataDir::new(Some(root.clone()));
    let thesis = root.join("thesis").is_dir();
    let (camera_name, chart_name, lighting_spec) = if thesis {
        (
            "canon_eos_5d_mark_ii_mod_bw486",
            "colorchecker_sg96",
            "gaussian:7",
        )
    } else {
        ("nikon_d5100_npl", "colorchecker24", "gaussian:7")
    };
    let (name, measured) = builtin::resolve_table(
        camera_name,
        "camera",
        builtin::CAMERAS,
        &data_dir,
        &["cameras", "thesis"],
    )
    .expect("camera sensitivities");
    let sensitivities = Sensitivities::new(&name, &measured, grid).expect("sensitivities");
    let chart = Chart::resolve(chart_name, None, &data_dir, grid).expect("chart");
    let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), grid).expect("camera");
    let lighting = Lighting::parse(lighting_spec, &data_dir, grid).expect("lighting");
    let label = format!(
        "{} on {} ({}), lighting {lighting_spec}, {} rayon threads",
        camera_name,
        chart_name,
        if thesis {
            "the thesis set-up"
        } else {
            "shared data not found: built-in fallback"
        },
        rayon::current_num_threads()
    );
    SetUp {
        camera,
        sensitivities,
        lighting,
        label,
    }
}

/// Generates `count` samples chunk by chunk in memory; returns (generate, generate + encode)
/// durations.
fn generate(generator: &Generator, count: u64) -> (Duration, Duration) {
    let (mut rendering, mut encoding) = (Duration::ZERO, Duration::ZERO);
    let mut start = 0;
    while start < count {
        let end = (start + DEFAULT_CHUNK_SIZE).min(count);
        let t = Instant::now();
        let batch = generator
            .samples(start..end, None, &|_| {})
            .expect("samples");
        rendering += t.elapsed();
        let t = Instant::now();
        black_box(dataset::encode_parquet(generator.columns(), &batch).expect("encode"));
        encoding += t.elapsed();
        start = end;
    }
    (rendering, rendering + encoding)
}

fn report(what: &str, count: u64, (alone, with_encoding): (Duration, Duration), target: f64) {
    let rate = count as f64 / alone.as_secs_f64();
    let rate_encoded = count as f64 / with_encoding.as_secs_f64();
    println!(
        "{what}: {count} samples in {:.2} s = {rate:.0} samples/s ({:.2}× the target {target:.0}/s, \
         {:.0}× the thesis's {THESIS_SAMPLES_PER_S:.2}/s)",
        alone.as_secs_f64(),
        rate / target,
        rate / THESIS_SAMPLES_PER_S
    );
    println!(
        "  with Parquet encoding: {rate_encoded:.0} samples/s ({:.2}× the target)",
        rate_encoded / target
    );
}

/// Bytes of the files under `dir`.
fn bytes_under(dir: &std::path::Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .map(|e| match e.metadata() {
                    Ok(m) if m.is_dir() => bytes_under(&e.path()),
                    Ok(m) => m.len(),
                    Err(_) => 0,
                })
                .sum()
        })
        .unwrap_or(0)
}

/// The previous writer: files rendered one after the other (samples in parallel), each sent
/// to one writer thread that encodes it uncompressed with DOUBLE SPDs and weights and writes
/// it. Returns the seconds taken.
fn write_previous(generator: &Generator, count: u64, dir: &std::path::Path) -> f64 {
    std::fs::create_dir_all(dir).expect("directory");
    let columns = generator.columns();
    let format = FileFormat::uncompressed_float64_values(columns);
    let t = Instant::now();
    std::thread::scope(|scope| {
        let (sender, receiver) = std::sync::mpsc::sync_channel::<(u64, SampleBatch)>(1);
        let writer = scope.spawn(move || {
            for (k, batch) in receiver {
                let bytes = dataset::encode_parquet_as(columns, &batch, &format).expect("encode");
                std::fs::write(dir.join(format!("part-{k:05}.parquet")), bytes).expect("write");
            }
        });
        let mut start = 0;
        while start < count {
            let end = (start + DEFAULT_CHUNK_SIZE).min(count);
            let batch = generator
                .samples(start..end, None, &|_| {})
                .expect("samples");
            sender
                .send((start / DEFAULT_CHUNK_SIZE, batch))
                .expect("writer");
            start = end;
        }
        drop(sender);
        writer.join().expect("writer thread");
    });
    t.elapsed().as_secs_f64()
}

/// The fast path written to disk now and by the previous writer, on the set-up of the
/// issue's measurement (built-in Nikon D5100, ColorChecker 24, `gaussian:7`: 72 features, 81
/// SPD values and 7 weights a sample).
fn written(grid: &Grid, count: u64) {
    let set = builtin::CAMERAS[0].load().expect("built-in camera");
    let nikon = Sensitivities::new("nikon_d5100_npl", &set, grid).expect("sensitivities");
    let chart = Chart::colorchecker24(grid).expect("chart");
    let camera = Camera::new(&nikon, chart, CameraConfig::default(), grid).expect("camera");
    let lighting = Lighting::parse("gaussian:7", &DataDir::default(), grid).expect("lighting");
    let options = GenerateOptions {
        pipeline: Pipeline::Fast,
        ..GenerateOptions::new(count, 1)
    };
    let generator = Generator::new(&camera, &lighting, options).expect("generator");
    let root = std::env::temp_dir().join(format!("spdcam-bench-generate-{}", std::process::id()));
    let (now_dir, previous_dir) = (root.join("now"), root.join("previous"));
    let _ = std::fs::remove_dir_all(&root);
    let previous = write_previous(&generator, count, &previous_dir);
    let t = Instant::now();
    let plan = generator.prepare(&now_dir, false).expect("plan");
    generator.run(&plan, &|_| {}).expect("run");
    let now = t.elapsed().as_secs_f64();
    let (now_bytes, previous_bytes) = (bytes_under(&now_dir), bytes_under(&previous_dir));
    let _ = std::fs::remove_dir_all(&root);
    let per = |b: u64| b as f64 / count as f64;
    println!(
        "fast path written to disk (Nikon D5100, ColorChecker 24, gaussian:7), {count} samples: \
         {:.0} samples/s ({:.2}× the target \
         100,000/s), {:.0} bytes a sample ({:.0} MB per million; target 150)",
        count as f64 / now,
        count as f64 / now / 100_000.0,
        per(now_bytes),
        per(now_bytes)
    );
    println!(
        "  previous writer, same run: {:.0} samples/s, {:.0} bytes a sample → now {:.2}× as \
         fast, {:.1}× smaller",
        count as f64 / previous,
        per(previous_bytes),
        previous / now,
        previous_bytes as f64 / now_bytes as f64
    );
}

/// One full-pipeline sample on one thread, stage by stage (median of `runs`).
fn stages(s: &SetUp, grid: &Grid, runs: usize) {
    let camera = &s.camera;
    let chart = camera.chart();
    let config = camera.config();
    let response = SpectralResponse::new(&s.sensitivities, chart, grid).expect("response");
    let region_map = chart.layout.region_map();
    let mut buffers = camera.buffers();
    let mut image = buffers.image.clone();
    let pattern = match config.sensor.mode {
        sensor::SensorMode::SingleSensor(p) => p,
        sensor::SensorMode::ThreeSensor => {
            println!("stage timing skipped: three-sensor camera");
            return;
        }
    };
    let mut mosaic =
        spdcam_core::raster::Mosaic::new(chart.layout.width, chart.layout.height, pattern);
    let mut raw = Vec::new();
    let mut features = Vec::new();
    let mut times: Vec<[Duration; 8]> = Vec::with_capacity(runs);
    for i in 0..runs as u64 {
        let mut t = [Duration::ZERO; 8];
        let mut clock = Instant::now();
        let mut lap = |k: usize, clock: &mut Instant| {
            t[k] = clock.elapsed();
            *clock = Instant::now();
        };
        let draw = s.lighting.draw(1, i).expect("draw");
        lap(0, &mut clock);
        let light = camera.light(&draw.spd).expect("light");
        lap(1, &mut clock);
        response.raw_into(&light, &mut raw);
        sensor::form_mosaic(&region_map, &raw, &mut mosaic);
        lap(2, &mut clock);
        if let Some(n) = &config.noise {
            noise::add_noise(&mut mosaic.data, mosaic.width, n, i);
        }
        lap(3, &mut clock);
        demosaic::demosaic_into(&mosaic, config.demosaic, &mut image);
        lap(4, &mut clock);
        let gains = config.white_balance.gains(&image);
        white_balance::apply_gains(&mut image, gains);
        lap(5, &mut clock);
        black_box(&image);
        features.clear();
        camera.render_features_into(&light, i, &mut buffers, &mut features);
        lap(6, &mut clock);
        black_box(&features);
        times.push(t);
    }
    let median = |k: usize| {
        let mut v: Vec<Duration> = times.iter().map(|t| t[k]).collect();
        v.sort();
        v[v.len() / 2]
    };
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let parts: Vec<(&str, Duration)> = vec![
        ("light draw", median(0)),
        ("light check (Camera::light)", median(1)),
        ("sensor (spectral integration + mosaic)", median(2)),
        ("noise", median(3)),
        ("demosaicing", median(4)),
        ("white balance (gains from full image, apply)", median(5)),
    ];
    let capture: Duration = parts[2..].iter().map(|p| p.1).sum();
    let whole = median(6);
    println!(
        "one full-pipeline sample on one thread, {}×{} px (median of {runs}):",
        chart.layout.width, chart.layout.height
    );
    for (name, d) in &parts {
        println!("  {name:<42} {:>7.3} ms", ms(*d));
    }
    println!(
        "  {:<42} {:>7.3} ms",
        "aberration + colour + feature sampling",
        ms(whole.saturating_sub(capture))
    );
    println!(
        "  {:<42} {:>7.3} ms (render_features_into) + {:.3} ms light draw and check",
        "camera total",
        ms(whole),
        ms(parts[0].1 + parts[1].1)
    );
}

fn main() {
    let grid = Grid::SIMULATION;
    let s = set_up(&grid);
    println!("set-up: {}", s.label);
    let full =
        Generator::new(&s.camera, &s.lighting, GenerateOptions::new(2_000, 1)).expect("generator");
    generate(&full, 200);
    report("full pipeline", 2_000, generate(&full, 2_000), 1_000.0);
    let fast = Generator::new(
        &s.camera,
        &s.lighting,
        GenerateOptions {
            pipeline: Pipeline::Fast,
            ..GenerateOptions::new(200_000, 1)
        },
    )
    .expect("generator");
    generate(&fast, 20_000);
    report("fast path", 200_000, generate(&fast, 200_000), 100_000.0);
    written(&grid, 400_000);
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
        .install(|| stages(&s, &grid, 200));
}
