//! `spdcam estimate`: the light's SPD from photos of a chart, or from chart features, with a
//! trained model (by default the one shipped inside the program).
//!
//! The work is the library's (`spdcam_infer::estimate`): this module reads the options,
//! reads truths, and prints and writes what the estimates say.

mod features;
mod meter_lines;
mod photos;
mod print;
mod row_lines;
mod truth;

use crate::args::photo::PhotoArgs;
use crate::outln;
use crate::plot_file::{plot_is_png, write_plot};
use anyhow::{bail, Result};
use clap::Args;
use features::run_features;
use photos::{estimate_from_photos, PhotoEstimates};
use print::{
    print_estimates, print_places, report_item, verdicts_to_stderr, with_bands, write_report,
};
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::light_families::LightKind;
use spdcam_core::spectral::{Grid, Spd, SpectralSet};
use spdcam_infer::trust::Uncertainty;
use spdcam_infer::{Estimate, Estimator, Model, ModelSet, NamedModel};
use spdcam_present::plot::spds_band_svg;
use std::path::{Path, PathBuf};
use truth::truths;

/// Estimates printed in full (colorimetry, SPD, score) when there are no more than these.
const DETAILED_MAX: usize = 20;

/// Options of `spdcam estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// Photos of a colour chart (JPEG, PNG, TIFF, or camera raw: DNG, CR2, CR3, NEF, ARW, RAF,
    /// ORF, RW2, PEF, …), or chart images from `spdcam render`;
    /// one estimate per chart found (a photo of several charts gives one per chart, labelled
    /// by its place and compared across places).
    #[arg(value_name = "PHOTO", required_unless_present = "features")]
    photos: Vec<PathBuf>,
    /// The model file (.spdm); default: the models shipped inside spdcam, one per chart
    /// (ColorChecker Digital SG, ColorChecker 24), chosen by the chart in the photo.
    #[arg(long)]
    model: Option<PathBuf>,
    /// A model that reads raw files' patches as XYZ through the file's matrices (trained on
    /// `spdcam generate --raw`), for the chart of a model above: on a raw photo its spectrum
    /// replaces that model's, which still judges it (repeatable, one per chart).
    #[arg(long, value_name = "MODEL.spdm", conflicts_with = "features")]
    raw_model: Vec<PathBuf>,
    /// Estimate from a features CSV instead of photos: a header naming the columns (p01_r,
    /// p01_g, …), one row per estimate; values on any scale (0–255 or 0–1). Streamed: up to
    /// 20 rows are printed in full, more one line each (xy, CCT, Duv, verdict) as they are
    /// estimated; -o writes the SPDs, --json every number as JSON Lines (one row a line).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "photos")]
    features: Option<PathBuf>,
    /// CSV of the SPDs to write, laid out as --layout says; `-` writes it to standard output
    /// (and nothing else goes there).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Layout of the --output CSV: `wide` (spectral CSV: wavelength_nm, then one column per
    /// estimate) or `long` (one row per estimate: name, then one column per wavelength,
    /// written as the rows are estimated, in bounded memory). Default: wide up to 256
    /// estimates, long above.
    #[arg(long, value_enum, value_name = "wide|long")]
    layout: Option<LayoutArg>,
    /// Wavelength grid of the output, START-END[:STEP] in nm (within the model's grid, two
    /// wavelengths at least). It changes what is printed and written only: the colorimetry,
    /// the metrics and the verdict are the model's whole estimate's.
    #[arg(long, default_value = "400-700:5", value_name = "START-END[:STEP]")]
    range: String,
    /// Also plot the estimates (SVG or PNG, by the name's extension), with CIE xy, CCT and
    /// Duv in the title.
    #[arg(long, value_name = "SPD.svg|png")]
    plot: Option<PathBuf>,
    /// The true SPDs as spectral CSV (one column, or one per estimate), to print each
    /// estimate's GFC and RMSE. Default for a photo: `<photo stem>.truth.csv` beside it,
    /// when it exists.
    #[arg(long, value_name = "FILE.csv")]
    truth: Option<PathBuf>,
    /// Also write one self-contained HTML page of the estimates (a section each: the photo
    /// with the chart found, the SPD plot, colorimetry, every lighting metric, the TM-30
    /// colour vector graphic, the score against the truth, every other number); it loads
    /// nothing from the network. With --features: the first 20 rows.
    #[arg(long, value_name = "FILE.html")]
    report: Option<PathBuf>,
    /// What lights the scene, when you know it: daylight, incandescent, fluorescent,
    /// white-led, hid, rgb-led, luminaire, or unknown (the default: any light). Each estimate
    /// is then moved to the lights of that kind (`spdcam light-kinds list`).
    #[arg(long, default_value = "unknown", value_name = "KIND", value_parser = parse_light)]
    light: LightKind,
    /// Also print what each number, the verdict and the GFC mean (a short glossary).
    #[arg(long)]
    explain: bool,
    #[command(flatten)]
    photo: PhotoArgs,
}

/// `--light`: a kind of light by name.
fn parse_light(text: &str) -> std::result::Result<LightKind, String> {
    LightKind::parse(text).map_err(|e| e.to_string())
}

/// `--layout`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum LayoutArg {
    Wide,
    Long,
}

/// The estimator of the model `--model` names, or of the shipped ones (with their raw
/// models), on `grid`, raw photos read by the `--raw-model`s `raw` names.
fn estimator(
    path: Option<&Path>,
    raw: &[PathBuf],
    data_dir: &DataDir,
    grid: Grid,
) -> Result<Estimator> {
    let estimator = match path {
        Some(p) => Estimator::new(
            ModelSet::single(Model::load(p)?, p.display().to_string()),
            data_dir.clone(),
            grid,
        )?,
        None => Estimator::shipped(data_dir.clone(), grid)?,
    };
    let raw_models = raw
        .iter()
        .map(|p| {
            Ok(NamedModel {
                name: p.display().to_string(),
                model: Model::load(p)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(estimator.with_raw_models(raw_models)?)
}

/// Whether the terminal report is left out: with `--json`, or with the SPDs on stdout.
fn quiet(args: &EstimateArgs) -> bool {
    args.photo.json || args.output.as_deref().is_some_and(fsio::is_stdout)
}

/// Runs `spdcam estimate`.
pub fn run(args: EstimateArgs, data_dir: &DataDir) -> Result<()> {
    for path in [&args.output, &args.plot, &args.photo.features_out]
        .into_iter()
        .flatten()
    {
        fsio::check_parent_dir(path)?;
    }
    if let Some(report) = &args.report {
        fsio::check_writable(report)?;
    }
    if args.photo.json && args.output.as_deref().is_some_and(fsio::is_stdout) {
        bail!("--json and -o - both write to standard output; choose one");
    }
    if let Some(plot) = &args.plot {
        plot_is_png(plot)?;
    }
    let grid = Grid::parse(&args.range)?;
    let estimator =
        estimator(args.model.as_deref(), &args.raw_model, data_dir, grid)?.for_light(args.light)?;
    if let Some(path) = &args.features {
        return run_features(&args, path, &estimator);
    }
    if args.layout == Some(LayoutArg::Long) && args.output.is_some() {
        bail!("--layout long is for --features; estimates of photos are written wide");
    }
    let PhotoEstimates {
        mut estimates,
        photos,
        overlays,
        failed,
    } = estimate_from_photos(&args, &estimator)?;
    if estimates.is_empty() {
        bail!(
            "no estimate: none of the {} photo(s) could be used (see the errors above)",
            failed
        );
    }
    let photo_refs: Vec<&Path> = photos.iter().map(PathBuf::as_path).collect();
    let places: Vec<_> = estimates
        .iter()
        .map(|e| e.photo.as_ref().and_then(|p| p.place))
        .collect();
    let truths = truths(
        args.truth.as_deref(),
        &photo_refs,
        &places,
        estimates.len(),
        &grid,
    )?;
    for (e, truth) in estimates.iter_mut().zip(&truths) {
        if let Some(t) = truth {
            e.score_against(t)?;
        }
    }
    let set = SpectralSet::on_grid(
        &grid,
        estimates.iter().map(|e| e.name.clone()).collect(),
        estimates.iter().map(|e| e.spd.to_vec()).collect(),
    )?;
    if let Some(out) = &args.output {
        fsio::write_output(
            out,
            with_bands(&estimates, &grid)?.to_csv_string().as_bytes(),
        )?;
    }
    if let Some(plot) = &args.plot {
        let shown = set.len().min(20);
        let series: Vec<(String, Vec<f64>)> = (0..shown)
            .map(|i| (set.names()[i].clone(), set.item(i).to_vec()))
            .collect();
        let title = if set.len() == 1 {
            format!("Estimated SPD: {}", estimates[0].colorimetry.label())
        } else {
            format!("Estimated SPDs ({shown} of {})", set.len())
        };
        let bands: Vec<Option<&Uncertainty>> = estimates[..shown]
            .iter()
            .map(|e| e.trust.as_ref().and_then(|t| t.uncertainty.as_ref()))
            .collect();
        let plotted_truths: Vec<Option<&[f64]>> =
            truths[..shown].iter().map(Option::as_deref).collect();
        write_plot(
            plot,
            &spds_band_svg(&title, &grid, &series, &bands, &plotted_truths)?,
        )?;
    }
    let mut reported = None;
    if let Some(path) = &args.report {
        let items = estimates
            .iter()
            .zip(overlays)
            .zip(truths)
            .map(|((e, overlay), truth)| report_item(e, overlay, truth.map(Spd::into_values)))
            .collect::<Result<Vec<_>>>()?;
        let mut distinct = photos.clone();
        distinct.dedup();
        let title = match (estimates.as_slice(), distinct.as_slice()) {
            ([one], _) => format!("The light in {}", one.name),
            (all, [photo]) => format!(
                "The light at {} places of {}",
                all.len(),
                photo.file_name().map_or_else(
                    || photo.display().to_string(),
                    |n| n.to_string_lossy().into()
                )
            ),
            (all, many) if all.len() == many.len() => {
                format!("The light in {} photos", all.len())
            }
            (all, many) => format!("The light at {} places in {} photos", all.len(), many.len()),
        };
        write_report(path, &title, &items)?;
        reported = Some(items);
    }
    if args.photo.json {
        let json = estimates
            .iter()
            .map(Estimate::to_json)
            .collect::<spdcam_infer::Result<Vec<_>>>()?;
        outln!("{}", serde_json::to_string_pretty(&json)?)?;
    }
    if quiet(&args) {
        verdicts_to_stderr(&estimates);
    } else {
        print_estimates(&estimates, &args, reported.as_deref())?;
        print_places(&estimates)?;
    }
    if failed > 0 {
        bail!(
            "{failed} of {} photo(s) gave no estimate (see the errors above)",
            failed + estimates.len()
        );
    }
    Ok(())
}
