//! The handlers of the API's routes: uploads to estimate, jobs polled, reports, the locus,
//! the charts, and the answers to unknown pages and methods.

use super::answer::Answer;
use super::plain_error::plain_error;
use super::Api;
use crate::serve::jobs::{Outcome, Progress};
use axum::extract::{Path, Request, State};
use axum::http::{Method, Uri};
use std::sync::Arc;

/// `POST /api/estimate`: the estimate of the uploaded photo, once made.
pub(super) async fn estimate(State(api): State<Arc<Api>>, request: Request) -> Answer {
    match api.upload(request).await {
        Ok(upload) => match api.jobs.submit(upload) {
            Some(id) => Answer::outcome(api.jobs.wait(id).await),
            None => busy(),
        },
        Err(answer) => answer,
    }
}

/// `POST /api/jobs`: queues the uploaded photo and answers its job's id at once.
pub(super) async fn submit(State(api): State<Arc<Api>>, request: Request) -> Answer {
    match api.upload(request).await {
        Ok(upload) => match api.jobs.submit(upload) {
            Some(id) => Answer::json(202, &serde_json::json!({ "id": id.to_string() })),
            None => busy(),
        },
        Err(answer) => answer,
    }
}

/// `GET /api/charts`: the charts a person can name for placed corners.
pub(super) async fn charts(State(api): State<Arc<Api>>) -> Answer {
    Answer(200, "application/json", api.charts.clone().into())
}

/// `GET /api/locus`: the outlines of the chromaticity diagram.
pub(super) async fn locus(State(api): State<Arc<Api>>) -> Answer {
    Answer(200, "application/json", api.locus.clone().into())
}

/// `GET /api/jobs/ID`: where the job is, and its result once finished.
pub(super) async fn job(State(api): State<Arc<Api>>, Path(id): Path<String>) -> Answer {
    let Some(progress) = id.parse::<u64>().ok().and_then(|id| api.jobs.progress(id)) else {
        return unknown_job(&api, &id, "job");
    };
    let value = match progress {
        Progress::Queued { ahead } => serde_json::json!({ "state": "queued", "ahead": ahead }),
        Progress::Running { since } => serde_json::json!({
            "state": "running",
            "seconds": since.elapsed().as_secs_f64(),
        }),
        Progress::Finished(Outcome::Done(json)) => {
            // The estimate's JSON text, made once by the engine, goes in as it is (keys in
            // the order serde_json's map writes them: "result", "state").
            let text = format!(r#"{{"result":{json},"state":"done"}}"#);
            return Answer(200, "application/json", text.into());
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
pub(super) async fn report(State(api): State<Arc<Api>>, Path(id): Path<String>) -> Answer {
    match id.parse::<u64>().ok().and_then(|id| api.jobs.report(id)) {
        Some(html) => Answer(
            200,
            "text/html; charset=utf-8",
            html.as_bytes().to_vec().into(),
        ),
        None => unknown_job(&api, &id, "report of job"),
    }
}

/// The 404 for a job (or its report) not kept: "no longer kept" when the id was given out
/// and has since been forgotten, else no such job.
fn unknown_job(api: &Api, id: &str, what: &str) -> Answer {
    if id.parse::<u64>().is_ok_and(|n| api.jobs.issued(n)) {
        Answer::error(
            404,
            format!("the {what} {id} is no longer kept (only the newest jobs are kept)"),
        )
    } else {
        Answer::error(404, format!("no such {what}: '{id}'"))
    }
}

pub(super) async fn not_allowed(method: Method, uri: Uri) -> Answer {
    Answer::error(405, format!("{method} is not allowed on {}", uri.path()))
}

/// Unknown addresses: a JSON error naming the path under `/api/`, a plain-text page
/// elsewhere.
pub(super) async fn not_found(uri: Uri) -> Answer {
    let path = uri.path();
    if path == "/api" || path.starts_with("/api/") {
        Answer::error(404, format!("no such API: {path}"))
    } else {
        Answer(
            404,
            "text/plain; charset=utf-8",
            "404: no such page on this server\n".into(),
        )
    }
}

fn busy() -> Answer {
    Answer::error(503, "too many photos are waiting; try again in a moment")
}
