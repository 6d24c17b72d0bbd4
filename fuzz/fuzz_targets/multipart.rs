//! An upload's body as the web server reads it: any bytes as a `multipart/form-data` body
//! with a fixed boundary, delivered in chunks of a size the first byte picks (as a
//! connection splits it), through the server's own form reader (`serve/multipart.rs`,
//! compiled here as it is), and any text as the `Content-Type` it takes the boundary from.
//! A form or a clear error, never a panic, a hang or a field over its limit.
#![no_main]

use bytes::Bytes;
use libfuzzer_sys::fuzz_target;
use std::future::Future;
use std::task::{Context, Poll, Waker};

#[path = "../../crates/spdcam/src/serve/multipart.rs"]
#[allow(dead_code)]
mod multipart;

const BOUNDARY: &str = "spdcam-fuzz-boundary";
const LIMITS: multipart::Limits = multipart::Limits {
    photo_bytes: 4096,
    field_bytes: 256,
};

fuzz_target!(|data: &[u8]| {
    let Some((&split, body)) = data.split_first() else {
        return;
    };
    if let Ok(text) = std::str::from_utf8(body) {
        if let Ok(boundary) = multipart::boundary(text) {
            assert!(!boundary.is_empty() && boundary.len() <= 200);
        }
    }
    let chunks: Vec<Result<Bytes, std::io::Error>> = body
        .chunks(usize::from(split) + 1)
        .map(|c| Ok(Bytes::copy_from_slice(c)))
        .collect();
    let form = multipart::read(futures_util::stream::iter(chunks), BOUNDARY, LIMITS);
    let mut form = std::pin::pin!(form);
    // The body is in memory, so the reader never waits: one poll finishes it.
    let Poll::Ready(form) = form.as_mut().poll(&mut Context::from_waker(Waker::noop())) else {
        panic!("the form reader waited on a body held in memory");
    };
    match form {
        Ok(form) => {
            if let Some(photo) = &form.photo {
                assert!(photo.bytes.len() <= LIMITS.photo_bytes);
            }
            if let Some(corners) = &form.corners {
                // Lossy UTF-8 may grow each byte to three.
                assert!(corners.len() <= 3 * LIMITS.field_bytes);
            }
        }
        Err(multipart::FormError::Invalid(message)) => assert!(!message.is_empty()),
        Err(multipart::FormError::PhotoTooLarge) => {}
        Err(multipart::FormError::Body(e)) => panic!("an in-memory body failed: {e}"),
    }
});
