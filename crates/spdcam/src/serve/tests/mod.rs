//! The server in-process on a free loopback port, spoken to over plain HTTP/1.1 sockets.

mod estimates;
mod jobs;
mod limits;
mod routes;

use super::{shipped_engine, Config, Server, Timeouts};
use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::Grid;
use spdcam_infer::{Estimator, ModelSet, PhotoOptions};
use spdcam_present::presentation::Presentation;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

const EXAMPLE: &[u8] = include_bytes!("../../../../../examples/sg-telelumen.jpg");
const BOUNDARY: &str = "spdcam-test-boundary-7f3a";

fn start(max_upload_bytes: usize) -> Server {
    start_with(max_upload_bytes, Timeouts::default())
}

fn start_with(max_upload_bytes: usize, timeouts: Timeouts) -> Server {
    Server::start(
        Config {
            addrs: vec!["127.0.0.1:0".parse().unwrap()],
            max_upload_bytes,
            workers: 2,
            timeouts,
        },
        shipped_engine(&DataDir::new(None)).unwrap(),
    )
    .unwrap()
}

/// A multipart body with `fields` (name, file name, content).
fn form(fields: &[(&str, Option<&str>, &[u8])]) -> Vec<u8> {
    let mut body = Vec::new();
    for (name, filename, data) in fields {
        body.extend_from_slice(format!("--{BOUNDARY}\r\n").as_bytes());
        match filename {
            Some(f) => body.extend_from_slice(
                format!("Content-Disposition: form-data; name=\"{name}\"; filename=\"{f}\"\r\nContent-Type: application/octet-stream\r\n\r\n").as_bytes(),
            ),
            None => body.extend_from_slice(
                format!("Content-Disposition: form-data; name=\"{name}\"\r\n\r\n").as_bytes(),
            ),
        }
        body.extend_from_slice(data);
        body.extend_from_slice(b"\r\n");
    }
    body.extend_from_slice(format!("--{BOUNDARY}--\r\n").as_bytes());
    body
}

/// Sends one request and gives the status and the body.
fn request(addr: SocketAddr, method: &str, path: &str, body: Option<&[u8]>) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let mut head = format!("{method} {path} HTTP/1.1\r\nHost: test\r\nConnection: close\r\n");
    if let Some(b) = body {
        head.push_str(&format!(
            "Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {}\r\n",
            b.len()
        ));
    }
    head.push_str("\r\n");
    stream.write_all(head.as_bytes()).unwrap();
    if let Some(b) = body {
        // A server may answer (413) and close before it has read all of a body.
        let _ = stream.write_all(b);
    }
    let (status, _, body) = read_answer(&mut stream);
    (status, body)
}

/// Reads an answer to its end (the connection closed): status, head, body.
fn read_answer(stream: &mut TcpStream) -> (u16, String, Vec<u8>) {
    let mut answer = Vec::new();
    // A reset after the answer (the server closed with unread bytes) ends it as well.
    let _ = stream.read_to_end(&mut answer);
    parse_answer(&answer)
}

fn parse_answer(answer: &[u8]) -> (u16, String, Vec<u8>) {
    let split = answer
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("not an HTTP answer: {:?}", String::from_utf8_lossy(answer)));
    let head = String::from_utf8_lossy(&answer[..split]).into_owned();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    (status, head, answer[split + 4..].to_vec())
}

fn json(body: &[u8]) -> serde_json::Value {
    serde_json::from_slice(body).unwrap_or_else(|e| {
        panic!("not JSON ({e}): {}", String::from_utf8_lossy(body));
    })
}

/// What `spdcam estimate --json` gives for the example under `name`, with its
/// `presentation`.
fn expected(name: &str) -> serde_json::Value {
    let estimate = Estimator::new(
        ModelSet::shipped().unwrap(),
        DataDir::new(None),
        Grid::ESTIMATION,
    )
    .unwrap()
    .estimate_photo_bytes(EXAMPLE, name, &PhotoOptions::default())
    .unwrap();
    let mut json = estimate.to_json().unwrap();
    json["presentation"] = serde_json::to_value(Presentation::of(&estimate)).unwrap();
    json
}
