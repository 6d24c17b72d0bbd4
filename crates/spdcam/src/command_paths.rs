//! The paths a command line reads and writes, read from clap's matches for every command
//! alike, and held to the core's output guard before the command runs: no output may
//! destroy an input or another output (`estimate p.jpg -o p.jpg`, `train -o DS/manifest.json`,
//! `render -o a.png --features a.png` are refused with both names).
//!
//! Outputs are the arguments named in [`OUTPUTS`]; every other argument whose value (or a
//! part of it: the file of `FILE.csv:COLUMN`, each item of a comma-separated list) names an
//! existing file or directory is an input. The data directory (`--data-dir`) is read by
//! name, never written into, and is left out.

use anyhow::Result;
use clap::{ArgMatches, Command};
use spdcam_core::output_guard::{self, NamedPath, PlannedOutput};
use std::path::{Path, PathBuf};

/// What an output argument names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    /// A file.
    File,
    /// A file, or `-` for standard output.
    FileOrStdout,
    /// A directory the command makes or replaces as a whole (a dataset, a report
    /// directory): it may not hold an input.
    Directory,
    /// A directory the command adds named files to (stage images, calibrations, missed
    /// photos): it may hold inputs, but may not be one or lie inside one.
    AddsFilesTo,
}

/// Every command's output arguments: the command (its subcommand names joined by spaces),
/// the argument's id, and what it names. A test checks this table against the command tree.
const OUTPUTS: &[(&str, &str, Output)] = &[
    ("render", "output", Output::FileOrStdout),
    ("render", "features", Output::FileOrStdout),
    ("render", "stages", Output::AddsFilesTo),
    ("render", "spd_out", Output::FileOrStdout),
    ("generate", "output", Output::Directory),
    ("dataset import", "output", Output::Directory),
    ("dataset export", "output", Output::Directory),
    ("dataset merge", "output", Output::Directory),
    ("dataset split", "output", Output::Directory),
    ("dataset info", "plot", Output::File),
    ("train", "output", Output::File),
    ("train", "log", Output::File),
    ("train", "plot", Output::File),
    ("average", "output", Output::File),
    ("estimate", "output", Output::FileOrStdout),
    ("estimate", "plot", Output::File),
    ("estimate", "report", Output::File),
    ("estimate", "debug", Output::File),
    ("estimate", "features_out", Output::File),
    ("detection", "misses", Output::AddsFilesTo),
    ("detection", "output", Output::File),
    ("evaluate", "output", Output::Directory),
    ("finetune", "output", Output::File),
    ("experiment thesis", "output", Output::Directory),
    ("experiment real-cameras", "output", Output::File),
    ("experiment colour", "output", Output::File),
    ("experiment colour", "photos_csv", Output::File),
    ("experiment places", "output", Output::File),
    ("fit-in-camera", "output", Output::File),
    ("sim2real", "output", Output::File),
    ("coverage", "output", Output::File),
    ("coverage", "per_lamp", Output::File),
    ("lamps split", "output", Output::File),
    ("lamps fit", "output", Output::File),
    ("light-kinds fit", "output", Output::File),
    ("colour-map fit", "output", Output::File),
    ("colour-map raw", "output", Output::File),
    ("lamps validate", "output", Output::File),
    ("trust calibrate", "output", Output::AddsFilesTo),
    ("trust report", "output", Output::File),
    ("trust report", "reliability", Output::File),
];

/// The global argument that names the data directory: read by name, left out.
const DATA_DIR_ID: &str = "data_dir";

/// Refuses the command line if one of its outputs would destroy one of its inputs or
/// another output, or names standard output where the command writes none; run before
/// the command reads or writes anything.
pub fn check(command: &Command, matches: &ArgMatches) -> Result<()> {
    let (inputs, outputs) = paths(command, matches)?;
    output_guard::check_outputs(&inputs, &outputs)?;
    Ok(())
}

/// Refuses `-` for an output that cannot go to standard output (it would make a file named
/// `-`).
fn check_not_stdout(option: &str, path: &Path) -> Result<()> {
    if spdcam_core::fsio::is_stdout(path) {
        anyhow::bail!(
            "{option} cannot go to standard output (`-`); name a file (`./-` for a file \
             named -)"
        );
    }
    Ok(())
}

/// The inputs and outputs of the command line that `matches` holds.
fn paths(command: &Command, matches: &ArgMatches) -> Result<(Vec<NamedPath>, Vec<PlannedOutput>)> {
    let (name, leaf, leaf_matches) = leaf(command, matches, String::new());
    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    for arg in leaf.get_arguments() {
        let id = arg.get_id().as_str();
        if id == DATA_DIR_ID {
            continue;
        }
        let Ok(Some(values)) = leaf_matches.try_get_raw(id) else {
            continue;
        };
        let option = option_name(arg);
        let kind = OUTPUTS
            .iter()
            .find(|(c, a, _)| *c == name && *a == id)
            .map(|(_, _, kind)| *kind);
        for value in values {
            let path = PathBuf::from(value);
            if kind.is_some_and(|k| k != Output::FileOrStdout) {
                check_not_stdout(&option, &path)?;
            }
            match kind {
                Some(Output::File | Output::FileOrStdout) => {
                    outputs.push(output_guard::file_output(&option, path))
                }
                Some(Output::Directory) => {
                    outputs.push(output_guard::directory_output(&option, path))
                }
                // Checked as a file: it may not be an input or lie inside one.
                Some(Output::AddsFilesTo) => outputs.push(output_guard::file_output(&option, path)),
                None => inputs.extend(
                    named_paths(&path)
                        .into_iter()
                        .map(|p| output_guard::named(&option, p)),
                ),
            }
        }
    }
    if name == "estimate" {
        inputs.extend(truths_beside_photos(leaf_matches));
    }
    Ok((inputs, outputs))
}

/// The leaf subcommand: its name (subcommand names joined by spaces), its definition and
/// its matches.
fn leaf<'a>(
    command: &'a Command,
    matches: &'a ArgMatches,
    name: String,
) -> (String, &'a Command, &'a ArgMatches) {
    match matches.subcommand() {
        Some((sub, sub_matches)) => match command.find_subcommand(sub) {
            Some(sub_command) => {
                let name = if name.is_empty() {
                    sub.to_string()
                } else {
                    format!("{name} {sub}")
                };
                leaf(sub_command, sub_matches, name)
            }
            None => (name, command, matches),
        },
        None => (name, command, matches),
    }
}

/// How the user names an argument: `-o`, `--features`, or the value name of a positional
/// one (`PHOTO`).
fn option_name(arg: &clap::Arg) -> String {
    if let Some(short) = arg.get_short() {
        return format!("-{short}");
    }
    if let Some(long) = arg.get_long() {
        return format!("--{long}");
    }
    arg.get_value_names()
        .and_then(|names| names.first())
        .map(|n| n.to_string())
        .unwrap_or_else(|| arg.get_id().to_string().to_uppercase())
}

/// The existing paths a value names: itself, the file of `FILE:COLUMN`, each item of a
/// comma-separated list (and each item's file).
fn named_paths(value: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut consider = |p: PathBuf| {
        if p.exists() && !found.contains(&p) {
            found.push(p);
        }
    };
    consider(value.to_path_buf());
    let text = value.to_string_lossy();
    for item in text.split(',') {
        consider(PathBuf::from(item));
        if let Some((file, _)) = item.rsplit_once(':') {
            consider(PathBuf::from(file));
        }
    }
    found
}

/// The truths `estimate` reads beside its photos when `--truth` is not given
/// (`<photo stem>.truth.csv`).
fn truths_beside_photos(matches: &ArgMatches) -> Vec<NamedPath> {
    let Ok(Some(photos)) = matches.try_get_raw("photos") else {
        return Vec::new();
    };
    photos
        .map(Path::new)
        .map(|photo| photo.with_extension("truth.csv"))
        .filter(|truth| truth.exists())
        .map(|truth| output_guard::named("the truth beside the photo", truth))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every leaf command with its name.
    fn leaves(command: &Command, name: String, out: &mut Vec<(String, Command)>) {
        if command.get_subcommands().next().is_none() {
            out.push((name, command.clone()));
            return;
        }
        for sub in command.get_subcommands() {
            let full = if name.is_empty() {
                sub.get_name().to_string()
            } else {
                format!("{name} {}", sub.get_name())
            };
            leaves(sub, full, out);
        }
    }

    #[test]
    fn the_output_table_names_every_output_argument_and_only_those() {
        // Argument ids that write wherever they appear; `features` writes in `render`
        // only (elsewhere it is an input), so the table is checked for it by hand below.
        const WRITES: [&str; 12] = [
            "output",
            "log",
            "plot",
            "report",
            "debug",
            "features_out",
            "spd_out",
            "stages",
            "misses",
            "reliability",
            "per_lamp",
            "photos_csv",
        ];
        let mut all = Vec::new();
        leaves(&crate::Cli::command(), String::new(), &mut all);
        for (name, command) in &all {
            for arg in command.get_arguments() {
                let id = arg.get_id().as_str();
                let listed = OUTPUTS.iter().any(|(c, a, _)| c == name && *a == id);
                assert_eq!(
                    listed,
                    WRITES.contains(&id) || (name == "render" && id == "features"),
                    "`spdcam {name}` argument {id}: the table of outputs and the command tree \
                     disagree"
                );
            }
        }
        for (name, id, _) in OUTPUTS {
            let found = all
                .iter()
                .any(|(n, c)| n == name && c.get_arguments().any(|a| a.get_id().as_str() == *id));
            assert!(
                found,
                "OUTPUTS names `{name}` {id}, which the command tree lacks"
            );
        }
    }
}
