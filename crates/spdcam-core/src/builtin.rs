//! The data spdcam ships inside the binary, and name resolution against a data directory.
//!
//! Built-in tables come from `data/` of the repository (see `data/PROVENANCE.md`); larger or
//! licence-restricted sets are read from a data directory given by `--data-dir` or
//! `SPDCAM_DATA`, where a name such as `canon_eos_5d_mark_ii_mod_bw486` resolves to a CSV.

use crate::error::{Error, Result};
use crate::spectral::SpectralSet;
use std::path::{Path, PathBuf};

/// Environment variable naming the data directory.
pub const DATA_DIR_ENV: &str = "SPDCAM_DATA";

/// A built-in spectral table: its name, what it is, and its CSV text.
#[derive(Debug, Clone, Copy)]
pub struct BuiltinTable {
    /// The name it is found by (`nikon_d5100_npl`).
    pub name: &'static str,
    /// What it is and where it comes from, for `spdcam list`.
    pub description: &'static str,
    /// The spectral CSV text (`wavelength_nm` and one column per item).
    pub csv: &'static str,
}

impl BuiltinTable {
    /// Parses the table (the shipped files are known to be valid).
    pub fn load(&self) -> Result<SpectralSet> {
        SpectralSet::from_csv_str(self.csv, &format!("built-in {}", self.name))
    }
}

/// Camera sensitivities shipped with the program.
pub const CAMERAS: &[BuiltinTable] = &[
    BuiltinTable {
        name: "nikon_d5100_npl",
        description: "Nikon D5100, NPL measurement (Darrodi et al. 2015)",
        csv: include_str!("../../../data/camera_nikon_d5100_npl.csv"),
    },
    BuiltinTable {
        name: "sigma_sd_merrill_npl",
        description: "Sigma SD Merrill, NPL measurement (Darrodi et al. 2015)",
        csv: include_str!("../../../data/camera_sigma_sd_merrill_npl.csv"),
    },
];

/// The 99 colour evaluation samples of ANSI/IES TM-30 (CIE 2017).
pub const TM30_CES99: BuiltinTable = BuiltinTable {
    name: "tm30_ces99",
    description: "ANSI/IES TM-30 / CIE 2017 colour evaluation samples (99)",
    csv: include_str!("../../../data/tm30_ces99.csv"),
};

/// The CIE 1964 10° supplementary standard observer x̄₁₀, ȳ₁₀, z̄₁₀ (360–830 nm, 1 nm), the
/// observer of CIE 224:2017 / ANSI/IES TM-30.
pub const CIE1964_10DEG_CMF: BuiltinTable = BuiltinTable {
    name: "cie_1964_10deg_cmf",
    description: "CIE 1964 10° standard observer colour-matching functions",
    csv: include_str!("../../../data/cie_1964_10deg_cmf.csv"),
};

/// The 14 test colour samples of CIE 13.3-1995 (TCS01–TCS14, 360–830 nm, 5 nm).
pub const CIE1995_TCS14: BuiltinTable = BuiltinTable {
    name: "cie_1995_tcs14",
    description: "CIE 13.3-1995 test colour samples TCS01–TCS14",
    csv: include_str!("../../../data/cie_1995_tcs14.csv"),
};

/// Test colour sample No. 15 of JIS Z 8726:1990 (Japanese skin complexion) as published by the
/// CIE in 2024 (380–780 nm, 5 nm): the sample of the special colour rendering index R15.
pub const CIE2024_TCS15: BuiltinTable = BuiltinTable {
    name: "cie_2024_tcs15",
    description: "JIS Z 8726 test colour sample No. 15 (Japanese skin), CIE 2024",
    csv: include_str!("../../../data/cie_2024_tcs15.csv"),
};

/// The 15 Munsell reflectance samples VS1–VS15 of the NIST Colour Quality Scale 9.0 (Davis &
/// Ohno 2010; 360–830 nm, 5 nm), as distributed by colour-science (BSD-3-Clause).
pub const NIST_CQS90_VS15: BuiltinTable = BuiltinTable {
    name: "nist_cqs90_vs15",
    description: "NIST Colour Quality Scale 9.0 reflectance samples VS1–VS15",
    csv: include_str!("../../../data/nist_cqs90_vs15.csv"),
};

/// The CIE 1951 scotopic spectral luminous efficiency V′(λ) (380–780 nm, 1 nm).
pub const CIE1951_SCOTOPIC: BuiltinTable = BuiltinTable {
    name: "cie_1951_scotopic",
    description: "CIE 1951 scotopic luminous efficiency V′(λ)",
    csv: include_str!("../../../data/cie_1951_scotopic.csv"),
};

/// The α-opic action spectra of CIE S 026:2018: sc, mc, lc, rh, mel (380–780 nm, 1 nm).
pub const CIE_S026_ALPHA_OPIC: BuiltinTable = BuiltinTable {
    name: "cie_s026_alpha_opic",
    description: "CIE S 026:2018 α-opic action spectra (sc, mc, lc, rh, mel)",
    csv: include_str!("../../../data/cie_s026_alpha_opic.csv"),
};

/// The blue-light hazard function B(λ) of ICNIRP 2013 / IEC 62471:2006 (300–700 nm, 1 nm).
pub const BLUE_LIGHT_HAZARD: BuiltinTable = BuiltinTable {
    name: "blue_light_hazard",
    description: "ICNIRP / IEC 62471 blue-light hazard function B(λ)",
    csv: include_str!("../../../data/blue_light_hazard.csv"),
};

/// Looks up a built-in table by name in `tables`.
pub fn find<'a>(tables: &'a [BuiltinTable], name: &str) -> Option<&'a BuiltinTable> {
    tables.iter().find(|t| t.name.eq_ignore_ascii_case(name))
}

/// Where named data files are looked for, besides built-in tables.
#[derive(Debug, Clone, Default)]
pub struct DataDir {
    root: Option<PathBuf>,
}

impl DataDir {
    /// A data directory given explicitly, else from `SPDCAM_DATA`, else none.
    pub fn new(explicit: Option<PathBuf>) -> DataDir {
        let root = explicit.or_else(|| std::env::var_os(DATA_DIR_ENV).map(PathBuf::from));
        DataDir { root }
    }

    /// Checks that a directory that is set exists, so a mistyped `--data-dir` or
    /// `SPDCAM_DATA` is named at once instead of surfacing as an unknown camera or chart.
    pub fn check(&self) -> Result<()> {
        match &self.root {
            Some(root) if !root.is_dir() => Err(Error::invalid(format!(
                "the data directory {} does not exist (given by --data-dir or {DATA_DIR_ENV}); \
                 it holds measured cameras, charts and luminaires, see data/PROVENANCE.md",
                root.display()
            ))),
            _ => Ok(()),
        }
    }

    /// The directory, if one is set.
    pub fn root(&self) -> Option<&Path> {
        self.root.as_deref()
    }

    /// Finds `<root>/<sub>/<name>.csv` for each of `subdirs` (and the root itself), first hit.
    pub fn find_csv(&self, name: &str, subdirs: &[&str]) -> Option<PathBuf> {
        let root = self.root.as_ref()?;
        let file = if name.ends_with(".csv") {
            name.to_string()
        } else {
            format!("{name}.csv")
        };
        std::iter::once("")
            .chain(subdirs.iter().copied())
            .map(|sub| root.join(sub).join(&file))
            .find(|p| p.is_file())
    }

    /// The names (file stems) of CSVs in the given subdirectories, sorted.
    pub fn list_csv(&self, subdirs: &[&str]) -> Vec<String> {
        let Some(root) = &self.root else {
            return Vec::new();
        };
        let mut names: Vec<String> = subdirs
            .iter()
            .filter_map(|sub| std::fs::read_dir(root.join(sub)).ok())
            .flat_map(|rd| rd.filter_map(|e| e.ok()))
            .filter_map(|e| {
                let p = e.path();
                if p.extension()? != "csv" {
                    return None;
                }
                Some(p.file_stem()?.to_string_lossy().into_owned())
            })
            .collect();
        names.sort();
        names.dedup();
        names
    }
}

/// Whether `spec` names a file path rather than a built-in or data-directory name.
pub fn looks_like_path(spec: &str) -> bool {
    spec.contains('/') || spec.contains('\\') || spec.ends_with(".csv")
}

/// Resolves `spec` as: an existing file path (or a pipe or device, see
/// [`crate::fsio::is_input`]); a built-in table; a CSV under the data directory.
/// Unknown names list the valid ones.
pub fn resolve_table(
    spec: &str,
    kind: &'static str,
    builtins: &[BuiltinTable],
    data_dir: &DataDir,
    subdirs: &[&str],
) -> Result<(String, SpectralSet)> {
    if looks_like_path(spec) {
        let path = Path::new(spec);
        if !crate::fsio::is_input(path) {
            let what = if path.is_dir() {
                "is a directory; name a spectral CSV file"
            } else {
                "does not exist"
            };
            return Err(Error::invalid(format!("{kind} file {spec} {what}")));
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| spec.to_string());
        return Ok((name, SpectralSet::read_csv(path)?));
    }
    if let Some(t) = find(builtins, spec) {
        return Ok((t.name.to_string(), t.load()?));
    }
    if let Some(path) = data_dir.find_csv(spec, subdirs) {
        return Ok((spec.to_string(), SpectralSet::read_csv(&path)?));
    }
    let mut valid: Vec<String> = builtins.iter().map(|t| t.name.to_string()).collect();
    valid.extend(data_dir.list_csv(subdirs));
    let hint = if data_dir.root().is_none() {
        format!(" (set --data-dir or {DATA_DIR_ENV} for more)")
    } else {
        String::new()
    };
    Err(Error::UnknownName {
        kind,
        name: spec.to_string(),
        valid: format!("{}{hint}", crate::error::brief_list(&valid)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_table_parses() {
        let quality = [
            &CIE1964_10DEG_CMF,
            &CIE1995_TCS14,
            &CIE2024_TCS15,
            &NIST_CQS90_VS15,
            &CIE1951_SCOTOPIC,
            &CIE_S026_ALPHA_OPIC,
            &BLUE_LIGHT_HAZARD,
        ];
        for t in CAMERAS.iter().chain([&TM30_CES99]).chain(quality) {
            let set = t.load().unwrap();
            assert!(!set.is_empty(), "{}", t.name);
        }
        assert_eq!(CIE1995_TCS14.load().unwrap().len(), 14);
        assert_eq!(CIE2024_TCS15.load().unwrap().names(), ["tcs15"]);
        assert_eq!(NIST_CQS90_VS15.load().unwrap().len(), 15);
        assert_eq!(
            CIE_S026_ALPHA_OPIC.load().unwrap().names(),
            ["sc", "mc", "lc", "rh", "mel"]
        );
        assert_eq!(TM30_CES99.load().unwrap().len(), 99);
        for c in CAMERAS {
            assert_eq!(c.load().unwrap().names(), ["r", "g", "b"]);
        }
    }

    #[test]
    fn a_missing_data_directory_is_named() {
        assert!(DataDir::default().check().is_ok());
        let missing = DataDir::new(Some(PathBuf::from("no/such/dir")));
        let msg = missing.check().unwrap_err().to_string();
        assert!(
            msg.contains("no/such/dir") && msg.contains("does not exist"),
            "{msg}"
        );
    }

    #[test]
    fn unknown_name_lists_valid_ones() {
        let e = resolve_table("nope", "camera", CAMERAS, &DataDir::default(), &[]).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("nikon_d5100_npl") && msg.contains("'nope'"),
            "{msg}"
        );
    }
}
