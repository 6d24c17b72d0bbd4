//! The limits on clients: uploads over the size limit, slow uploads, slow and huge headers.

use super::{expected, form, json, read_answer, request, start, start_with, BOUNDARY, EXAMPLE};
use crate::serve::Timeouts;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

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
