//! `spdcam experiment real-cameras`: the real-camera study (`spdcam_eval::real_cameras`) as
//! a Markdown table: every candidate on each real set's validation and test photos, beside
//! the constant and ridge on real photos, with the label-free look of real and virtual photos.

use anyhow::{Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::real_cameras::{
    appearance, baseline_rows, model_row, recipes, split_sets, virtual_photos, virtual_rows,
    CameraSource, Row, DEV_SPLIT_SEED,
};
use spdcam_infer::model::Model;
use std::path::PathBuf;

/// Options of `spdcam experiment real-cameras`.
#[derive(Debug, Args)]
pub struct RealCamerasArgs {
    /// Virtual photos per recipe.
    #[arg(long, default_value_t = 8000)]
    count: u64,
    /// Ridge penalty of the virtual ridges (relative to the mean diagonal of XᵀX).
    #[arg(long, default_value_t = 1e-2)]
    ridge: f64,
    /// Seed of the virtual photos.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Trained model files to score beside the ridges (NAME=FILE or FILE).
    #[arg(long, value_delimiter = ',')]
    models: Vec<String>,
    /// The validation split whose held-out cameras stay out of the virtual pool.
    #[arg(long, default_value = "docs/validation-split.json")]
    camera_split: PathBuf,
    /// Output Markdown file.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam experiment real-cameras`.
pub fn run(args: RealCamerasArgs, data_dir: &DataDir) -> Result<()> {
    let root = data_dir
        .root()
        .context("the study needs the measured data directory (--data-dir / SPDCAM_DATA)")?
        .to_path_buf();
    let sets = split_sets(&root.join("thesis"))?;
    let source = CameraSource {
        data_dir: data_dir.clone(),
        cameras: root.join("cameras"),
        camera_split: Some(args.camera_split.clone()),
    };
    let mut rows = baseline_rows(&sets)?;
    for spec in &args.models {
        let (name, path) = spec.split_once('=').unwrap_or((spec, spec));
        let model = Model::load(std::path::Path::new(path))?;
        rows.push(model_row(&format!("model `{name}`"), &model, &sets)?);
        eprintln!("{}", rows.last().map(|r| r.name.as_str()).unwrap_or(""));
    }
    let mut looks = vec![(
        "real".to_string(),
        sets.iter()
            .map(|s| appearance(&s.val.features))
            .collect::<Vec<_>>(),
    )];
    let labels: Vec<&str> = sets.iter().map(|s| s.label).collect();
    for recipe in recipes() {
        let photos = virtual_photos(&recipe, &source, args.count, args.seed)?;
        looks.push((recipe.name.clone(), vec![appearance(&photos.features)]));
        rows.extend(virtual_rows(&recipe.name, &photos, args.ridge, &sets)?);
        eprintln!("{} done", recipe.name);
        // Written after each recipe: the rows so far survive an interruption.
        write_atomic(
            &args.output,
            table(&args, &labels, &rows, &looks).as_bytes(),
        )?;
    }
    print!("{}", table(&args, &labels, &rows, &looks));
    Ok(())
}

/// The Markdown page.
fn table(
    args: &RealCamerasArgs,
    labels: &[&str],
    rows: &[Row],
    looks: &[(String, Vec<[f64; 2]>)],
) -> String {
    let mut md = String::from("| estimator |");
    for l in labels {
        md += &format!(" {l}: val GFC | test GFC | test Δu′v′ |");
    }
    md += "\n|---|";
    md += &"---:|".repeat(3 * labels.len());
    md.push('\n');
    for row in rows {
        md += &format!("| {} |", row.name);
        for (val, test) in &row.scores {
            let v = val.map_or("–".to_string(), |s| format!("{:.4}", s.gfc));
            md += &format!(" {v} | {:.4} | {:.4} |", test.gfc, test.duv);
        }
        md.push('\n');
    }
    md += &format!(
        "\nMean GFC (400–700 nm, 10 nm) and median Δu′v′ (CIE 1976, 2° observer) against the \
         measured SPDs. Validation / test: Telelumen–Canon 5D IV photos shuffled with seed \
         {DEV_SPLIT_SEED}, first half / second half; Hue and Galaxy Tab S7: their `train` / \
         `val` files. Virtual ridges: {} noise-free patch-level photos of the ColorChecker \
         Digital SG per recipe (seed {}), cameras from the data directory's `cameras/` less \
         those `{}` holds out (one perturbed copy each), penalty {} relative; unlabelled \
         alignments are fitted on each set's validation features alone.\n",
        args.count,
        args.seed,
        args.camera_split.display(),
        args.ridge
    );
    md += "\nHow the photos look, without labels (median over photos): darkest patch value ÷ \
           the mean of all patches (flare and glare raise it) and the brightest patch's \
           channel spread ÷ its mean (the cast white balance left on the white).\n\n\
           | photos | darkest ÷ mean | white's cast |\n|---|---:|---:|\n";
    for (name, values) in looks {
        for (k, v) in values.iter().enumerate() {
            let which = if values.len() > 1 {
                format!("{name}: {}", labels[k])
            } else {
                format!("virtual: {name}")
            };
            md += &format!("| {which} | {:.3} | {:.3} |\n", v[0], v[1]);
        }
    }
    md
}
