//! The estimation queue: uploads wait in a bounded queue and a fixed pool of worker threads
//! (one per core) estimates them off the server's connection tasks, so at most that many
//! photos are decoded at once (memory stays bounded however many uploads arrive), no
//! connection waits on another's estimate, and a page can poll its job's progress while a
//! 24 MP photo is worked on. Each finished estimate keeps its HTML report (the one `spdcam
//! estimate --report` writes) for the newest [`KEEP_REPORTS`] jobs.

mod engine;

pub use engine::Engine;

use engine::Estimated;
use spdcam_core::chart::KnownChart;
use spdcam_core::light_families::LightKind;
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Instant;
use tokio::sync::{Notify, OwnedSemaphorePermit};

/// Reports (each with its photo, a few hundred kB) are kept for this many newest jobs.
pub const KEEP_REPORTS: usize = 32;

/// The charts a client may name for its corners (a name, never a path): those a shipped
/// model reads, from the chart registry ([`KnownChart::with_shipped_model`]).
pub fn charts() -> Vec<KnownChart> {
    KnownChart::with_shipped_model()
}

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
    /// The chart, when the client named it (one of [`charts`]).
    pub chart: Option<KnownChart>,
    /// The kind of light the client named (`Unknown` when none).
    pub light: LightKind,
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

    /// Whether `id` was given to an upload (which may have been forgotten since): a job
    /// no longer kept, as opposed to one that never was.
    pub fn issued(&self, id: u64) -> bool {
        (1..self.lock().next_id).contains(&id)
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
