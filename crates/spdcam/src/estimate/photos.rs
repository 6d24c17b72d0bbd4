//! Estimates from photos: each photo analysed, its debug image announced, its estimate
//! made; the photos that give none reported and counted.

use super::{quiet, EstimateArgs};
use crate::args::photo::describe;
use crate::outln;
use anyhow::Result;
use spdcam_core::photo::{self, PhotoAnalysis};
use spdcam_infer::report::REPORT_IMAGE_WIDTH;
use spdcam_infer::{Estimate, Estimator};
use std::path::PathBuf;

/// Column labels for photos: their file names, or their paths where names repeat.
pub(super) fn photo_labels(photos: &[PathBuf]) -> Vec<String> {
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

/// What [`estimate_from_photos`] gives: the estimates, their photos, with `--report` each
/// photo with the chart found drawn on it, and how many photos gave none.
pub(super) struct PhotoEstimates {
    pub(super) estimates: Vec<Estimate>,
    pub(super) photos: Vec<PathBuf>,
    pub(super) overlays: Vec<Option<Vec<u8>>>,
    pub(super) failed: usize,
}

/// Estimates from the photos, one per photo that could be used; the photos that could not
/// (no chart found, no model for its chart, unreadable) are reported on stderr and counted.
pub(super) fn estimate_from_photos(
    args: &EstimateArgs,
    estimator: &Estimator,
) -> Result<PhotoEstimates> {
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
            outln!("{}", describe(&analysis))?;
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
