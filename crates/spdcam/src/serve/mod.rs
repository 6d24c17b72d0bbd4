//! `spdcam serve`: a local web app. A page embedded in the binary (no CDN, no network) where
//! photos are dropped and the light's SPD, chromaticity and warnings are shown, and the small
//! HTTP API it uses (see `docs/web-api.md`). Requests are served by a few threads; the
//! estimates are made by the bounded queue of [`jobs`], one worker per core.

mod api;
mod jobs;
mod multipart;
#[cfg(test)]
mod tests;

use anyhow::{anyhow, Context, Result};
use clap::Args;
use jobs::{Engine, Jobs};
use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::Grid;
use spdcam_infer::Estimator;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::Arc;
use std::thread::JoinHandle;

/// Threads that read requests and write answers (they wait on the queue, not compute).
const REQUEST_THREADS: usize = 8;
/// Uploads that may wait for a worker before new ones are refused with 503.
const MAX_QUEUED: usize = 64;
/// Finished jobs remembered for polling.
const KEEP_FINISHED: usize = 256;

/// Options of `spdcam serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Port to listen on; 0 picks a free one.
    #[arg(long, default_value_t = 8747)]
    port: u16,
    /// Address to listen on. The default serves this machine only; give 0.0.0.0 to let
    /// other machines of the network in.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    host: IpAddr,
    /// Largest photo accepted, in megabytes (larger uploads are refused with 413).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=1024))]
    max_upload_mb: u64,
}

/// How a server is set up.
pub struct Config {
    /// Where to listen (port 0: any free one).
    pub addr: SocketAddr,
    /// Largest photo accepted, in bytes.
    pub max_upload_bytes: usize,
    /// Estimating workers.
    pub workers: usize,
}

/// A running server.
pub struct Server {
    #[cfg(test)]
    http: Arc<tiny_http::Server>,
    #[cfg(test)]
    jobs: Arc<Jobs>,
    threads: Vec<JoinHandle<()>>,
    addr: SocketAddr,
}

impl Server {
    /// Starts listening and the worker threads.
    pub fn start(config: Config, engine: Engine) -> Result<Server> {
        let http = tiny_http::Server::http(config.addr)
            .map_err(|e| anyhow!("cannot listen on {}: {e}", config.addr))?;
        let addr = http
            .server_addr()
            .to_ip()
            .context("the server listens on no IP address")?;
        let http = Arc::new(http);
        let jobs = Arc::new(Jobs::new(engine, MAX_QUEUED, KEEP_FINISHED));
        let api = Arc::new(api::Api::new(Arc::clone(&jobs), config.max_upload_bytes)?);
        let mut threads = Vec::new();
        for _ in 0..config.workers.max(1) {
            let jobs = Arc::clone(&jobs);
            threads.push(std::thread::spawn(move || jobs.work()));
        }
        for _ in 0..REQUEST_THREADS {
            let (http, api) = (Arc::clone(&http), Arc::clone(&api));
            threads.push(std::thread::spawn(move || {
                while let Ok(request) = http.recv() {
                    api.handle(request);
                }
            }));
        }
        Ok(Server {
            #[cfg(test)]
            http,
            #[cfg(test)]
            jobs,
            threads,
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

    /// Serves until the threads end (they end only when stopped).
    pub fn wait(self) {
        for t in self.threads {
            let _ = t.join();
        }
    }

    /// Stops serving and joins the threads.
    #[cfg(test)]
    pub fn stop(self) {
        self.jobs.stop();
        for _ in 0..REQUEST_THREADS {
            self.http.unblock();
        }
        self.wait();
    }
}

/// The engine of `spdcam serve`: the shipped models, estimates on 400–700 nm in 5 nm steps
/// (the default of `spdcam estimate`, so the answers equal its `--json`).
pub fn shipped_engine(data_dir: &DataDir) -> Result<Engine> {
    Ok(Engine {
        estimator: Estimator::shipped(data_dir.clone(), Grid::parse("400-700:5")?)?,
    })
}

/// Runs `spdcam serve`.
pub fn run(args: ServeArgs, data_dir: &DataDir) -> Result<()> {
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get().clamp(1, 8));
    let server = Server::start(
        Config {
            addr: SocketAddr::new(args.host, args.port),
            max_upload_bytes: usize::try_from(args.max_upload_mb << 20)?,
            workers,
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
