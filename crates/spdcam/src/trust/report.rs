//! `spdcam trust report`: the calibrated models measured on the split's test lamps, the real
//! photo sets and photos made bad on purpose (`spdcam_eval::trust::report`), as Markdown.

use crate::args::held_out::HeldOutArgs;
use crate::plot_file;
use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::held_out::file_name;
use spdcam_eval::trust::report::TrustReport;
use std::path::PathBuf;

/// Options of `spdcam trust report`.
#[derive(Debug, Args)]
pub(super) struct ReportArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// The calibrations, in the order of the models.
    #[arg(long, required = true)]
    calibration: Vec<PathBuf>,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Output Markdown (printed too).
    #[arg(short, long)]
    output: PathBuf,
    /// Also draw the reliability diagram (.svg or .png) and show it in the Markdown.
    #[arg(long)]
    reliability: Option<PathBuf>,
}

/// Runs `spdcam trust report`.
pub(super) fn run(args: ReportArgs, data_dir: &DataDir) -> Result<()> {
    let measured = TrustReport::measure(
        &args.photos.protocol(),
        &args.calibration,
        args.thesis_data.as_deref(),
        data_dir,
        &mut |model| eprintln!("{}: measured", model.display()),
    )?;
    for skipped in measured.skipped() {
        eprintln!("warning: {skipped}");
    }
    let diagram = match &args.reliability {
        Some(path) => {
            plot_file::write_plot(path, &measured.diagram_svg()?)?;
            // Beside the report, the image is named by its file name alone.
            Some(match (path.parent(), args.output.parent()) {
                (Some(a), Some(b)) if a == b => file_name(path),
                _ => path.display().to_string(),
            })
        }
        None => None,
    };
    let photos = args.photos.command_line();
    let report_options: String = args
        .calibration
        .iter()
        .map(|c| format!(" --calibration {}", c.display()))
        .chain(
            args.reliability
                .iter()
                .map(|r| format!(" --reliability {}", r.display())),
        )
        .collect();
    let commands = format!(
        "spdcam trust calibrate --real --scenes {}{photos} -o models\nspdcam trust report{photos}{report_options} -o {}",
        measured.scenes_per_lamp(),
        args.output.display()
    );
    let md = measured.markdown(diagram.as_deref(), &commands);
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
