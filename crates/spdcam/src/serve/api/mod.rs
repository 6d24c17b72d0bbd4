//! The routes: the embedded page and its assets, and the JSON API (`docs/web-api.md`).
//! Uploads are read into memory as they stream in, up to the size limit and at a minimum
//! pace, checked, and queued; nothing the client sends is used as a path.

mod answer;
mod chromaticity;
mod handlers;
mod plain_error;
mod upload;

use super::body::{Budget, Pace};
use super::jobs::{self, Jobs};
use answer::Answer;
use anyhow::Result;
use axum::body::Body;
use axum::routing::{get, post};
use axum::Router;
use chromaticity::locus_json;
use handlers::{charts, estimate, job, locus, not_allowed, not_found, report, submit};
use std::sync::{Arc, OnceLock};

const INDEX_HTML: &str = include_str!("../page/index.html");
/// Where the page names the charts it reads ([`index_html`]).
const CHARTS_MARK: &str = "<!--charts-->";
const APP_JS: &str = include_str!("../page/app.js");
const STYLE_CSS: &str = include_str!("../page/style.css");
/// The example photo "Try the example photo" loads: the ColorChecker 24 one, whose
/// reflectances are built in, so its verdict is judged with nothing beside the program.
const EXAMPLE_JPG: &[u8] = include_bytes!("../../../../../examples/cc24-led.jpg");
/// Room for the multipart framing and the small fields beside the photo; also the longest
/// field other than the photo.
const FORM_OVERHEAD: usize = 64 * 1024;

/// The page, the charts it reads named where it marks them ([`CHARTS_MARK`]) from the
/// chart registry: ` (ColorChecker 24 or ColorChecker Digital SG)`.
fn index_html() -> &'static [u8] {
    static PAGE: OnceLock<String> = OnceLock::new();
    PAGE.get_or_init(|| {
        let names: Vec<&str> = jobs::charts().iter().map(|c| c.shown_name()).collect();
        INDEX_HTML.replace(CHARTS_MARK, &format!(" ({})", names.join(" or ")))
    })
    .as_bytes()
}

/// The charts a person can name for placed corners ([`jobs::charts`]), each with its name and
/// a label that tells it apart: `{"name": "colorchecker24", "label": "ColorChecker 24
/// (4 × 6 patches)"}`.
fn charts_json() -> serde_json::Value {
    jobs::charts()
        .iter()
        .map(|c| {
            let label = match c.printed_layout() {
                Some((rows, cols)) => format!("{} ({rows} × {cols} patches)", c.shown_name()),
                None => c.shown_name().to_string(),
            };
            serde_json::json!({ "name": c.name(), "label": label })
        })
        .collect()
}

/// The request handler's state, shared by the connections.
pub struct Api {
    jobs: Arc<Jobs>,
    max_upload_bytes: usize,
    pace: Pace,
    budget: Budget,
    locus: String,
    charts: String,
}

impl Api {
    /// The handler for `jobs`, refusing photos over `max_upload_bytes` and uploads slower
    /// than `pace`, holding at most `budget_bytes` of uploads in memory.
    pub fn new(
        jobs: Arc<Jobs>,
        max_upload_bytes: usize,
        pace: Pace,
        budget_bytes: usize,
    ) -> Result<Api> {
        Ok(Api {
            jobs,
            max_upload_bytes,
            pace,
            budget: Budget::new(budget_bytes.max(max_upload_bytes + FORM_OVERHEAD)),
            locus: locus_json()?.to_string(),
            charts: charts_json().to_string(),
        })
    }

    /// The routes (`GET` routes answer `HEAD` too, without the body).
    pub fn router(self: Arc<Api>) -> Router {
        let page = |kind: &'static str, body: &'static [u8]| {
            get(move || async move { Answer(200, kind, Body::from(body)) })
        };
        Router::new()
            .route("/", page("text/html; charset=utf-8", index_html()))
            .route(
                "/index.html",
                page("text/html; charset=utf-8", index_html()),
            )
            .route(
                "/app.js",
                page("text/javascript; charset=utf-8", APP_JS.as_bytes()),
            )
            .route(
                "/style.css",
                page("text/css; charset=utf-8", STYLE_CSS.as_bytes()),
            )
            .route("/example.jpg", page("image/jpeg", EXAMPLE_JPG))
            .route("/api/locus", get(locus))
            .route("/api/charts", get(charts))
            .route("/api/estimate", post(estimate))
            .route("/api/jobs", post(submit))
            .route("/api/jobs/{id}", get(job))
            .route("/api/jobs/{id}/report", get(report))
            .method_not_allowed_fallback(not_allowed)
            .fallback(not_found)
            .with_state(self)
    }
}
