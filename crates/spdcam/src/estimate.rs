//! `spdcam estimate`: the light's SPD from photos of a chart, or from chart features, with a
//! trained model (by default the one shipped inside the program).
//!
//! The work is the library's (`spdcam_infer::estimate`): this module reads the options,
//! reads truths, and prints and writes what the estimates say.

use crate::photo_args::{self, PhotoArgs};
use crate::plot_file::{plot_is_png, write_plot};
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::photo::{self, PhotoAnalysis};
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use spdcam_infer::estimate::{Colorimetry, Score};
use spdcam_infer::estimator::EstimatedBlock;
use spdcam_infer::plot::spds_band_svg;
use spdcam_infer::presentation::meaningful_value;
use spdcam_infer::report::{report_html, ReportImage, ReportItem, REPORT_IMAGE_WIDTH};
use spdcam_infer::stream::{
    long_header, long_rows, row_name, FeatureStream, Layout, WIDE_LAYOUT_MAX_ROWS,
};
use spdcam_infer::trust::{MetricInterval, Trust, Uncertainty, Verdict};
use spdcam_infer::{Estimate, Estimator, Model, ModelSet, RowStream};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Truth files found beside a photo: `<photo stem>` + this.
const TRUTH_SUFFIX: &str = ".truth.csv";

/// Options of `spdcam estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// Photos of a colour chart (JPEG, PNG, TIFF), or chart images from `spdcam render`;
    /// one estimate each.
    #[arg(value_name = "PHOTO", required_unless_present = "features")]
    photos: Vec<PathBuf>,
    /// The model file (.spdm); default: the models shipped inside spdcam, one per chart
    /// (ColorChecker Digital SG, ColorChecker 24), chosen by the chart in the photo.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Estimate from a features CSV instead of photos: a header naming the columns (p01_r,
    /// p01_g, …), one row per estimate; values on any scale (0–255 or 0–1).
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
    /// Wavelength grid of the output, START-END[:STEP] in nm (within the model's grid).
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
    #[command(flatten)]
    photo: PhotoArgs,
}

/// `--layout`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum LayoutArg {
    Wide,
    Long,
}

/// The estimator of the model `--model` names, or of the shipped ones, on `grid`.
fn estimator(path: Option<&Path>, data_dir: &DataDir, grid: Grid) -> Result<Estimator> {
    let models = match path {
        Some(p) => ModelSet::single(Model::load(p)?, p.display().to_string()),
        None => ModelSet::shipped()?,
    };
    Ok(Estimator::new(models, data_dir.clone(), grid)?)
}

/// Column labels for photos: their file names, or their paths where names repeat.
fn photo_labels(photos: &[PathBuf]) -> Vec<String> {
    let names: Vec<String> = photos
        .iter()
        .map(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string())
        })
        .collect();
    names
        .iter()
        .zip(photos)
        .map(|(n, p)| {
            if names.iter().filter(|m| *m == n).count() > 1 {
                p.display().to_string()
            } else {
                n.clone()
            }
        })
        .collect()
}

/// Reads a spectral CSV of true SPDs, resampled to `grid`; a truth that is negative or
/// holds no light on `grid` is refused (a GFC against it means nothing).
fn read_truths(path: &Path, grid: &Grid) -> Result<SpectralSet> {
    let set = SpectralSet::read_csv(path)
        .and_then(|s| s.require_non_negative("true SPD", 0.01))
        .with_context(|| format!("reading the true SPDs {}", path.display()))?;
    let (set, _) = set.resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
    if let Some(i) = (0..set.len()).find(|&i| set.item(i).iter().all(|&v| v <= 0.0)) {
        bail!(
            "{}: the true SPD '{}' is zero everywhere on {grid}; a truth must hold light",
            path.display(),
            set.names()[i]
        );
    }
    Ok(set)
}

/// Whether the terminal report is left out: with `--json`, or with the SPDs on stdout.
fn quiet(args: &EstimateArgs) -> bool {
    args.photo.json || args.output.as_deref().is_some_and(fsio::is_stdout)
}

/// The truth for each estimate: from `--truth` (one column for all, or one per estimate),
/// else from `<stem>.truth.csv` beside each photo (`photos`, one per estimate); resampled
/// to `grid`.
fn truths(
    truth: Option<&Path>,
    photos: &[&Path],
    count: usize,
    grid: &Grid,
) -> Result<Vec<Option<Spd>>> {
    let item = |set: &SpectralSet, i: usize| Spd::new(*grid, set.item(i).to_vec());
    if let Some(path) = truth {
        let set = read_truths(path, grid)?;
        return match set.len() {
            1 => Ok(vec![Some(item(&set, 0)?); count]),
            n if n == count => (0..n).map(|i| Ok(Some(item(&set, i)?))).collect(),
            n => bail!(
                "{}: {n} true SPDs for {count} estimates; give one, or one per estimate",
                path.display()
            ),
        };
    }
    if photos.is_empty() {
        return Ok(vec![None; count]);
    }
    photos
        .iter()
        .map(|photo| {
            let Some(stem) = photo.file_stem() else {
                return Ok(None);
            };
            let path = photo.with_file_name(format!("{}{TRUTH_SUFFIX}", stem.to_string_lossy()));
            if !path.is_file() {
                return Ok(None);
            }
            let set = read_truths(&path, grid)?;
            if set.len() != 1 {
                bail!(
                    "{}: one true SPD expected, found {}",
                    path.display(),
                    set.len()
                );
            }
            Ok(Some(item(&set, 0)?))
        })
        .collect()
}

/// What [`estimate_from_photos`] gives: the estimates, their photos, with `--report` each
/// photo with the chart found drawn on it, and how many photos gave none.
struct PhotoEstimates {
    estimates: Vec<Estimate>,
    photos: Vec<PathBuf>,
    overlays: Vec<Option<Vec<u8>>>,
    failed: usize,
}

/// Estimates from the photos, one per photo that could be used; the photos that could not
/// (no chart found, no model for its chart, unreadable) are reported on stderr and counted.
fn estimate_from_photos(args: &EstimateArgs, estimator: &Estimator) -> Result<PhotoEstimates> {
    let mut options = args.photo.options()?;
    options.overlay_width = args.report.is_some().then_some(REPORT_IMAGE_WIDTH);
    // Debug images written from now on are announced (file times run on a coarser clock).
    let started = std::time::SystemTime::now() - std::time::Duration::from_secs(1);
    let results = estimator.analyse_photos(&args.photos, &options)?;
    let labels = photo_labels(&args.photos);
    let debug = options
        .debug
        .as_ref()
        .map(|d| photo::debug_paths(d, &args.photos));
    let mut analyses: Vec<(PathBuf, String, PhotoAnalysis, Option<Vec<u8>>)> = Vec::new();
    let mut failed = 0;
    for (i, ((path, label), result)) in args.photos.iter().zip(labels).zip(results).enumerate() {
        if let Some(written) = debug.as_ref().map(|d| &d[i]).filter(|d| {
            std::fs::metadata(d)
                .and_then(|m| m.modified())
                .is_ok_and(|t| t >= started)
        }) {
            let factor = result.as_ref().map_or(1, |a| {
                photo::debug_factor(a.analysis.width, a.analysis.height)
            });
            match factor {
                1 => eprintln!("debug → {}", written.display()),
                k => eprintln!("debug → {} (1:{k} of the photo)", written.display()),
            }
        }
        match result {
            Ok(a) => {
                for w in &a.analysis.warnings {
                    eprintln!("warning: {}: {w}", a.analysis.source);
                }
                analyses.push((path.clone(), label, a.analysis, a.overlay));
            }
            Err(e) => {
                eprintln!("error: cannot use photo {}: {e}", path.display());
                failed += 1;
            }
        }
    }
    if let Some(out) = &args.photo.features_out {
        let all: Vec<PhotoAnalysis> = analyses.iter().map(|(_, _, a, _)| a.clone()).collect();
        if !all.is_empty() {
            photo::write_features_csv(out, &all)?;
            eprintln!("features → {}", out.display());
        }
    }
    let mut estimates = Vec::with_capacity(analyses.len());
    let mut paths = Vec::with_capacity(analyses.len());
    let mut overlays = Vec::with_capacity(analyses.len());
    for (path, label, analysis, overlay) in analyses {
        if !quiet(args) {
            println!("{}", photo_args::describe(&analysis));
        }
        match estimator.estimate_analysis(analysis, label) {
            Ok(e) => {
                estimates.push(e);
                paths.push(path);
                overlays.push(overlay);
            }
            Err(e) => {
                eprintln!("error: no estimate for {}: {e}", path.display());
                failed += 1;
            }
        }
    }
    Ok(PhotoEstimates {
        estimates,
        photos: paths,
        overlays,
        failed,
    })
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
    let estimator = estimator(args.model.as_deref(), data_dir, grid)?;
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
    let truths = truths(args.truth.as_deref(), &photo_refs, estimates.len(), &grid)?;
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
    if let Some(path) = &args.report {
        let items = estimates
            .iter()
            .zip(overlays)
            .zip(truths)
            .map(|((e, overlay), truth)| report_item(e, overlay, truth.map(Spd::into_values)))
            .collect::<Result<Vec<_>>>()?;
        let title = match estimates.as_slice() {
            [one] => format!("The light in {}", one.name),
            all => format!("The light in {} photos", all.len()),
        };
        write_report(path, &title, &items)?;
    }
    if args.photo.json {
        let json = estimates
            .iter()
            .map(Estimate::to_json)
            .collect::<spdcam_infer::Result<Vec<_>>>()?;
        println!("{}", serde_json::to_string_pretty(&json)?);
    }
    if quiet(&args) {
        verdicts_to_stderr(&estimates);
    } else {
        print_estimates(&estimates, &args);
    }
    if failed > 0 {
        bail!(
            "{failed} of {} photo(s) gave no estimate (see the errors above)",
            failed + estimates.len()
        );
    }
    Ok(())
}

/// Estimates printed in full (colorimetry, SPD, score) when there are no more than these.
const DETAILED_MAX: usize = 20;

/// What `estimate --features` keeps while it streams: the first estimates (to print and
/// plot), the scores against the truths, and the count.
struct FeatureRun {
    model: String,
    grid: Grid,
    truths: Option<SpectralSet>,
    /// The first [`DETAILED_MAX`] estimates, judged.
    first: Vec<Estimate>,
    rows: usize,
    /// (sum of GFC, sum of RMSE) over the scored estimates.
    score_sums: (f64, f64),
    /// Every SPD while the output may still be laid out wide (row-major).
    wide: Option<Vec<f64>>,
    layout: Option<Layout>,
    json_started: bool,
}

impl FeatureRun {
    /// The truth of row `row`: the only one, or the row's own.
    fn truth(&self, row: usize) -> Result<Option<&[f64]>> {
        let Some(set) = &self.truths else {
            return Ok(None);
        };
        match set.len() {
            1 => Ok(Some(set.item(0))),
            n if row < n => Ok(Some(set.item(row))),
            n => bail!("{n} true SPDs for more estimates; give one, or one per estimate"),
        }
    }

    /// Takes a block of estimated rows: scores, keeps the first judged estimates, prints
    /// JSON (every row judged), writes the SPDs.
    fn add(
        &mut self,
        stream: &RowStream,
        block: &EstimatedBlock,
        json: bool,
        out: &mut Option<&mut dyn Write>,
    ) -> Result<()> {
        let width = self.grid.count;
        let spds = &block.spds;
        let scores: Vec<Option<Score>> = spds
            .chunks_exact(width)
            .enumerate()
            .map(|(k, spd)| match self.truth(block.first_row + k)? {
                Some(t) => Ok(Some(Score::of(t, spd)?)),
                None => Ok(None),
            })
            .collect::<Result<_>>()?;
        for s in scores.iter().flatten() {
            self.score_sums.0 += s.gfc;
            self.score_sums.1 += s.rmse;
        }
        let mut text = String::new();
        for (k, score) in scores.iter().enumerate() {
            let kept = self.first.len() < DETAILED_MAX;
            if !kept && !json {
                break;
            }
            let mut e = stream.estimate(block, k)?;
            e.truth = *score;
            if json {
                text.push_str(if self.json_started { ",\n" } else { "[\n" });
                self.json_started = true;
                text.push_str(&serde_json::to_string_pretty(&e.to_json()?)?);
            }
            if kept {
                self.first.push(e);
            }
        }
        if json {
            std::io::stdout().lock().write_all(text.as_bytes())?;
        }
        self.rows += block.rows;
        if let Some(out) = out {
            if let Some(wide) = &mut self.wide {
                wide.extend_from_slice(spds);
                if self.layout.is_none() && self.rows > WIDE_LAYOUT_MAX_ROWS {
                    self.layout = Some(Layout::Long);
                    let held = std::mem::take(wide);
                    self.wide = None;
                    out.write_all(long_header(&self.grid).as_bytes())?;
                    out.write_all(&long_rows(&held, width, 0))?;
                }
            } else {
                if block.first_row == 0 {
                    out.write_all(long_header(&self.grid).as_bytes())?;
                }
                out.write_all(&long_rows(spds, width, block.first_row))?;
            }
        }
        Ok(())
    }

    /// Writes the estimates held for the wide layout.
    fn finish(&mut self, out: &mut Option<&mut dyn Write>) -> Result<()> {
        if let (Some(out), Some(wide)) = (out, self.wide.take()) {
            let width = self.grid.count;
            let set = SpectralSet::on_grid(
                &self.grid,
                (0..self.rows).map(row_name).collect(),
                wide.chunks_exact(width).map(<[f64]>::to_vec).collect(),
            )?;
            out.write_all(set.to_csv_string().as_bytes())?;
        }
        Ok(())
    }
}

/// `estimate --features`: the rows of the features CSV streamed through the model for their
/// columns a block at a time by the estimator, the SPDs written as they come (long layout),
/// so that time is linear in the rows and memory bounded whatever their number. The full
/// judged estimates (colorimetry, lighting metrics, verdict, bands) are made only for what
/// is printed: the estimates shown in full (up to 20), the plot's title, and every estimate
/// of `--json`.
fn run_features(args: &EstimateArgs, path: &Path, estimator: &Estimator) -> Result<()> {
    let source = path.display().to_string();
    let mut stream = estimator.stream(FeatureStream::open(path)?, &source)?;
    let grid = *estimator.grid();
    let mut run = FeatureRun {
        model: stream.model_name().to_string(),
        grid,
        truths: args
            .truth
            .as_deref()
            .map(|t| read_truths(t, &grid))
            .transpose()?,
        first: Vec::new(),
        rows: 0,
        score_sums: (0.0, 0.0),
        wide: (args.layout != Some(LayoutArg::Long)).then(Vec::new),
        layout: args.layout.map(|l| match l {
            LayoutArg::Wide => Layout::Wide,
            LayoutArg::Long => Layout::Long,
        }),
        json_started: false,
    };
    let mut estimate_all = |out: &mut Option<&mut dyn Write>| -> Result<()> {
        while let Some(block) = stream.next_block()? {
            run.add(&stream, &block, args.photo.json, out)?;
        }
        if run.rows == 0 {
            bail!("{source}: no rows of features below the header");
        }
        run.finish(out)
    };
    match &args.output {
        None => estimate_all(&mut None)?,
        Some(out) if fsio::is_stdout(out) => {
            let mut lock = std::io::BufWriter::new(std::io::stdout().lock());
            estimate_all(&mut Some(&mut lock as &mut dyn Write))?;
            lock.flush()?;
        }
        Some(out) => {
            let mut failure = None;
            let written = fsio::write_atomic_with(out, |w| {
                estimate_all(&mut Some(w as &mut dyn Write)).map_err(|e| {
                    failure = Some(e);
                    std::io::Error::other("no estimates written")
                })
            });
            if let Some(e) = failure {
                return Err(e);
            }
            written?;
        }
    }
    if run.json_started {
        println!("\n]");
    }
    let detailed = run.rows <= DETAILED_MAX;
    if let Some(report) = &args.report {
        let items = run
            .first
            .iter()
            .enumerate()
            .map(|(row, e)| report_item(e, None, run.truth(row)?.map(<[f64]>::to_vec)))
            .collect::<Result<Vec<_>>>()?;
        let title = if run.rows > items.len() {
            format!(
                "The light of {source}: the first {} of {} rows",
                items.len(),
                run.rows
            )
        } else {
            format!("The light of {source}")
        };
        write_report(report, &title, &items)?;
    }
    if let Some(plot) = &args.plot {
        let series: Vec<(String, Vec<f64>)> = run
            .first
            .iter()
            .map(|e| (e.name.clone(), e.spd.to_vec()))
            .collect();
        let title = if run.rows == 1 {
            format!("Estimated SPD: {}", run.first[0].colorimetry.label())
        } else {
            format!("Estimated SPDs ({} of {})", series.len(), run.rows)
        };
        let bands: Vec<Option<&Uncertainty>> = run
            .first
            .iter()
            .map(|e| e.trust.as_ref().and_then(|t| t.uncertainty.as_ref()))
            .collect();
        let truths = (0..series.len())
            .map(|row| run.truth(row))
            .collect::<Result<Vec<_>>>()?;
        write_plot(
            plot,
            &spds_band_svg(&title, &grid, &series, &bands, &truths)?,
        )?;
    }
    if quiet(args) {
        for e in &run.first {
            if let Some(trust) = &e.trust {
                eprintln!("{}", verdict_line(&e.name, trust));
            }
        }
        if run.rows > run.first.len() {
            eprintln!(
                "(verdicts of the first {} of {} rows; --json gives every one)",
                run.first.len(),
                run.rows
            );
        }
        return Ok(());
    }
    if detailed {
        print_estimates(&run.first, args);
        return Ok(());
    }
    println!("{} estimates with {}", run.rows, run.model);
    if run.truths.is_some() {
        println!(
            "against the true SPDs: mean GFC {:.4}, mean RMSE {:.4} (both peak-normalised)",
            run.score_sums.0 / run.rows as f64,
            run.score_sums.1 / run.rows as f64
        );
    }
    if let Some(out) = &args.output {
        let layout = if run.layout == Some(Layout::Wide) {
            "wide"
        } else {
            "long"
        };
        println!("SPDs ({layout} layout) → {}", out.display());
    }
    if let Some(plot) = &args.plot {
        println!("plot → {}", plot.display());
    }
    if let Some(report) = &args.report {
        println!("report → {}", report.display());
    }
    Ok(())
}

/// The estimates as text: colorimetry and the SPD every 25 nm (for up to 20), the score
/// against the truth, what each number means, and where the files went.
fn print_estimates(estimates: &[Estimate], args: &EstimateArgs) {
    let mut models: Vec<&str> = estimates.iter().map(|e| e.model.as_str()).collect();
    models.dedup();
    println!("{} estimate(s) with {}", estimates.len(), models.join(", "));
    let detailed = estimates.len() <= DETAILED_MAX;
    for e in estimates {
        let unusable = e
            .trust
            .as_ref()
            .is_some_and(|t| t.verdict == Verdict::Unusable);
        if unusable {
            println!("{}: UNUSABLE, no estimate to rely on", e.name);
        } else if detailed {
            let intervals = e
                .trust
                .as_ref()
                .and_then(|t| t.uncertainty.as_ref())
                .map(|u| &u.metrics);
            println!(
                "{}: {}",
                e.name,
                colorimetry_line(&e.colorimetry, intervals)
            );
            println!("  relative SPD: {}", spd_line(&e.spd));
            println!("  {}", metrics_line(e, intervals));
            match (&e.absolute, e.photo.as_ref().and_then(|p| p.exposure)) {
                (Some(Ok(a)), _) => println!(
                    "  absolute (approximate, from {}): {:.0} lx, PPFD {}, melanopic EDI {}",
                    a.exposure.label(),
                    a.illuminance_lux,
                    a.ppfd_umol_m2_s
                        .map_or_else(|| "—".into(), |v| format!("{v:.1} µmol/m²/s")),
                    a.melanopic_edi_lux
                        .map_or_else(|| "—".into(), |v| format!("{v:.0} lx")),
                ),
                (Some(Err(reason)), Some(_)) => println!("  no absolute levels: {reason}"),
                _ => {}
            }
        }
        if let Some(t) = &e.trust {
            println!("  {}", trust_line(t));
            if let (Some(u), false) = (&t.uncertainty, unusable) {
                println!(
                    "  expected GFC {:.3}; 95 % band {:.2} wide on average (68 %: {:.2}; SPD peak 1){}",
                    u.expected_gfc,
                    u.band95.mean_width(),
                    u.band68.mean_width(),
                    if u.widening > 1.0 {
                        format!(
                            ", widened {:.1}× (the light found explains this photo {:.1}× worse than typical calibration photos)",
                            u.widening, u.widening
                        )
                    } else {
                        String::new()
                    }
                );
            }
        }
        if let Some(s) = e.truth {
            println!(
                "  against the true SPD: GFC {:.4}, RMSE {:.4} (both peak-normalised)",
                s.gfc, s.rmse
            );
        }
    }
    if estimates.iter().any(|e| e.photo.is_some()) {
        println!(
            "confidence: how sure the chart's detection is (0–1; below 0.8 check the --debug image)"
        );
    }
    if detailed {
        println!(
            "Ra: CIE 13.3 colour rendering (R9 saturated red); Rf, Rg: TM-30 fidelity and gamut; \
             M-EDER: melanopic daylight efficacy ratio (CIE S 026); S/P: scotopic/photopic; \
             PPF: µmol/s of 400–700 nm photons per klm; ± the 95 % interval when calibrated; \
             — where not defined or not meaningful (CRI and TM-30 need a light near white); \
             computed on the estimate's {}–{} nm only \
             (`spdcam metrics` on a wider SPD, `--json` for every number)",
            estimates[0].spd.grid().start_nm,
            estimates[0].spd.grid().end_nm()
        );
    }
    if estimates.iter().any(|e| e.trust.is_some()) {
        println!(
            "verdict: ok, doubtful (use with care) or unusable, from the detection, clipped and \
             dark patches, the self-check (the chart re-rendered under the estimate) and the \
             calibrated uncertainty; the bands hold the true SPD at 68 % and 95 % per wavelength"
        );
    }
    if estimates.iter().any(|e| e.truth.is_some()) {
        println!(
            "GFC: goodness-of-fit of the spectral shape, 1 = identical (≥ 0.999 excellent, ≥ 0.99 good)"
        );
    }
    if let Some(out) = &args.output {
        println!(
            "SPD{} → {}",
            if estimates.len() > 1 { "s" } else { "" },
            out.display()
        );
    }
    if let Some(plot) = &args.plot {
        println!("plot → {}", plot.display());
    }
    if let Some(report) = &args.report {
        println!("report → {}", report.display());
    }
}

/// One estimate of the report: the estimate, for a photo the photo with the chart found
/// (the `overlay` drawn when it was analysed), and its truth.
fn report_item(
    estimate: &Estimate,
    overlay: Option<Vec<u8>>,
    truth: Option<Vec<f64>>,
) -> Result<ReportItem> {
    let image = overlay.map(|bytes| ReportImage {
        mime: "image/jpeg",
        bytes,
    });
    Ok(ReportItem::new(estimate.clone(), image, truth))
}

/// Writes the report of `items` to `path` atomically.
fn write_report(path: &Path, title: &str, items: &[ReportItem]) -> Result<()> {
    fsio::write_atomic(path, report_html(title, items).as_bytes())?;
    Ok(())
}

/// With the data on standard output (`-o -`, `--json`), each estimate's verdict on standard
/// error, so that whoever runs the command still hears that an estimate is unusable.
fn verdicts_to_stderr(estimates: &[Estimate]) {
    for e in estimates {
        if let Some(t) = &e.trust {
            eprintln!("{}", verdict_line(&e.name, t));
        }
    }
}

/// `name: UNUSABLE, no estimate to rely on; verdict: unusable (reasons)`, or
/// `name: verdict: ok` — the verdict of one estimate on one line.
fn verdict_line(name: &str, t: &Trust) -> String {
    if t.verdict == Verdict::Unusable {
        format!(
            "{name}: UNUSABLE, no estimate to rely on; {}",
            trust_line(t)
        )
    } else {
        format!("{name}: {}", trust_line(t))
    }
}

/// The verdict and its reasons on one line: `verdict: doubtful (2 of 24 patches are …)`.
fn trust_line(t: &Trust) -> String {
    if t.reasons.is_empty() {
        format!("verdict: {}", t.verdict.label())
    } else {
        format!("verdict: {} ({})", t.verdict.label(), t.reasons.join("; "))
    }
}

/// The estimates' SPDs as a spectral set, each followed by its bands when it has them:
/// `<name>_lower68, <name>_upper68, <name>_lower95, <name>_upper95`.
fn with_bands(estimates: &[Estimate], grid: &Grid) -> Result<SpectralSet> {
    let mut names = Vec::new();
    let mut values = Vec::new();
    for e in estimates {
        names.push(e.name.clone());
        values.push(e.spd.to_vec());
        if let Some(u) = e.trust.as_ref().and_then(|t| t.uncertainty.as_ref()) {
            for (band, level) in [(&u.band68, "68"), (&u.band95, "95")] {
                names.push(format!("{}_lower{level}", e.name));
                values.push(band.lower.to_vec());
                names.push(format!("{}_upper{level}", e.name));
                values.push(band.upper.to_vec());
            }
        }
    }
    Ok(SpectralSet::on_grid(grid, names, values)?)
}

/// The main lighting-quality numbers on one line, `—` where undefined or not meaningful for
/// this light (CRI and TM-30 far from white, as the report shows them), each with its 95 %
/// interval when the estimate has one: `Ra 82 ± 4 (R9 20 ± 15), …`.
fn metrics_line(e: &Estimate, intervals: Option<&BTreeMap<String, MetricInterval>>) -> String {
    let f = |key: &str, d: usize, unit: f64| {
        let Ok(v) = meaningful_value(e, key) else {
            return "—".to_string();
        };
        match intervals.and_then(|i| i.get(key)) {
            Some(i) => format!("{:.d$} ± {:.d$}", unit * v, unit * i.half95),
            None => format!("{:.d$}", unit * v),
        }
    };
    format!(
        "Ra {} (R9 {}), Rf {}, Rg {}, M-EDER {}, S/P {}, PPF {}",
        f("cri_ra", 0, 1.0),
        f("cri_r9", 0, 1.0),
        f("tm30_rf", 0, 1.0),
        f("tm30_rg", 0, 1.0),
        f("mel_der", 2, 1.0),
        f("sp_ratio", 2, 1.0),
        f("ppf_per_lux", 1, 1000.0),
    )
}

/// xy, CCT and Duv of an estimate, CCT and Duv with their 95 % intervals when it has them.
fn colorimetry_line(
    c: &Colorimetry,
    intervals: Option<&BTreeMap<String, MetricInterval>>,
) -> String {
    let half = |key: &str| intervals.and_then(|i| i.get(key)).map(|i| i.half95);
    match (c.cct, c.duv, half("cct_k"), half("duv")) {
        (Some(cct), Some(duv), Some(hc), Some(hd)) => format!(
            "xy ({:.4}, {:.4}), CCT {cct:.0} ± {hc:.0} K, Duv {duv:+.4} ± {hd:.4}",
            c.xy[0], c.xy[1]
        ),
        _ => c.label(),
    }
}

/// The SPD every 25 nm, peak-normalised, on one terminal line: `400:0.12 425:0.40 …`.
fn spd_line(spd: &Spd) -> String {
    let spd = spd.normalised_by_max();
    spd.grid()
        .wavelengths()
        .iter()
        .zip(spd.iter())
        .filter(|(w, _)| (*w % 25.0).abs() < 1e-9)
        .map(|(w, v)| format!("{w:.0}:{v:.2}"))
        .collect::<Vec<_>>()
        .join(" ")
}
