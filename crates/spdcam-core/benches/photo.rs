//! Photo speed (issue targets): a 24-megapixel JPEG to its features, decoding included
//! (≤ 1 s), and chart detection alone (≤ 300 ms). The photo is a synthetic ColorChecker 24
//! scene (the test suite's generator) enlarged to 6000 × 4000 and JPEG-encoded at quality 92.
//!
//! First a summary prints median times, their ratio to the targets, and the speed-up over a
//! simple baseline measured in the same run: the same detector run directly on the full
//! resolution photo, without the pyramid; and the search for every chart (`detect_all`)
//! against the search for the best one on this one-chart photo (goal: the same time, a
//! ratio of 1). Then criterion measures each step.

#[path = "../tests/photo_support/mod.rs"]
mod photo_support;
mod support;

use criterion::{criterion_group, Criterion};
use spdcam_core::photo::{
    analyse, decode_photo, detect, detect_all, detect_at, AnalyseOptions, ChartTemplate, Photo,
};
use std::hint::black_box;
use std::time::Duration;
use support::median;

struct Fixture {
    jpeg: Vec<u8>,
    photo: Photo,
    templates: Vec<ChartTemplate>,
}

fn fixture() -> Fixture {
    let setup = photo_support::colorchecker24();
    let scene = photo_support::scene(
        &setup,
        3,
        photo_support::SceneSize {
            width: 1500,
            height: 1000,
        },
    );
    let small = image::load_from_memory(&scene.jpeg).expect("scene decodes");
    let jpeg = support::enlarged_jpeg(&small);
    let photo = decode_photo(&jpeg, "bench.jpg").expect("decode");
    Fixture {
        jpeg,
        photo,
        templates: vec![setup.template],
    }
}

fn summary(fx: &Fixture) {
    let options = AnalyseOptions {
        templates: fx.templates.clone(),
        ..AnalyseOptions::default()
    };
    let decode = median(5, || {
        black_box(decode_photo(&fx.jpeg, "bench.jpg").expect("decode"));
    });
    let detection = median(7, || {
        black_box(detect(&fx.photo, &fx.templates).expect("chart found"));
    });
    let whole = median(5, || {
        let photo = decode_photo(&fx.jpeg, "bench.jpg").expect("decode");
        black_box(analyse(&photo, &options).expect("analysis"));
    });
    let every = median(7, || {
        let (found, _) = detect_all(&fx.photo, &fx.templates).expect("search");
        assert_eq!(found.len(), 1, "one chart in the photo");
        black_box(found);
    });
    let naive = median(3, || {
        let (found, _) = detect_at(&fx.photo, &fx.templates, usize::MAX).expect("search");
        black_box(found.expect("chart found at full resolution"));
    });
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "24-megapixel JPEG ({} MB), median of runs:",
        fx.jpeg.len() / 1_000_000
    );
    println!("  decode                  {:8.1} ms", ms(decode));
    println!(
        "  photo → features        {:8.1} ms  ({:.2} of the 1 s target)",
        ms(whole),
        whole.as_secs_f64() / 1.0
    );
    println!(
        "  detection (pyramid)     {:8.1} ms  ({:.2} of the 300 ms target)",
        ms(detection),
        detection.as_secs_f64() / 0.3
    );
    println!(
        "  detection, baseline at full resolution {:8.1} ms: the pyramid is {:.1}× faster",
        ms(naive),
        naive.as_secs_f64() / detection.as_secs_f64()
    );
    println!(
        "  every chart (detect_all) {:7.1} ms: {:.2}× the search for the best one (goal 1)",
        ms(every),
        every.as_secs_f64() / detection.as_secs_f64()
    );
}

fn benches(c: &mut Criterion) {
    let fx = fixture();
    summary(&fx);
    let options = AnalyseOptions {
        templates: fx.templates.clone(),
        ..AnalyseOptions::default()
    };
    let mut g = c.benchmark_group("photo_24mp");
    g.sample_size(10);
    g.bench_function("decode", |b| {
        b.iter(|| decode_photo(black_box(&fx.jpeg), "bench.jpg").expect("decode"))
    });
    g.bench_function("detect", |b| {
        b.iter(|| detect(black_box(&fx.photo), &fx.templates).expect("found"))
    });
    g.bench_function("jpeg_to_features", |b| {
        b.iter(|| {
            let photo = decode_photo(black_box(&fx.jpeg), "bench.jpg").expect("decode");
            analyse(&photo, &options).expect("analysis")
        })
    });
    g.finish();
}

criterion_group!(photo, benches);

fn main() {
    photo();
    Criterion::default().configure_from_args().final_summary();
}
