//! Warnings in the words of a person who reads the report or the web page, not of the
//! command line: the library's warnings name command-line options, the debug image and
//! feature indices, which mean nothing there.

/// `text` without command-line words: `(features 1, 2, 4)` dropped, `feature patches 3, 7
/// are` → `some of the chart's patches are`, `feature patches` → `the chart's patches`,
/// `check the debug image` → `check the chart's outline on the photo`, `--corners …` → the
/// chart's corners.
pub fn for_people(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    // `(features …)`: an index list a person cannot use.
    while let Some(i) = rest.find(" (features ") {
        out.push_str(&rest[..i]);
        rest = rest[i..].find(')').map_or("", |j| &rest[i + j + 1..]);
    }
    out.push_str(rest);
    // `feature patches 3, 7 are …`: the list goes, the patches stay.
    if let Some(i) = out.find("feature patches ") {
        let after = &out[i + "feature patches ".len()..];
        if after.starts_with(|c: char| c.is_ascii_digit()) {
            let end = after.find(" are ").unwrap_or(0);
            out = format!("{}some of the chart's patches{}", &out[..i], &after[end..]);
        }
    }
    let out = out
        .replace("feature patches", "of the chart's patches")
        .replace(
            "check the debug image",
            "check the chart's outline on the photo",
        );
    match out.find("--corners") {
        Some(i) => format!(
            "{}its four corners on the photo",
            &out[..i].trim_end_matches("with ")
        ),
        None => out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_for_people_name_no_flags_images_or_indices() {
        let cases = [
            (
                "3 of 24 feature patches are clipped (features 1, 2, 4): the photo is over-exposed",
                "3 of 24 of the chart's patches are clipped: the photo is over-exposed",
            ),
            (
                "feature patches 19, 20 are very dark: their colour is mostly noise",
                "some of the chart's patches are very dark: their colour is mostly noise",
            ),
            (
                "chart placement confidence is only 0.61; check the debug image",
                "chart placement confidence is only 0.61; check the chart's outline on the photo",
            ),
        ];
        for (library, person) in cases {
            let shown = for_people(library);
            assert_eq!(shown, person);
            assert!(!shown.contains("--") && !shown.contains("debug") && !shown.contains("  "));
        }
    }
}
