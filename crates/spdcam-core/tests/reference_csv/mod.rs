//! Reading the reference CSVs that tools/ exports from independent implementations: one
//! row per light (its name first), one column per number, `#` lines describing the file.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;

/// Rows of a reference CSV by name; an empty cell (a number the reference leaves
/// undefined) is `None`.
pub fn read_optional(path: &Path) -> BTreeMap<String, BTreeMap<String, Option<f64>>> {
    let text = std::fs::read_to_string(path).unwrap();
    let body: String = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    let mut reader = csv::Reader::from_reader(body.as_bytes());
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            let values = header
                .iter()
                .zip(r.iter())
                .skip(1)
                .map(|(k, v)| (k.to_string(), (!v.is_empty()).then(|| v.parse().unwrap())))
                .collect();
            (r[0].to_string(), values)
        })
        .collect()
}

/// Rows of a reference CSV by name, every cell a number.
pub fn read(path: &Path) -> BTreeMap<String, BTreeMap<String, f64>> {
    read_optional(path)
        .into_iter()
        .map(|(name, row)| {
            let row = row
                .into_iter()
                .map(|(k, v)| {
                    let v = v.unwrap_or_else(|| panic!("{}: {name} has no {k}", path.display()));
                    (k, v)
                })
                .collect();
            (name, row)
        })
        .collect()
}
