//! Named spectra sharing one list of wavelengths, and the spectral CSV layout.

use crate::error::{short_number, Error, Result};
use crate::spectral::{Grid, Spd};
use crate::{fsio, limits};
use std::collections::HashSet;
use std::path::Path;

/// A set of named spectra (SPDs, reflectances or sensitivities) sampled at common wavelengths.
///
/// The CSV layout is the one colour-science's `read_sds_from_csv_file` reads: a header row,
/// the first column `wavelength_nm`, then one column per item.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralSet {
    wavelengths: Vec<f64>,
    names: Vec<String>,
    /// `values[item][sample]`.
    values: Vec<Vec<f64>>,
}

impl SpectralSet {
    /// Builds a set, checking that wavelengths are finite and strictly increasing, that every
    /// item has one finite value per wavelength, and that names are unique.
    pub fn new(wavelengths: Vec<f64>, names: Vec<String>, values: Vec<Vec<f64>>) -> Result<Self> {
        if wavelengths.is_empty() {
            return Err(Error::invalid(
                "a spectral set needs at least one wavelength",
            ));
        }
        if let Some(w) = wavelengths.iter().find(|w| !w.is_finite()) {
            return Err(Error::invalid(format!(
                "wavelength {w} is not a finite number"
            )));
        }
        for pair in wavelengths.windows(2) {
            if pair[1] <= pair[0] {
                return Err(Error::invalid(format!(
                    "wavelength {} nm follows {} nm: wavelengths must be strictly increasing",
                    pair[1], pair[0]
                )));
            }
        }
        if names.len() != values.len() {
            return Err(Error::invalid(format!(
                "{} names for {} spectra",
                names.len(),
                values.len()
            )));
        }
        for (name, v) in names.iter().zip(&values) {
            if v.len() != wavelengths.len() {
                return Err(Error::invalid(format!(
                    "spectrum '{name}' has {} values for {} wavelengths",
                    v.len(),
                    wavelengths.len()
                )));
            }
            if v.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(format!(
                    "spectrum '{name}' has a non-finite value"
                )));
            }
        }
        let mut seen = HashSet::with_capacity(names.len());
        if let Some(n) = names.iter().find(|n| !seen.insert(n.as_str())) {
            return Err(Error::invalid(format!("spectrum name '{n}' appears twice")));
        }
        Ok(SpectralSet {
            wavelengths,
            names,
            values,
        })
    }

    /// A set on a regular grid.
    pub fn on_grid(grid: &Grid, names: Vec<String>, values: Vec<Vec<f64>>) -> Result<Self> {
        SpectralSet::new(grid.wavelengths(), names, values)
    }

    /// A set of `spds`, which must all be on one grid, named `names`.
    pub fn from_spds(names: Vec<String>, spds: &[Spd]) -> Result<Self> {
        let Some(first) = spds.first() else {
            return Err(Error::invalid("a spectral set needs at least one spectrum"));
        };
        let grid = *first.grid();
        let values = spds
            .iter()
            .map(|s| s.on(&grid, "a spectral set").map(<[f64]>::to_vec))
            .collect::<Result<Vec<_>>>()?;
        SpectralSet::on_grid(&grid, names, values)
    }

    /// Parses spectral CSV text; `source_name` (a path or built-in name) is used in errors.
    pub fn from_csv_str(text: &str, source_name: &str) -> Result<Self> {
        SpectralSet::parse_csv(text, source_name, false)
    }

    /// [`SpectralSet::from_csv_str`]; with `limited`, refusing more than
    /// [`limits::CSV_COLUMNS`] columns or [`limits::CSV_ROWS`] rows (text from outside; the
    /// built-in tables are not limited).
    fn parse_csv(text: &str, source_name: &str, limited: bool) -> Result<Self> {
        let err = |msg: String| Error::parse(source_name, msg);
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .flexible(true)
            .from_reader(text.as_bytes());
        let mut records = reader.records();
        let header = match records.next() {
            None => return Err(err("the file is empty".into())),
            Some(r) => r.map_err(|e| err(format!("line 1: {e}")))?,
        };
        if limited {
            limits::check_csv_columns(header.len(), source_name)?;
        }
        let first = header.get(0).unwrap_or("");
        if first.parse::<f64>().is_ok() {
            return Err(err(
                "line 1: no header row; the first line must be 'wavelength_nm,<name>,…'".into(),
            ));
        }
        if !first.eq_ignore_ascii_case("wavelength_nm") && !first.eq_ignore_ascii_case("wavelength")
        {
            return Err(err(format!(
                "line 1: first column is '{first}', expected 'wavelength_nm'"
            )));
        }
        let names: Vec<String> = header.iter().skip(1).map(str::to_string).collect();
        if names.is_empty() {
            return Err(err(
                "line 1: no spectrum columns after 'wavelength_nm'".into()
            ));
        }
        if let Some(i) = names.iter().position(|n| n.is_empty()) {
            return Err(err(format!("line 1: column {} has an empty name", i + 2)));
        }
        let mut wavelengths = Vec::new();
        let mut values = vec![Vec::new(); names.len()];
        let max_rows = if limited {
            limits::CSV_ROWS.value()?
        } else {
            u64::MAX
        };
        for record in records {
            let record = record.map_err(|e| err(e.to_string()))?;
            if wavelengths.len() as u64 >= max_rows {
                return Err(limits::CSV_ROWS.exceeded(source_name));
            }
            let line = record.position().map(|p| p.line()).unwrap_or(0);
            if record.iter().all(str::is_empty) {
                continue;
            }
            if record.len() != names.len() + 1 {
                return Err(err(format!(
                    "line {line}: {} cells, expected {} (wavelength_nm + {} columns)",
                    record.len(),
                    names.len() + 1,
                    names.len()
                )));
            }
            let number = |cell: &str, column: &str| -> Result<f64> {
                cell.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        err(format!(
                            "line {line}, column '{column}': '{cell}' is not a number"
                        ))
                    })
            };
            let w = number(&record[0], "wavelength_nm")?;
            if let Some(&prev) = wavelengths.last() {
                if w <= prev {
                    let what = if w == prev { "duplicate" } else { "unsorted" };
                    return Err(err(format!(
                        "line {line}: {what} wavelength {w} nm after {prev} nm; wavelengths must be strictly increasing"
                    )));
                }
            }
            wavelengths.push(w);
            for (k, name) in names.iter().enumerate() {
                values[k].push(number(&record[k + 1], name)?);
            }
        }
        if wavelengths.len() < 2 {
            return Err(err("fewer than two wavelength rows".into()));
        }
        check_nanometres(&wavelengths).map_err(err)?;
        SpectralSet::new(wavelengths, names, values).map_err(|e| err(e.to_string()))
    }

    /// Reads a spectral CSV file (within [`limits::TEXT_FILE_BYTES`], [`limits::CSV_COLUMNS`]
    /// and [`limits::CSV_ROWS`]).
    pub fn read_csv(path: &Path) -> Result<Self> {
        let text = fsio::read_text(path)?;
        SpectralSet::parse_csv(&text, &path.display().to_string(), true)
    }

    /// The set as spectral CSV text.
    pub fn to_csv_string(&self) -> String {
        let mut out = String::from("wavelength_nm");
        for n in &self.names {
            out.push(',');
            out.push_str(&csv_escape(n));
        }
        out.push('\n');
        for (i, w) in self.wavelengths.iter().enumerate() {
            out.push_str(&format_number(*w));
            for v in &self.values {
                out.push(',');
                out.push_str(&format_number(v[i]));
            }
            out.push('\n');
        }
        out
    }

    /// Writes the set as spectral CSV, atomically.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        fsio::write_atomic(path, self.to_csv_string().as_bytes())
    }

    /// The wavelengths, in nm.
    pub fn wavelengths(&self) -> &[f64] {
        &self.wavelengths
    }

    /// The item names, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The number of items.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the set holds no items.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The values of item `i`, one per wavelength.
    pub fn item(&self, i: usize) -> &[f64] {
        &self.values[i]
    }

    /// Item `i` as a spectrum with its grid; an error when the wavelengths are not a
    /// regular grid.
    pub fn spd(&self, i: usize) -> Result<Spd> {
        let grid = self
            .grid()
            .ok_or_else(|| Error::invalid("the spectra are not on a regular wavelength grid"))?;
        Spd::new(grid, self.values[i].clone())
    }

    /// All items, `[item][sample]`.
    pub fn items(&self) -> &[Vec<f64>] {
        &self.values
    }

    /// The index of the item called `name`.
    pub fn position(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The regular grid the wavelengths form, if they form one.
    pub fn grid(&self) -> Option<Grid> {
        let w = &self.wavelengths;
        if w.len() < 2 {
            return None;
        }
        let step = w[1] - w[0];
        let regular = w
            .windows(2)
            .all(|p| ((p[1] - p[0]) - step).abs() <= 1e-6 * step.max(1.0));
        regular.then_some(Grid {
            start_nm: w[0],
            step_nm: step,
            count: w.len(),
        })
    }

    /// Checks that the set is sampled exactly on `grid`.
    pub fn require_grid(&self, grid: &Grid, what: &str) -> Result<()> {
        match self.grid() {
            Some(g)
                if g.count == grid.count
                    && (g.start_nm - grid.start_nm).abs() < 1e-6
                    && (g.step_nm - grid.step_nm).abs() < 1e-6 =>
            {
                Ok(())
            }
            _ => Err(Error::invalid(format!(
                "{what} is not sampled on the working grid {grid}; resample it first"
            ))),
        }
    }

    /// A new set with only the items at `indices`, in that order.
    pub fn select(&self, indices: &[usize]) -> SpectralSet {
        SpectralSet {
            wavelengths: self.wavelengths.clone(),
            names: indices.iter().map(|&i| self.names[i].clone()).collect(),
            values: indices.iter().map(|&i| self.values[i].clone()).collect(),
        }
    }

    /// Renames the items; the count must match.
    pub fn with_names(mut self, names: Vec<String>) -> Result<Self> {
        if names.len() != self.values.len() {
            return Err(Error::invalid(format!(
                "{} names for {} spectra",
                names.len(),
                self.values.len()
            )));
        }
        self.names = names;
        SpectralSet::new(self.wavelengths, self.names, self.values)
    }

    /// Each item divided by its own maximum. An item whose maximum is not positive is an error.
    pub fn normalised_by_max(&self) -> Result<SpectralSet> {
        let mut out = self.clone();
        for (name, v) in out.names.iter().zip(out.values.iter_mut()) {
            let max = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            if max <= 0.0 {
                return Err(Error::invalid(format!(
                    "spectrum '{name}' has no positive value (all zero or negative)"
                )));
            }
            v.iter_mut().for_each(|x| *x /= max);
        }
        Ok(out)
    }

    /// Rejects values below `-tolerance × max` of their item (physically meaningless for
    /// `kind`, e.g. a reflectance) and clamps the remaining small negatives (measurement
    /// noise) to zero.
    pub fn require_non_negative(self, kind: &str, tolerance: f64) -> Result<Self> {
        self.clamp_negative_noise(kind, None, tolerance)
            .map(|(set, _)| set)
    }

    /// [`SpectralSet::require_non_negative`] for a set read from `source` (a file, named
    /// in the messages with the column): negatives no larger than `tolerance` × the item's
    /// peak are measurement noise (a spectrometer's dark-subtracted ends) and set to zero,
    /// each item so changed given a note saying so; a larger negative is refused, naming
    /// the column, the wavelength, the value and the tolerance.
    pub fn clamp_negative_noise(
        mut self,
        kind: &str,
        source: Option<&str>,
        tolerance: f64,
    ) -> Result<(Self, Vec<String>)> {
        let mut notes = Vec::new();
        let percent = short_number(100.0 * tolerance);
        for (name, v) in self.names.iter().zip(self.values.iter_mut()) {
            let whose = match source {
                Some(source) => format!("{source}, column '{name}'"),
                None => format!("{kind} '{name}'"),
            };
            let peak = v.iter().cloned().fold(0.0f64, f64::max);
            let floor = -tolerance * peak.max(f64::MIN_POSITIVE);
            if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| **x < floor) {
                return Err(Error::invalid(format!(
                    "{whose}: the {kind} is {} at {} nm, more negative than −{percent} % of \
                     its peak ({}); a {kind} cannot be negative (negatives within {percent} % \
                     of the peak are taken as noise and set to 0): correct that value",
                    short_number(*x),
                    short_number(self.wavelengths[i]),
                    short_number(peak)
                )));
            }
            let negative: Vec<usize> = (0..v.len()).filter(|&i| v[i] < 0.0).collect();
            if let Some(&lowest) = negative.iter().min_by(|&&a, &&b| v[a].total_cmp(&v[b])) {
                notes.push(format!(
                    "{whose}: {} negative value(s) of the {kind}, down to {} at {} nm, within \
                     {percent} % of its peak ({}), set to 0 as measurement noise",
                    negative.len(),
                    short_number(v[lowest]),
                    short_number(self.wavelengths[lowest]),
                    short_number(peak)
                ));
            }
            v.iter_mut().for_each(|x| *x = x.max(0.0));
        }
        Ok((self, notes))
    }
}

/// Wavelengths in nm lie somewhere within this range (nm): the ultraviolet from UV-C to
/// the near infrared of silicon and InGaAs sensors.
const PLAUSIBLE_NM: (f64, f64) = (200.0, 2500.0);

/// Refuses wavelengths (sorted) of which none lies within [`PLAUSIBLE_NM`]: they are not in
/// nanometres (micrometres, 0.38–0.78, or ångström, 3800–7800, most likely), and read as
/// nm they would describe no visible light at all, a confident answer to a mistake.
fn check_nanometres(wavelengths: &[f64]) -> std::result::Result<(), String> {
    let (lo, hi) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    if hi >= PLAUSIBLE_NM.0 && lo <= PLAUSIBLE_NM.1 {
        return Ok(());
    }
    let found = format!(
        "the wavelengths run from {} to {}",
        crate::error::short_number(lo),
        crate::error::short_number(hi)
    );
    let guess = if lo >= 0.1 && hi <= 2.5 {
        format!(
            "; they look like micrometres (µm): multiply them by 1000 ({}–{} nm)",
            crate::error::short_number(lo * 1000.0),
            crate::error::short_number(hi * 1000.0)
        )
    } else if lo >= 2000.0 && hi <= 25000.0 {
        format!(
            "; they look like ångström (Å): divide them by 10 ({}–{} nm)",
            crate::error::short_number(lo / 10.0),
            crate::error::short_number(hi / 10.0)
        )
    } else {
        String::new()
    };
    Err(format!(
        "{found}, none within {}–{} nm{guess}; the first column holds wavelengths in \
         nanometres (nm)",
        PLAUSIBLE_NM.0, PLAUSIBLE_NM.1
    ))
}

/// Shortest text that reads back to the same `f64`.
fn format_number(v: f64) -> String {
    let s = format!("{v}");
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn csv_escape(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "wavelength_nm,a,b\n400,0.1,1\n410,0.25,2\n420,0.5,3\n";

    #[test]
    fn names_with_quotes_and_line_breaks_survive_the_round_trip() {
        // Found by the spectral_csv fuzz target: a carriage return inside a quoted name was
        // written unquoted and broke the row.
        let text = "wavelength_nm,\"a\rb\",\"c\"\"d\",\"e\nf\"\n400,1,2,3\n410,4,5,6\n";
        let set = SpectralSet::from_csv_str(text, "names.csv").unwrap();
        assert_eq!(set.names(), ["a\rb", "c\"d", "e\nf"]);
        let again = SpectralSet::from_csv_str(&set.to_csv_string(), "again.csv").unwrap();
        assert_eq!(set, again);
    }

    #[test]
    fn csv_round_trip_keeps_every_number() {
        let set = SpectralSet::from_csv_str(SAMPLE, "sample").unwrap();
        assert_eq!(set.names(), ["a", "b"]);
        assert_eq!(set.item(0), [0.1, 0.25, 0.5]);
        let again = SpectralSet::from_csv_str(&set.to_csv_string(), "again").unwrap();
        assert_eq!(set, again);
        let odd = SpectralSet::new(
            vec![380.0, 380.8],
            vec!["x,y".into()],
            vec![vec![1.0 / 3.0, 2e-17]],
        )
        .unwrap();
        assert_eq!(
            SpectralSet::from_csv_str(&odd.to_csv_string(), "odd").unwrap(),
            odd
        );
    }

    fn parse_err(text: &str) -> String {
        SpectralSet::from_csv_str(text, "f.csv")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn malformed_csv_gives_located_errors() {
        assert!(parse_err("400,1\n410,2\n").contains("no header"));
        let e = parse_err("wavelength_nm,a\n400,1\n410,x\n");
        assert!(
            e.contains("line 3") && e.contains("'a'") && e.contains("'x'"),
            "{e}"
        );
        assert!(parse_err("wavelength_nm,a\n410,1\n400,2\n").contains("unsorted"));
        assert!(parse_err("wavelength_nm,a\n400,1\n400,2\n").contains("duplicate"));
        assert!(parse_err("wavelength_nm,a\n400,1\n410\n").contains("cells"));
        assert!(parse_err("").contains("empty"));
        assert!(parse_err("nm,a\n400,1\n410,2\n").contains("expected 'wavelength_nm'"));
    }

    #[test]
    fn wavelengths_not_in_nanometres_are_named() {
        let e = parse_err("wavelength_nm,a\n0.38,1\n0.58,2\n0.78,1\n");
        assert!(
            e.contains("0.38 to 0.78") && e.contains("micrometres") && e.contains("380–780 nm"),
            "{e}"
        );
        let e = parse_err("wavelength_nm,a\n3800,1\n7800,1\n");
        assert!(e.contains("ångström") && e.contains("380–780 nm"), "{e}");
        let e = parse_err("wavelength_nm,a\n1e9,1\n2e9,1\n");
        assert!(e.contains("1e9 to 2e9") && e.contains("nanometres"), "{e}");
        // Ultraviolet and near-infrared data are nanometres.
        assert!(SpectralSet::from_csv_str("wavelength_nm,a\n250,1\n350,1\n", "uv").is_ok());
        assert!(SpectralSet::from_csv_str("wavelength_nm,a\n900,1\n2400,1\n", "ir").is_ok());
    }

    #[test]
    fn negative_values_rejected_small_noise_clamped() {
        let set = SpectralSet::from_csv_str("wavelength_nm,a\n400,-0.5\n410,1\n", "f").unwrap();
        let e = set.require_non_negative("reflectance", 0.01).unwrap_err();
        assert!(e.to_string().contains("400 nm"), "{e}");
        let set = SpectralSet::from_csv_str("wavelength_nm,a\n400,-0.001\n410,1\n", "f").unwrap();
        let ok = set.require_non_negative("reflectance", 0.01).unwrap();
        assert_eq!(ok.item(0), [0.0, 1.0]);
        // Issue 39: the file, the column, the wavelength, the value and the tolerance named.
        let set = SpectralSet::from_csv_str("wavelength_nm,a\n400,-0.02\n410,1\n", "f").unwrap();
        let e = set
            .clamp_negative_noise("SPD", Some("lamp.csv"), 0.01)
            .unwrap_err()
            .to_string();
        for part in ["lamp.csv, column 'a'", "-0.02", "400 nm", "1 %"] {
            assert!(e.contains(part), "{part}: {e}");
        }
        let set =
            SpectralSet::from_csv_str("wavelength_nm,a\n400,-0.004\n410,1\n420,-0.001\n", "f")
                .unwrap();
        let (ok, notes) = set
            .clamp_negative_noise("SPD", Some("lamp.csv"), 0.01)
            .unwrap();
        assert_eq!(ok.item(0), [0.0, 1.0, 0.0]);
        assert_eq!(notes.len(), 1);
        assert!(
            notes[0].contains("2 negative") && notes[0].contains("-0.004 at 400 nm"),
            "{notes:?}"
        );
    }

    #[test]
    fn normalisation_by_max_and_zero_spd() {
        let set = SpectralSet::from_csv_str(SAMPLE, "s").unwrap();
        let n = set.normalised_by_max().unwrap();
        assert_eq!(n.item(1), [1.0 / 3.0, 2.0 / 3.0, 1.0]);
        let zero = SpectralSet::from_csv_str("wavelength_nm,z\n400,0\n410,0\n", "s").unwrap();
        assert!(zero
            .normalised_by_max()
            .unwrap_err()
            .to_string()
            .contains("'z'"));
    }

    #[test]
    fn duplicate_names_are_found_among_many() {
        let names = |n: usize| (0..n).map(|i| format!("s{i}")).collect::<Vec<String>>();
        let values = |n: usize| vec![vec![1.0]; n];
        assert!(SpectralSet::new(vec![500.0], names(50_000), values(50_000)).is_ok());
        let mut twice = names(50_000);
        twice[49_999] = "s17".into();
        let e = SpectralSet::new(vec![500.0], twice, values(50_000)).unwrap_err();
        assert!(e.to_string().contains("'s17' appears twice"), "{e}");
    }

    #[test]
    fn grid_detection() {
        let set = SpectralSet::from_csv_str(SAMPLE, "s").unwrap();
        assert_eq!(set.grid(), Some(Grid::new(400.0, 420.0, 10.0).unwrap()));
        let irregular = SpectralSet::new(vec![1.0, 2.0, 4.0], vec!["a".into()], vec![vec![0.0; 3]]);
        assert_eq!(irregular.unwrap().grid(), None);
    }
}
