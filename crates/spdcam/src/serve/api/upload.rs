//! Reading an upload: the multipart form read into memory as it streams in, up to the size
//! limit, at a minimum pace and within the memory budget, and its fields checked.

use super::answer::Answer;
use super::{Api, FORM_OVERHEAD};
use crate::serve::body::{self, BodyError, Held};
use crate::serve::jobs::{charts, Upload};
use crate::serve::multipart::{self, FormError, Limits};
use axum::extract::Request;
use axum::http::header;
use spdcam_core::light_families::LightKind;
use std::sync::{Arc, Mutex};

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

impl Api {
    /// Reads and checks an upload form: the size limit (413), the pace (408), the memory
    /// budget (503), the `photo` field, `corners`.
    pub(super) async fn upload(&self, request: Request) -> Result<Upload, Answer> {
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
                crate::args::photo::parse_corners(text)
                    .map_err(|e| Answer::error(400, e.to_string()))?,
            ),
            _ => None,
        };
        let chart = match form.chart.as_deref().map(str::trim) {
            Some(name) if !name.is_empty() => Some(
                charts()
                    .into_iter()
                    .find(|c| c.name() == name)
                    .ok_or_else(|| {
                        Answer::error(
                            400,
                            format!(
                                "unknown chart '{name}'; valid: {}",
                                charts()
                                    .iter()
                                    .map(|c| c.name())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                    })?,
            ),
            _ => None,
        };
        let light = match form.light.as_deref().map(str::trim) {
            Some(text) if !text.is_empty() => {
                LightKind::parse(text).map_err(|e| Answer::error(400, e.to_string()))?
            }
            _ => LightKind::Unknown,
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
            light,
        })
    }
}

/// A label from a client's file name: its last component only, without control or
/// bidirectional formatting characters ([`multipart::shown`]), not too long.
fn label(filename: Option<&str>) -> String {
    let name = filename
        .unwrap_or("")
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or("")
        .chars()
        .filter(|&c| multipart::shown(c))
        .take(MAX_NAME_CHARS)
        .collect::<String>();
    let name = name.trim();
    if name.is_empty() || name == "." || name == ".." {
        "photo".to_string()
    } else {
        name.to_string()
    }
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
    fn labels_drop_bidirectional_controls() {
        // Issue 39, item 22: U+202E made `room\u{202E}gpj.exe` show as `roomexe.jpg`.
        assert_eq!(label(Some("room\u{202E}gpj.exe")), "roomgpj.exe");
        let every = "a\u{202A}\u{202B}\u{202C}\u{202D}\u{202E}\u{2066}\u{2067}\u{2068}\u{2069}\u{200E}\u{200F}\u{061C}\u{2028}\u{85}b.jpg";
        assert_eq!(label(Some(every)), "ab.jpg");
        assert_eq!(label(Some("\u{202E}\u{2066}")), "photo");
        assert_eq!(
            label(Some("café ünïcode 照片.jpg")),
            "café ünïcode 照片.jpg"
        );
    }
}
