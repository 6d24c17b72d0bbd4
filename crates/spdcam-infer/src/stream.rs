//! Feature rows in, SPD estimates out, a block of rows at a time: estimating any number of
//! rows in bounded memory, in time linear in the rows, on every core.
//!
//! ```text
//! features CSV ─► FeatureStream (blocks of lines parsed in parallel) ─► the Estimator's
//!     RowStream (Model::estimate_rows) ─► GridMap (model grid → output grid) ─► long CSV
//!     rows (formatted in parallel) ─► file
//! ```

use crate::error::{InferError, Result};
use rayon::prelude::*;
use spdcam_core::spectral::{clamp_undershoot, Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_core::{feature_check, limits};
use std::io::{Read, Write};
use std::path::Path;

/// Bytes of the features file read and parsed at a time.
const BLOCK_BYTES: usize = 8 << 20;
/// Lines one parallel task parses.
const LINES_PER_TASK: usize = 512;

/// The rows of a features CSV (a header naming the columns, then one numeric row per
/// estimate), read a block at a time. Lines are split and parsed in parallel; a line with a
/// quoted field goes through the CSV parser. Blank lines are skipped.
pub struct FeatureStream {
    input: Box<dyn Read + Send>,
    source: String,
    names: Vec<String>,
    /// Bytes read but not yet parsed (the start of an unfinished line).
    pending: Vec<u8>,
    /// The line number of the first pending byte.
    line: usize,
    finished: bool,
}

/// One block of feature rows and where they were in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureBlock {
    /// Values, row-major, in the file's column order.
    pub values: Vec<f64>,
    /// Number of rows.
    pub rows: usize,
    /// The number (0-based) of the block's first row among all rows of the file.
    pub first_row: usize,
}

impl FeatureStream {
    /// Opens a features CSV and reads its header.
    pub fn open(path: &Path) -> Result<FeatureStream> {
        let file = std::fs::File::open(path)
            .map_err(|e| InferError::invalid(format!("reading {}: {e}", path.display())))?;
        FeatureStream::new(Box::new(file), &path.display().to_string())
    }

    /// A stream over `input`, named `source` in errors; reads the header, refusing one of
    /// more than [`limits::CSV_COLUMNS`] columns as soon as it has read that many.
    pub fn new(input: Box<dyn Read + Send>, source: &str) -> Result<FeatureStream> {
        let mut stream = FeatureStream {
            input,
            source: source.to_string(),
            names: Vec::new(),
            pending: Vec::new(),
            line: 1,
            finished: false,
        };
        let max_columns = limits::CSV_COLUMNS.value()?;
        // Bytes of the header looked at so far, and the separators among them.
        let (mut scanned, mut separators) = (0, 0u64);
        let header = loop {
            let fresh = &stream.pending[scanned..];
            if let Some(end) = fresh.iter().position(|&b| b == b'\n') {
                let header: Vec<u8> = stream.pending.drain(..=scanned + end).collect();
                break header;
            }
            if stream.finished {
                break std::mem::take(&mut stream.pending);
            }
            separators += fresh.iter().filter(|&&b| b == b',').count() as u64;
            scanned = stream.pending.len();
            if separators >= max_columns {
                return Err(limits::CSV_COLUMNS
                    .exceeded(&format!("{source}, line 1"))
                    .into());
            }
            stream.check_line_length(1)?;
            stream.fill()?;
        };
        stream.line = 2;
        let names = parse_quoted(&header).map_err(|e| stream.error(1, e))?;
        limits::check_csv_columns(names.len(), source)?;
        if names.iter().all(String::is_empty) {
            return Err(InferError::invalid(format!(
                "{}: the file is empty",
                stream.source
            )));
        }
        stream.names = names;
        Ok(stream)
    }

    /// The column names of the header.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Reads up to [`BLOCK_BYTES`] more bytes into `pending` (into its spare capacity,
    /// without first zeroing it).
    fn fill(&mut self) -> Result<()> {
        self.pending.reserve(BLOCK_BYTES);
        let read = (&mut self.input)
            .take(BLOCK_BYTES as u64)
            .read_to_end(&mut self.pending)
            .map_err(|e| InferError::invalid(format!("reading {}: {e}", self.source)))?;
        if read < BLOCK_BYTES {
            self.finished = true;
        }
        Ok(())
    }

    /// Refuses a line (`line`, still unfinished in `pending`) longer than
    /// [`limits::TEXT_FILE_BYTES`]: a stream without line breaks (`/dev/zero`) must not
    /// fill the memory.
    fn check_line_length(&self, line: usize) -> Result<()> {
        if self.pending.len() as u64 > limits::TEXT_FILE_BYTES.value()? {
            return Err(limits::TEXT_FILE_BYTES
                .exceeded(&format!("{} line {line} (one line)", self.source))
                .into());
        }
        Ok(())
    }

    fn error(&self, line: usize, message: String) -> InferError {
        InferError::invalid(format!("{} line {line}: {message}", self.source))
    }

    /// The next block of rows (`first_row` counts the rows before it), or `None` after the
    /// last. Errors name the line and column of a bad value.
    pub fn next_block(&mut self, first_row: usize) -> Result<Option<FeatureBlock>> {
        loop {
            if self.pending.is_empty() && self.finished {
                return Ok(None);
            }
            let cut = if self.finished {
                self.pending.len()
            } else {
                self.fill()?;
                match self.pending.iter().rposition(|&b| b == b'\n') {
                    Some(end) => end + 1,
                    None if self.finished => self.pending.len(),
                    // One line longer than a block: read on.
                    None => {
                        self.check_line_length(self.line)?;
                        continue;
                    }
                }
            };
            // The block's whole lines; the start of an unfinished one stays pending.
            let rest = self.pending.split_off(cut);
            let text = std::mem::replace(&mut self.pending, rest);
            let first_line = self.line;
            let lines: Vec<&[u8]> = text
                .strip_suffix(b"\n")
                .unwrap_or(&text)
                .split(|&b| b == b'\n')
                .collect();
            self.line += lines.len();
            let (names, source) = (&self.names, &self.source);
            let width = names.len();
            let parsed = lines
                .par_chunks(LINES_PER_TASK)
                .enumerate()
                .map(|(task, chunk)| {
                    let mut values = Vec::with_capacity(chunk.len() * width);
                    for (k, line) in chunk.iter().enumerate() {
                        let number = first_line + task * LINES_PER_TASK + k;
                        parse_row(line, names, &mut values).map_err(|e| {
                            InferError::invalid(format!("{source} line {number}: {e}"))
                        })?;
                    }
                    Ok(values)
                })
                .collect::<Result<Vec<Vec<f64>>>>()?;
            let values: Vec<f64> = parsed.concat();
            let rows = values.len() / width.max(1);
            if rows > 0 {
                return Ok(Some(FeatureBlock {
                    values,
                    rows,
                    first_row,
                }));
            }
        }
    }
}

/// Fields of one CSV line, through the CSV parser (quotes, escaped quotes), trimmed.
fn parse_quoted(line: &[u8]) -> std::result::Result<Vec<String>, String> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(line);
    let mut record = csv::StringRecord::new();
    match reader.read_record(&mut record) {
        Ok(_) => Ok(record.iter().map(str::to_string).collect()),
        Err(e) => Err(e.to_string()),
    }
}

/// Appends the values of one line to `out`; a blank line (or one of empty fields) adds none.
fn parse_row(line: &[u8], names: &[String], out: &mut Vec<f64>) -> std::result::Result<(), String> {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let start = out.len();
    if parse_plain_row(line, names.len(), out) {
        return Ok(());
    }
    out.truncate(start);
    let fields: Vec<String>;
    let cells: Vec<&str> = if line.contains(&b'"') {
        fields = parse_quoted(line)?;
        fields.iter().map(String::as_str).collect()
    } else {
        let text = std::str::from_utf8(line).map_err(|_| "the line is not UTF-8".to_string())?;
        text.split(',').map(str::trim).collect()
    };
    if cells.iter().all(|c| c.is_empty()) {
        return Ok(());
    }
    if cells.len() != names.len() {
        return Err(format!(
            "{} values, the header names {} columns",
            cells.len(),
            names.len()
        ));
    }
    for (cell, name) in cells.iter().zip(names) {
        let v: f64 = cell
            .parse()
            .map_err(|_| format!("column {name}: '{cell}' is not a number"))?;
        if !v.is_finite() {
            return Err(format!("column {name}: {v} is not a finite number"));
        }
        out.push(v);
    }
    Ok(())
}

/// Appends the `width` values of a line of plain finite numbers (spaces or tabs around them,
/// no quotes) to `out`, read straight from its bytes: the common line, without splitting it
/// into fields first. `false` for any other line, which [`parse_row`]'s general path then
/// reads or names what is wrong with; both read a number to the nearest `f64`
/// (Eisel–Lemire, with a fallback for the hard cases: Lemire 2021, "Number parsing at a
/// gigabyte per second").
fn parse_plain_row(line: &[u8], width: usize, out: &mut Vec<f64>) -> bool {
    let skip_blanks = |bytes: &[u8]| -> usize {
        bytes
            .iter()
            .position(|&b| b != b' ' && b != b'\t')
            .unwrap_or(bytes.len())
    };
    let mut at = 0;
    for column in 0..width {
        at += skip_blanks(&line[at..]);
        let Ok((value, used)) = fast_float2::parse_partial::<f64, _>(&line[at..]) else {
            return false;
        };
        if used == 0 || !value.is_finite() {
            return false;
        }
        out.push(value);
        at += used;
        at += skip_blanks(&line[at..]);
        match line.get(at) {
            Some(b',') if column + 1 < width => at += 1,
            None if column + 1 == width => return true,
            _ => return false,
        }
    }
    false
}

/// SPDs of the model's grid taken to another grid (within it) by the interpolation
/// [`SpectralSet::resample`] uses, precomputed as a matrix: resampling is linear in the
/// values, so row `j` of the matrix is the resampled unit spectrum `eⱼ`; as in
/// [`SpectralSet::resample`], a non-negative SPD's undershoots are then set to zero.
#[derive(Debug, Clone, PartialEq)]
pub struct GridMap {
    from: usize,
    to: usize,
    /// `None` when the grids are the same.
    matrix: Option<Vec<f64>>,
}

impl GridMap {
    /// The map from the model's grid `from` to `to`, which must lie within it.
    pub fn new(from: &Grid, to: &Grid) -> Result<GridMap> {
        if to.start_nm < from.start_nm - 1e-9 || to.end_nm() > from.end_nm() + 1e-9 {
            return Err(InferError::invalid(format!(
                "the range {}: the model estimates {} nm only",
                to.label(),
                from.label()
            )));
        }
        if from == to {
            return Ok(GridMap {
                from: from.count,
                to: to.count,
                matrix: None,
            });
        }
        let units: Vec<Vec<f64>> = (0..from.count)
            .map(|j| {
                (0..from.count)
                    .map(|i| f64::from(u8::from(i == j)))
                    .collect()
            })
            .collect();
        let names = (0..from.count).map(|j| format!("e{j}")).collect();
        let set = SpectralSet::on_grid(from, names, units)?;
        let (resampled, _) =
            set.resample_unclamped(to, Interpolation::Auto, Extrapolation::HoldEdge)?;
        let matrix = (0..from.count)
            .flat_map(|j| resampled.item(j).to_vec())
            .collect();
        Ok(GridMap {
            from: from.count,
            to: to.count,
            matrix: Some(matrix),
        })
    }

    /// Rows of SPDs on the model's grid (row-major) on the output grid.
    pub fn apply(&self, spds: Vec<f64>) -> Vec<f64> {
        let Some(m) = &self.matrix else {
            return spds;
        };
        let mut out = vec![0.0; spds.len() / self.from * self.to];
        out.par_chunks_mut(self.to)
            .zip(spds.par_chunks(self.from))
            .for_each(|(o, s)| {
                for (j, &v) in s.iter().enumerate() {
                    for (o, &w) in o.iter_mut().zip(&m[j * self.to..(j + 1) * self.to]) {
                        *o += v * w;
                    }
                }
                clamp_undershoot(s, o);
            });
        out
    }
}

/// Refuses feature rows (row-major, named `names`) that say nothing about the light:
/// values outside the encoding's range, a black chart, a chart without colour (see
/// [`feature_check`]). The first bad row is named (`first_row` counts the rows before these,
/// 1-based in the message) when `name_rows`. Rows on 0–1 are told from rows on 0–255 by
/// their largest value.
pub fn check_feature_rows(
    values: &[f64],
    names: &[String],
    source: &str,
    first_row: usize,
    name_rows: bool,
) -> Result<()> {
    let width = names.len().max(1);
    let bad = values
        .par_chunks(width)
        .enumerate()
        .find_map_first(|(i, row)| {
            let scale = if row.iter().any(|&v| v > 1.0) {
                255.0
            } else {
                1.0
            };
            feature_check::check_feature_row(row, names, scale)
                .err()
                .map(|e| (i, e))
        });
    match bad {
        None => Ok(()),
        Some((i, e)) if name_rows => Err(InferError::invalid(format!(
            "{source} row {}: {e}",
            first_row + i + 1
        ))),
        Some((_, e)) => Err(InferError::invalid(format!("{source}: {e}"))),
    }
}

/// The name of feature row `row` (0-based): `estimate_1`, `estimate_2`, ….
pub fn row_name(row: usize) -> String {
    format!("estimate_{}", row + 1)
}

/// How many SPDs one estimate file lays out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `wavelength_nm` then one column per estimate (the spectral CSV of colour-science):
    /// every estimate is held until the end.
    Wide,
    /// One row per estimate: `name`, then one column per wavelength; written as it comes.
    Long,
}

/// Estimates up to this many rows are laid out wide unless told otherwise; more, long.
pub const WIDE_LAYOUT_MAX_ROWS: usize = 256;

/// The header of the long layout: `name,400,405,…`.
pub fn long_header(grid: &Grid) -> String {
    let mut line = String::from("name");
    for w in grid.wavelengths() {
        line.push(',');
        line.push_str(&format!("{w}"));
    }
    line.push('\n');
    line
}

/// Rows of the long layout for SPDs (row-major on a grid of `width` values) whose first is
/// row `first_row`, formatted in parallel: `estimate_N,v1,v2,…` (shortest round-trip
/// decimals, −0 as 0, as the wide layout writes them).
pub fn long_rows(spds: &[f64], width: usize, first_row: usize) -> Vec<u8> {
    let chunks: Vec<Vec<u8>> = spds
        .par_chunks(width * LINES_PER_TASK)
        .enumerate()
        .map(|(task, chunk)| {
            let mut out = Vec::with_capacity(chunk.len() * 20);
            let mut decimals = zmij::Buffer::new();
            for (k, spd) in chunk.chunks_exact(width).enumerate() {
                let _ = write!(out, "{}", row_name(first_row + task * LINES_PER_TASK + k));
                for &v in spd {
                    out.push(b',');
                    push_decimal(&mut out, &mut decimals, v);
                }
                out.push(b'\n');
            }
            out
        })
        .collect();
    chunks.concat()
}

/// Appends `v` as `format!("{v}")` writes it: the shortest decimals that read back as `v`,
/// never an exponent, −0 as 0 as the wide layout writes it. The digits come from Schubfach
/// (Giulietti 2020, "The Schubfach way to render doubles"), which picks the same shortest,
/// nearest decimals as std at a fraction of the cost; where two are equally near (an exact
/// tie, as for 1690060720831323.25) it takes the even one and std the upper, both reading
/// back as `v`. A value whose Schubfach text has an exponent is written by std.
fn push_decimal(out: &mut Vec<u8>, decimals: &mut zmij::Buffer, v: f64) {
    if v == 0.0 {
        out.push(b'0');
        return;
    }
    if v.is_finite() {
        let text = decimals.format_finite(v);
        if !text.contains('e') {
            out.extend_from_slice(text.strip_suffix(".0").unwrap_or(text).as_bytes());
            return;
        }
    }
    let _ = write!(out, "{v}");
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream(text: &str) -> FeatureStream {
        FeatureStream::new(
            Box::new(std::io::Cursor::new(text.as_bytes().to_vec())),
            "f.csv",
        )
        .unwrap()
    }

    #[test]
    fn blocks_hold_every_row_and_errors_name_the_line() {
        let mut text = String::from("a,\"b\", c\r\n");
        for i in 0..3000usize {
            if i.is_multiple_of(700) {
                text.push('\n');
            }
            text.push_str(&format!("{i}, {}.5,\"{}\"\r\n", i * 2, -(i as i64)));
        }
        let mut s = stream(&text);
        assert_eq!(s.names(), ["a", "b", "c"]);
        let block = s.next_block(0).unwrap().unwrap();
        assert_eq!(block.rows, 3000);
        assert_eq!(&block.values[3 * 2999..], [2999.0, 5998.5, -2999.0]);
        assert!(s.next_block(3000).unwrap().is_none());

        let e = stream("a,b\n1,2\n3,x\n")
            .next_block(0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("f.csv line 3: column b: 'x' is not a number"),
            "{e}"
        );
        let e = stream("a,b\n1,2\n\n3\n")
            .next_block(0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 4: 1 values, the header names 2 columns"),
            "{e}"
        );
        let e = stream("a,b\n1,inf\n")
            .next_block(0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a finite number"), "{e}");
        assert!(FeatureStream::new(Box::new(std::io::empty()), "e.csv").is_err());
    }

    #[test]
    fn plain_lines_read_as_the_general_path_reads_them() {
        let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let general = |line: &str| -> std::result::Result<Vec<f64>, String> {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 3 {
                return Err("width".into());
            }
            fields
                .iter()
                .map(|f| f.parse::<f64>().map_err(|e| e.to_string()))
                .filter(|v| !matches!(v, Ok(x) if !x.is_finite()))
                .collect::<std::result::Result<Vec<f64>, String>>()
                .and_then(|v| {
                    if v.len() == 3 {
                        Ok(v)
                    } else {
                        Err("inf".into())
                    }
                })
        };
        for line in [
            "1,2,3",
            " 1.5 ,\t-2.25e-3, +7 ",
            "0.1,0.2,0.30000000000000004",
            "1.,.5,1e308",
            "2.2250738585072014e-308,4.9e-324,123456789012345678901234567890",
            "1e,2,3",
            "1,2",
            "1,2,3,",
            "1,,3",
            "1,2,3x",
            "1 2,3,4",
            "inf,1,2",
            "nan,1,2",
            "1e400,1,2",
            "0x10,1,2",
            "1_0,1,2",
            "\u{a0}1,2,3",
        ] {
            let mut fast = Vec::new();
            let read = parse_plain_row(line.as_bytes(), 3, &mut fast);
            match general(line) {
                Ok(values) => {
                    // Only a line with other blanks than spaces and tabs is left to the
                    // general path.
                    assert!(
                        read || line.contains('\u{a0}'),
                        "{line}: left to the general path"
                    );
                    let fast = if read { fast } else { values.clone() };
                    assert_eq!(
                        fast.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        "{line}"
                    );
                }
                Err(_) => assert!(!read, "{line}: read by the plain path only"),
            }
            // Whichever path reads it, the row is the general reading or its error.
            let mut out = Vec::new();
            match (parse_row(line.as_bytes(), &names, &mut out), general(line)) {
                (Ok(()), Ok(values)) => assert_eq!(out, values, "{line}"),
                (Err(_), Err(_)) => {}
                (got, want) => panic!("{line}: {got:?} against {want:?}"),
            }
        }
        // Shortest decimals of many values come back bit for bit.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let v = f64::from_bits(state >> 2) % 1e6;
            let line = format!("{v},{},{:.2}", v * 1e-9, v);
            let mut fast = Vec::new();
            assert!(parse_plain_row(line.as_bytes(), 3, &mut fast), "{line}");
            assert_eq!(fast, general(&line).unwrap(), "{line}");
        }
    }

    #[test]
    fn rows_longer_than_a_read_and_many_blocks_come_whole() {
        let width = 40_000;
        let names: Vec<String> = (0..width).map(|j| format!("c{j}")).collect();
        let mut text = names.join(",") + "\n";
        for r in 0..300 {
            let row: Vec<String> = (0..width)
                .map(|j| format!("{}", (r * 7 + j) % 1000))
                .collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        let mut s = stream(&text);
        let mut rows = 0;
        let mut blocks = 0;
        while let Some(b) = s.next_block(rows).unwrap() {
            assert_eq!(b.first_row, rows);
            assert_eq!(b.values[0], ((rows * 7) % 1000) as f64);
            rows += b.rows;
            blocks += 1;
        }
        assert_eq!(rows, 300);
        assert!(blocks > 1, "{blocks}");
    }

    #[test]
    fn grid_map_is_the_set_resampling() {
        let from = Grid::ESTIMATION;
        let to = Grid::parse("401-698:3").unwrap();
        let map = GridMap::new(&from, &to).unwrap();
        let spds: Vec<Vec<f64>> = (0..5)
            .map(|r| {
                (0..from.count)
                    .map(|i| ((i * (r + 3)) as f64 * 0.1).sin().abs() + 0.1)
                    .collect()
            })
            .collect();
        let names = (0..5).map(|r| format!("s{r}")).collect();
        let set = SpectralSet::on_grid(&from, names, spds.clone()).unwrap();
        let (expected, _) = set
            .resample(&to, Interpolation::Auto, Extrapolation::HoldEdge)
            .unwrap();
        let got = map.apply(spds.concat());
        for r in 0..5 {
            for (a, b) in got[r * to.count..(r + 1) * to.count]
                .iter()
                .zip(expected.item(r))
            {
                assert!((a - b).abs() < 1e-12, "{a} {b}");
            }
        }
        assert_eq!(
            GridMap::new(&from, &from).unwrap().apply(vec![1.0; 61]),
            vec![1.0; 61]
        );
        assert!(GridMap::new(&from, &Grid::parse("380-700:5").unwrap()).is_err());
    }

    #[test]
    fn decimals_are_written_as_std_writes_them() {
        let mut decimals = zmij::Buffer::new();
        let mut ties = 0;
        let mut check = |v: f64| {
            let mut out = Vec::new();
            push_decimal(&mut out, &mut decimals, v);
            let got = String::from_utf8(out).unwrap();
            let want = if v == 0.0 {
                "0".to_string()
            } else {
                format!("{v}")
            };
            if got != want {
                // Only an exact tie between two shortest decimals may differ: same length,
                // both read back as v.
                assert_eq!(got.len(), want.len(), "{v:e}: {got} against {want}");
                assert_eq!(got.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{got}");
                ties += 1;
            }
        };
        for v in [
            1.0,
            0.5,
            0.1,
            1.0 / 3.0,
            2.0,
            100.0,
            1e15,
            1e16,
            1e17,
            1.5e300,
            1e-5,
            1.2e-6,
            1e-7,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            -0.0,
            -1.25,
            123456.789,
            0.30000000000000004,
        ] {
            check(v);
        }
        // 1690060720831323.25, exactly representable (the spacing there is 0.25): a tie.
        check(1_690_060_720_831_323.0 + 0.25);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut spd_range = Vec::new();
        for i in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            // Any bit pattern, then values of an SPD's range.
            let v = match i % 2 {
                0 => f64::from_bits(state),
                _ => (state >> 11) as f64 / (1u64 << 53) as f64,
            };
            if v.is_finite() {
                check(v);
            }
            if i % 2 == 1 {
                spd_range.push(v);
            }
        }
        assert!(ties < 100, "{ties} ties");
        // Values of an SPD's range (multiples of 2⁻⁵³ have no exact tie): std's text exactly.
        for v in spd_range {
            let mut out = Vec::new();
            push_decimal(&mut out, &mut decimals, v);
            assert_eq!(String::from_utf8(out).unwrap(), format!("{v}"));
        }
    }

    #[test]
    fn long_rows_are_named_and_exact() {
        let text = String::from_utf8(long_rows(&[0.1, 1.0 / 3.0, 2.0, -0.0], 2, 9)).unwrap();
        assert_eq!(
            text,
            "estimate_10,0.1,0.3333333333333333\nestimate_11,2,0\n"
        );
        assert_eq!(
            long_header(&Grid::parse("400-410:5").unwrap()),
            "name,400,405,410\n"
        );
    }
}
