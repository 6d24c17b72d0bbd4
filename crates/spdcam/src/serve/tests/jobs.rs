//! Jobs: queued, polled until done, their reports kept; corners with a named chart.

use super::{expected, form, json, request, start, EXAMPLE};
use crate::serve::jobs::{Jobs, Progress, Upload};
use crate::serve::shipped_engine;
use spdcam_core::builtin::DataDir;
use std::sync::Arc;
use std::time::Duration;

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
    assert_eq!(json(&got)["code"], "no_such_page");
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

#[test]
fn a_forgotten_job_is_told_from_one_that_never_was() {
    // Issue 39, item 22: every 404 said "no longer kept", even for pages that never were.
    let jobs = Arc::new(Jobs::new(
        shipped_engine(&DataDir::new(None)).unwrap(),
        4,
        1,
    ));
    let worker = {
        let jobs = Arc::clone(&jobs);
        std::thread::spawn(move || jobs.work())
    };
    let upload = || Upload {
        name: "notes.txt".into(),
        bytes: b"not a photo".to_vec(),
        corners: None,
        memory: None,
        chart: None,
        light: Default::default(),
    };
    let first = jobs.submit(upload()).unwrap();
    let second = jobs.submit(upload()).unwrap();
    while !matches!(jobs.progress(second), Some(Progress::Finished(_))) {
        std::thread::sleep(Duration::from_millis(10));
    }
    jobs.stop();
    worker.join().unwrap();
    // Only the newest finished job is kept: the first is forgotten but was given out.
    assert!(jobs.progress(first).is_none());
    assert!(jobs.issued(first) && jobs.issued(second));
    assert!(!jobs.issued(0) && !jobs.issued(second + 1));
}
