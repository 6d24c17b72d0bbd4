//! Failed requests in plain words: a message for a person (no command-line words) and a
//! code the page acts on.

/// The message for a person (no command-line words) and a code for the page, of a failed
/// request's `status` and `error`: `no_chart` when the chart was not found and
/// `not_the_chart` when what was found or placed is not the chart (the page then asks for
/// its corners, again), else `bad_photo`, `unknown_chart`, `bad_corners`, `too_large`,
/// `busy`, `not_found` (a job no longer kept), `no_such_page` or `failed`.
pub(super) fn plain_error(status: u16, error: &str) -> (&'static str, String) {
    let (code, message) = if let Some(words) = not_the_chart(error) {
        ("not_the_chart", words)
    } else if error.contains("no chart found") {
        (
            "no_chart",
            "No colour chart was found in this photo. Click its four corners on the photo to \
             show where it is."
                .to_string(),
        )
    } else if error.contains("not an image") || error.contains("decod") {
        (
            "bad_photo",
            "This file is not a photo the page can read: use a JPEG, PNG, TIFF or a camera raw \
             file (DNG, CR2, CR3, NEF, ARW, RAF, …)."
                .to_string(),
        )
    } else if error.contains("no model for chart") {
        let charts: Vec<String> = crate::serve::jobs::charts()
            .iter()
            .map(|c| format!("a {}", c.shown_name()))
            .collect();
        (
            "unknown_chart",
            format!(
                "The chart in this photo is not one spdcam reads: use {}.",
                charts.join(" or ")
            ),
        )
    } else if error.contains("corners") {
        (
            "bad_corners",
            "The four corners could not be used: click the chart's four outer corners.".to_string(),
        )
    } else {
        match status {
            413 => (
                "too_large",
                "This photo is larger than this server accepts; use a smaller file.".to_string(),
            ),
            503 => (
                "busy",
                "The server is busy with other photos; try again in a moment.".to_string(),
            ),
            404 if error.contains("no longer kept") => (
                "not_found",
                "This is no longer kept on the server; add the photo again.".to_string(),
            ),
            404 => (
                "no_such_page",
                "There is no such page or photo on this server; check the address.".to_string(),
            ),
            _ => (
                "failed",
                format!("The photo could not be estimated: {}", without_flags(error)),
            ),
        }
    };
    (code, message)
}

/// The refusal of patches that are not the chart (`spdcam_core::advice::not_the_chart`)
/// for a person: from its first words on, without the photo's name and the command-line
/// clause, as a sentence; where the chart was detected, how to show it on the page.
fn not_the_chart(error: &str) -> Option<String> {
    let (start, detected) = ["these corners do not hold a ", "what was found is not a "]
        .iter()
        .enumerate()
        .find_map(|(k, words)| error.find(words).map(|i| (i, k == 1)))?;
    let words = without_flags(&error[start..]);
    let mut chars = words.chars();
    let first = chars.next()?.to_uppercase().collect::<String>();
    let mut message = format!("{first}{}.", chars.as_str());
    if detected {
        message.push_str(" Click the chart's four outer corners on the photo.");
    }
    Some(message)
}

/// The library's `error` for an HTTP client: command-line options become the form fields
/// that do their job (`--corners` → the `corners` field, `--chart` → the `chart` field),
/// and clauses naming other options or commands go.
pub(super) fn for_http(error: &str) -> String {
    let named = error
        .replace(
            "give its corners with --corners x1,y1,…,x4,y4",
            "give its corners in the form field `corners` (x1,y1,…,x4,y4)",
        )
        .replace("--corners", "the form field `corners`")
        .replace("--chart", "the form field `chart`");
    without_flags(&named)
}

/// `error` without the clauses (split at `;` and parentheses) that name command-line
/// options or commands.
fn without_flags(error: &str) -> String {
    error
        .split(';')
        .map(|part| match part.find('(') {
            Some(i) if part[i..].contains("--") || part[i..].contains("spdcam ") => &part[..i],
            _ => part,
        })
        .filter(|part| !part.contains("--") && !part.contains("spdcam "))
        .map(str::trim)
        .filter(|part| !part.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_for_people_name_no_command_line_words() {
        let cases = [
            (
                400,
                "room.jpg: no chart found (looked for ColorChecker 24); give its corners with --corners x1,y1,…,x4,y4",
                "no_chart",
            ),
            (400, "notes.txt: not an image (unknown format)", "bad_photo"),
            (
                413,
                "the upload is larger than the limit of 64 MB (spdcam serve --max-upload-mb)",
                "too_large",
            ),
            (400, "--corners needs eight numbers x1,y1,x2,y2,x3,y3,x4,y4; got 3", "bad_corners"),
            (503, "too many photos are waiting; try again in a moment", "busy"),
            (500, "the model broke (try spdcam estimate --debug d.png); really", "failed"),
            (404, "the job 3 is no longer kept (only the newest jobs are kept)", "not_found"),
            (404, "no such API: /api/nope", "no_such_page"),
            (
                400,
                "noise.png: these corners do not hold a ColorChecker 24: place them on the \
                 chart's four outer corners (the patches are not flat: they hold detail, not \
                 one colour each)",
                "not_the_chart",
            ),
            (
                400,
                "room.jpg: what was found is not a ColorChecker Digital SG: show where the \
                 chart is by its four outer corners (the patches' colours do not follow the \
                 chart's); give its corners with --corners x1,y1,…,x4,y4",
                "not_the_chart",
            ),
        ];
        for (status, error, want) in cases {
            let (code, message) = plain_error(status, error);
            assert_eq!(code, want, "{error}");
            for word in ["--", "spdcam serve", "spdcam estimate", "corners with"] {
                assert!(!message.contains(word), "{message}");
            }
        }
        let http = for_http(cases[0].1);
        assert!(
            http.contains("form field `corners`") && !http.contains("--"),
            "{http}"
        );
        for (status, error, _) in cases {
            for text in [plain_error(status, error).1, for_http(error)] {
                assert!(!text.contains("  ") && !text.contains("--"), "{text}");
            }
        }
        assert_eq!(
            plain_error(
                500,
                "the model broke (try spdcam estimate --debug d.png); really"
            )
            .1,
            "The photo could not be estimated: the model broke; really"
        );
        assert_eq!(
            plain_error(400, cases[8].1).1,
            "These corners do not hold a ColorChecker 24: place them on the chart's four outer \
             corners (the patches are not flat: they hold detail, not one colour each)."
        );
        let detected = plain_error(400, cases[9].1).1;
        assert!(
            detected.starts_with("What was found is not a ColorChecker Digital SG: ")
                && detected
                    .ends_with("chart's). Click the chart's four outer corners on the photo."),
            "{detected}"
        );
        assert!(for_http(cases[9].1).contains("in the form field `corners` (x1,y1,…,x4,y4)"));
        let (code, unknown) = plain_error(
            422,
            "p.jpg: no model for chart my_chart; the models are for ColorChecker 24",
        );
        assert_eq!(code, "unknown_chart");
        assert_eq!(
            unknown,
            "The chart in this photo is not one spdcam reads: use a ColorChecker 24 or a \
             ColorChecker Digital SG."
        );
    }
}
