//! Accepting connections and serving each as a task: hyper's HTTP/1 server with a time limit
//! on request headers, a size limit on them (431) and a bound on open connections.

use axum::Router;
use hyper::body::Incoming;
use hyper::server::conn::http1;
use hyper_util::rt::{TokioIo, TokioTimer};
use std::sync::Arc;
use std::time::Duration;
use tokio::io::AsyncWriteExt;
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::Semaphore;
use tower_service::Service;

/// The largest request head (request line and headers) read; a larger one is answered with
/// 431 Request Header Fields Too Large without reading the rest.
pub const MAX_HEADER_BYTES: usize = 64 * 1024;
/// The message to a client whose headers began but did not end in time.
const HEADERS_TOO_SLOW: &str = "the request's headers did not arrive in time";

/// How connections are served.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// The time a client has to send a request's headers.
    pub header_timeout: Duration,
    /// Connections served at once.
    pub max_connections: usize,
}

/// Accepts connections on `listener` for ever, each served by its own task.
pub async fn accept(listener: TcpListener, app: Router, settings: Settings) {
    let open = Arc::new(Semaphore::new(settings.max_connections));
    loop {
        let Ok(permit) = Arc::clone(&open).acquire_owned().await else {
            return;
        };
        let stream = match listener.accept().await {
            Ok((stream, _)) => stream,
            // Out of file descriptors or a connection reset before it was accepted: wait a
            // little rather than spin.
            Err(_) => {
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        let _ = stream.set_nodelay(true);
        let app = app.clone();
        tokio::spawn(async move {
            serve(stream, app, settings.header_timeout).await;
            drop(permit);
        });
    }
}

/// Serves the requests of one connection until it closes, is closed by the client or
/// breaks a limit.
async fn serve(stream: TcpStream, app: Router, header_timeout: Duration) {
    let service = hyper::service::service_fn(move |request: hyper::Request<Incoming>| {
        let mut app = app.clone();
        Box::pin(async move { app.call(request).await })
    });
    let mut connection = http1::Builder::new()
        .timer(TokioTimer::new())
        .header_read_timeout(header_timeout)
        .max_buf_size(MAX_HEADER_BYTES)
        .max_header_size(MAX_HEADER_BYTES)
        .serve_connection(TokioIo::new(stream), service);
    let served = std::future::poll_fn(|cx| connection.poll_without_shutdown(cx)).await;
    let parts = connection.into_parts();
    let begun = !parts.read_buf.is_empty();
    let mut stream = parts.io.into_inner();
    // hyper closes a connection whose headers are late without a word; when a request had
    // begun, its client is told why (an idle kept-alive connection is just closed).
    if served.is_err_and(|e| e.is_timeout()) && begun {
        let body = serde_json::json!({ "error": HEADERS_TOO_SLOW }).to_string();
        let answer = format!(
            "HTTP/1.1 408 Request Timeout\r\nConnection: close\r\nContent-Type: application/json\r\n\
             Cache-Control: no-store\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        );
        let _ =
            tokio::time::timeout(Duration::from_secs(1), stream.write_all(answer.as_bytes())).await;
    }
    let _ = tokio::time::timeout(Duration::from_secs(1), stream.shutdown()).await;
}
