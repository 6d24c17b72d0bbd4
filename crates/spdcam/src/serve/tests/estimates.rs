//! Estimates over HTTP: many at once, equal to the library's, and clear errors for bad
//! uploads.

use super::{expected, form, json, request, start, EXAMPLE};

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
fn the_kind_of_light_named_on_the_page_reaches_the_estimate() {
    let server = start(16 << 20);
    let addr = server.addr();
    let told = form(&[
        ("photo", Some("sg-telelumen.jpg"), EXAMPLE),
        ("light", None, b"luminaire"),
    ]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(told.as_slice()));
    assert_eq!(status, 200);
    let got = json(&got);
    assert_eq!(got["light"], "luminaire", "{got}");
    let plain = expected("sg-telelumen.jpg");
    assert!(plain.get("light").is_none());
    assert_ne!(got["spd"], plain["spd"]);
    // "Don't know" is the estimate without a kind; an unknown kind is refused by name.
    let unknown = form(&[
        ("photo", Some("sg-telelumen.jpg"), EXAMPLE),
        ("light", None, b"unknown"),
    ]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(unknown.as_slice()));
    assert_eq!(status, 200);
    assert_eq!(json(&got)["spd"], plain["spd"]);
    let candle = form(&[
        ("photo", Some("sg-telelumen.jpg"), EXAMPLE),
        ("light", None, b"candle"),
    ]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(candle.as_slice()));
    assert_eq!(status, 400);
    let message = json(&got)["error"].as_str().unwrap().to_string();
    assert!(
        message.contains("'candle' is not a kind of light"),
        "{message}"
    );
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
    assert!(String::from_utf8_lossy(&got).contains("no such page"));
    let (status, got) = request(addr, "GET", "/api/no/such/page", None);
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

/// A PNG of `w × h` pixel noise (a seeded linear congruential generator).
fn noise_png(w: u32, h: u32) -> Vec<u8> {
    let mut state = 41u64;
    let image = image::RgbImage::from_fn(w, h, |_, _| {
        image::Rgb(std::array::from_fn(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 56) as u8
        }))
    });
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

#[test]
fn corners_on_no_chart_are_refused_with_why_in_a_persons_words() {
    // Issue 41: four clicks on a screenshot and "ColorChecker 24" gave a warm white light.
    let server = start(16 << 20);
    let addr = server.addr();
    let png = noise_png(400, 300);
    let body = form(&[
        ("photo", Some("screenshot.png"), png.as_slice()),
        ("corners", None, b"40,30,360,40,350,270,50,260"),
        ("chart", None, b"colorchecker24"),
    ]);
    let (status, got) = request(addr, "POST", "/api/estimate", Some(body.as_slice()));
    let got = json(&got);
    assert_eq!(status, 400, "{got}");
    assert_eq!(got["code"], "not_the_chart", "{got}");
    assert!(got.get("spd").is_none(), "{got}");
    let message = got["message"].as_str().unwrap();
    assert!(
        message.starts_with(
            "These corners do not hold a ColorChecker 24: place them on the chart's four \
             outer corners ("
        ),
        "{message}"
    );
    let error = got["error"].as_str().unwrap();
    assert!(
        error.contains("screenshot.png") && !error.contains("--"),
        "{error}"
    );
    server.stop();
}
