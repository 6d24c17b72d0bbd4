//! Lights named on the command line: a standard illuminant, a colour temperature, or a
//! spectral CSV, resolved to an SPD on the simulation grid.

use crate::builtin::{self, DataDir};
use crate::cie_illuminant::{self, StandardIlluminant};
use crate::error::{short_number, Error, Result};
use crate::spectral::{Extrapolation, Grid, Interpolation, ResampleReport, Spd};

/// The forms an SPD may be named in, for help and error messages.
pub const SPD_FORMS: &str = "D65, A, D50, daylight:CCT (4000–25000 K), planck:CCT, \
cct:CCT (CIE reference: Planckian below 5000 K, daylight from 5000 K), or a spectral CSV \
(FILE.csv or FILE.csv:COLUMN)";

/// A light resolved to the simulation grid.
#[derive(Debug, Clone)]
pub struct ResolvedSpd {
    /// A name for the light: the illuminant, `planck:CCT`, or the file (and column).
    pub name: String,
    /// Relative spectral power on the grid it was resolved to.
    pub spd: Spd,
    /// Present when the light came from a file: how it was resampled.
    pub resampling: Option<ResampleReport>,
    /// What was done to the file's values that its user should know (small negatives set
    /// to zero), one line each; empty for named lights.
    pub notes: Vec<String>,
}

/// Negative values of a light's SPD file down to this fraction of its peak (1 %) are taken
/// as measurement noise and set to zero, with a note; more negative ones are refused.
/// Measured spectra carry such noise at their ends (a spectrometer's dark current
/// subtracted), and a real light has no negative power.
pub const SPD_NEGATIVE_TOLERANCE: f64 = 0.01;

/// The peaks a light's SPD file may have as it is: the camera computes in single precision
/// (whose range ends near 1e±38, with sums over the bands and the sensitivities on top), so
/// a file in units far beyond these would overflow or vanish there. Only the SPD's shape
/// matters, so such a file is divided by its peak before anything else, with a note (two
/// lights mixed keep their ratio only when both are within this range).
pub const SPD_PEAK_RANGE: (f64, f64) = (1e-30, 1e30);

/// Resolves `spec` (see [`SPD_FORMS`]) to an SPD on `grid`. A file's small negatives are
/// set to zero (see [`SPD_NEGATIVE_TOLERANCE`]; the notes say so), larger ones refused.
pub fn resolve_spd(spec: &str, data_dir: &DataDir, grid: &Grid) -> Result<ResolvedSpd> {
    if let Ok(ill) = StandardIlluminant::parse(spec) {
        return Ok(ResolvedSpd {
            name: ill.name().to_string(),
            spd: ill.spd(grid)?,
            resampling: None,
            notes: Vec::new(),
        });
    }
    if let Some((kind, value)) = spec.split_once(':') {
        let kind_lc = kind.to_ascii_lowercase();
        if matches!(kind_lc.as_str(), "daylight" | "planck" | "cct") {
            let t: f64 = value.trim_end_matches(['K', 'k']).parse().map_err(|_| {
                Error::invalid(format!(
                    "'{spec}': '{value}' is not a temperature in kelvin"
                ))
            })?;
            let spd = match kind_lc.as_str() {
                "daylight" => cie_illuminant::daylight(t, grid)?,
                "planck" => cie_illuminant::planck(t, grid)?,
                _ if t < 5000.0 => cie_illuminant::planck(t, grid)?,
                _ => cie_illuminant::daylight(t, grid)?,
            };
            return Ok(ResolvedSpd {
                name: spec.to_string(),
                spd,
                resampling: None,
                notes: Vec::new(),
            });
        }
    }
    let (file, column) = match spec.rsplit_once(".csv:") {
        Some((f, c)) => (format!("{f}.csv"), Some(c)),
        None => (spec.to_string(), None),
    };
    if !builtin::looks_like_path(&file) && data_dir.find_csv(&file, &["spds"]).is_none() {
        return Err(Error::UnknownName {
            kind: "light",
            name: spec.to_string(),
            valid: SPD_FORMS.to_string(),
        });
    }
    let (name, set) = builtin::resolve_table(&file, "light", &[], data_dir, &["spds"])?;
    let index = match column {
        Some(c) => set.position(c).ok_or_else(|| {
            Error::invalid(format!(
                "{file} has no column '{c}'; it has {}",
                crate::error::brief_list(set.names())
            ))
        })?,
        None if set.len() == 1 => 0,
        None => {
            return Err(Error::invalid(format!(
                "{file} holds {} SPDs ({}); pick one as {file}:COLUMN",
                set.len(),
                crate::error::brief_list(set.names())
            )))
        }
    };
    let (mut one, mut notes) =
        set.select(&[index])
            .clamp_negative_noise("SPD", Some(&file), SPD_NEGATIVE_TOLERANCE)?;
    let peak = one.item(0).iter().fold(0.0f64, |m, &v| m.max(v));
    let (lowest, highest) = SPD_PEAK_RANGE;
    if peak > highest || (peak > 0.0 && peak < lowest) {
        one = one.normalised_by_max()?;
        notes.push(format!(
            "{file}, column '{}': its peak {} lies outside what the camera's single-precision \
             arithmetic holds ({}…{}); only the SPD's shape matters, so it was divided by its \
             peak",
            one.names()[0],
            short_number(peak),
            short_number(lowest),
            short_number(highest)
        ));
    }
    let (resampled, report) = one.resample(grid, Interpolation::Auto, Extrapolation::Zero)?;
    let spd = Spd::new(*grid, resampled.item(0).to_vec())?;
    if spd.iter().all(|&v| v == 0.0) {
        return Err(Error::invalid(format!(
            "SPD '{}' in {file} is zero everywhere on {grid}",
            one.names()[0]
        )));
    }
    Ok(ResolvedSpd {
        name: format!("{name}:{}", one.names()[0]),
        spd,
        resampling: Some(report),
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_lights_resolve() {
        let g = Grid::SIMULATION;
        let d = DataDir::default();
        for spec in [
            "D65",
            "a",
            "cct:3000",
            "cct:6500",
            "daylight:5000",
            "planck:2856K",
        ] {
            let spd = resolve_spd(spec, &d, &g).unwrap();
            assert_eq!(spd.spd.grid(), &g, "{spec}");
            assert!(spd.spd.iter().all(|v| *v >= 0.0));
        }
        let e = resolve_spd("moonlight", &d, &g).unwrap_err().to_string();
        assert!(e.contains("D65") && e.contains("moonlight"), "{e}");
        assert!(resolve_spd("planck:hot", &d, &g).is_err());
    }

    #[test]
    fn zero_spd_file_is_rejected() {
        let dir = std::env::temp_dir().join(format!("spdcam-light-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("zero.csv");
        std::fs::write(&f, "wavelength_nm,z\n380,0\n780,0\n").unwrap();
        let e = resolve_spd(f.to_str().unwrap(), &DataDir::default(), &Grid::SIMULATION)
            .unwrap_err()
            .to_string();
        assert!(e.contains("zero everywhere"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
