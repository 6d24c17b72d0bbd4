//! `spdcam coverage`: how well lighting recipes cover a file of measured SPDs, per lamp type:
//! for each SPD the best GFC (400–700 nm) among N draws of each recipe (and of each member
//! of a `mix:`), and the GFC of the lamp-family model fitted to it directly.

use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_core::lighting::coverage::best_gfc;
use spdcam_core::lighting::lamp_families::fit_lamp;
use spdcam_core::lighting::validation_split::LampPart;
use spdcam_core::lighting::{LampFamily, LampLibrary, LampType, Lighting, ValidationSplit};
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

/// Options of `spdcam coverage`.
#[derive(Debug, Args)]
pub struct CoverageArgs {
    /// Measured SPDs (spectral CSV, one column per lamp).
    spds: PathBuf,
    /// Lighting recipe to measure (repeatable); a `mix:` is measured whole and member by member.
    #[arg(long, required = true)]
    lighting: Vec<String>,
    /// The SPDs' types (`column,type[,category]`, as the TM-30 library's info file); without
    /// it every SPD is of type "other".
    #[arg(long, value_name = "INFO.csv")]
    types: Option<PathBuf>,
    /// Only the lamps of one part of this validation split (`spdcam lamps split`)…
    #[arg(long, value_name = "SPLIT.json", requires = "part")]
    split: Option<PathBuf>,
    /// …this part: fit, validation or test.
    #[arg(long, value_parser = ["fit", "validation", "test"], requires = "split")]
    part: Option<String>,
    /// Draws per recipe (and per member of a mixture).
    #[arg(long, default_value_t = 20_000)]
    draws: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Skip the direct fit of each lamp's family model.
    #[arg(long)]
    no_fit: bool,
    /// Markdown table to write (it is printed too).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Per-SPD results as CSV.
    #[arg(long, value_name = "FILE.csv")]
    per_lamp: Option<PathBuf>,
}

/// Runs `spdcam coverage`.
pub fn run(args: CoverageArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    let mut library = LampLibrary::read(&args.spds, args.types.as_deref(), &grid)?;
    if let (Some(path), Some(part)) = (&args.split, &args.part) {
        let split = ValidationSplit::read(path)?;
        let part = match part.as_str() {
            "fit" => LampPart::Fit,
            "validation" => LampPart::Validation,
            _ => LampPart::Test,
        };
        let keep = library.positions(split.lamps(part), "the split")?;
        library = library.subset(&keep);
    }
    let mut columns: Vec<(String, Vec<f64>)> = Vec::new();
    for spec in &args.lighting {
        let lighting = Lighting::parse(spec, data_dir, &grid)?;
        if let Some(members) = lighting.mix_members() {
            for (member, _) in members {
                let best = best_gfc(member, args.seed, args.draws, &library.spds)?;
                columns.push((format!("`{}`", member.spec()), best));
            }
        }
        let label = if lighting.mix_members().is_some() {
            "the mixture".to_string()
        } else {
            format!("`{spec}`")
        };
        columns.push((
            label,
            best_gfc(&lighting, args.seed, args.draws, &library.spds)?,
        ));
        eprintln!("{spec}: done");
    }
    let fitted: Option<Vec<Option<f64>>> = (!args.no_fit).then(|| {
        library
            .spds
            .iter()
            .enumerate()
            .map(|(i, spd)| {
                LampFamily::for_type(library.types[i])
                    .and_then(|f| fit_lamp(f, &library.names[i], spd, &grid).ok())
                    .map(|l| l.gfc)
            })
            .collect()
    });
    let kinds: Vec<Option<LampType>> = LampType::ALL
        .iter()
        .filter(|t| library.types.contains(t))
        .map(|&t| Some(t))
        .chain([None])
        .collect();
    let members = |kind: Option<LampType>| -> Vec<usize> {
        (0..library.names.len())
            .filter(|&i| kind.is_none_or(|k| library.types[i] == k))
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
    for (label, best) in &columns {
        md += &format!("| {label} |");
        for &kind in &kinds {
            md += &format!(
                " {} |",
                cell(members(kind).iter().map(|&i| best[i]).collect())
            );
        }
        md.push('\n');
    }
    if let Some(f) = &fitted {
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
        args.draws,
        args.seed,
        if fitted.is_some() {
            "; family model fitted: the GFC of the lamp family of the lamp's type fitted to it \
             by least squares (what the family's model can reach)"
        } else {
            ""
        }
    );
    print!("{md}");
    if let Some(path) = &args.output {
        write_atomic(path, md.as_bytes())?;
    }
    if let Some(path) = &args.per_lamp {
        let mut csv = String::from("lamp,type");
        for (label, _) in &columns {
            csv += &format!(",\"{}\"", label.replace('"', "\"\""));
        }
        if fitted.is_some() {
            csv += ",family_fit";
        }
        csv.push('\n');
        for i in 0..library.names.len() {
            csv += &format!(
                "\"{}\",{}",
                library.names[i].replace('"', "\"\""),
                library.types[i].label()
            );
            for (_, best) in &columns {
                csv += &format!(",{:.5}", best[i]);
            }
            if let Some(f) = &fitted {
                csv += &f[i].map_or(",".to_string(), |v| format!(",{v:.5}"));
            }
            csv.push('\n');
        }
        write_atomic(path, csv.as_bytes())?;
    }
    Ok(())
}
