//! The routes: the embedded page and its assets, and the JSON API (`docs/web-api.md`).
//! Uploads are read into memory as they stream in, up to the size limit and at a minimum
//! pace, checked, and queued; nothing the client sends is used as a path.

use super::body::{self, BodyError, Budget, Held, Pace};
use super::jobs::{plain_error, Jobs, Outcome, Progress, Upload, CHARTS};
use super::multipart::{self, FormError, Limits};
use anyhow::Result;
use axum::body::Body;
use axum::extract::{Path, Request, State};
use axum::http::{header, HeaderValue, Method, StatusCode, Uri};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use spdcam_core::colorimetry::{cct_to_uv_planck, uv1960_to_xy, Observer};
use spdcam_core::spectral::Grid;
use std::sync::{Arc, Mutex};

const INDEX_HTML: &str = include_str!("page/index.html");
const APP_JS: &str = include_str!("page/app.js");
const STYLE_CSS: &str = include_str!("page/style.css");
const EXAMPLE_JPG: &[u8] = include_bytes!("../../../../examples/sg-telelumen.jpg");
/// Room for the multipart framing and the small fields beside the photo; also the longest
/// field other than the photo.
const FORM_OVERHEAD: usize = 64 * 1024;

/// `bytes` in megabytes (2²⁰ bytes) for messages: whole from 10 MB, else to 0.1 MB.
fn megabytes(bytes: usize) -> String {
    let mb = bytes as f64 / f64::from(1 << 20);
    if mb >= 10.0 {
        format!("{mb:.0}")
    } else {
        format!("{mb:.1}")
    }
}
/// Longest label kept from a client's file name.
const MAX_NAME_CHARS: usize = 120;

/// The request handler's state, shared by the connections.
pub struct Api {
    jobs: Arc<Jobs>,
    max_upload_bytes: usize,
    pace: Pace,
    budget: Budget,
    locus: String,
}

/// An answer: status, content type, body.
struct Answer(u16, &'static str, Body);

impl Answer {
    fn json(status: u16, value: &serde_json::Value) -> Answer {
        Answer(status, "application/json", value.to_string().into())
    }

    /// `{"error", "code", "message"}`: the library's message, and a code and a message
    /// for a person ([`plain_error`]).
    fn error(status: u16, error: impl Into<String>) -> Answer {
        let error = error.into();
        let (code, message) = plain_error(status, &error);
        Answer::json(
            status,
            &serde_json::json!({ "error": error, "code": code, "message": message }),
        )
    }

    fn outcome(outcome: Outcome) -> Answer {
        match outcome {
            Outcome::Done(json) => Answer(200, "application/json", json.to_string().into()),
            Outcome::Failed(status, message) => Answer::error(status, message),
        }
    }
}

impl IntoResponse for Answer {
    fn into_response(self) -> Response {
        let Answer(status, kind, body) = self;
        let mut response = Response::new(body);
        *response.status_mut() =
            StatusCode::from_u16(status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
        let headers = response.headers_mut();
        headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(kind));
        headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        headers.insert(
            header::X_CONTENT_TYPE_OPTIONS,
            HeaderValue::from_static("nosniff"),
        );
        // The rest of an upload cut off for its size or pace is not read: the connection
        // closes after the answer.
        if status == 413 || status == 408 {
            headers.insert(header::CONNECTION, HeaderValue::from_static("close"));
        }
        response
    }
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
        })
    }

    /// The routes (`GET` routes answer `HEAD` too, without the body).
    pub fn router(self: Arc<Api>) -> Router {
        let page = |kind: &'static str, body: &'static [u8]| {
            get(move || async move { Answer(200, kind, Body::from(body)) })
        };
        Router::new()
            .route("/", page("text/html; charset=utf-8", INDEX_HTML.as_bytes()))
            .route(
                "/index.html",
                page("text/html; charset=utf-8", INDEX_HTML.as_bytes()),
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
            .route("/api/estimate", post(estimate))
            .route("/api/jobs", post(submit))
            .route("/api/jobs/{id}", get(job))
            .route("/api/jobs/{id}/report", get(report))
            .method_not_allowed_fallback(not_allowed)
            .fallback(not_found)
            .with_state(self)
    }

    /// Reads and checks an upload form: the size limit (413), the pace (408), the memory
    /// budget (503), the `photo` field, `corners`.
    async fn upload(&self, request: Request) -> Result<Upload, Answer> {
        let limit = self.max_upload_bytes + FORM_OVERHEAD;
        let too_large = || {
            Answer::error(
                413,
                format!(
                    "the upload is larger than the limit of {} MB (spdcam serve --max-upload-mb, \
                     at most SPDCAM_MAX_PHOTO_BYTES)",
                    megabytes(self.max_upload_bytes)
                ),
            )
        };
        let (parts, content) = request.into_parts();
        let declared = parts
            .headers
            .get(header::CONTENT_LENGTH)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.parse::<u64>().ok());
        if declared.is_some_and(|n| n > limit as u64) {
            return Err(too_large());
        }
        let content_type = parts
            .headers
            .get(header::CONTENT_TYPE)
            .map(|v| String::from_utf8_lossy(v.as_bytes()).into_owned())
            .unwrap_or_default();
        let boundary = multipart::boundary(&content_type).map_err(|e| Answer::error(400, e))?;
        let held = Arc::new(Mutex::new(Held::default()));
        let stream = body::limited(content, limit, self.pace, &self.budget, Arc::clone(&held));
        let limits = Limits {
            photo_bytes: self.max_upload_bytes,
            field_bytes: FORM_OVERHEAD,
        };
        let form = multipart::read(stream, &boundary, limits).await;
        let mut held = std::mem::take(&mut *held.lock().unwrap_or_else(|p| p.into_inner()));
        let form = match (form, held.failure.take()) {
            (Ok(form), _) => form,
            // The body's own failure explains any error multer reports after it.
            (Err(_), Some(failure)) => {
                return Err(match failure {
                    BodyError::TooLarge => too_large(),
                    BodyError::TimedOut => Answer::error(
                        408,
                        format!(
                            "the upload arrived too slowly (under {} KB/s after the first {} s); \
                             the connection is closed",
                            body::MIN_BYTES_PER_SECOND >> 10,
                            self.pace.grace.as_secs_f64()
                        ),
                    ),
                    BodyError::Busy => Answer::error(
                        503,
                        "too many uploads are being received at once; try again in a moment",
                    ),
                    BodyError::Read(e) => Answer::error(400, format!("reading the upload: {e}")),
                })
            }
            (Err(FormError::PhotoTooLarge), None) => return Err(too_large()),
            (Err(FormError::Invalid(message)), None) => return Err(Answer::error(400, message)),
            (Err(FormError::Body(e)), None) => {
                return Err(Answer::error(400, format!("reading the upload: {e}")))
            }
        };
        let corners = match form.corners.as_deref().map(str::trim) {
            Some(text) if !text.is_empty() => Some(
                crate::photo_args::parse_corners(text)
                    .map_err(|e| Answer::error(400, e.to_string()))?,
            ),
            _ => None,
        };
        let chart = match form.chart.as_deref().map(str::trim) {
            Some(name) if !name.is_empty() => Some(
                CHARTS
                    .into_iter()
                    .find(|c| c.name() == name)
                    .ok_or_else(|| {
                        Answer::error(
                            400,
                            format!(
                                "unknown chart '{name}'; valid: {}",
                                CHARTS.map(|c| c.name()).join(", ")
                            ),
                        )
                    })?,
            ),
            _ => None,
        };
        let Some(photo) = form.photo else {
            return Err(Answer::error(400, "the form has no field 'photo'"));
        };
        if photo.bytes.is_empty() {
            return Err(Answer::error(400, "the photo is empty"));
        }
        Ok(Upload {
            name: label(photo.filename.as_deref()),
            bytes: photo.bytes,
            corners,
            memory: held.permit,
            chart,
        })
    }
}

/// `POST /api/estimate`: the estimate of the uploaded photo, once made.
async fn estimate(State(api): State<Arc<Api>>, request: Request) -> Answer {
    match api.upload(request).await {
        Ok(upload) => match api.jobs.submit(upload) {
            Some(id) => Answer::outcome(api.jobs.wait(id).await),
            None => busy(),
        },
        Err(answer) => answer,
    }
}

/// `POST /api/jobs`: queues the uploaded photo and answers its job's id at once.
async fn submit(State(api): State<Arc<Api>>, request: Request) -> Answer {
    match api.upload(request).await {
        Ok(upload) => match api.jobs.submit(upload) {
            Some(id) => Answer::json(202, &serde_json::json!({ "id": id.to_string() })),
            None => busy(),
        },
        Err(answer) => answer,
    }
}

/// `GET /api/locus`: the outlines of the chromaticity diagram.
async fn locus(State(api): State<Arc<Api>>) -> Answer {
    Answer(200, "application/json", api.locus.clone().into())
}

/// `GET /api/jobs/ID`: where the job is, and its result once finished.
async fn job(State(api): State<Arc<Api>>, Path(id): Path<String>) -> Answer {
    let Some(progress) = id.parse::<u64>().ok().and_then(|id| api.jobs.progress(id)) else {
        return Answer::error(
            404,
            format!("no job '{id}' (finished jobs are kept a while)"),
        );
    };
    let value = match progress {
        Progress::Queued { ahead } => serde_json::json!({ "state": "queued", "ahead": ahead }),
        Progress::Running { since } => serde_json::json!({
            "state": "running",
            "seconds": since.elapsed().as_secs_f64(),
        }),
        Progress::Finished(Outcome::Done(json)) => {
            let result: serde_json::Value =
                serde_json::from_str(&json).unwrap_or(serde_json::Value::Null);
            serde_json::json!({ "state": "done", "result": result })
        }
        Progress::Finished(Outcome::Failed(status, error)) => {
            let (code, message) = plain_error(status, &error);
            serde_json::json!({
                "state": "failed", "status": status, "error": error, "code": code,
                "message": message,
            })
        }
    };
    Answer::json(200, &value)
}

/// `GET /api/jobs/ID/report`: the finished job's HTML report, while it is kept.
async fn report(State(api): State<Arc<Api>>, Path(id): Path<String>) -> Answer {
    match id.parse::<u64>().ok().and_then(|id| api.jobs.report(id)) {
        Some(html) => Answer(
            200,
            "text/html; charset=utf-8",
            html.as_bytes().to_vec().into(),
        ),
        None => Answer::error(404, format!("no report of job '{id}' is kept")),
    }
}

async fn not_allowed(method: Method, uri: Uri) -> Answer {
    Answer::error(405, format!("{method} is not allowed on {}", uri.path()))
}

async fn not_found(uri: Uri) -> Answer {
    Answer::error(404, format!("no such page or API: {}", uri.path()))
}

fn busy() -> Answer {
    Answer::error(503, "too many photos are waiting; try again in a moment")
}

/// A label from a client's file name: its last component only, printable, not too long.
fn label(filename: Option<&str>) -> String {
    let name = filename
        .unwrap_or("")
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or("")
        .chars()
        .filter(|c| !c.is_control())
        .take(MAX_NAME_CHARS)
        .collect::<String>();
    let name = name.trim();
    if name.is_empty() || name == "." || name == ".." {
        "photo".to_string()
    } else {
        name.to_string()
    }
}

/// The spectral locus (CIE 1931 2° observer, 380–780 nm in 5 nm steps) and the Planckian
/// locus (1000–20000 K, Planck's law through the same observer) in CIE 1931 xy, for the
/// page's chromaticity diagram.
fn locus_json() -> Result<serde_json::Value> {
    let grid = Grid::parse("380-780:5")?;
    let observer = Observer::cie1931(&grid)?;
    let (xbar, ybar, zbar) = (observer.cmf(0), observer.cmf(1), observer.cmf(2));
    let mut spectral = Vec::new();
    for (i, nm) in grid.wavelengths().into_iter().enumerate() {
        let sum = xbar[i] + ybar[i] + zbar[i];
        if sum > 0.0 {
            spectral.push(serde_json::json!([nm, xbar[i] / sum, ybar[i] / sum]));
        }
    }
    let mut planckian = Vec::new();
    let mut t = 1000.0_f64;
    while t <= 20000.0 {
        let xy = uv1960_to_xy(cct_to_uv_planck(t)?);
        planckian.push(serde_json::json!([t, xy[0], xy[1]]));
        t *= 1.05;
    }
    Ok(serde_json::json!({
        "spectral": spectral,
        "planckian": planckian,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_keep_only_the_file_name() {
        assert_eq!(label(Some("../../etc/passwd")), "passwd");
        assert_eq!(label(Some("C:\\photos\\room.jpg")), "room.jpg");
        assert_eq!(label(Some("..")), "photo");
        assert_eq!(label(None), "photo");
        assert_eq!(label(Some("a\u{7}b.jpg")), "ab.jpg");
    }

    #[test]
    fn the_locus_passes_through_known_points() {
        let locus = locus_json().unwrap();
        // CIE 1931 2° at 520 nm: x 0.0743, y 0.8338 (CIE 015:2018 table).
        let at520 = locus["spectral"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p[0].as_f64() == Some(520.0))
            .unwrap();
        assert!(
            (at520[1].as_f64().unwrap() - 0.0743).abs() < 5e-4,
            "{at520}"
        );
        assert!(
            (at520[2].as_f64().unwrap() - 0.8338).abs() < 5e-4,
            "{at520}"
        );
        // The Planckian radiator near 2856 K (illuminant A): x 0.4476, y 0.4074.
        let near_a = locus["planckian"]
            .as_array()
            .unwrap()
            .iter()
            .min_by(|a, b| {
                let d = |p: &serde_json::Value| (p[0].as_f64().unwrap() - 2856.0).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let t = near_a[0].as_f64().unwrap();
        assert!((t - 2856.0).abs() < 80.0, "{near_a}");
        assert!(
            (near_a[1].as_f64().unwrap() - 0.4476).abs() < 0.006,
            "{near_a}"
        );
    }
}
