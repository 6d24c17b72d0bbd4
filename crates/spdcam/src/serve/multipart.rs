//! Reading an upload form (`multipart/form-data`, RFC 7578) as it streams in, with multer:
//! the `photo` file with the file name the browser sent (kept as a label, never used as a
//! path), the `corners`, `chart` and `light` texts, each under a size limit; other fields are
//! read and dropped.
//!
//! This file depends only on multer, bytes and futures-util, so that the fuzz target
//! `fuzz/fuzz_targets/multipart.rs` compiles it as it is and feeds it what the server would.

use bytes::Bytes;
use futures_util::Stream;
use std::error::Error as StdError;

/// A boxed error of the body stream (a time-out, a size limit, a closed connection).
pub type BodyFailure = Box<dyn StdError + Send + Sync>;

/// What an upload form holds.
#[derive(Debug, Default, PartialEq)]
pub struct Form {
    /// The `photo` field.
    pub photo: Option<Photo>,
    /// The last `corners` field, as text (parsed by the caller).
    pub corners: Option<String>,
    /// The last `chart` field (the chart the corners belong to), as text.
    pub chart: Option<String>,
    /// The last `light` field (the kind of light the person named), as text.
    pub light: Option<String>,
}

/// The `photo` field of a form.
#[derive(Debug, PartialEq)]
pub struct Photo {
    /// The file name the client gave.
    pub filename: Option<String>,
    /// The file's content.
    pub bytes: Vec<u8>,
}

/// The largest fields [`read`] keeps.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// The photo, in bytes.
    pub photo_bytes: usize,
    /// Any other field, in bytes.
    pub field_bytes: usize,
}

/// Why a form was not read.
#[derive(Debug)]
pub enum FormError {
    /// The photo is larger than [`Limits::photo_bytes`].
    PhotoTooLarge,
    /// The form is not one the server reads; the message says why.
    Invalid(String),
    /// The body stream failed (its own error).
    Body(BodyFailure),
}

/// The boundary named by a `Content-Type: multipart/form-data; boundary=…` header.
pub fn boundary(content_type: &str) -> Result<String, String> {
    let kind = content_type.split(';').next().unwrap_or("").trim();
    if !kind.eq_ignore_ascii_case("multipart/form-data") {
        return Err(format!(
            "the request must be multipart/form-data with a field 'photo', not '{kind}'"
        ));
    }
    multer::parse_boundary(content_type)
        .ok()
        .filter(|b| !b.is_empty() && b.len() <= 200)
        .ok_or_else(|| "the multipart/form-data request names no valid boundary".to_string())
}

/// Reads the form of `body`, delimited by `boundary`, stopping at the first field over its
/// limit, the first malformed part or the first error of `body`.
pub async fn read<S, E>(body: S, boundary: &str, limits: Limits) -> Result<Form, FormError>
where
    S: Stream<Item = Result<Bytes, E>> + Send,
    E: Into<BodyFailure>,
{
    let mut multipart = multer::Multipart::new(body, boundary);
    let mut form = Form::default();
    while let Some(mut field) = multipart.next_field().await.map_err(form_error)? {
        let name = field.name().unwrap_or("").to_string();
        let filename = field.file_name().map(str::to_string);
        let limit = if name == "photo" {
            if form.photo.is_some() {
                return Err(FormError::Invalid("one photo per request".into()));
            }
            limits.photo_bytes
        } else {
            limits.field_bytes
        };
        let mut data = Vec::new();
        while let Some(chunk) = field.chunk().await.map_err(form_error)? {
            if data.len() + chunk.len() > limit {
                return Err(if name == "photo" {
                    FormError::PhotoTooLarge
                } else {
                    FormError::Invalid(format!(
                        "the form field '{}' is longer than {} bytes",
                        printable(&name),
                        limit
                    ))
                });
            }
            data.extend_from_slice(&chunk);
        }
        match name.as_str() {
            "photo" => {
                form.photo = Some(Photo {
                    filename,
                    bytes: data,
                })
            }
            "corners" => form.corners = Some(String::from_utf8_lossy(&data).into_owned()),
            "chart" => form.chart = Some(String::from_utf8_lossy(&data).into_owned()),
            "light" => form.light = Some(String::from_utf8_lossy(&data).into_owned()),
            _ => {}
        }
    }
    Ok(form)
}

/// A multer error as a form error: the body stream's own failure passed on, the rest a
/// message that says the body is malformed.
fn form_error(error: multer::Error) -> FormError {
    match error {
        multer::Error::StreamReadFailed(e) => FormError::Body(e),
        e => FormError::Invalid(format!("the multipart body is malformed: {e}")),
    }
}

/// A field name as it may appear in a message: printable, at most 40 characters.
fn printable(name: &str) -> String {
    name.chars().filter(|&c| shown(c)).take(40).collect()
}

/// Whether a character a client sent may be shown to a person: not a control character
/// (C0, DEL, C1), a line or paragraph separator, nor a bidirectional formatting character
/// (Unicode UAX #9: the embeddings and overrides U+202A–U+202E, the isolates U+2066–U+2069,
/// the marks U+200E, U+200F and U+061C), which would reorder the text around it, e.g.
/// make `photo\u{202E}gpj.exe` read as `photoexe.jpg`.
pub(super) fn shown(c: char) -> bool {
    !(c.is_control()
        || matches!(
            c,
            '\u{202A}'..='\u{202E}'
                | '\u{2066}'..='\u{2069}'
                | '\u{200E}'
                | '\u{200F}'
                | '\u{061C}'
                | '\u{2028}'
                | '\u{2029}'
        ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::task::{Context, Poll, Waker};

    const LIMITS: Limits = Limits {
        photo_bytes: 64,
        field_bytes: 32,
    };

    /// Runs `read` over `body` split into chunks of `chunk` bytes (an in-memory stream is
    /// always ready, so one poll finishes it).
    fn parse(body: &[u8], boundary: &str, chunk: usize) -> Result<Form, FormError> {
        let chunks: Vec<Result<Bytes, std::io::Error>> = body
            .chunks(chunk)
            .map(|c| Ok(Bytes::copy_from_slice(c)))
            .collect();
        let future = read(futures_util::stream::iter(chunks), boundary, LIMITS);
        let mut future = std::pin::pin!(future);
        match future
            .as_mut()
            .poll(&mut Context::from_waker(Waker::noop()))
        {
            Poll::Ready(result) => result,
            Poll::Pending => panic!("an in-memory form is read at once"),
        }
    }

    use std::future::Future;

    const FORM: &[u8] = b"--XyZ\r\nContent-Disposition: form-data; name=\"corners\"\r\n\r\n1,2,3,4,5,6,7,8\r\n\
--XyZ\r\nContent-Disposition: form-data; name=\"other\"\r\n\r\nignored\r\n\
--XyZ\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"a b.jpg\"\r\nContent-Type: image/jpeg\r\n\r\n\
\xff\xd8\r\n--X\r\n\xff\xd9\r\n--XyZ--\r\n";

    #[test]
    fn fields_and_file_names_are_read_however_the_body_is_split() {
        for chunk in [1, 2, 7, 64, FORM.len()] {
            let form = parse(FORM, "XyZ", chunk).unwrap();
            assert_eq!(form.corners.as_deref(), Some("1,2,3,4,5,6,7,8"), "{chunk}");
            let photo = form.photo.unwrap();
            assert_eq!(photo.filename.as_deref(), Some("a b.jpg"));
            // A line that starts like the boundary but is not it stays in the data.
            assert_eq!(photo.bytes, b"\xff\xd8\r\n--X\r\n\xff\xd9");
        }
    }

    #[test]
    fn limits_and_broken_bodies_give_errors() {
        let big_photo = [
            &b"--b\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"p\"\r\n\r\n"[..],
            &[7u8; 65],
            b"\r\n--b--\r\n",
        ]
        .concat();
        assert!(matches!(
            parse(&big_photo, "b", 10),
            Err(FormError::PhotoTooLarge)
        ));
        let big_field = [
            &b"--b\r\nContent-Disposition: form-data; name=\"corners\"\r\n\r\n"[..],
            &[b'1'; 33],
            b"\r\n--b--\r\n",
        ]
        .concat();
        match parse(&big_field, "b", 10) {
            Err(FormError::Invalid(m)) => {
                assert_eq!(m, "the form field 'corners' is longer than 32 bytes")
            }
            other => panic!("{other:?}"),
        }
        let two_photos = b"--b\r\nContent-Disposition: form-data; name=\"photo\"\r\n\r\nx\r\n\
--b\r\nContent-Disposition: form-data; name=\"photo\"\r\n\r\ny\r\n--b--\r\n";
        match parse(two_photos, "b", 5) {
            Err(FormError::Invalid(m)) => assert_eq!(m, "one photo per request"),
            other => panic!("{other:?}"),
        }
        for broken in [
            &b"--b\r\nContent-Disposition: form-data; name=\"x\"\r\n\r\nabc"[..],
            b"--garbage",
        ] {
            match parse(broken, "b", 3) {
                Err(FormError::Invalid(m)) => assert!(m.contains("multipart"), "{m}"),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn the_body_streams_own_error_is_passed_on() {
        let chunks: Vec<Result<Bytes, std::io::Error>> = vec![
            Ok(Bytes::from_static(
                b"--b\r\nContent-Disposition: form-data; name=\"photo\"\r\n\r\nab",
            )),
            Err(std::io::Error::other("too slow")),
        ];
        let future = read(futures_util::stream::iter(chunks), "b", LIMITS);
        let mut future = std::pin::pin!(future);
        match future
            .as_mut()
            .poll(&mut Context::from_waker(Waker::noop()))
        {
            Poll::Ready(Err(FormError::Body(e))) => assert_eq!(e.to_string(), "too slow"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn boundaries_are_read_from_the_content_type() {
        assert_eq!(
            boundary("multipart/form-data; boundary=\"ab\"").unwrap(),
            "ab"
        );
        assert_eq!(
            boundary("application/json").unwrap_err(),
            "the request must be multipart/form-data with a field 'photo', not 'application/json'"
        );
        assert!(boundary("multipart/form-data")
            .unwrap_err()
            .contains("boundary"));
    }
}
