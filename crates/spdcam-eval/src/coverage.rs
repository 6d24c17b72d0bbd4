//! How well lighting recipes cover a file of measured SPDs, per lamp type (`spdcam
//! coverage`): for each SPD the best GFC (400–700 nm) among N draws of each recipe (and of
//! each member of a `mix:`), and the GFC of the lamp-family model fitted to it directly.
//!
//! [`Coverage::measure`] runs it; [`Coverage::markdown`] and [`Coverage::per_lamp_csv`] are
//! what `spdcam coverage` prints and writes.

use crate::error::Result;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::coverage::best_gfc;
use spdcam_core::light_families::lamp_families::fit_lamp;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::{LampLibrary, LampType, Lighting, ValidationSplit};
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

/// What to measure: the SPDs, the recipes and the draws.
#[derive(Debug, Clone)]
pub struct CoverageOptions {
    /// Measured SPDs (spectral CSV, one column per lamp).
    pub spds: PathBuf,
    /// The SPDs' types (`column,type[,category]`); `None`: every SPD is of type "other".
    pub types: Option<PathBuf>,
    /// Only the lamps of this part of this validation split; `None`: every SPD.
    pub split: Option<(PathBuf, LampPart)>,
    /// The lighting recipes; a `mix:` is measured whole and member by member.
    pub lighting: Vec<String>,
    /// Draws per recipe (and per member of a mixture).
    pub draws: u64,
    /// Seed of the draws.
    pub seed: u64,
    /// Also fit each lamp's family model to it directly (what the family can reach).
    pub fit: bool,
}

/// One recipe (or member of a mixture) measured.
#[derive(Debug, Clone, PartialEq)]
pub struct RecipeCoverage {
    /// The recipe's label in the tables (a spec in backticks, or "the mixture").
    pub label: String,
    /// Each lamp's best GFC among the draws, in [`Coverage::lamps`]' order.
    pub best: Vec<f64>,
}

/// The coverage of the lamps by each recipe.
///
/// Built by hand, the table of two incandescent lamps and one recipe:
///
/// ```
/// use spdcam_core::light_families::LampType;
/// use spdcam_eval::coverage::{Coverage, RecipeCoverage};
///
/// let coverage = Coverage {
///     lamps: vec!["halogen".into(), "filament".into()],
///     types: vec![LampType::Incandescent; 2],
///     recipes: vec![RecipeCoverage { label: "`planck`".into(), best: vec![0.99, 0.97] }],
///     fitted: None,
///     draws: 100,
///     seed: 1,
/// };
/// // Per type, then all lamps: the mean best GFC, the worst lamp in brackets.
/// assert!(coverage
///     .markdown()
///     .contains("| `planck` | 0.9800 (0.970) | 0.9800 (0.970) |\n"));
/// assert!(coverage.per_lamp_csv().ends_with("\"filament\",incandescent/halogen,0.97000\n"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// The lamps measured (their CSV columns).
    pub lamps: Vec<String>,
    /// Each lamp's type, in the same order.
    pub types: Vec<LampType>,
    /// Each recipe measured, the members of a mixture before the mixture.
    pub recipes: Vec<RecipeCoverage>,
    /// Each lamp's GFC of its type's family model fitted to it (`None` where the type has no
    /// family or the fit failed); `None` when not fitted.
    pub fitted: Option<Vec<Option<f64>>>,
    /// Draws per recipe.
    pub draws: u64,
    /// Seed of the draws.
    pub seed: u64,
}

impl Coverage {
    /// Reads the SPDs (only the split's part, if given) and measures each recipe on them;
    /// `progress` hears of each recipe measured.
    pub fn measure(
        options: &CoverageOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Coverage> {
        let grid = Grid::SIMULATION;
        let mut library = LampLibrary::read(&options.spds, options.types.as_deref(), &grid)?;
        if let Some((path, part)) = &options.split {
            let split = ValidationSplit::read(path)?;
            let keep = library.positions(split.lamps(*part), "the split")?;
            library = library.subset(&keep);
        }
        let mut recipes: Vec<RecipeCoverage> = Vec::new();
        for spec in &options.lighting {
            let lighting = Lighting::parse(spec, data_dir, &grid)?;
            if let Some(members) = lighting.mix_members() {
                for (member, _) in members {
                    let best = best_gfc(member, options.seed, options.draws, &library.spds)?;
                    recipes.push(RecipeCoverage {
                        label: format!("`{}`", member.spec()),
                        best,
                    });
                }
            }
            let label = if lighting.mix_members().is_some() {
                "the mixture".to_string()
            } else {
                format!("`{spec}`")
            };
            recipes.push(RecipeCoverage {
                label,
                best: best_gfc(&lighting, options.seed, options.draws, &library.spds)?,
            });
            progress(spec);
        }
        let fitted: Option<Vec<Option<f64>>> = options.fit.then(|| {
            library
                .spds
                .iter()
                .enumerate()
                .map(|(i, spd)| {
                    Some(library.types[i])
                        .filter(|t| t.has_model())
                        .and_then(|t| fit_lamp(t, &library.names[i], spd, &grid).ok())
                        .map(|l| l.gfc)
                })
                .collect()
        });
        Ok(Coverage {
            lamps: library.names,
            types: library.types,
            recipes,
            fitted,
            draws: options.draws,
            seed: options.seed,
        })
    }

    /// The table `spdcam coverage` prints: a row per recipe (and the family fit), a column
    /// per lamp type present and one for all lamps, then what the numbers are.
    pub fn markdown(&self) -> String {
        let kinds: Vec<Option<LampType>> = LampType::ALL
            .iter()
            .filter(|t| self.types.contains(t))
            .map(|&t| Some(t))
            .chain([None])
            .collect();
        let members = |kind: Option<LampType>| -> Vec<usize> {
            (0..self.lamps.len())
                .filter(|&i| kind.is_none_or(|k| self.types[i] == k))
                .collect()
        };
        let mut md = String::from("| recipe |");
        for &kind in &kinds {
            let label = kind.map_or("all", LampType::label);
            md += &format!(" {label} ({}) |", members(kind).len());
        }
        md += "\n|---|";
        md += &"---:|".repeat(kinds.len());
        md.push('\n');
        let cell = |values: Vec<f64>| -> String {
            if values.is_empty() {
                return "–".into();
            }
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let worst = values.iter().cloned().fold(1.0, f64::min);
            format!("{mean:.4} ({worst:.3})")
        };
        for recipe in &self.recipes {
            md += &format!("| {} |", recipe.label);
            for &kind in &kinds {
                md += &format!(
                    " {} |",
                    cell(members(kind).iter().map(|&i| recipe.best[i]).collect())
                );
            }
            md.push('\n');
        }
        if let Some(f) = &self.fitted {
            md += "| family model of the lamp's type, fitted |";
            for &kind in &kinds {
                md += &format!(
                    " {} |",
                    cell(members(kind).iter().filter_map(|&i| f[i]).collect())
                );
            }
            md.push('\n');
        }
        md += &format!(
            "\nBest GFC (400–700 nm) of each SPD among {} draws (seed {}) of each recipe, mean over \
             the lamps of a type (worst in brackets){}.\n",
            self.draws,
            self.seed,
            if self.fitted.is_some() {
                "; family model fitted: the GFC of the lamp family of the lamp's type fitted to it \
                 by least squares (what the family's model can reach)"
            } else {
                ""
            }
        );
        md
    }

    /// The per-lamp results as CSV: a row per lamp (name, type), a column per recipe and, if
    /// fitted, the family fit.
    pub fn per_lamp_csv(&self) -> String {
        let mut csv = String::from("lamp,type");
        for recipe in &self.recipes {
            csv += &format!(",\"{}\"", recipe.label.replace('"', "\"\""));
        }
        if self.fitted.is_some() {
            csv += ",family_fit";
        }
        csv.push('\n');
        for i in 0..self.lamps.len() {
            csv += &format!(
                "\"{}\",{}",
                self.lamps[i].replace('"', "\"\""),
                self.types[i].label()
            );
            for recipe in &self.recipes {
                csv += &format!(",{:.5}", recipe.best[i]);
            }
            if let Some(f) = &self.fitted {
                csv += &f[i].map_or(",".to_string(), |v| format!(",{v:.5}"));
            }
            csv.push('\n');
        }
        csv
    }
}
