//! The page and its assets, `HEAD` and unknown methods, and a server on a host name.

use super::{json, request, start};
use crate::serve::{resolve, shipped_engine, Config, Server, Timeouts};
use spdcam_core::builtin::DataDir;

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
    // The page's example is the ColorChecker 24 one, judged with nothing beside the program.
    let (status, body) = request(server.addr(), "GET", "/example.jpg", None);
    assert_eq!(status, 200);
    assert_eq!(
        body,
        include_bytes!("../../../../../examples/cc24-led.jpg").as_slice()
    );
    server.stop();
}

#[test]
fn the_charts_to_name_come_from_the_server_with_labels_that_tell_them_apart() {
    let server = start(16 << 20);
    let (status, body) = request(server.addr(), "GET", "/api/charts", None);
    assert_eq!(status, 200);
    let charts = json(&body);
    let listed: Vec<(&str, &str)> = charts
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["name"].as_str().unwrap(), c["label"].as_str().unwrap()))
        .collect();
    assert_eq!(
        listed,
        [
            ("colorchecker24", "ColorChecker 24 (4 × 6 patches)"),
            (
                "colorchecker_sg96",
                "ColorChecker Digital SG (10 × 14 patches)"
            ),
        ]
    );
    // The page holds no list of its own: its script asks, the server names them in its text.
    let (_, page) = request(server.addr(), "GET", "/app.js", None);
    let page = String::from_utf8_lossy(&page);
    assert!(page.contains("api/charts") && !page.contains("ColorChecker"));
    assert!(!include_str!("../page/index.html").contains("ColorChecker"));
    let (_, page) = request(server.addr(), "GET", "/", None);
    let page = String::from_utf8_lossy(&page);
    assert!(
        page.contains("a colour chart (ColorChecker 24 or ColorChecker Digital SG) in the light"),
        "{page}"
    );
    server.stop();
}

#[test]
fn the_page_offers_every_kind_of_light_and_no_other() {
    use spdcam_core::light_families::LightKind;
    let page = include_str!("../page/index.html");
    let offered: Vec<&str> = page
        .split("<option value=\"")
        .skip(1)
        .filter_map(|s| s.split('"').next())
        .collect();
    let kinds: Vec<&str> = LightKind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(offered, kinds);
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
fn unknown_addresses_are_no_such_page_not_an_expired_photo() {
    // Issue 39, item 22: `GET /nope` answered "This is no longer kept on the server".
    let server = start(16 << 20);
    let (status, body) = request(server.addr(), "GET", "/nope", None);
    assert_eq!(status, 404);
    let text = String::from_utf8_lossy(&body);
    assert!(text.contains("no such page"), "{text}");
    assert!(!text.contains("no longer kept"), "{text}");
    for path in ["/api/nope", "/api/jobs/999999", "/api/jobs/abc/report"] {
        let (status, body) = request(server.addr(), "GET", path, None);
        assert_eq!(status, 404, "{path}");
        let got = json(&body);
        assert_eq!(got["code"], "no_such_page", "{path}: {got}");
        assert!(
            !got["message"].as_str().unwrap().contains("no longer kept"),
            "{got}"
        );
    }
    let (_, body) = request(server.addr(), "GET", "/api/nope", None);
    assert_eq!(json(&body)["error"], "no such API: /api/nope");
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
