//! The estimation queue: uploads wait in a bounded queue and a fixed pool of worker threads
//! (one per core) estimates them off the server's connection tasks, so at most that many
//! photos are decoded at once (memory stays bounded however many uploads arrive), no
//! connection waits on another's estimate, and a page can poll its job's progress while a
//! 24 MP photo is worked on. Each finished estimate keeps its HTML report (the one `spdcam
//! estimate --report` writes) for the newest [`KEEP_REPORTS`] jobs.

use spdcam_core::chart::KnownChart;
use spdcam_core::photo;
use spdcam_infer::presentation::Presentation;
use spdcam_infer::report::{report_html, ReportImage, ReportItem, REPORT_IMAGE_WIDTH};
use spdcam_infer::{Estimator, InferError, PhotoOptions};
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Instant;
use tokio::sync::{Notify, OwnedSemaphorePermit};

/// Reports (each with its photo, a few hundred kB) are kept for this many newest jobs.
pub const KEEP_REPORTS: usize = 32;

/// The charts a client may name for its corners: a name, never a path.
pub const CHARTS: [KnownChart; 2] = [KnownChart::ColorChecker24, KnownChart::Sg96];

/// One uploaded photo to estimate, held in memory.
#[derive(Debug)]
pub struct Upload {
    /// The label of the estimate (the client's file name without any folder).
    pub name: String,
    /// The photo file's bytes.
    pub bytes: Vec<u8>,
    /// The chart's four corners, when the client placed them.
    pub corners: Option<Vec<[f64; 2]>>,
    /// The share of the server's upload memory budget the bytes hold; released with them.
    pub memory: Option<OwnedSemaphorePermit>,
    /// The chart, when the client named it (one of [`CHARTS`]).
    pub chart: Option<KnownChart>,
}

/// How a job ended: the estimate's JSON, or an HTTP status and a message.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// The JSON object of `spdcam estimate --json` for the photo, with its `presentation`.
    Done(Arc<str>),
    /// The status (400 bad photo or no chart, 422 no model for the chart, 500) and message.
    Failed(u16, String),
}

/// Where a job is.
#[derive(Debug, Clone)]
pub enum Progress {
    /// Waiting; `ahead` jobs come first.
    Queued { ahead: usize },
    /// Being estimated since `since`.
    Running { since: Instant },
    /// Finished.
    Finished(Outcome),
}

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
        let analysed = match photo::decode_photo(&upload.bytes, &upload.name)
            .map_err(InferError::from)
            .and_then(|decoded| self.estimator.analyse_decoded(&decoded, &options))
        {
            Ok(a) => a,
            Err(e) => return failed(400, e.to_string()),
        };
        drop(upload.bytes);
        drop(upload.memory);
        let overlay = analysed.overlay;
        let estimate = match self
            .estimator
            .estimate_analysis(analysed.analysis, upload.name)
        {
            Ok(e) => e,
            Err(e) => return failed(422, e.to_string()),
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

/// The message for a person (no command-line words) and a code for the page, of a failed
/// request's `status` and `error`: `no_chart` when the chart was not found (the page then
/// asks for its corners), else `bad_photo`, `unknown_chart`, `bad_corners`, `too_large`,
/// `busy`, `not_found` or `failed`.
pub fn plain_error(status: u16, error: &str) -> (&'static str, String) {
    let (code, message) = if error.contains("no chart found") {
        (
            "no_chart",
            "No colour chart was found in this photo. Click its four corners on the photo to              show where it is."
                .to_string(),
        )
    } else if error.contains("not an image") || error.contains("decod") {
        (
            "bad_photo",
            "This file is not a photo the page can read: use a JPEG, PNG or TIFF.".to_string(),
        )
    } else if error.contains("no model for chart") {
        (
            "unknown_chart",
            "The chart in this photo is not one spdcam reads: use a ColorChecker 24 or a              ColorChecker Digital SG."
                .to_string(),
        )
    } else if error.contains("corners") {
        (
            "bad_corners",
            "The four corners could not be used: click the chart's four outer corners.".to_string(),
        )
    } else {
        match status {
            413 => (
                "too_large",
                "This photo is larger than this server accepts; use a smaller file.".to_string(),
            ),
            503 => (
                "busy",
                "The server is busy with other photos; try again in a moment.".to_string(),
            ),
            404 => (
                "not_found",
                "This is no longer kept on the server; add the photo again.".to_string(),
            ),
            _ => (
                "failed",
                format!("The photo could not be estimated: {}", without_flags(error)),
            ),
        }
    };
    (code, message)
}

/// `error` without the clauses (split at `;` and parentheses) that name command-line
/// options or commands.
fn without_flags(error: &str) -> String {
    error
        .split(';')
        .map(|part| match part.find('(') {
            Some(i) if part[i..].contains("--") || part[i..].contains("spdcam ") => &part[..i],
            _ => part,
        })
        .filter(|part| !part.contains("--") && !part.contains("spdcam "))
        .map(str::trim)
        .filter(|part| !part.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[derive(Default)]
struct State {
    queue: VecDeque<(u64, Upload)>,
    progress: HashMap<u64, Progress>,
    finished: VecDeque<u64>,
    reports: HashMap<u64, Arc<str>>,
    next_id: u64,
    stopping: bool,
}

/// The queue and its workers' shared state.
pub struct Jobs {
    state: Mutex<State>,
    /// Wakes the workers when an upload is queued or the queue stops.
    changed: Condvar,
    /// Wakes the connections waiting for an outcome when a job finishes.
    finished: Notify,
    engine: Engine,
    max_queued: usize,
    keep_finished: usize,
}

impl Jobs {
    /// A queue of at most `max_queued` waiting uploads that remembers the last
    /// `keep_finished` outcomes for polling.
    pub fn new(engine: Engine, max_queued: usize, keep_finished: usize) -> Jobs {
        Jobs {
            state: Mutex::new(State {
                next_id: 1,
                ..State::default()
            }),
            changed: Condvar::new(),
            finished: Notify::new(),
            engine,
            max_queued,
            keep_finished,
        }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A worker that panicked holds no invariant half-changed: the state stays usable.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Queues an upload; `None` when the queue is full (the client should retry later).
    pub fn submit(&self, upload: Upload) -> Option<u64> {
        let mut state = self.lock();
        if state.queue.len() >= self.max_queued || state.stopping {
            return None;
        }
        let id = state.next_id;
        state.next_id += 1;
        state.queue.push_back((id, upload));
        state.progress.insert(id, Progress::Queued { ahead: 0 });
        self.changed.notify_all();
        Some(id)
    }

    /// Where job `id` is, or `None` for an unknown (or long forgotten) job.
    pub fn progress(&self, id: u64) -> Option<Progress> {
        let state = self.lock();
        match state.progress.get(&id)? {
            Progress::Queued { .. } => Some(Progress::Queued {
                ahead: state.queue.iter().take_while(|(j, _)| *j != id).count(),
            }),
            p => Some(p.clone()),
        }
    }

    /// The HTML report of finished job `id`, while it is kept.
    pub fn report(&self, id: u64) -> Option<Arc<str>> {
        self.lock().reports.get(&id).cloned()
    }

    /// Waits until job `id` has finished and gives its outcome (without holding a thread).
    pub async fn wait(&self, id: u64) -> Outcome {
        loop {
            let finished = self.finished.notified();
            let mut finished = std::pin::pin!(finished);
            // Registered before the state is read, so a job finishing in between wakes it.
            finished.as_mut().enable();
            {
                let state = self.lock();
                match state.progress.get(&id) {
                    Some(Progress::Finished(outcome)) => return outcome.clone(),
                    None => return Outcome::Failed(500, format!("job {id} was forgotten")),
                    _ if state.stopping => {
                        return Outcome::Failed(503, "the server is stopping".into())
                    }
                    _ => {}
                }
            }
            finished.await;
        }
    }

    /// A worker's loop: takes the oldest upload, estimates it, records the outcome; ends
    /// when the queue is stopped.
    pub fn work(&self) {
        loop {
            let (id, upload) = {
                let mut state = self.lock();
                loop {
                    if state.stopping {
                        return;
                    }
                    if let Some(job) = state.queue.pop_front() {
                        state.progress.insert(
                            job.0,
                            Progress::Running {
                                since: Instant::now(),
                            },
                        );
                        break job;
                    }
                    state = self.changed.wait(state).unwrap_or_else(|p| p.into_inner());
                }
            };
            let estimated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                self.engine.estimate(upload)
            }))
            .unwrap_or_else(|_| Estimated {
                outcome: Outcome::Failed(500, "internal error while estimating".into()),
                report: None,
            });
            let mut state = self.lock();
            state
                .progress
                .insert(id, Progress::Finished(estimated.outcome));
            if let Some(report) = estimated.report {
                state.reports.insert(id, report);
            }
            state.finished.push_back(id);
            while state.finished.len() > self.keep_finished {
                if let Some(old) = state.finished.pop_front() {
                    state.progress.remove(&old);
                    state.reports.remove(&old);
                }
            }
            if state.reports.len() > KEEP_REPORTS {
                let newest = state.finished.len().saturating_sub(KEEP_REPORTS);
                let old: Vec<u64> = state.finished.iter().take(newest).copied().collect();
                for j in old {
                    state.reports.remove(&j);
                }
            }
            drop(state);
            self.finished.notify_waiters();
        }
    }

    /// Stops the workers (after their current job) and wakes every waiter.
    #[cfg(test)]
    pub fn stop(&self) {
        self.lock().stopping = true;
        self.changed.notify_all();
        self.finished.notify_waiters();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_for_people_name_no_command_line_words() {
        let cases = [
            (
                400,
                "room.jpg: no chart found (looked for colorchecker24); give its corners with --corners x1,y1,…,x4,y4",
                "no_chart",
            ),
            (400, "notes.txt: not an image (unknown format)", "bad_photo"),
            (
                413,
                "the upload is larger than the limit of 64 MB (spdcam serve --max-upload-mb)",
                "too_large",
            ),
            (400, "--corners needs eight numbers x1,y1,x2,y2,x3,y3,x4,y4; got 3", "bad_corners"),
            (503, "too many photos are waiting; try again in a moment", "busy"),
            (500, "the model broke (try spdcam estimate --debug d.png); really", "failed"),
        ];
        for (status, error, want) in cases {
            let (code, message) = plain_error(status, error);
            assert_eq!(code, want, "{error}");
            for word in ["--", "spdcam serve", "spdcam estimate", "corners with"] {
                assert!(!message.contains(word), "{message}");
            }
        }
        assert_eq!(
            plain_error(
                500,
                "the model broke (try spdcam estimate --debug d.png); really"
            )
            .1,
            "The photo could not be estimated: the model broke; really"
        );
    }
}
