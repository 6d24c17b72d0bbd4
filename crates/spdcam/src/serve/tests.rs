//! The server in-process on a free loopback port, spoken to over plain HTTP/1.1 sockets.

use super::{resolve, shipped_engine, Config, Server, Timeouts};
use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::Grid;
use spdcam_infer::presentation::Presentation;
use spdcam_infer::{estimate_photo_bytes, ModelSet, PhotoOptions};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

const EXAMPLE: &[u8] = include_bytes!("../../../../examples/sg-telelumen.jpg");
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
    let estimate = estimate_photo_bytes(
        EXAMPLE,
        name,
        &ModelSet::shipped().unwrap(),
        &PhotoOptions::default(),
        &DataDir::new(None),
        &Grid::parse("400-700:5").unwrap(),
    )
    .unwrap();
    let mut json = estimate.to_json().unwrap();
    json["presentation"] = serde_json::to_value(Presentation::of(&estimate)).unwrap();
    json
}

#[test]
fn twenty_concurrent_uploads_are_all_answered_correctly() {
    let server = start(16 << 20);
    let addr = server.addr();
    let want = expected("room-0.jpg");
    let answers: Vec<(u16, serde_json::Value)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..20)
            .map(|i| {
                s.spawn(move || {
                    let name = format!("room-{i}.jpg");
                    let body = form(&[("photo", Some(name.as_str()), EXAMPLE)]);
                    let (status, body) =
                        request(addr, "POST", "/api/estimate", Some(body.as_slice()));
                    (status, json(&body))
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (i, (status, got)) in answers.iter().enumerate() {
        assert_eq!(*status, 200, "{got}");
        assert_eq!(got["name"], format!("room-{i}.jpg"));
        assert_eq!(got["spd"], want["spd"]);
        assert_eq!(got["colorimetry"], want["colorimetry"]);
        assert_eq!(got["photo"]["corners"], want["photo"]["corners"]);
    }
    server.stop();
}

#[test]
fn the_answer_equals_the_library_estimate() {
    let server = start(16 << 20);
    let body = form(&[("photo", Some("sg-telelumen.jpg"), EXAMPLE)]);
    let (status, got) = request(
        server.addr(),
        "POST",
        "/api/estimate",
        Some(body.as_slice()),
    );
    assert_eq!(status, 200);
    assert_eq!(json(&got), expected("sg-telelumen.jpg"));
    server.stop();
}

#[test]
fn an_upload_over_the_limit_is_refused_with_413() {
    let server = start(100 << 10);
    let body = form(&[("photo", Some("big.jpg"), EXAMPLE)]);
    let (status, got) = request(
        server.addr(),
        "POST",
        "/api/estimate",
        Some(body.as_slice()),
    );
    assert_eq!(status, 413);
    let message = json(&got)["error"].as_str().unwrap().to_string();
    assert!(message.contains("limit"), "{message}");
    // Still serving afterwards.
    let (status, _) = request(server.addr(), "GET", "/api/locus", None);
    assert_eq!(status, 200);
    server.stop();
}

#[test]
fn bad_input_gets_a_clear_error_and_the_server_keeps_serving() {
    let server = start(16 << 20);
    let addr = server.addr();
    let cases: [(Vec<u8>, u16, &str); 4] = [
        (
            form(&[("photo", Some("notes.txt"), b"not a photo at all")]),
            400,
            "not an image",
        ),
        (form(&[("other", None, b"x")]), 400, "no field 'photo'"),
        (
            form(&[
                ("photo", Some("p.jpg"), EXAMPLE),
                ("corners", None, b"1,2,3"),
            ]),
            400,
            "eight numbers",
        ),
        (b"--garbage".to_vec(), 400, "multipart"),
    ];
    for (body, want_status, want_text) in cases {
        let (status, got) = request(addr, "POST", "/api/estimate", Some(body.as_slice()));
        assert_eq!(status, want_status);
        let got = json(&got);
        let message = got["error"].as_str().unwrap().to_string();
        assert!(message.contains(want_text), "{message}");
        // Beside it, a message for a person, without command-line words.
        let plain = got["message"].as_str().unwrap();
        assert!(!plain.contains("--") && !plain.is_empty(), "{plain}");
    }
    let (status, got) = request(addr, "GET", "/no/such/page", None);
    assert_eq!(status, 404);
    assert!(json(&got)["error"].is_string());
    let (status, _) = request(addr, "GET", "/api/estimate", None);
    assert_eq!(status, 405);
    let body = form(&[("photo", Some("p.jpg"), EXAMPLE)]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(body.as_slice()));
    assert_eq!(status, 200);
    assert_eq!(json(&got)["spd"], expected("p.jpg")["spd"]);
    server.stop();
}

#[test]
fn a_job_is_polled_until_its_estimate_is_done() {
    let server = start(16 << 20);
    let addr = server.addr();
    let body = form(&[("photo", Some("p.jpg"), EXAMPLE)]);
    let (status, got) = request(addr, "POST", "/api/jobs", Some(body.as_slice()));
    assert_eq!(status, 202);
    let id = json(&got)["id"].as_str().unwrap().to_string();
    let mut states = Vec::new();
    let result = loop {
        let (status, got) = request(addr, "GET", &format!("/api/jobs/{id}"), None);
        assert_eq!(status, 200);
        let got = json(&got);
        let state = got["state"].as_str().unwrap().to_string();
        assert!(
            ["queued", "running", "done"].contains(&state.as_str()),
            "{got}"
        );
        states.push(state);
        if got["state"] == "done" {
            break got["result"].clone();
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(result["spd"], expected("p.jpg")["spd"]);
    let (status, _) = request(addr, "GET", "/api/jobs/999999", None);
    assert_eq!(status, 404);
    server.stop();
}

#[test]
fn the_page_and_its_assets_are_embedded() {
    let server = start(16 << 20);
    for (path, needle) in [
        ("/", "<html"),
        ("/app.js", "api/jobs/"),
        ("/style.css", "{"),
    ] {
        let (status, body) = request(server.addr(), "GET", path, None);
        assert_eq!(status, 200, "{path}");
        assert!(String::from_utf8_lossy(&body).contains(needle), "{path}");
    }
    let (status, body) = request(server.addr(), "GET", "/example.jpg", None);
    assert_eq!(status, 200);
    assert_eq!(body, EXAMPLE);
    server.stop();
}

/// A connection that sent the head of an upload of `declared` bytes and `sent` bytes of its
/// body, and stays open.
fn slow_upload(addr: SocketAddr, declared: usize, sent: usize) -> TcpStream {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let head = format!(
        "POST /api/estimate HTTP/1.1\r\nHost: test\r\n\
         Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {declared}\r\n\r\n"
    );
    let mut body = format!(
        "--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"slow.jpg\"\r\n\r\n"
    )
    .into_bytes();
    body.resize(sent, b'x');
    stream.write_all(head.as_bytes()).unwrap();
    stream.write_all(&body).unwrap();
    stream
}

#[test]
fn slow_uploads_block_nothing_and_are_cut_off_with_408() {
    let server = start_with(
        16 << 20,
        Timeouts {
            headers: Duration::from_secs(2),
            body_grace: Duration::from_secs(2),
        },
    );
    let addr = server.addr();
    let started = Instant::now();
    let mut slow: Vec<TcpStream> = (0..12).map(|_| slow_upload(addr, 100_000, 1000)).collect();
    // One of them trickles a byte every 300 ms: it is cut off all the same.
    let trickle = std::thread::spawn({
        let mut stream = slow.pop().unwrap();
        move || {
            while stream.write_all(b"x").is_ok() && started.elapsed() < Duration::from_secs(20) {
                std::thread::sleep(Duration::from_millis(300));
            }
            stream
        }
    });
    // Meanwhile other requests are answered at once, an upload too.
    for _ in 0..5 {
        let asked = Instant::now();
        let (status, body) = request(addr, "GET", "/api/locus", None);
        assert_eq!(status, 200);
        assert!(json(&body)["spectral"].is_array());
        assert!(
            asked.elapsed() < Duration::from_secs(1),
            "{:?}",
            asked.elapsed()
        );
    }
    let body = form(&[("photo", Some("p.jpg"), EXAMPLE)]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(body.as_slice()));
    assert_eq!(status, 200);
    assert_eq!(json(&got)["spd"], expected("p.jpg")["spd"]);
    slow.push(trickle.join().unwrap());
    for mut stream in slow {
        let (status, head, body) = read_answer(&mut stream);
        assert_eq!(status, 408, "{head}");
        assert!(
            head.to_ascii_lowercase().contains("connection: close"),
            "{head}"
        );
        let message = json(&body)["error"].as_str().unwrap().to_string();
        assert!(message.contains("arrived too slowly"), "{message}");
    }
    // The grace of 2 s plus the pace's allowance for 1000 bytes (31 ms), with room for a
    // busy machine; not the 60 s a client could hold them.
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "{:?}",
        started.elapsed()
    );
    server.stop();
}

#[test]
fn slow_headers_are_cut_off_with_408_and_idle_connections_closed() {
    let server = start_with(
        16 << 20,
        Timeouts {
            headers: Duration::from_secs(1),
            body_grace: Duration::from_secs(10),
        },
    );
    let addr = server.addr();
    let started = Instant::now();
    let mut begun = TcpStream::connect(addr).unwrap();
    begun
        .write_all(b"GET /api/locus HTTP/1.1\r\nHost: test\r\nX-Slow: a")
        .unwrap();
    let mut idle = TcpStream::connect(addr).unwrap();
    let (status, head, body) = read_answer(&mut begun);
    assert_eq!(status, 408, "{head}");
    assert_eq!(
        json(&body)["error"],
        "the request's headers did not arrive in time"
    );
    let mut nothing = Vec::new();
    let _ = idle.read_to_end(&mut nothing);
    assert!(nothing.is_empty(), "{}", String::from_utf8_lossy(&nothing));
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "{:?}",
        started.elapsed()
    );
    server.stop();
}

#[test]
fn a_huge_header_is_refused_with_431_without_being_read() {
    let server = start(16 << 20);
    let mut stream = TcpStream::connect(server.addr()).unwrap();
    stream
        .set_write_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let started = Instant::now();
    stream
        .write_all(b"GET /api/locus HTTP/1.1\r\nHost: test\r\nX-Huge: ")
        .unwrap();
    // A 400 MB header line, sent until the server stops reading it.
    let chunk = vec![b'a'; 1 << 20];
    let mut sent = 0usize;
    while sent < 400 << 20 && stream.write_all(&chunk).is_ok() {
        sent += chunk.len();
    }
    let (status, head, _) = read_answer(&mut stream);
    assert_eq!(status, 431, "{head}");
    assert!(
        sent < 64 << 20,
        "the server read {} MB of headers",
        sent >> 20
    );
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "{:?}",
        started.elapsed()
    );
    // Still serving.
    let (status, _) = request(server.addr(), "GET", "/api/locus", None);
    assert_eq!(status, 200);
    server.stop();
}

#[test]
fn head_answers_like_get_without_a_body() {
    let server = start(16 << 20);
    for path in ["/", "/app.js", "/api/locus"] {
        let (status, body) = request(server.addr(), "HEAD", path, None);
        assert_eq!(status, 200, "{path}");
        assert!(body.is_empty(), "{path}");
    }
    let (status, got) = request(server.addr(), "DELETE", "/", None);
    assert_eq!(status, 405);
    assert_eq!(json(&got)["error"], "DELETE is not allowed on /");
    server.stop();
}

#[test]
fn a_host_name_is_resolved() {
    let addrs = resolve("localhost", 0).unwrap();
    assert!(addrs.iter().all(|a| a.ip().is_loopback()), "{addrs:?}");
    let server = Server::start(
        Config {
            addrs,
            max_upload_bytes: 1 << 20,
            workers: 1,
            timeouts: Timeouts::default(),
        },
        shipped_engine(&DataDir::new(None)).unwrap(),
    )
    .unwrap();
    assert!(server.addr().ip().is_loopback());
    let (status, body) = request(server.addr(), "GET", "/", None);
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&body).contains("<html"));
    server.stop();
    let error = resolve("no-such-host.invalid", 0).unwrap_err();
    assert!(
        format!("{error:#}").starts_with("cannot resolve the host 'no-such-host.invalid'"),
        "{error:#}"
    );
}

#[test]
fn a_job_keeps_its_report_and_corners_take_a_named_chart_only() {
    let server = start(16 << 20);
    let addr = server.addr();
    // The corners and the chart the detection finds, given by hand.
    let found = expected("p.jpg");
    let corners: Vec<String> = found["photo"]["corners"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|c| {
            c.as_array()
                .unwrap()
                .iter()
                .map(|v| format!("{:.2}", v.as_f64().unwrap()))
        })
        .collect();
    let body = form(&[
        ("photo", Some("p.jpg"), EXAMPLE),
        ("corners", None, corners.join(",").as_bytes()),
        ("chart", None, b"colorchecker_sg96"),
    ]);
    let (status, got) = request(addr, "POST", "/api/jobs", Some(body.as_slice()));
    assert_eq!(status, 202);
    let id = json(&got)["id"].as_str().unwrap().to_string();
    let result = loop {
        let (_, got) = request(addr, "GET", &format!("/api/jobs/{id}"), None);
        let got = json(&got);
        if got["state"] == "done" {
            break got["result"].clone();
        }
        assert_ne!(got["state"], "failed", "{got}");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(result["photo"]["method"], "corners");
    assert_eq!(result["photo"]["chart"], found["photo"]["chart"]);
    assert_eq!(
        result["presentation"]["summary"],
        found["presentation"]["summary"]
    );
    let (status, report) = request(addr, "GET", &format!("/api/jobs/{id}/report"), None);
    assert_eq!(status, 200);
    let report = String::from_utf8(report).unwrap();
    assert!(report.contains("<h1>The light in p.jpg</h1>"), "no title");
    assert_eq!(report.matches("<polyline class=\"spd\"").count(), 1);
    assert!(report.contains("src=\"data:image/jpeg;base64,"));
    let (status, got) = request(addr, "GET", "/api/jobs/999999/report", None);
    assert_eq!(status, 404);
    assert_eq!(json(&got)["code"], "not_found");
    // A chart is a name, never a path.
    let body = form(&[
        ("photo", Some("p.jpg"), EXAMPLE),
        ("chart", None, b"/etc/passwd"),
    ]);
    let (status, got) = request(addr, "POST", "/api/jobs", Some(body.as_slice()));
    assert_eq!(status, 400);
    let error = json(&got)["error"].as_str().unwrap().to_string();
    assert_eq!(
        error,
        "unknown chart '/etc/passwd'; valid: colorchecker24, colorchecker_sg96"
    );
    server.stop();
}
