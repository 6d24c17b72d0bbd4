//! The evaluation protocols on small hand-made inputs, without the measured data: the real
//! cameras' constant and ridge baselines and their score, the reliability diagram's bins,
//! the held-out protocols' file helpers, and the coverage of lamps by lighting recipes.

use spdcam_core::builtin::DataDir;
use spdcam_core::cie_illuminant::planck;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::light_families::LampType;
use spdcam_core::spectral::{Grid, Spd};
use spdcam_eval::coverage::{Coverage, CoverageOptions};
use spdcam_eval::held_out::{camera_names, file_name, in_data_dir};
use spdcam_eval::real_cameras::{
    constant, real_ridge, ridge_estimates, score, score_grid, targets,
};
use spdcam_eval::reliability::{diagram_svg, SetReliability};
use std::path::{Path, PathBuf};

/// A Gaussian bump at `mu` nm on `grid`.
fn bump(grid: &Grid, mu: f64) -> Vec<f64> {
    grid.wavelengths()
        .iter()
        .map(|l| (-((l - mu) / 40.0).powi(2)).exp())
        .collect()
}

/// Photos whose light mixes a blue and a red bump as `a : 2 − a`, and whose features say
/// `a` (their mean is 1 whatever `a`, so the ridge's exposure removal keeps them as they are).
fn mixed_photos(n: usize) -> MeasuredPhotos {
    let grid = score_grid();
    let (blue, red) = (bump(&grid, 450.0), bump(&grid, 630.0));
    let mut photos = MeasuredPhotos {
        features: Vec::new(),
        spds: Vec::new(),
    };
    for i in 0..n {
        let a = 0.1 + 1.8 * i as f64 / (n - 1) as f64;
        let spd: Vec<f64> = blue
            .iter()
            .zip(&red)
            .map(|(b, r)| a * b + (2.0 - a) * r)
            .collect();
        photos.features.push(vec![a, 2.0 - a, 1.0]);
        photos.spds.push(Spd::new(grid, spd).unwrap());
    }
    photos
}

#[test]
fn the_constant_guess_is_the_mean_of_the_peak_normalised_spds() {
    let grid = Grid::parse("400-700:100").unwrap();
    let photos = MeasuredPhotos {
        features: vec![vec![1.0], vec![2.0]],
        spds: vec![
            Spd::new(grid, vec![0.0, 1.0, 2.0, 4.0]).unwrap(),
            Spd::new(grid, vec![8.0, 4.0, 2.0, 0.0]).unwrap(),
        ],
    };
    assert_eq!(targets(&photos)[1], vec![1.0, 0.5, 0.25, 0.0]);
    assert_eq!(constant(&photos), vec![0.5, 0.375, 0.375, 0.5]);
}

#[test]
fn the_truth_scores_perfectly_and_another_light_does_not() {
    let photos = mixed_photos(6);
    let truths = targets(&photos);
    let perfect = score(&truths, &truths).unwrap();
    assert!((perfect.gfc - 1.0).abs() < 1e-12, "{perfect:?}");
    assert!(perfect.duv < 1e-12, "{perfect:?}");
    let reversed: Vec<Vec<f64>> = truths.iter().rev().cloned().collect();
    let wrong = score(&truths, &reversed).unwrap();
    assert!(wrong.gfc < 0.95 && wrong.duv > 0.01, "{wrong:?}");
    assert!(score(&truths, &truths[..2]).is_err());
    assert!(score(&[], &[]).is_err());
}

#[test]
fn ridge_on_real_photos_beats_the_constant_guess_where_the_light_follows_the_features() {
    let photos = mixed_photos(20);
    let truths = targets(&photos);
    let ridge = real_ridge(&photos).unwrap();
    let by_ridge = score(&truths, &ridge_estimates(&ridge, &photos.features)).unwrap();
    let mean = constant(&photos);
    let by_constant = score(&truths, &vec![mean; truths.len()]).unwrap();
    assert!(by_ridge.gfc > 0.99, "{by_ridge:?}");
    assert!(
        by_ridge.gfc > by_constant.gfc + 0.02,
        "{by_ridge:?} {by_constant:?}"
    );
    assert!(
        by_ridge.duv < by_constant.duv,
        "{by_ridge:?} {by_constant:?}"
    );
}

#[test]
fn the_reliability_bins_hold_the_median_gaps_of_photos_sorted_by_expected_gfc() {
    // Ten photos, expected GFC 0.99 … 0.90, each 0.01 worse in fact: five bins of two.
    let pairs: Vec<(f64, f64)> = (0..10)
        .map(|i| {
            let expected = 0.99 - 0.01 * i as f64;
            (expected, expected - 0.01)
        })
        .collect();
    let set = SetReliability::new("hand-made".into(), vec![0.5; 11], &pairs);
    assert_eq!(set.gaps.len(), 5);
    // The first bin holds the two best photos; the median of two is the upper value.
    let (expected, actual) = set.gaps[0];
    assert!((expected - 0.02).abs() < 1e-9, "{expected}");
    assert!((actual - 0.03).abs() < 1e-9, "{actual}");
    let (expected, actual) = set.gaps[4];
    assert!((expected - 0.10).abs() < 1e-9, "{expected}");
    assert!((actual - 0.11).abs() < 1e-9, "{actual}");
    // A perfect estimate sits on the log axis's floor, not at 0.
    let perfect = SetReliability::new("perfect".into(), vec![0.5; 11], &[(1.0, 1.0)]);
    assert_eq!(perfect.gaps, vec![(1e-3, 1e-3)]);
    let svg = diagram_svg(&[set, perfect]).unwrap();
    assert!(
        svg.starts_with("<svg") || svg.contains("<svg"),
        "{}",
        &svg[..80]
    );
    assert!(svg.contains("hand-made") && svg.contains("perfect"));
}

#[test]
fn the_held_out_protocols_name_files_and_find_cameras() {
    assert_eq!(file_name(Path::new("models/run/cc24.spdm")), "cc24.spdm");
    let dir = std::env::temp_dir().join(format!("spdcam-eval-protocols-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["nikon.csv", "canon.csv", "notes.txt"] {
        std::fs::write(dir.join(name), "").unwrap();
    }
    assert_eq!(camera_names(&dir).unwrap(), vec!["canon", "nikon"]);
    let data = DataDir::new(Some(dir.clone()));
    assert_eq!(
        in_data_dir(None, "cameras", &data).unwrap(),
        dir.join("cameras")
    );
    let given = PathBuf::from("elsewhere/cameras");
    assert_eq!(in_data_dir(Some(&given), "cameras", &data).unwrap(), given);
    let missing = camera_names(&dir.join("absent")).unwrap_err().to_string();
    assert!(missing.contains("absent"), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn planckian_draws_cover_filament_lamps_and_narrow_bands_do_not() {
    // Two filament lamps (Planckian radiators of 2700 K and 3200 K) and their types.
    let dir = std::env::temp_dir().join(format!("spdcam-eval-coverage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let grid = Grid::new(380.0, 780.0, 5.0).unwrap();
    let lamps: Vec<Vec<f64>> = [2700.0, 3200.0]
        .iter()
        .map(|&t| planck(t, &grid).unwrap().values().to_vec())
        .collect();
    let mut csv = String::from("wavelength_nm,warm,halogen\n");
    for (i, l) in grid.wavelengths().iter().enumerate() {
        csv += &format!("{l},{},{}\n", lamps[0][i], lamps[1][i]);
    }
    let spds = dir.join("lamps.csv");
    let types = dir.join("types.csv");
    std::fs::write(&spds, csv).unwrap();
    std::fs::write(
        &types,
        "column,type,category\nwarm,Incandescent/Filament,Residential\nhalogen,Incandescent/Filament,Residential\n",
    )
    .unwrap();
    let options = CoverageOptions {
        spds,
        types: Some(types),
        split: None,
        lighting: vec!["planck".into(), "gaussian:3".into()],
        draws: 400,
        seed: 1,
        fit: true,
    };
    let mut heard = Vec::new();
    let coverage = Coverage::measure(&options, &DataDir::new(None), &mut |r| {
        heard.push(r.to_string())
    })
    .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(heard, ["planck", "gaussian:3"]);
    assert_eq!(coverage.lamps, ["warm", "halogen"]);
    assert_eq!(coverage.types, [LampType::Incandescent; 2]);
    let [planckian, gaussian] = [&coverage.recipes[0].best, &coverage.recipes[1].best];
    // 400 draws uniform in mired over 1500–10000 K land within a few kelvin of each lamp.
    assert!(planckian.iter().all(|&g| g > 0.9999), "{planckian:?}");
    // Three broad channels cannot make a Planckian spectrum as well.
    assert!(
        gaussian.iter().zip(planckian).all(|(g, p)| g < p),
        "{gaussian:?} against {planckian:?}"
    );
    // The filament family fitted to each lamp reaches it.
    let fitted = coverage.fitted.as_ref().unwrap();
    assert!(
        fitted.iter().all(|g| g.is_some_and(|g| g > 0.999)),
        "{fitted:?}"
    );
    assert!(coverage.markdown().contains("| `planck` |"));
}
