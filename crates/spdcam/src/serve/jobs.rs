//! The estimation queue: uploads wait in a bounded queue and a fixed pool of worker threads
//! (one per core) estimates them off the server's connection tasks, so at most that many
//! photos are decoded at once (memory stays bounded however many uploads arrive), no
//! connection waits on another's estimate, and a page can poll its job's progress while a
//! 24 MP photo is worked on.

use spdcam_core::photo;
use spdcam_infer::{Estimator, InferError, PhotoOptions};
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Instant;
use tokio::sync::{Notify, OwnedSemaphorePermit};

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
}

/// How a job ended: the estimate's JSON, or an HTTP status and a message.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// The JSON object of `spdcam estimate --json` for the photo.
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

impl Engine {
    /// The estimate of one upload, by the estimator `spdcam estimate` uses: a photo that
    /// cannot be read or shows no chart is a 400, one with no model for its chart 422.
    /// The one place the server estimates.
    pub fn estimate(&self, upload: Upload) -> Outcome {
        let options = PhotoOptions {
            corners: upload.corners,
            ..PhotoOptions::default()
        };
        let analysed = match photo::decode_photo(&upload.bytes, &upload.name)
            .map_err(InferError::from)
            .and_then(|decoded| self.estimator.analyse_decoded(&decoded, &options))
        {
            Ok(a) => a,
            Err(e) => return Outcome::Failed(400, e.to_string()),
        };
        drop(upload.bytes);
        drop(upload.memory);
        let estimate = match self
            .estimator
            .estimate_analysis(analysed.analysis, upload.name)
        {
            Ok(e) => e,
            Err(e) => return Outcome::Failed(422, e.to_string()),
        };
        match estimate.to_json() {
            Ok(json) => Outcome::Done(json.to_string().into()),
            Err(e) => Outcome::Failed(500, e.to_string()),
        }
    }
}

#[derive(Default)]
struct State {
    queue: VecDeque<(u64, Upload)>,
    progress: HashMap<u64, Progress>,
    finished: VecDeque<u64>,
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
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                self.engine.estimate(upload)
            }))
            .unwrap_or_else(|_| Outcome::Failed(500, "internal error while estimating".into()));
            let mut state = self.lock();
            state.progress.insert(id, Progress::Finished(outcome));
            state.finished.push_back(id);
            while state.finished.len() > self.keep_finished {
                if let Some(old) = state.finished.pop_front() {
                    state.progress.remove(&old);
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
