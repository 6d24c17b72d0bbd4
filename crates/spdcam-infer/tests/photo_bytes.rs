//! A photo held in memory (an upload) gives the same estimate as the same photo read from
//! its file, and bad bytes give the same clear errors.

use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::Grid;
use spdcam_infer::{Estimator, ModelSet, PhotoOptions};
use std::path::PathBuf;

fn example() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg")
}

#[test]
fn bytes_and_file_give_the_same_estimate() {
    let models = ModelSet::shipped().unwrap();
    let grid = Grid::parse("400-700:5").unwrap();
    let data = DataDir::new(None);
    let options = PhotoOptions::default();
    let path = example();
    let from_file = Estimator::new(models.clone(), data.clone(), grid)
        .unwrap()
        .estimate_photo(&path, &options)
        .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let from_bytes = Estimator::new(models, data, grid)
        .unwrap()
        .estimate_photo_bytes(&bytes, "sg-telelumen.jpg", &options)
        .unwrap();
    assert_eq!(from_bytes.name, "sg-telelumen.jpg");
    assert_eq!(from_bytes.spd, from_file.spd);
    assert_eq!(from_bytes.colorimetry, from_file.colorimetry);
    let (a, b) = (from_file.photo.unwrap(), from_bytes.photo.unwrap());
    assert_eq!(a.corners, b.corners);
    assert_eq!(a.features, b.features);
    assert_eq!(b.source, "sg-telelumen.jpg");
}

#[test]
fn corners_in_memory_move_the_sampling() {
    let models = ModelSet::shipped().unwrap();
    let grid = Grid::parse("400-700:5").unwrap();
    let data = DataDir::new(None);
    let bytes = std::fs::read(example()).unwrap();
    let estimator = Estimator::new(models, data, grid).unwrap();
    let detected = estimator
        .estimate_photo_bytes(&bytes, "p.jpg", &PhotoOptions::default())
        .unwrap();
    let mut corners = detected.photo.as_ref().unwrap().corners.to_vec();
    corners[0][0] += 40.0;
    corners[0][1] += 30.0;
    let options = PhotoOptions {
        corners: Some(corners),
        ..PhotoOptions::default()
    };
    let moved = estimator
        .estimate_photo_bytes(&bytes, "p.jpg", &options)
        .unwrap();
    assert_eq!(moved.photo.as_ref().unwrap().method, "corners");
    assert_ne!(moved.spd, detected.spd);
}

#[test]
fn bytes_that_are_no_image_are_named_in_the_error() {
    let models = ModelSet::shipped().unwrap();
    let grid = Grid::parse("400-700:5").unwrap();
    let err = Estimator::new(models, DataDir::new(None), grid)
        .unwrap()
        .estimate_photo_bytes(b"hello, not a photo", "notes.txt", &PhotoOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("notes.txt"), "{err}");
    assert!(err.contains("not an image"), "{err}");
}
