//! `spdcam serve`: a local web app. A page embedded in the binary (no CDN, no network) where
//! photos are dropped and the light's SPD, chromaticity and warnings are shown, and the small
//! HTTP API it uses (see `docs/web-api.md`). Connections are tasks of a small tokio runtime
//! (hyper's HTTP/1 server under axum's routes), not threads: a slow client holds no thread,
//! and is cut off by the header and body time limits. The estimates are made by the bounded
//! queue of [`jobs`], one worker thread per core.

mod api;
mod body;
mod connection;
mod jobs;
mod multipart;
#[cfg(test)]
mod tests;

use anyhow::{bail, Context, Result};
use clap::Args;
use jobs::{Engine, Jobs};
use spdcam_core::builtin::DataDir;
use spdcam_core::limits;
use spdcam_core::spectral::Grid;
use spdcam_infer::Estimator;
use std::net::{SocketAddr, ToSocketAddrs};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Threads of the runtime that reads requests and writes answers (they never estimate).
const IO_THREADS: usize = 2;
/// Connections served at once; more wait to be accepted until one closes.
const MAX_CONNECTIONS: usize = 512;
/// Uploads that may wait for a worker before new ones are refused with 503.
const MAX_QUEUED: usize = 64;
/// Finished jobs remembered for polling.
const KEEP_FINISHED: usize = 256;
/// Upload bytes held in memory at once (being received or waiting for a worker), at least
/// one upload of the largest size; an upload that would overdraw it is refused with 503.
const UPLOAD_BUDGET_BYTES: usize = 512 << 20;

/// Options of `spdcam serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Port to listen on; 0 picks a free one.
    #[arg(long, default_value_t = 8747)]
    port: u16,
    /// Address or host name to listen on. The default serves this machine only; give
    /// 0.0.0.0 to let other machines of the network in.
    #[arg(long, default_value = "127.0.0.1")]
    host: String,
    /// Largest photo accepted, in megabytes (larger uploads are refused with 413); never
    /// more than the photo size every command keeps to (`SPDCAM_MAX_PHOTO_BYTES`).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=1024))]
    max_upload_mb: u64,
}

/// How long a client may take.
#[derive(Debug, Clone, Copy)]
pub struct Timeouts {
    /// To send a request's headers, and on a kept-alive connection to begin the next
    /// request; then the connection is closed (after a 408 when headers had begun).
    pub headers: Duration,
    /// To send an upload's first bytes: after it the body must keep a pace of
    /// 32 KiB/s on average or it is answered with 408.
    pub body_grace: Duration,
}

impl Default for Timeouts {
    fn default() -> Timeouts {
        Timeouts {
            headers: Duration::from_secs(10),
            body_grace: Duration::from_secs(10),
        }
    }
}

/// How a server is set up.
pub struct Config {
    /// Where to listen, tried in turn until one is free (port 0: any free one).
    pub addrs: Vec<SocketAddr>,
    /// Largest photo accepted, in bytes.
    pub max_upload_bytes: usize,
    /// Estimating workers.
    pub workers: usize,
    /// The time limits of clients.
    pub timeouts: Timeouts,
}

/// A running server.
pub struct Server {
    runtime: tokio::runtime::Runtime,
    accepting: tokio::task::JoinHandle<()>,
    #[cfg(test)]
    jobs: Arc<Jobs>,
    workers: Vec<JoinHandle<()>>,
    addr: SocketAddr,
}

impl Server {
    /// Starts listening, the runtime and the worker threads.
    pub fn start(config: Config, engine: Engine) -> Result<Server> {
        let listener = std::net::TcpListener::bind(&config.addrs[..])
            .with_context(|| format!("cannot listen on {}", list(&config.addrs)))?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(IO_THREADS)
            .thread_name("spdcam-http")
            .enable_io()
            .enable_time()
            .build()
            .context("cannot start the server's runtime")?;
        let listener = {
            let _entered = runtime.enter();
            tokio::net::TcpListener::from_std(listener)?
        };
        let jobs = Arc::new(Jobs::new(engine, MAX_QUEUED, KEEP_FINISHED));
        let pace = body::Pace {
            grace: config.timeouts.body_grace,
        };
        let api = Arc::new(api::Api::new(
            Arc::clone(&jobs),
            config.max_upload_bytes,
            pace,
            UPLOAD_BUDGET_BYTES,
        )?);
        let workers = (0..config.workers.max(1))
            .map(|_| {
                let jobs = Arc::clone(&jobs);
                std::thread::spawn(move || jobs.work())
            })
            .collect();
        let settings = connection::Settings {
            header_timeout: config.timeouts.headers,
            max_connections: MAX_CONNECTIONS,
        };
        let accepting = runtime.spawn(connection::accept(listener, api.router(), settings));
        Ok(Server {
            runtime,
            accepting,
            #[cfg(test)]
            jobs,
            workers,
            addr,
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Serves until the process ends.
    pub fn wait(self) {
        let _ = self.runtime.block_on(self.accepting);
        for worker in self.workers {
            let _ = worker.join();
        }
    }

    /// Stops serving and joins the workers.
    #[cfg(test)]
    pub fn stop(self) {
        self.jobs.stop();
        self.accepting.abort();
        self.runtime.shutdown_timeout(Duration::from_secs(1));
        for worker in self.workers {
            let _ = worker.join();
        }
    }
}

/// `addrs` as a list for a message.
fn list(addrs: &[SocketAddr]) -> String {
    addrs
        .iter()
        .map(SocketAddr::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The addresses of `host` (an IP address or a name such as `localhost`) at `port`.
fn resolve(host: &str, port: u16) -> Result<Vec<SocketAddr>> {
    let addrs: Vec<SocketAddr> = (host, port)
        .to_socket_addrs()
        .with_context(|| format!("cannot resolve the host '{host}' (spdcam serve --host)"))?
        .collect();
    if addrs.is_empty() {
        bail!("the host '{host}' has no address (spdcam serve --host)");
    }
    Ok(addrs)
}

/// The engine of `spdcam serve`: the shipped models, estimates on 400–700 nm in 5 nm steps
/// (the default of `spdcam estimate`, so the answers equal its `--json`).
pub fn shipped_engine(data_dir: &DataDir) -> Result<Engine> {
    Ok(Engine {
        estimator: Estimator::shipped(data_dir.clone(), Grid::ESTIMATION)?,
    })
}

/// Runs `spdcam serve`.
pub fn run(args: ServeArgs, data_dir: &DataDir) -> Result<()> {
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get().clamp(1, 8));
    let server = Server::start(
        Config {
            addrs: resolve(&args.host, args.port)?,
            max_upload_bytes: usize::try_from(
                (args.max_upload_mb << 20).min(limits::PHOTO_BYTES.value()?),
            )?,
            workers,
            timeouts: Timeouts::default(),
        },
        shipped_engine(data_dir)?,
    )?;
    println!("spdcam serves {} (Ctrl-C stops it)", server.url());
    if !server.addr().ip().is_loopback() {
        eprintln!(
            "warning: listening on {}: other machines of the network can reach the page",
            server.addr().ip()
        );
    }
    server.wait();
    Ok(())
}
