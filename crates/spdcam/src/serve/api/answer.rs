//! The answer of every route: a status, a content type and a body, with the headers every
//! answer carries; errors as JSON with a message for a person.

use super::plain_error::{for_http, plain_error};
use crate::serve::jobs::Outcome;
use axum::body::Body;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};

/// An answer: status, content type, body.
pub(super) struct Answer(pub(super) u16, pub(super) &'static str, pub(super) Body);

impl Answer {
    pub(super) fn json(status: u16, value: &serde_json::Value) -> Answer {
        Answer(status, "application/json", value.to_string().into())
    }

    /// `{"error", "code", "message"}`: the library's message in an HTTP client's words
    /// ([`for_http`]: form fields, not flags), and a code and a message for a person
    /// ([`plain_error`]).
    pub(super) fn error(status: u16, error: impl Into<String>) -> Answer {
        let error = error.into();
        let (code, message) = plain_error(status, &error);
        Answer::json(
            status,
            &serde_json::json!({ "error": for_http(&error), "code": code, "message": message }),
        )
    }

    pub(super) fn outcome(outcome: Outcome) -> Answer {
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
