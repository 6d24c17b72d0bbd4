//! A soak test of `spdcam serve` (the built binary, on loopback, about a minute): 16 clients
//! that send an upload's body too slowly and 16 that send their headers too slowly, each
//! reconnecting when cut off, while 20 ordinary uploads of the example photo arrive. Every
//! upload must be answered with the CLI's estimate within 5 s, every slow client cut off
//! with 408, and the server's peak memory must stay under 500 MB.

use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const EXAMPLE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/sg-telelumen.jpg"
);
const BOUNDARY: &str = "spdcam-soak-boundary";
/// Slow clients start no new connection after this.
const SLOW_UNTIL: Duration = Duration::from_secs(42);
/// Ordinary uploads, one every `UPLOAD_EVERY` from the start.
const UPLOADS: usize = 20;
const UPLOAD_EVERY: Duration = Duration::from_millis(2100);
/// The longest an ordinary upload may wait for its answer.
const ANSWER_WITHIN: Duration = Duration::from_secs(5);
/// The server's default limits: headers within 10 s, a body's first bytes within 10 s.
const CUT_WITHIN: Duration = Duration::from_secs(20);
/// One slow connection's end: whether it was a slow body, the status it got, and when.
type Cut = (bool, Option<u16>, Duration);

/// `spdcam serve` running, killed when dropped.
struct Serving {
    child: Child,
    addr: SocketAddr,
}

impl Drop for Serving {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `spdcam serve --port 0 --host HOST` and reads the address it prints.
fn serve(host: &str) -> Serving {
    serve_with(host, &[])
}

/// As [`serve`], with environment variables set.
fn serve_with(host: &str, env: &[(&str, &str)]) -> Serving {
    let mut child = Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(["serve", "--port", "0", "--host", host])
        .env_remove("SPDCAM_DATA")
        .envs(env.iter().copied())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spdcam serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    // "spdcam serves http://127.0.0.1:PORT/ (Ctrl-C stops it)"
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap_or_else(|| panic!("no URL in {line:?}"));
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_socket_addrs()
        .unwrap()
        .next()
        .unwrap();
    Serving { child, addr }
}

/// Reads what the server sends until it closes the connection, calling `idle` whenever
/// nothing came for the read time-out; the status of the answer, if one came.
fn answer(stream: &mut TcpStream, mut idle: impl FnMut(&mut TcpStream)) -> Option<u16> {
    let mut got = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        match stream.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => got.extend_from_slice(&buf[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                idle(stream)
            }
            Err(_) => break,
        }
    }
    let head = String::from_utf8_lossy(&got);
    head.strip_prefix("HTTP/1.1 ")?.get(..3)?.parse().ok()
}

/// One connection of a slow client: `body` true sends an upload's head and part of its body,
/// false part of a head; `trickle` adds a byte every 3 s, else it stays idle. The answer's
/// status and when it came.
fn slow_connection(addr: SocketAddr, body: bool, trickle: bool) -> (Option<u16>, Duration) {
    let started = Instant::now();
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(3)))
        .unwrap();
    let sent = if body {
        format!(
            "POST /api/estimate HTTP/1.1\r\nHost: soak\r\nContent-Type: multipart/form-data; \
             boundary={BOUNDARY}\r\nContent-Length: 10000000\r\n\r\n--{BOUNDARY}\r\n\
             Content-Disposition: form-data; name=\"photo\"; filename=\"slow.jpg\"\r\n\r\n{}",
            "x".repeat(1000)
        )
    } else {
        "POST /api/estimate HTTP/1.1\r\nHost: soak\r\nContent-Type: multipart/form-data; X".into()
    };
    let _ = stream.write_all(sent.as_bytes());
    let status = answer(&mut stream, |s| {
        if trickle {
            let _ = s.write_all(b"x");
        }
        assert!(
            started.elapsed() < CUT_WITHIN * 2,
            "a slow client is never cut off"
        );
    });
    (status, started.elapsed())
}

/// Uploads the example photo as `name`; the status, the answer and the time it took.
fn upload(addr: SocketAddr, photo: &[u8], name: &str) -> (u16, serde_json::Value, Duration) {
    let started = Instant::now();
    let mut body = format!(
        "--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"{name}\"\r\n\
         Content-Type: image/jpeg\r\n\r\n"
    )
    .into_bytes();
    body.extend_from_slice(photo);
    body.extend_from_slice(format!("\r\n--{BOUNDARY}--\r\n").as_bytes());
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let head = format!(
        "POST /api/estimate HTTP/1.1\r\nHost: soak\r\nConnection: close\r\n\
         Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes()).unwrap();
    stream.write_all(&body).unwrap();
    let mut got = Vec::new();
    stream.read_to_end(&mut got).unwrap();
    let took = started.elapsed();
    let split = got
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP answer");
    let status = String::from_utf8_lossy(&got[9..12]).parse().unwrap();
    let json = serde_json::from_slice(&got[split + 4..]).unwrap_or(serde_json::Value::Null);
    (status, json, took)
}

/// A field of the server's `/proc/PID/status` in kB.
fn proc_kb(pid: u32, field: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

#[test]
#[cfg(target_os = "linux")]
fn slow_clients_never_stop_uploads_and_memory_stays_bounded() {
    let server = serve("127.0.0.1");
    let (addr, pid) = (server.addr, server.child.id());
    let photo = std::fs::read(EXAMPLE).unwrap();
    let cli = Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(["estimate", "--json", EXAMPLE])
        .env_remove("SPDCAM_DATA")
        .output()
        .unwrap();
    assert!(cli.status.success());
    let cli: serde_json::Value = serde_json::from_slice(&cli.stdout).unwrap();
    let want_spd = if cli.is_array() {
        cli[0]["spd"].clone()
    } else {
        cli["spd"].clone()
    };
    assert!(want_spd.is_array());

    let started = Instant::now();
    let cuts: Arc<Mutex<Vec<Cut>>> = Arc::default();
    let peak_rss_kb = Arc::new(AtomicU64::new(0));
    let sampling = Arc::new(AtomicBool::new(true));
    let uploads = std::thread::scope(|s| {
        let slow: Vec<_> = (0..32usize)
            .map(|i| {
                let cuts = Arc::clone(&cuts);
                s.spawn(move || {
                    let (body, trickle) = (i < 16, i.is_multiple_of(2));
                    while started.elapsed() < SLOW_UNTIL {
                        let (status, took) = slow_connection(addr, body, trickle);
                        cuts.lock().unwrap().push((body, status, took));
                    }
                })
            })
            .collect();
        s.spawn({
            let (peak, sampling) = (Arc::clone(&peak_rss_kb), Arc::clone(&sampling));
            move || {
                while sampling.load(Ordering::Relaxed) {
                    peak.fetch_max(proc_kb(pid, "VmRSS:"), Ordering::Relaxed);
                    std::thread::sleep(Duration::from_millis(250));
                }
            }
        });
        let uploads: Vec<_> = (0..UPLOADS)
            .map(|i| {
                std::thread::sleep((UPLOAD_EVERY * i as u32).saturating_sub(started.elapsed()));
                let photo = photo.as_slice();
                s.spawn(move || upload(addr, photo, &format!("soak-{i}.jpg")))
            })
            .collect();
        let uploads: Vec<_> = uploads.into_iter().map(|h| h.join().unwrap()).collect();
        for h in slow {
            h.join().unwrap();
        }
        sampling.store(false, Ordering::Relaxed);
        uploads
    });
    let slowest = uploads.iter().map(|u| u.2).max().unwrap();
    let peak_rss_mb = proc_kb(pid, "VmHWM:").max(peak_rss_kb.load(Ordering::Relaxed)) / 1024;
    let cuts = cuts.lock().unwrap();
    let (bodies, heads): (Vec<&Cut>, Vec<_>) = cuts.iter().partition(|c| c.0);
    let longest_cut = cuts.iter().map(|c| c.2).max().unwrap();
    println!(
        "soak {:.0} s: {} uploads answered, slowest {:.2} s; {} slow bodies and {} slow \
         headers cut off, the longest after {:.1} s; server peak RSS {} MB",
        started.elapsed().as_secs_f64(),
        uploads.len(),
        slowest.as_secs_f64(),
        bodies.len(),
        heads.len(),
        longest_cut.as_secs_f64(),
        peak_rss_mb
    );
    for (i, (status, json, took)) in uploads.iter().enumerate() {
        assert_eq!(*status, 200, "upload {i}: {json}");
        assert_eq!(json["name"], format!("soak-{i}.jpg"));
        assert_eq!(json["spd"], want_spd, "upload {i}");
        assert!(*took < ANSWER_WITHIN, "upload {i} took {took:?}");
    }
    // Every slow client was cut, at least once per connection started.
    assert!(bodies.len() >= 16 && heads.len() >= 16, "{cuts:?}");
    for (body, status, took) in cuts.iter() {
        assert_eq!(*status, Some(408), "slow body {body}: {took:?}");
        assert!(*took < CUT_WITHIN, "slow body {body}: cut after {took:?}");
    }
    assert!(peak_rss_mb < 500, "server peak RSS {peak_rss_mb} MB");
}

#[test]
fn serve_listens_on_a_host_name() {
    let server = serve("localhost");
    assert!(server.addr.ip().is_loopback(), "{}", server.addr);
    let mut stream = TcpStream::connect(server.addr).unwrap();
    stream
        .write_all(b"HEAD / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut got = String::new();
    stream.read_to_string(&mut got).unwrap();
    assert!(got.starts_with("HTTP/1.1 200 OK\r\n"), "{got}");
    assert!(got.ends_with("\r\n\r\n"), "a body after HEAD: {got}");
}

#[test]
fn the_photo_size_limit_of_every_command_caps_uploads_too() {
    let server = serve_with("127.0.0.1", &[("SPDCAM_MAX_PHOTO_BYTES", "100000")]);
    let mut stream = TcpStream::connect(server.addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    // Under the server's own 64 MB default, over the photo limit with the form's overhead.
    let head = format!(
        "POST /api/estimate HTTP/1.1\r\nHost: cap\r\nConnection: close\r\n\
         Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: 300000\r\n\r\n"
    );
    stream.write_all(head.as_bytes()).unwrap();
    let mut got = String::new();
    stream.read_to_string(&mut got).unwrap();
    assert!(got.starts_with("HTTP/1.1 413"), "{got}");
    assert!(got.contains("too_large"), "{got}");
}
