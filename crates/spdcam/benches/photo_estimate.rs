//! Speed of `spdcam estimate` on one 24-megapixel photo, the trust stage included (issue 14:
//! under 1 s with the perturbed copies and the self-check). The example photo (a ColorChecker
//! Digital SG scene, 2000 × 1500) enlarged to 6000 × 4000 and JPEG-encoded at quality 92.
//! The SG's self-check needs its reflectances, read from `$SPDCAM_DATA` or else
//! `../shared/data` beside the repository; without them it is skipped, and the summary says
//! so.
//!
//! Prints the median of runs of the whole estimate against the 1 s target, and in the same
//! run its two parts: the photo to features (decoding, detection, sampling), the baseline,
//! and the estimate with its trust stage and metrics from those features.
//! `cargo bench -p spdcam --bench photo_estimate`.

use spdcam_core::builtin::DataDir;
use spdcam_core::photo::decode_photo;
use spdcam_core::spectral::Grid;
use spdcam_infer::{Estimator, PhotoOptions};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use support::median;

#[path = "../../spdcam-core/benches/support/mod.rs"]
mod support;

fn main() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let example = image::open(repo.join("examples/sg-telelumen.jpg")).expect("the example photo");
    let jpeg = support::enlarged_jpeg(&example);
    let data = spdcam_test_data::measured_data_dir();
    let data_dir = DataDir::new(data.is_dir().then_some(data));
    let estimator = Estimator::shipped(data_dir, Grid::ESTIMATION).expect("the estimator");
    let options = PhotoOptions::default();

    let estimate = estimator
        .estimate_photo_bytes(&jpeg, "bench.jpg", &options)
        .expect("an estimate");
    let trust = estimate.trust.as_ref().expect("a judged estimate");
    let whole = median(5, || {
        black_box(
            estimator
                .estimate_photo_bytes(&jpeg, "bench.jpg", &options)
                .expect("estimate"),
        );
    });
    let analyse = || {
        let decoded = decode_photo(&jpeg, "bench.jpg").expect("decoded");
        estimator
            .analyse_decoded(&decoded, &options)
            .expect("analysis")
            .analysis
    };
    let analysis = analyse();
    let features = median(5, || {
        black_box(analyse());
    });
    let judged = median(9, || {
        black_box(
            estimator
                .estimate_analysis(analysis.clone(), "bench.jpg".into())
                .expect("estimate"),
        );
    });
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "24-megapixel JPEG ({} MB) → judged SPD, median of runs (self-check: {}):",
        jpeg.len() / 1_000_000,
        if trust.self_check.is_some() {
            "made"
        } else {
            "skipped, no SG reflectances"
        }
    );
    println!(
        "  whole estimate                      {:8.1} ms  ({:.2} of the 1 s target)",
        ms(whole),
        whole.as_secs_f64()
    );
    println!(
        "  baseline: photo → features          {:8.1} ms  (the whole is {:.2}× it)",
        ms(features),
        whole.as_secs_f64() / features.as_secs_f64()
    );
    println!(
        "  estimate, trust stage and metrics   {:8.1} ms  ({:.2} of the target)",
        ms(judged),
        judged.as_secs_f64()
    );
}
