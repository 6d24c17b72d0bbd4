//! Estimates from photos, in one call to the Estimator per run: each photo analysed, its
//! debug image announced (the path the library says it wrote), its estimate made; the
//! photos that give none reported and counted.

use super::{quiet, EstimateArgs};
use crate::args::photo::describe;
use crate::outln;
use anyhow::Result;
use spdcam_core::photo::{self, PhotoAnalysis};
use spdcam_infer::error::unusable_photo;
use spdcam_infer::{Estimate, Estimator, PhotoEstimate, PhotoProgress};
use spdcam_present::report::REPORT_IMAGE_WIDTH;
use std::path::PathBuf;

/// What [`estimate_from_photos`] gives: the estimates, their photos, with `--report` each
/// photo with the chart found drawn on it, and how many photos gave none.
pub(super) struct PhotoEstimates {
    pub(super) estimates: Vec<Estimate>,
    pub(super) photos: Vec<PathBuf>,
    pub(super) overlays: Vec<Option<Vec<u8>>>,
    pub(super) failed: usize,
}

/// Estimates from the photos, one per chart found (a photo may show several); the photos
/// that could not be used (no chart found, no model for its chart, unreadable) are reported
/// on stderr and counted.
pub(super) fn estimate_from_photos(
    args: &EstimateArgs,
    estimator: &Estimator,
) -> Result<PhotoEstimates> {
    let mut options = args.photo.options()?;
    options.overlay_width = args.report.is_some().then_some(REPORT_IMAGE_WIDTH);
    let done = estimator.estimate_photos(&args.photos, &options, |step| -> Result<()> {
        match step {
            PhotoProgress::Analysed(photos) => analysed(args, photos),
            PhotoProgress::Estimating(analysis) if !quiet(args) => {
                outln!("{}", describe(analysis))?;
                Ok(())
            }
            PhotoProgress::Estimating(_) => Ok(()),
        }
    })?;
    let mut out = PhotoEstimates {
        estimates: Vec::with_capacity(done.len()),
        photos: Vec::with_capacity(done.len()),
        overlays: Vec::with_capacity(done.len()),
        failed: 0,
    };
    for photo in done {
        let path = &args.photos[photo.photo];
        match (photo.analysed, photo.estimate) {
            (Ok(analysed), Some(Ok(estimate))) => {
                out.estimates.push(estimate);
                out.photos.push(path.clone());
                out.overlays.push(analysed.overlay);
            }
            (Ok(analysed), Some(Err(e))) => {
                let place = analysed
                    .analysis
                    .place
                    .map_or_else(String::new, |p| format!(" place {}", p.number));
                eprintln!("error: no estimate for {}{place}: {e}", path.display());
                out.failed += 1;
            }
            // Reported when the photos were analysed.
            _ => out.failed += 1,
        }
    }
    Ok(out)
}

/// Every photo analysed: each debug image written announced, each photo's warnings or why
/// it cannot be used printed, and with `--features-out` the features of those that can.
fn analysed(args: &EstimateArgs, photos: &[PhotoEstimate]) -> Result<()> {
    let mut analyses: Vec<PhotoAnalysis> = Vec::new();
    for photo in photos {
        let path = &args.photos[photo.photo];
        if let Some(written) = &photo.debug {
            let factor = photo.analysed.as_ref().map_or(1, |a| {
                photo::debug_factor(a.analysis.width, a.analysis.height)
            });
            match factor {
                1 => eprintln!("debug → {}", written.display()),
                k => eprintln!("debug → {} (1:{k} of the photo)", written.display()),
            }
        }
        match &photo.analysed {
            Ok(a) => {
                for w in &a.analysis.warnings {
                    eprintln!("warning: {}: {w}", a.analysis.source);
                }
                analyses.push(a.analysis.clone());
            }
            Err(e) => eprintln!("error: {}", unusable_photo(path, e)),
        }
    }
    if let Some(out) = &args.photo.features_out {
        if !analyses.is_empty() {
            photo::write_features_csv(out, &analyses)?;
            eprintln!("features → {}", out.display());
        }
    }
    Ok(())
}
