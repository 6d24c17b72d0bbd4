//! Reading a `multipart/form-data` body (RFC 7578) held in memory: the named fields and,
//! for file fields, the file name the browser sent (kept as a label, never used as a path).

/// One field of a form.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's name (`photo`, `corners`).
    pub name: String,
    /// The file name the client gave, for file fields.
    pub filename: Option<String>,
    /// The field's content.
    pub data: Vec<u8>,
}

/// The boundary named by a `Content-Type: multipart/form-data; boundary=…` header.
pub fn boundary(content_type: &str) -> Result<String, String> {
    let mut parts = content_type.split(';').map(str::trim);
    let kind = parts.next().unwrap_or("");
    if !kind.eq_ignore_ascii_case("multipart/form-data") {
        return Err(format!(
            "the request must be multipart/form-data with a field 'photo', not '{kind}'"
        ));
    }
    parts
        .filter_map(|p| p.split_once('='))
        .find(|(k, _)| k.trim().eq_ignore_ascii_case("boundary"))
        .map(|(_, v)| v.trim().trim_matches('"').to_string())
        .filter(|b| !b.is_empty() && b.len() <= 200)
        .ok_or_else(|| "the multipart/form-data request names no boundary".to_string())
}

/// The fields of a multipart body delimited by `boundary`.
pub fn parse(body: &[u8], boundary: &str) -> Result<Vec<Field>, String> {
    let delimiter = format!("--{boundary}");
    let next_part = format!("\r\n--{boundary}");
    let Some(start) = find(body, delimiter.as_bytes(), 0) else {
        return Err("the multipart body holds no part".into());
    };
    let mut at = start + delimiter.len();
    let mut fields = Vec::new();
    loop {
        if body[at..].starts_with(b"--") {
            return Ok(fields);
        }
        if !body[at..].starts_with(b"\r\n") {
            return Err("the multipart body is malformed (no line break after a boundary)".into());
        }
        at += 2;
        let Some(head_end) = find(body, b"\r\n\r\n", at) else {
            return Err("a multipart part has no end of its headers".into());
        };
        let head = String::from_utf8_lossy(&body[at..head_end]);
        let data_start = head_end + 4;
        let Some(data_end) = find(body, next_part.as_bytes(), data_start) else {
            return Err("the multipart body ends before its closing boundary".into());
        };
        let (name, filename) = disposition(&head)?;
        fields.push(Field {
            name,
            filename,
            data: body[data_start..data_end].to_vec(),
        });
        at = data_end + next_part.len();
    }
}

/// The `name` and `filename` of a part's `Content-Disposition: form-data` header.
fn disposition(head: &str) -> Result<(String, Option<String>), String> {
    let line = head
        .lines()
        .find(|l| {
            l.split(':')
                .next()
                .is_some_and(|k| k.trim().eq_ignore_ascii_case("content-disposition"))
        })
        .ok_or("a multipart part has no Content-Disposition header")?;
    let value = line.split_once(':').map_or("", |(_, v)| v);
    let param = |key: &str| {
        value
            .split(';')
            .filter_map(|p| p.trim().split_once('='))
            .find(|(k, _)| k.trim().eq_ignore_ascii_case(key))
            .map(|(_, v)| v.trim().trim_matches('"').to_string())
    };
    let name = param("name").ok_or("a multipart part has no field name")?;
    Ok((name, param("filename")))
}

/// The first position of `needle` in `haystack` at or after `from`.
fn find(haystack: &[u8], needle: &[u8], from: usize) -> Option<usize> {
    if from > haystack.len() {
        return None;
    }
    haystack[from..]
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|p| p + from)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_and_file_names_are_read() {
        let body = b"--XyZ\r\nContent-Disposition: form-data; name=\"corners\"\r\n\r\n1,2,3,4,5,6,7,8\r\n\
--XyZ\r\nContent-Disposition: form-data; name=\"photo\"; filename=\"a b.jpg\"\r\nContent-Type: image/jpeg\r\n\r\n\
\xff\xd8\r\n--X\r\n\xff\xd9\r\n--XyZ--\r\n";
        let fields = parse(body, "XyZ").unwrap();
        assert_eq!(fields.len(), 2);
        assert_eq!(fields[0].name, "corners");
        assert_eq!(fields[0].filename, None);
        assert_eq!(fields[0].data, b"1,2,3,4,5,6,7,8");
        assert_eq!(fields[1].name, "photo");
        assert_eq!(fields[1].filename.as_deref(), Some("a b.jpg"));
        // A line that starts like the boundary but is not it stays in the data.
        assert_eq!(fields[1].data, b"\xff\xd8\r\n--X\r\n\xff\xd9");
    }

    #[test]
    fn boundaries_and_broken_bodies_give_messages() {
        assert_eq!(
            boundary("multipart/form-data; boundary=\"ab\"").unwrap(),
            "ab"
        );
        assert!(boundary("application/json")
            .unwrap_err()
            .contains("multipart"));
        assert!(boundary("multipart/form-data").is_err());
        assert!(parse(b"no parts here", "b").is_err());
        assert!(parse(
            b"--b\r\nContent-Disposition: form-data; name=\"x\"\r\n\r\nabc",
            "b"
        )
        .unwrap_err()
        .contains("closing boundary"));
    }
}
