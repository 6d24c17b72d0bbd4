//! Regular wavelength grids.

use crate::error::{short_number, Error, Result};
use crate::limits;
use serde::{Deserialize, Serialize};

/// A regular wavelength grid: `count` samples from `start_nm` in steps of `step_nm`.
///
/// A grid read from a file (a manifest, a model) is checked as one built with
/// [`Grid::new`]: finite, a positive step, 1 to [`limits::GRID_BANDS`] samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GridFields")]
pub struct Grid {
    /// The first wavelength (nm).
    pub start_nm: f64,
    /// The spacing of the samples (nm, positive).
    pub step_nm: f64,
    /// The number of samples.
    pub count: usize,
}

impl Grid {
    /// The simulation grid: 380–780 nm at 5 nm (81 bands).
    pub const SIMULATION: Grid = Grid {
        start_nm: 380.0,
        step_nm: 5.0,
        count: 81,
    };
    /// The estimation and scoring grid: 400–700 nm at 5 nm (61 bands).
    pub const ESTIMATION: Grid = Grid {
        start_nm: 400.0,
        step_nm: 5.0,
        count: 61,
    };

    /// A grid from `start` to `end` inclusive in steps of `step` nanometres.
    pub fn new(start: f64, end: f64, step: f64) -> Result<Grid> {
        let (a, b, s) = (short_number(start), short_number(end), short_number(step));
        if !(start.is_finite() && end.is_finite() && step.is_finite()) || step <= 0.0 || end < start
        {
            return Err(Error::invalid(format!(
                "wavelength range {a}-{b} nm at {s} nm is not a valid grid (need start <= end, step > 0)"
            )));
        }
        let steps = (end - start) / step;
        limits::GRID_BANDS.check_f64(
            steps.round() + 1.0,
            &format!("wavelength range {a}-{b} nm at {s} nm"),
        )?;
        if (steps - steps.round()).abs() > 1e-6 {
            return Err(Error::invalid(format!(
                "wavelength range {a}-{b} nm is not a whole number of {s} nm steps"
            )));
        }
        Ok(Grid {
            start_nm: start,
            step_nm: step,
            count: steps.round() as usize + 1,
        })
    }

    /// A grid of `count` samples from `start_nm` in steps of `step_nm`, checked.
    pub fn from_parts(start_nm: f64, step_nm: f64, count: usize) -> Result<Grid> {
        let what = format!("wavelength grid of {count} samples from {start_nm} nm at {step_nm} nm");
        if !(start_nm.is_finite() && step_nm.is_finite()) || step_nm <= 0.0 || count == 0 {
            return Err(Error::invalid(format!(
                "{what} is not a valid grid (need a finite start, a step > 0 and a sample)"
            )));
        }
        limits::GRID_BANDS.check(count as u64, &what)?;
        Ok(Grid {
            start_nm,
            step_nm,
            count,
        })
    }

    /// Parses `START-END:STEP` or `START-END` (5 nm step), e.g. `400-700:5`.
    ///
    /// ```
    /// use spdcam_core::spectral::Grid;
    ///
    /// let grid = Grid::parse("400-700:5")?;
    /// assert_eq!((grid.count, grid.end_nm()), (61, 700.0));
    /// assert_eq!(grid, Grid::ESTIMATION);
    /// assert!(Grid::parse("700-400").is_err());
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn parse(text: &str) -> Result<Grid> {
        let bad = || {
            Error::invalid(format!(
                "wavelength range '{text}' is not START-END[:STEP] in nm, e.g. 400-700:5"
            ))
        };
        let (range, step) = match text.split_once(':') {
            Some((r, s)) => (r, s.trim().parse::<f64>().map_err(|_| bad())?),
            None => (text, 5.0),
        };
        let (a, b) = range.split_once('-').ok_or_else(bad)?;
        let a = a.trim().parse::<f64>().map_err(|_| bad())?;
        let b = b.trim().parse::<f64>().map_err(|_| bad())?;
        Grid::new(a, b, step)
    }

    /// The last wavelength of the grid.
    pub fn end_nm(&self) -> f64 {
        self.wavelength(self.count - 1)
    }

    /// The wavelength of sample `i`.
    pub fn wavelength(&self, i: usize) -> f64 {
        self.start_nm + self.step_nm * i as f64
    }

    /// All wavelengths of the grid.
    pub fn wavelengths(&self) -> Vec<f64> {
        (0..self.count).map(|i| self.wavelength(i)).collect()
    }

    /// The index of `nm` on this grid, if it is one of its samples.
    pub fn index_of(&self, nm: f64) -> Option<usize> {
        let k = (nm - self.start_nm) / self.step_nm;
        let r = k.round();
        ((k - r).abs() < 1e-6 && r >= 0.0 && (r as usize) < self.count).then_some(r as usize)
    }

    /// Whether `other` lies inside this grid with samples on this grid's samples.
    pub fn contains_grid(&self, other: &Grid) -> bool {
        self.index_of(other.start_nm).is_some()
            && self.index_of(other.end_nm()).is_some()
            && (other.step_nm / self.step_nm - (other.step_nm / self.step_nm).round()).abs() < 1e-6
    }

    /// `START-END:STEP` text of the grid.
    pub fn label(&self) -> String {
        format!("{}-{}:{}", self.start_nm, self.end_nm(), self.step_nm)
    }
}

/// The fields of a [`Grid`] as a file stores them, checked by [`Grid::from_parts`].
#[derive(Deserialize)]
struct GridFields {
    start_nm: f64,
    step_nm: f64,
    count: usize,
}

impl TryFrom<GridFields> for Grid {
    type Error = Error;

    fn try_from(f: GridFields) -> Result<Grid> {
        Grid::from_parts(f.start_nm, f.step_nm, f.count)
    }
}

impl std::fmt::Display for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}–{} nm at {} nm ({} bands)",
            self.start_nm,
            self.end_nm(),
            self.step_nm,
            self.count
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulation_grid_has_81_bands() {
        let g = Grid::new(380.0, 780.0, 5.0).unwrap();
        assert_eq!(g, Grid::SIMULATION);
        assert_eq!(g.end_nm(), 780.0);
        assert_eq!(g.index_of(560.0), Some(36));
        assert_eq!(g.index_of(561.0), None);
    }

    #[test]
    fn parse_accepts_range_and_step() {
        assert_eq!(Grid::parse("400-700:5").unwrap(), Grid::ESTIMATION);
        assert_eq!(Grid::parse("400-700").unwrap(), Grid::ESTIMATION);
        assert!(Grid::parse("700-400").is_err());
        assert!(Grid::parse("400-703:5").is_err());
        assert!(Grid::parse("abc").is_err());
    }

    #[test]
    fn grids_past_the_band_limit_are_refused() {
        // Issue 15: `--range 400-700:0.0000001` and `--spd-grid 380-780:0.00001` ran for
        // minutes and took gigabytes.
        for text in ["400-700:0.0000001", "380-780:0.00001", "0-1e300:1"] {
            let e = Grid::parse(text).unwrap_err().to_string();
            assert!(e.contains("SPDCAM_MAX_GRID_BANDS"), "{text}: {e}");
        }
        assert_eq!(Grid::parse("380-780:0.1").unwrap().count, 4001);
    }

    #[test]
    fn grids_read_from_files_are_checked() {
        let ok: Grid = serde_json::from_str(r#"{"start_nm":400,"step_nm":5,"count":61}"#).unwrap();
        assert_eq!(ok, Grid::ESTIMATION);
        for bad in [
            r#"{"start_nm":400,"step_nm":5,"count":1000000000000}"#,
            r#"{"start_nm":400,"step_nm":0,"count":61}"#,
            r#"{"start_nm":400,"step_nm":-5,"count":61}"#,
            r#"{"start_nm":400,"step_nm":5,"count":0}"#,
        ] {
            assert!(serde_json::from_str::<Grid>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn estimation_grid_is_inside_simulation_grid() {
        assert!(Grid::SIMULATION.contains_grid(&Grid::ESTIMATION));
        assert!(!Grid::ESTIMATION.contains_grid(&Grid::SIMULATION));
    }
}
