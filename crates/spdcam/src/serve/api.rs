//! The routes: the embedded page and its assets, and the JSON API (`docs/web-api.md`).
//! Uploads are read into memory up to the size limit, checked, and queued; nothing the
//! client sends is used as a path.

use super::jobs::{plain_error, Jobs, Outcome, Progress, Upload, CHARTS};
use super::multipart;
use anyhow::Result;
use spdcam_core::colorimetry::{cct_to_uv_planck, uv1960_to_xy, Observer};
use spdcam_core::spectral::Grid;
use std::io::Read;
use std::sync::Arc;
use tiny_http::{Header, Method, Request, Response};

const INDEX_HTML: &str = include_str!("page/index.html");
const APP_JS: &str = include_str!("page/app.js");
const STYLE_CSS: &str = include_str!("page/style.css");
const EXAMPLE_JPG: &[u8] = include_bytes!("../../../../examples/sg-telelumen.jpg");
/// Room for the multipart framing and the small fields beside the photo.
const FORM_OVERHEAD: usize = 64 * 1024;
/// Longest label kept from a client's file name.
const MAX_NAME_CHARS: usize = 120;

/// The request handler, shared by the request threads.
pub struct Api {
    jobs: Arc<Jobs>,
    max_upload_bytes: usize,
    locus: String,
}

/// An answer: status, content type, body.
struct Answer(u16, &'static str, Vec<u8>);

impl Answer {
    fn json(status: u16, value: &serde_json::Value) -> Answer {
        Answer(status, "application/json", value.to_string().into_bytes())
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
            Outcome::Done(json) => Answer(200, "application/json", json.as_bytes().to_vec()),
            Outcome::Failed(status, message) => Answer::error(status, message),
        }
    }
}

impl Api {
    /// The handler for `jobs`, refusing photos over `max_upload_bytes`.
    pub fn new(jobs: Arc<Jobs>, max_upload_bytes: usize) -> Result<Api> {
        Ok(Api {
            jobs,
            max_upload_bytes,
            locus: locus_json()?.to_string(),
        })
    }

    /// Answers one request (never panics on what the client sent).
    pub fn handle(&self, mut request: Request) {
        let answer = self.route(&mut request);
        let Answer(status, kind, body) = answer;
        let mut response = Response::from_data(body)
            .with_chunked_threshold(usize::MAX)
            .with_status_code(status)
            .with_header(header("Content-Type", kind))
            .with_header(header("Cache-Control", "no-store"))
            .with_header(header("X-Content-Type-Options", "nosniff"));
        if status == 413 {
            response = response.with_header(header("Connection", "close"));
        }
        // A client that went away cannot be answered; nothing else to do.
        let _ = request.respond(response);
    }

    fn route(&self, request: &mut Request) -> Answer {
        let url = request.url().to_string();
        let path = url.split('?').next().unwrap_or("");
        let get = *request.method() == Method::Get;
        let post = *request.method() == Method::Post;
        if let Some(id) = path.strip_prefix("/api/jobs/").filter(|_| get) {
            return match id.strip_suffix("/report") {
                Some(id) => self.report(id),
                None => self.job(id),
            };
        }
        match path {
            "/" | "/index.html" if get => {
                Answer(200, "text/html; charset=utf-8", INDEX_HTML.into())
            }
            "/app.js" if get => Answer(200, "text/javascript; charset=utf-8", APP_JS.into()),
            "/style.css" if get => Answer(200, "text/css; charset=utf-8", STYLE_CSS.into()),
            "/example.jpg" if get => Answer(200, "image/jpeg", EXAMPLE_JPG.to_vec()),
            "/api/locus" if get => Answer(200, "application/json", self.locus.clone().into()),
            "/api/estimate" if post => match self.upload(request) {
                Ok(upload) => match self.jobs.submit(upload) {
                    Some(id) => Answer::outcome(self.jobs.wait(id)),
                    None => busy(),
                },
                Err(answer) => answer,
            },
            "/api/jobs" if post => match self.upload(request) {
                Ok(upload) => match self.jobs.submit(upload) {
                    Some(id) => Answer::json(202, &serde_json::json!({ "id": id.to_string() })),
                    None => busy(),
                },
                Err(answer) => answer,
            },
            "/" | "/index.html" | "/app.js" | "/style.css" | "/example.jpg" | "/api/locus"
            | "/api/estimate" | "/api/jobs" => Answer::error(
                405,
                format!("{} is not allowed on {path}", request.method()),
            ),
            _ => Answer::error(404, format!("no such page or API: {path}")),
        }
    }

    /// `GET /api/jobs/ID`: where the job is, and its result once finished.
    fn job(&self, id: &str) -> Answer {
        let Some(progress) = id.parse::<u64>().ok().and_then(|id| self.jobs.progress(id)) else {
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
    fn report(&self, id: &str) -> Answer {
        match id.parse::<u64>().ok().and_then(|id| self.jobs.report(id)) {
            Some(html) => Answer(200, "text/html; charset=utf-8", html.as_bytes().to_vec()),
            None => Answer::error(404, format!("no report of job '{id}' is kept")),
        }
    }

    /// Reads and checks an upload form: the size limit (413), the `photo` field, `corners`.
    fn upload(&self, request: &mut Request) -> Result<Upload, Answer> {
        let limit = self.max_upload_bytes + FORM_OVERHEAD;
        let too_large = || {
            Answer::error(
                413,
                format!(
                    "the upload is larger than the limit of {} MB (spdcam serve --max-upload-mb)",
                    self.max_upload_bytes >> 20
                ),
            )
        };
        if request.body_length().is_some_and(|n| n > limit) {
            return Err(too_large());
        }
        let content_type = request
            .headers()
            .iter()
            .find(|h| h.field.equiv("Content-Type"))
            .map(|h| h.value.as_str().to_string())
            .unwrap_or_default();
        let boundary = multipart::boundary(&content_type).map_err(|e| Answer::error(400, e))?;
        let mut body = Vec::new();
        request
            .as_reader()
            .take(limit as u64 + 1)
            .read_to_end(&mut body)
            .map_err(|e| Answer::error(400, format!("reading the upload: {e}")))?;
        if body.len() > limit {
            return Err(too_large());
        }
        let fields = multipart::parse(&body, &boundary).map_err(|e| Answer::error(400, e))?;
        drop(body);
        let mut photo = None;
        let mut corners = None;
        let mut chart = None;
        for field in fields {
            match field.name.as_str() {
                "photo" if photo.is_none() => photo = Some(field),
                "photo" => return Err(Answer::error(400, "one photo per request")),
                "corners" => {
                    let text = String::from_utf8_lossy(&field.data);
                    if !text.trim().is_empty() {
                        corners = Some(
                            crate::photo_args::parse_corners(&text)
                                .map_err(|e| Answer::error(400, e.to_string()))?,
                        );
                    }
                }
                "chart" => {
                    let text = String::from_utf8_lossy(&field.data);
                    let name = text.trim();
                    if !name.is_empty() {
                        chart = Some(CHARTS.into_iter().find(|c| c.name() == name).ok_or_else(
                            || {
                                Answer::error(
                                    400,
                                    format!(
                                        "unknown chart '{name}'; valid: {}",
                                        CHARTS.map(|c| c.name()).join(", ")
                                    ),
                                )
                            },
                        )?);
                    }
                }
                _ => {}
            }
        }
        let Some(photo) = photo else {
            return Err(Answer::error(400, "the form has no field 'photo'"));
        };
        if photo.data.len() > self.max_upload_bytes {
            return Err(too_large());
        }
        if photo.data.is_empty() {
            return Err(Answer::error(400, "the photo is empty"));
        }
        Ok(Upload {
            name: label(photo.filename.as_deref()),
            bytes: photo.data,
            corners,
            chart,
        })
    }
}

fn busy() -> Answer {
    Answer::error(503, "too many photos are waiting; try again in a moment")
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("static header is valid")
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
