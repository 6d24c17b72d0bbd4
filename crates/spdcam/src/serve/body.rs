//! An upload's body as it arrives, under three limits: its size, its pace (a client that
//! sends too slowly is cut off, so a slow upload holds nothing for long) and the server's
//! memory budget for uploads (the bytes of every upload being read or waiting for a worker).

use axum::body::Body;
use bytes::Bytes;
use futures_util::{Stream, StreamExt};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio::time::Instant;

/// The pace an upload must keep after its grace period: the body's deadline is the grace
/// period plus one second per this many bytes received (the rule of Apache's
/// `mod_reqtimeout`, `body=…,MinRate=…`), so a client that trickles a byte every few
/// seconds is cut off soon after the grace period while any real network keeps up.
pub const MIN_BYTES_PER_SECOND: u64 = 32 * 1024;
/// The unit of the memory budget's permits.
const BUDGET_UNIT: usize = 1024;

/// Why an upload's body was not read to its end.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyError {
    /// It is larger than the limit.
    TooLarge,
    /// It did not arrive in time.
    TimedOut,
    /// The memory budget for uploads is spent.
    Busy,
    /// The connection failed.
    Read(String),
}

impl std::fmt::Display for BodyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BodyError::TooLarge => write!(f, "the upload is larger than the limit"),
            BodyError::TimedOut => write!(f, "the upload did not arrive in time"),
            BodyError::Busy => write!(f, "too many uploads are held at once"),
            BodyError::Read(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for BodyError {}

/// The memory budget for upload bytes held by the server, in [`BUDGET_UNIT`]s.
pub struct Budget(Arc<Semaphore>);

impl Budget {
    /// A budget of `bytes`.
    pub fn new(bytes: usize) -> Budget {
        Budget(Arc::new(Semaphore::new(bytes.div_ceil(BUDGET_UNIT))))
    }
}

/// What a body's reading leaves behind: the share of the budget its bytes hold (to be kept
/// as long as the bytes are), and why it stopped early.
#[derive(Default)]
pub struct Held {
    /// The budget the bytes read so far hold.
    pub permit: Option<OwnedSemaphorePermit>,
    /// The first error, when the body was not read to its end.
    pub failure: Option<BodyError>,
}

/// How long a body may take.
#[derive(Debug, Clone, Copy)]
pub struct Pace {
    /// The time the body's first bytes may take; then [`MIN_BYTES_PER_SECOND`] applies.
    pub grace: Duration,
}

impl Pace {
    /// The latest moment by which the next bytes of a body begun at `start`, with
    /// `received` bytes so far, must arrive.
    fn deadline(self, start: Instant, received: u64) -> Instant {
        start + self.grace + Duration::from_secs_f64(received as f64 / MIN_BYTES_PER_SECOND as f64)
    }
}

/// The reading of one body.
struct Reading {
    data: axum::body::BodyDataStream,
    start: Instant,
    received: u64,
    limit: usize,
    pace: Pace,
    budget: Arc<Semaphore>,
    held: Arc<Mutex<Held>>,
    done: bool,
}

impl Reading {
    /// The next chunk, or why there is none.
    async fn next(&mut self) -> Option<Result<Bytes, BodyError>> {
        let deadline = self.pace.deadline(self.start, self.received);
        let next = match tokio::time::timeout_at(deadline, self.data.next()).await {
            Err(_) => Err(BodyError::TimedOut),
            Ok(None) => return None,
            Ok(Some(Err(e))) => Err(BodyError::Read(e.to_string())),
            Ok(Some(Ok(chunk))) => self.take(chunk),
        };
        if let Err(e) = &next {
            self.done = true;
            let mut held = self.held();
            if held.failure.is_none() {
                held.failure = Some(e.clone());
            }
        }
        Some(next)
    }

    /// Counts `chunk` against the limit and draws its bytes from the budget.
    fn take(&mut self, chunk: Bytes) -> Result<Bytes, BodyError> {
        self.received += chunk.len() as u64;
        if self.received > self.limit as u64 {
            return Err(BodyError::TooLarge);
        }
        let units =
            u32::try_from(chunk.len().div_ceil(BUDGET_UNIT)).map_err(|_| BodyError::TooLarge)?;
        if units > 0 {
            let permit = Arc::clone(&self.budget)
                .try_acquire_many_owned(units)
                .map_err(|_| BodyError::Busy)?;
            let mut held = self.held();
            match &mut held.permit {
                Some(p) => p.merge(permit),
                None => held.permit = Some(permit),
            }
        }
        Ok(chunk)
    }

    fn held(&self) -> std::sync::MutexGuard<'_, Held> {
        self.held.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// `body` as a stream of chunks, ended by an error when it grows over `limit` bytes, falls
/// behind `pace` or would overdraw `budget`; the budget its bytes hold and the first error
/// are kept in `held`.
pub fn limited(
    body: Body,
    limit: usize,
    pace: Pace,
    budget: &Budget,
    held: Arc<Mutex<Held>>,
) -> impl Stream<Item = Result<Bytes, BodyError>> + Send {
    let reading = Reading {
        data: body.into_data_stream(),
        start: Instant::now(),
        received: 0,
        limit,
        pace,
        budget: Arc::clone(&budget.0),
        held,
        done: false,
    };
    futures_util::stream::unfold(reading, |mut reading| async move {
        if reading.done {
            return None;
        }
        let next = reading.next().await?;
        Some((next, reading))
    })
}
