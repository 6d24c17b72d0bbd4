//! The estimating of one upload: the estimate's JSON with its presentation, and its HTML
//! report.

use super::{Outcome, Upload};
use spdcam_infer::{Estimator, PhotoOptions};
use spdcam_present::presentation::Presentation;
use spdcam_present::report::{report_html, ReportImage, ReportItem, REPORT_IMAGE_WIDTH};
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
    /// JSON carries the estimate's [`Presentation`] under `presentation`; a photo of several
    /// charts gives the first place's estimate with every place's (each with its
    /// presentation and `across_places_lines`, the comparison in words) under `places`, and
    /// a report of them all. The one place the server estimates.
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
        // Every chart of the photo, or the one the corners hold.
        let estimated = estimator.photo_bytes_places(&upload.bytes, &upload.name, &options);
        drop(upload.bytes);
        drop(upload.memory);
        let mut made = Vec::new();
        let mut first_failure = None;
        for one in estimated {
            let overlay = match one.analysed {
                Ok(a) => a.overlay,
                Err(e) => {
                    first_failure.get_or_insert((400, e.to_string()));
                    continue;
                }
            };
            match one.estimate {
                Some(Ok(e)) => made.push((e, overlay)),
                Some(Err(e)) => {
                    first_failure.get_or_insert((422, e.to_string()));
                }
                None => {
                    first_failure.get_or_insert((500, "no estimate was made".into()));
                }
            }
        }
        if made.is_empty() {
            let (status, message) = first_failure.unwrap_or((500, "no estimate was made".into()));
            return failed(status, message);
        }
        let mut jsons = Vec::with_capacity(made.len());
        // Each estimate's presentation, made once for the JSON and the report.
        let mut presentations = Vec::with_capacity(made.len());
        for (estimate, _) in &made {
            let mut json = match estimate.to_json() {
                Ok(json) => json,
                Err(e) => return failed(500, e.to_string()),
            };
            let presentation = Presentation::of(estimate);
            match serde_json::to_value(&presentation) {
                Ok(p) => json["presentation"] = p,
                Err(e) => return failed(500, e.to_string()),
            }
            presentations.push(presentation);
            if let Some(across) = &estimate.across_places {
                json["across_places_lines"] = serde_json::json!(across.lines());
            }
            jsons.push(json);
        }
        // The first place's estimate, with every place's beside it when there are several.
        let mut json = jsons[0].clone();
        if jsons.len() > 1 {
            json["places"] = serde_json::Value::Array(jsons);
        }
        let title = match made.as_slice() {
            [(one, _)] => format!("The light in {}", one.name),
            all => format!("The light at {} places", all.len()),
        };
        let items: Vec<ReportItem> = made
            .into_iter()
            .zip(presentations)
            .map(|((estimate, overlay), presentation)| {
                let image = overlay.map(|bytes| ReportImage {
                    mime: "image/jpeg",
                    bytes,
                });
                ReportItem::presented(presentation, estimate, image, None)
            })
            .collect();
        let report = report_html(&title, &items);
        Estimated {
            outcome: Outcome::Done(json.to_string().into()),
            report: Some(report.into()),
        }
    }
}
