//! Training, estimating and the model file, end to end on a synthetic Gaussian dataset
//! (`spdcam_learn::synthetic`): each test fails if learning, the file format or the checks
//! break.

use spdcam_core::spectral::Grid;
use spdcam_infer::model::Model;
use spdcam_infer::network::{Architecture, CnnSpec, MlpSpec};
use spdcam_infer::pca::Components;
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;
use spdcam_learn::synthetic::gaussian_set;
use spdcam_learn::train::{
    finetune, train, Backend, FinetuneOptions, Schedule, TrainOptions, Trained, TrainingSet,
};

fn options(architecture: Architecture, target: TargetKind, epochs: usize) -> TrainOptions {
    TrainOptions {
        architecture,
        target,
        row_scale: RowScale::Max,
        grid: Grid::ESTIMATION,
        schedule: Schedule {
            epochs,
            batch: 64,
            lr: 2e-3,
            patience: Some(10),
            plateau: Some(4),
        },
        seed: 7,
        val_split: 0.15,
        backend: Backend::Cpu,
    }
}

/// Mean GFC of the model's estimates on `set` (SPDs cut to the model grid).
fn mean_gfc(model: &Model, set: &TrainingSet) -> f64 {
    let spds =
        spdcam_learn::train::spds_on_grid(&set.samples, &set.columns, &model.grid()).expect("spds");
    let est = model
        .estimate_rows(&set.samples.features)
        .expect("estimates");
    let d = model.grid().count;
    let n = set.samples.len();
    (0..n)
        .map(|i| {
            spdcam_core::spectral_error::compare(
                &spds[i * d..(i + 1) * d],
                &est[i * d..(i + 1) * d],
            )
            .expect("metrics")
            .gfc
        })
        .sum::<f64>()
        / n as f64
}

fn trained_cnn(data: &TrainingSet) -> Trained {
    let o = options(
        Architecture::Cnn1d(CnnSpec::thesis()),
        TargetKind::Pca(Components::default()),
        25,
    );
    train(data, None, &o, &mut |_| {}).expect("training")
}

#[test]
fn cnn_learns_gaussian_lights_and_beats_the_linear_baseline() {
    let data = gaussian_set(3000, 24, 1, 2);
    let test = gaussian_set(500, 24, 99, 2);
    let cnn = trained_cnn(&data);
    assert!(!cnn.log.is_empty());
    let gfc = mean_gfc(&cnn.model, &test);
    // A broken loop, loss, scaling or decoding stays far below this.
    assert!(gfc > 0.999, "CNN test GFC {gfc}");
    let linear = train(
        &data,
        None,
        &options(
            Architecture::Linear { ridge: 0.0 },
            TargetKind::Pca(Components::default()),
            1,
        ),
        &mut |_| {},
    )
    .expect("ridge");
    let lin = mean_gfc(&linear.model, &test);
    eprintln!("synthetic G1, 24 patches: CNN test GFC {gfc:.5}, linear {lin:.5}");
    assert!(lin > 0.99, "linear test GFC {lin}");
    assert!(gfc > lin, "CNN {gfc} should beat linear {lin}");
    // The log improves: the best validation loss is below the first epoch's.
    let best = cnn
        .log
        .iter()
        .map(|r| r.val_loss)
        .fold(f64::INFINITY, f64::min);
    assert!(best < cnn.log[0].val_loss);
}

#[test]
fn weights_targets_and_the_mlp_train() {
    let data = gaussian_set(2000, 24, 3, 2);
    let test = gaussian_set(300, 24, 98, 2);
    let mlp = train(
        &data,
        None,
        &options(
            Architecture::Mlp(MlpSpec::thesis()),
            TargetKind::Weights,
            25,
        ),
        &mut |_| {},
    )
    .expect("training");
    let gfc = mean_gfc(&mlp.model, &test);
    eprintln!("synthetic G1, MLP on weights: test GFC {gfc:.5}");
    assert!(gfc > 0.995, "MLP on weights: test GFC {gfc}");
}

#[test]
fn save_load_gives_identical_predictions_and_damage_is_an_error() {
    let data = gaussian_set(600, 24, 4, 2);
    let o = options(
        Architecture::Cnn1d(CnnSpec::thesis()),
        TargetKind::Pca(Components::Count(6)),
        2,
    );
    let model = train(&data, None, &o, &mut |_| {}).expect("training").model;
    let dir = std::env::temp_dir().join(format!("spdcam-learn-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("m.spdm");
    model.save(&path).unwrap();
    let back = Model::load(&path).unwrap();
    assert_eq!(back, model);
    let rows = &data.samples.features[..50 * 72];
    assert_eq!(
        back.estimate_rows(rows).unwrap(),
        model.estimate_rows(rows).unwrap()
    );

    let bytes = std::fs::read(&path).unwrap();
    let check = |b: &[u8], what: &str| {
        let p = dir.join("bad.spdm");
        std::fs::write(&p, b).unwrap();
        let err = Model::load(&p).expect_err(what).to_string();
        assert!(err.contains("bad.spdm"), "{what}: {err}");
        err
    };
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x55;
    assert!(check(&flipped, "flipped byte").contains("damaged"));
    assert!(check(&bytes[..bytes.len() - 100], "truncated").contains("damaged"));
    assert!(check(b"P3\n2 2\n", "not a model").contains("not a spdcam model"));
    let mut newer = bytes.clone();
    newer[8] = 99;
    assert!(check(&newer, "newer version").contains("version 99"));
    assert!(Model::load(&dir.join("missing.spdm")).is_err());

    // Features of another chart: a clear error naming both column sets.
    let other = gaussian_set(5, 96, 4, 2);
    let err = model
        .check_features(&other.columns.feature_names, "other.csv")
        .expect_err("96-patch features on a 24-patch model")
        .to_string();
    assert!(err.contains("288") && err.contains("72"), "{err}");
    assert!(model.estimate(&other.samples.features[..288]).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn finetuning_adapts_to_a_new_camera() {
    // Pretrain on one camera, fine-tune on a little data of another.
    let data = gaussian_set(2000, 24, 5, 2);
    let pretrained = trained_cnn(&data).model;
    let new_camera = gaussian_set(400, 24, 6, 77);
    let test = gaussian_set(300, 24, 97, 77);
    let before = mean_gfc(&pretrained, &test);
    let mut o = FinetuneOptions::thesis();
    o.schedule.epochs = 20;
    o.schedule.patience = Some(8);
    let tuned = finetune(&pretrained, &new_camera, None, &o, &mut |_| {})
        .expect("finetune")
        .model;
    let after = mean_gfc(&tuned, &test);
    eprintln!("fine-tuning to a new camera: test GFC {before:.5} → {after:.5}");
    assert!(
        after > 0.95 && after > before + 0.1,
        "fine-tuning {before} → {after}"
    );
    assert!(tuned.training().finetuned_from.is_some());
}

#[test]
fn the_recipe_choice_weighs_ridge_on_the_photos_and_never_loses_to_it() {
    // A model trained on one camera, a few photos of another: ridge on those photos alone
    // is among the candidates, and the recipe chosen cross-validates at least as well as it.
    let pretrained = trained_cnn(&gaussian_set(600, 24, 5, 2)).model;
    let few = gaussian_set(40, 24, 6, 77);
    let scored = spdcam_learn::recipe::choose(&pretrained, &few, 3, Backend::Cpu, &mut |_, _| {})
        .expect("choose");
    let ridge: Vec<_> = scored
        .iter()
        .filter(|s| matches!(s.recipe.fit, spdcam_learn::recipe::Fit::Ridge { .. }))
        .collect();
    assert_eq!(ridge.len(), 3, "three ridge candidates");
    assert!(ridge.iter().all(|s| scored[0].cv_gfc >= s.cv_gfc));
    // On a new camera the photos' own ridge beats the model as it is (GFC well above it).
    let unchanged = scored
        .iter()
        .find(|s| matches!(s.recipe.fit, spdcam_learn::recipe::Fit::Unchanged))
        .expect("the model unchanged is a candidate");
    assert!(
        ridge[0].cv_gfc > unchanged.cv_gfc,
        "ridge {} vs unchanged {}",
        ridge[0].cv_gfc,
        unchanged.cv_gfc
    );
    // The ridge model keeps the grid and estimates photos of the new camera.
    let model = ridge[0]
        .recipe
        .fit
        .run(&pretrained, &few, 3)
        .expect("ridge fit");
    assert_eq!(model.grid(), pretrained.grid());
    let test = gaussian_set(100, 24, 98, 77);
    assert!(mean_gfc(&model, &test) > 0.9, "{}", mean_gfc(&model, &test));
}
