//! The estimator's tests: one estimate per photo, its ways in agreeing, the model run once.

use super::*;
use crate::photo_options::PhotoOptions;
use crate::stream::FeatureStream;
use spdcam_core::chart::KnownChart;
use spdcam_core::photo::decode_photo;
use spdcam_core::photo::Photo;
use std::path::{Path, PathBuf};

fn example_photo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg")
}

fn shipped() -> Estimator {
    Estimator::shipped(DataDir::new(None), Grid::ESTIMATION).unwrap()
}

/// The ColorChecker 24 features of `spd` through the first built-in camera.
fn colorchecker24_row(spd: &Spd) -> FeatureRows {
    use spdcam_core::builtin;
    use spdcam_core::camera::sensor::Sensitivities;
    use spdcam_core::camera::{Camera, CameraConfig};
    let grid = Grid::SIMULATION;
    let table = &builtin::CAMERAS[0];
    let sensitivities = Sensitivities::new(table.name, &table.load().unwrap(), &grid).unwrap();
    let chart = Chart::colorchecker24(&grid).unwrap();
    let names = chart.feature_names();
    let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).unwrap();
    let (mut raw, mut row) = (Vec::new(), Vec::new());
    camera.features_fast(&camera.light(spd).unwrap(), &mut raw, &mut row);
    let values = row.iter().map(|&v| f64::from(v)).collect();
    FeatureRows::from_values(names, values, "rendered").unwrap()
}

#[test]
fn told_the_kind_an_estimate_keeps_to_such_lights_and_a_wrong_kind_is_named() {
    use spdcam_core::cie_illuminant::{planck, StandardIlluminant};
    let estimator = shipped();
    let a = StandardIlluminant::A.spd(&Grid::SIMULATION).unwrap();
    let truth = planck(2856.0, &Grid::ESTIMATION).unwrap();
    let row = colorchecker24_row(&a);
    let gfc =
        |e: &Estimate| spdcam_core::spectral_error::gfc(truth.values(), e.spd.values()).unwrap();
    let plain = &estimator.estimate_rows(&row, "A").unwrap()[0];
    let told = estimator.for_light(LightKind::Incandescent).unwrap();
    let incandescent = &told.estimate_rows(&row, "A").unwrap()[0];
    assert_eq!(
        (plain.light, incandescent.light),
        (LightKind::Unknown, LightKind::Incandescent)
    );
    assert!(
        gfc(incandescent) > gfc(plain).max(0.995),
        "told {} against {}",
        gfc(incandescent),
        gfc(plain)
    );
    let json = incandescent.to_json().unwrap();
    assert_eq!(json["light"], "incandescent");
    assert!(plain.to_json().unwrap().get("light").is_none());
    let said = |e: &Estimate| e.trust.as_ref().unwrap().reasons.join(" ");
    assert!(!said(incandescent).contains("does not look like"));
    // Told the light is a colour-mixing LED lamp, the filament's photo is named unlike it
    // and never ok.
    let rgb = &estimator
        .for_light(LightKind::RgbLed)
        .unwrap()
        .estimate_rows(&row, "A")
        .unwrap()[0];
    assert!(
        said(rgb).contains("does not look like colour-mixing LED light"),
        "{}",
        said(rgb)
    );
    assert_ne!(rgb.trust.as_ref().unwrap().verdict, Verdict::Ok);
    // A kind is carried to other grids, and every shipped model knows every kind.
    assert_eq!(
        told.on_grid(Grid::parse("420-680:20").unwrap())
            .unwrap()
            .light(),
        LightKind::Incandescent
    );
    assert_eq!(estimator.light_kinds().unwrap(), LightKind::ALL);
}

#[test]
fn a_candidate_is_judged_by_the_calibration_given_and_refuses_another_models() {
    use spdcam_core::cie_illuminant::StandardIlluminant;
    let shipped_set = ModelSet::shipped().unwrap();
    let cc24 = shipped_set
        .for_known(KnownChart::ColorChecker24)
        .unwrap()
        .clone();
    let sg = shipped_set.for_known(KnownChart::Sg96).unwrap().clone();
    let own = trust::calibration_for(&cc24.model).unwrap().unwrap();
    let row = colorchecker24_row(&StandardIlluminant::D65.spd(&Grid::SIMULATION).unwrap());
    let judge = |cal: TrustCalibration| {
        let e =
            Estimator::calibrated(cc24.clone(), cal, DataDir::new(None), Grid::ESTIMATION).unwrap();
        e.estimate_rows(&row, "D65")
            .unwrap()
            .remove(0)
            .trust
            .unwrap()
    };
    // With its own calibration, exactly as the shipped estimator judges it.
    let as_shipped = shipped()
        .estimate_rows(&row, "D65")
        .unwrap()
        .remove(0)
        .trust
        .unwrap();
    let given = judge(own.clone());
    assert_eq!(given.verdict, as_shipped.verdict);
    assert_eq!(given.reasons, as_shipped.reasons);
    // A calibration that calls every spread too large is the one that judges.
    let strict = TrustCalibration {
        difficulty_doubtful: 0.0,
        ..own
    };
    let judged = judge(strict);
    assert_ne!(judged.verdict, Verdict::Ok);
    assert!(
        judged.reasons.len() > as_shipped.reasons.len(),
        "{:?}",
        judged.reasons
    );
    // The SG's calibration is not this model's.
    let other = trust::calibration_for(&sg.model).unwrap().unwrap();
    let err = Estimator::calibrated(cc24, other, DataDir::new(None), Grid::ESTIMATION)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("made for another model"), "{err}");
}

#[test]
fn a_model_without_priors_cannot_be_told_the_kind() {
    let shipped = ModelSet::shipped().unwrap();
    let model = shipped.models()[0].model.clone();
    let estimator = Estimator::new(
        ModelSet::single(model.clone(), "mine.spdm".to_string()),
        DataDir::new(None),
        Grid::ESTIMATION,
    )
    .unwrap()
    .with_priors(Vec::new())
    .unwrap();
    // The shipped model keeps its built-in priors; priors of another model are refused.
    assert!(estimator.for_light(LightKind::Daylight).is_ok());
    let mut other = kind_prior::priors_for(&model).unwrap().unwrap();
    other.model = "another model".into();
    let err = estimator.with_priors(vec![other]).err().unwrap();
    assert!(err.to_string().contains("no model of the set"), "{err}");
    let mut bare = estimator.clone();
    bare.priors = Arc::new(OnceLock::from(vec![None]));
    let err = bare.for_light(LightKind::Daylight).err().unwrap();
    assert!(
        err.to_string().contains("mine.spdm") && err.to_string().contains("none"),
        "{err}"
    );
    assert_eq!(bare.light_kinds().unwrap(), [LightKind::Unknown]);
    assert!(bare.for_light(LightKind::Unknown).is_ok());
}

#[test]
fn a_photo_runs_the_model_once_for_its_estimate_and_once_for_its_spread() {
    // Issue 52: the chart check and the estimate each ran the model, and a named kind of
    // light ran it a third time. Now: once for the estimate (whose SPD the chart check
    // also uses) and once for the perturbed copies the bands need, by design.
    let bytes = std::fs::read(example_photo()).unwrap();
    for estimator in [
        shipped(),
        shipped().for_light(LightKind::Luminaire).unwrap(),
    ] {
        let before = crate::model::RUNS.with(|r| r.get());
        let photo = estimator.photo_bytes(&bytes, "example.jpg", &PhotoOptions::default());
        let runs = crate::model::RUNS.with(|r| r.get()) - before;
        assert!(photo.into_estimate().is_ok());
        assert_eq!(runs, 2, "{:?}", estimator.light());
    }
}

#[test]
fn a_photo_its_bytes_its_pixels_and_its_row_give_one_estimate() {
    let estimator = shipped();
    let options = PhotoOptions::default();
    let path = example_photo();
    let from_file = estimator.estimate_photo(&path, &options).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let from_bytes = estimator
        .estimate_photo_bytes(&bytes, "in memory", &options)
        .unwrap();
    let decoded = decode_photo(&bytes, "decoded").unwrap();
    let from_pixels = estimator.estimate_decoded(&decoded, &options).unwrap();
    assert_eq!(from_bytes.name, "in memory");
    assert_eq!(from_pixels.name, "decoded");
    let analysis = from_file.photo.as_ref().unwrap();
    let rows = FeatureRows::of_analyses(&[analysis]).unwrap();
    let from_row = estimator.estimate_rows(&rows, "row").unwrap().remove(0);
    assert_eq!(from_row.name, "estimate_1");
    for other in [&from_bytes, &from_pixels, &from_row] {
        assert_eq!(other.spd, from_file.spd);
        assert_eq!(other.colorimetry, from_file.colorimetry);
    }
    // The row carries no photo flags; the photo's own judgement is the same here, as
    // the example photo has no clipped or dark feature patch and a sure detection.
    let verdicts: Vec<_> = [&from_file, &from_bytes, &from_pixels, &from_row]
        .iter()
        .map(|e| e.trust.as_ref().unwrap().clone())
        .collect();
    assert!(verdicts.iter().all(|t| t.verdict == verdicts[0].verdict));
    assert_eq!(verdicts[0].uncertainty, verdicts[3].uncertainty);
    assert_eq!(verdicts[0].self_check, verdicts[3].self_check);
}

#[test]
fn another_grid_shares_the_models_and_resamples_spd_and_bands() {
    let estimator = shipped();
    let coarse = estimator
        .on_grid(Grid::parse("400-700:10").unwrap())
        .unwrap();
    assert!(Arc::ptr_eq(&estimator.prepared, &coarse.prepared));
    let path = example_photo();
    let fine = estimator
        .estimate_photo(&path, &PhotoOptions::default())
        .unwrap();
    let e = coarse
        .estimate_photo(&path, &PhotoOptions::default())
        .unwrap();
    assert_eq!(e.spd.grid(), coarse.grid());
    // Every other 5 nm sample is a 10 nm sample.
    for (k, v) in e.spd.iter().enumerate() {
        assert!((v - fine.spd[2 * k]).abs() < 1e-12, "at {k}");
    }
    let u = e.trust.as_ref().unwrap().uncertainty.as_ref().unwrap();
    assert_eq!(u.band95.lower.grid(), coarse.grid());
    assert_eq!(u.band68.upper.len(), 31);
    // Issue 39: the colorimetry, the metrics and the verdict are the whole estimate's,
    // whatever range is shown.
    let narrow = estimator
        .on_grid(Grid::parse("500-600:5").unwrap())
        .unwrap()
        .estimate_photo(&path, &PhotoOptions::default())
        .unwrap();
    for other in [&e, &narrow] {
        assert_eq!(other.colorimetry, fine.colorimetry);
        assert_eq!(other.metrics, fine.metrics);
        assert_eq!(
            other.trust.as_ref().unwrap().verdict,
            fine.trust.as_ref().unwrap().verdict
        );
    }
}

#[test]
fn a_range_beyond_the_model_or_of_one_wavelength_is_refused() {
    for (range, expected) in [
        ("380-780:5", "the model estimates"),
        ("550-550", "single wavelength"),
    ] {
        let err = shipped()
            .on_grid(Grid::parse(range).unwrap())
            .err()
            .unwrap_or_else(|| panic!("{range} was taken"))
            .to_string();
        assert!(err.contains(expected), "{err}");
    }
}

#[test]
fn a_stream_gives_the_rows_estimates_and_judges_any_row_of_a_block() {
    let estimator = shipped();
    let photo = estimator
        .estimate_photo(&example_photo(), &PhotoOptions::default())
        .unwrap();
    let analysis = photo.photo.as_ref().unwrap();
    let mut text = analysis.feature_names.join(",") + "\n";
    for scale in [1.0f32, 0.5, 0.25] {
        let row: Vec<String> = analysis
            .features
            .iter()
            .map(|v| format!("{}", v * scale))
            .collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    let rows = FeatureRows::from_csv_str(&text, "f.csv").unwrap();
    let all = estimator.estimate_rows(&rows, "f.csv").unwrap();
    let source =
        FeatureStream::new(Box::new(std::io::Cursor::new(text.into_bytes())), "f.csv").unwrap();
    let mut stream = estimator.stream(source, "f.csv").unwrap();
    assert_eq!(
        stream.model_name(),
        "the shipped ColorChecker Digital SG model"
    );
    let block = stream.next_block().unwrap().unwrap();
    assert_eq!((block.first_row, block.rows), (0, 3));
    assert!(stream.next_block().unwrap().is_none());
    for (k, e) in all.iter().enumerate() {
        let streamed = stream.estimate(&block, k).unwrap();
        assert_eq!(streamed.name, e.name);
        assert_eq!(streamed.spd.values(), &block.spds[k * 61..(k + 1) * 61]);
        assert_eq!(streamed.trust, e.trust);
    }
    assert!(stream.estimate(&block, 3).is_err());
}

#[test]
fn a_photo_without_a_chart_names_itself() {
    let photo = Photo::from_rgb8("grey.png", 200, 150, vec![128; 200 * 150 * 3]).unwrap();
    let err = shipped()
        .estimate_decoded(&photo, &PhotoOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("grey.png"), "{err}");
}

#[test]
fn one_call_gives_the_analysis_the_estimate_and_the_debug_image_written() {
    let debug = std::env::temp_dir().join(format!("spdcam-debug-{}.png", std::process::id()));
    let options = PhotoOptions {
        debug: Some(debug.clone()),
        ..PhotoOptions::default()
    };
    let missing = PathBuf::from("no-such-photo.jpg");
    let mut steps = Vec::new();
    let photos = shipped()
        .estimate_photos(&[example_photo(), missing], &options, |step| {
            steps.push(match step {
                PhotoProgress::Analysed(all) => format!("analysed {}", all.len()),
                PhotoProgress::Estimating(a) => format!("estimating {}", a.chart),
            });
            Ok::<(), InferError>(())
        })
        .unwrap();
    assert_eq!(steps, ["analysed 2", "estimating colorchecker_sg140"]);
    let written = photos[0].debug.clone().unwrap();
    assert!(written.is_file(), "{}", written.display());
    std::fs::remove_file(&written).unwrap();
    assert!(photos[0].analysed.is_ok());
    assert!(matches!(photos[0].estimate, Some(Ok(_))));
    // The photo that cannot be read writes no debug image and has no estimate.
    assert!(photos[1].debug.is_none() && photos[1].estimate.is_none());
    assert!(photos[1]
        .analysed
        .as_ref()
        .unwrap_err()
        .to_string()
        .contains("no-such-photo"));
}

#[test]
fn the_report_picture_is_drawn_from_the_one_decoding() {
    let options = PhotoOptions {
        overlay_width: Some(320),
        ..PhotoOptions::default()
    };
    let analysed = shipped()
        .estimate_photos(&[example_photo()], &options, |_| Ok::<(), InferError>(()))
        .unwrap()
        .pop()
        .unwrap()
        .analysed
        .unwrap();
    let jpeg = analysed.overlay.unwrap();
    let picture = decode_photo(&jpeg, "overlay.jpg").unwrap();
    assert_eq!(picture.width, 320);
    let plain = shipped()
        .estimate_photos(&[example_photo()], &PhotoOptions::default(), |_| {
            Ok::<(), InferError>(())
        })
        .unwrap()
        .pop()
        .unwrap()
        .analysed
        .unwrap();
    assert!(plain.overlay.is_none());
    assert_eq!(plain.analysis, analysed.analysis);
}
