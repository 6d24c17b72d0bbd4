//! The estimating of one upload: the estimate's JSON with its presentation, and its HTML
//! report.

use super::{Outcome, Upload};
use spdcam_infer::presentation::Presentation;
use spdcam_infer::report::{report_html, ReportImage, ReportItem, REPORT_IMAGE_WIDTH};
use spdcam_infer::{Estimator, PhotoOptions};
use std::sync::Arc;

/// What estimates: the estimator of the models, built once for every upload.
pub struct Engine {
    /// The models with their calibrations and chart checks, and the output grid (that of
    /// `spdcam estimate`'s default).
    pub estimator: Estimator,
}

/// An estimate's outcome and, when it succeeded, its HTML report.
pub struct Estimated {
    /// The outcome.
    pub outcome: Outcome,
    /// The report of the estimate, for a successful one.
    pub report: Option<Arc<str>>,
}

impl Engine {
    /// The estimate of one upload, by the estimator `spdcam estimate` uses: a photo that
    /// cannot be read or shows no chart is a 400, one with no model for its chart 422. Its
    /// JSON carries the estimate's [`Presentation`] under `presentation`. The one place the
    /// server estimates.
    pub fn estimate(&self, upload: Upload) -> Estimated {
        let failed = |status, message: String| Estimated {
            outcome: Outcome::Failed(status, message),
            report: None,
        };
        let options = PhotoOptions {
            corners: upload.corners,
            chart: upload.chart.map(|c| c.name().to_string()),
            overlay_width: Some(REPORT_IMAGE_WIDTH),
            ..PhotoOptions::default()
        };
        let estimator = match self.estimator.for_light(upload.light) {
            Ok(e) => e,
            Err(e) => return failed(400, e.to_string()),
        };
        let estimated = estimator.photo_bytes(&upload.bytes, &upload.name, &options);
        drop(upload.bytes);
        drop(upload.memory);
        let overlay = match estimated.analysed {
            Ok(a) => a.overlay,
            Err(e) => return failed(400, e.to_string()),
        };
        let estimate = match estimated.estimate {
            Some(Ok(e)) => e,
            Some(Err(e)) => return failed(422, e.to_string()),
            None => return failed(500, "no estimate was made".into()),
        };
        let mut json = match estimate.to_json() {
            Ok(json) => json,
            Err(e) => return failed(500, e.to_string()),
        };
        let presentation = Presentation::of(&estimate);
        match serde_json::to_value(&presentation) {
            Ok(p) => json["presentation"] = p,
            Err(e) => return failed(500, e.to_string()),
        }
        let image = overlay.map(|bytes| ReportImage {
            mime: "image/jpeg",
            bytes,
        });
        let title = format!("The light in {}", estimate.name);
        let report = report_html(&title, &[ReportItem::new(estimate, image, None)]);
        Estimated {
            outcome: Outcome::Done(json.to_string().into()),
            report: Some(report.into()),
        }
    }
}
