//! The front ends agree: `spdcam estimate --json` and the web app's `POST /api/estimate`
//! give the same estimate of the same photo (SPD, verdict, bands, every number), and the
//! photo's feature row estimated by `spdcam estimate --features` gives its SPD and verdict.
//! (The Python package is compared with the command line in python/tests.)

mod common;

use common::{ok, s, scratch};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

const EXAMPLE: &str = "../../examples/sg-telelumen.jpg";
const BOUNDARY: &str = "spdcam-front-ends-5c1d";

/// `spdcam serve` on a free loopback port, stopped when dropped.
struct Served {
    child: Child,
    addr: String,
}

impl Served {
    fn start() -> Served {
        let mut child = Command::new(env!("CARGO_BIN_EXE_spdcam"))
            .args(["serve", "--port", "0"])
            .env_remove("SPDCAM_DATA")
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spdcam serve starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("its output"))
            .read_line(&mut line)
            .expect("the address line");
        // `spdcam serves http://127.0.0.1:PORT/ (Ctrl-C stops it)`
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .unwrap_or_else(|| panic!("no address in '{line}'"))
            .to_string();
        Served { child, addr }
    }

    /// `POST /api/estimate` of `photo` as a file named `name`: the status and the JSON.
    fn estimate(&self, name: &str, photo: &[u8]) -> (u16, serde_json::Value) {
        let mut body = format!(
            "--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"{name}\"\r\n\
             Content-Type: image/jpeg\r\n\r\n"
        )
        .into_bytes();
        body.extend_from_slice(photo);
        body.extend_from_slice(format!("\r\n--{BOUNDARY}--\r\n").as_bytes());
        let mut stream = TcpStream::connect(&self.addr).expect("the server answers");
        stream
            .set_read_timeout(Some(Duration::from_secs(300)))
            .unwrap();
        let head = format!(
            "POST /api/estimate HTTP/1.1\r\nHost: test\r\nConnection: close\r\n\
             Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {}\r\n\r\n",
            body.len()
        );
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(&body).unwrap();
        let mut answer = Vec::new();
        stream.read_to_end(&mut answer).unwrap();
        let split = answer
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .expect("an HTTP answer");
        let status_line = String::from_utf8_lossy(&answer[..split]);
        let status = status_line.split(' ').nth(1).unwrap().parse().unwrap();
        let mut body = &answer[split + 4..];
        let chunked = status_line
            .to_ascii_lowercase()
            .contains("transfer-encoding: chunked");
        let unchunked;
        if chunked {
            unchunked = dechunk(body);
            body = &unchunked;
        }
        let json = serde_json::from_slice(body).unwrap_or_else(|e| {
            panic!("not JSON ({e}): {}", String::from_utf8_lossy(body));
        });
        (status, json)
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        self.child.kill().ok();
        self.child.wait().ok();
    }
}

/// The body of a chunked HTTP answer.
fn dechunk(mut body: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let end = body.windows(2).position(|w| w == b"\r\n").unwrap();
        let size =
            usize::from_str_radix(std::str::from_utf8(&body[..end]).unwrap().trim(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&body[end + 2..end + 2 + size]);
        body = &body[end + 2 + size + 2..];
    }
}

/// The JSON without the keys that name where the photo came from (the command line's path,
/// the upload's name).
/// The estimate without what only one front end adds: the photo's source (a path for the
/// command line, the upload's name for the web app), the web app's `presentation` (the
/// page's words, documented in docs/web-api.md) and the command line's `truth` (the score
/// against `<photo>.truth.csv` beside the photo, which an upload does not have).
fn without_source(mut v: serde_json::Value) -> serde_json::Value {
    if let Some(photo) = v.get_mut("photo").and_then(|p| p.as_object_mut()) {
        photo.remove("source");
    }
    if let Some(object) = v.as_object_mut() {
        object.remove("presentation");
        object.remove("truth");
    }
    v
}

#[test]
fn the_command_line_and_the_web_app_give_one_estimate() {
    let cli: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", EXAMPLE, "--json"])).unwrap();
    let cli = cli[0].clone();
    let served = Served::start();
    let photo =
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(EXAMPLE)).unwrap();
    let (status, web) = served.estimate("sg-telelumen.jpg", &photo);
    assert_eq!(status, 200, "{web}");
    assert_eq!(web["spd"], cli["spd"]);
    assert_eq!(web["verdict"], cli["verdict"]);
    assert_eq!(web["reasons"], cli["reasons"]);
    assert_eq!(web["band95"], cli["band95"]);
    assert_eq!(web["photo"]["source"], "sg-telelumen.jpg");
    // Every other number too.
    let (web, cli) = (without_source(web), without_source(cli));
    let keys: std::collections::BTreeSet<&String> = web
        .as_object()
        .unwrap()
        .keys()
        .chain(cli.as_object().unwrap().keys())
        .collect();
    let differ: Vec<&&String> = keys.iter().filter(|k| web[k] != cli[k]).collect();
    assert!(
        differ.is_empty(),
        "the web app and the CLI differ in {differ:?}"
    );
}

#[test]
fn the_photos_feature_row_gives_the_photos_spd_and_verdict() {
    let dir = scratch("front-ends-rows");
    let features = dir.join("features.csv");
    let photo: serde_json::Value = serde_json::from_str(&ok(&[
        "estimate",
        EXAMPLE,
        "--json",
        "--features-out",
        &s(&features),
    ]))
    .unwrap();
    // JSON Lines: the features file's one row on one line.
    let rows = ok(&["estimate", "--features", &s(&features), "--json"]);
    let row: serde_json::Value = serde_json::from_str(rows.lines().next().unwrap()).unwrap();
    let (photo, row) = (&photo[0], &row);
    assert_eq!(row["name"], "estimate_1");
    // The features file holds the features rounded to what the CSV writes; the SPD is the
    // photo's to within what that rounding moves (the SG model's ridge member carries a
    // feature's last digit on to about 10⁻⁶ of the peak).
    let (a, b) = (
        photo["spd"].as_array().unwrap(),
        row["spd"].as_array().unwrap(),
    );
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
        assert!((x - y).abs() < 1e-5, "{x} {y}");
    }
    assert_eq!(row["verdict"], photo["verdict"]);
    assert_eq!(row["model"], photo["model"]);
}
