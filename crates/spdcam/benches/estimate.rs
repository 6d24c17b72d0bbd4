//! Speed of `spdcam estimate --features` (issue 16: linear in the rows, 1,000,000 rows → SPDs
//! in ≤ 10 s, memory bounded). Feature rows of the ColorChecker Digital SG (288 columns, two
//! decimals, as `--features-out` writes them) through the shipped model:
//!
//! - the command itself on 40,000 rows (issue 52: ≤ 1 s on two cores), then on 1,000,000
//!   (100,000 with `--quick`), long layout written to a file, with its peak memory (Linux);
//! - against the in-memory path in the same run, on 2,000 rows in the process: the whole file
//!   read into memory, every estimate judged with its colorimetry (xy, CCT, Duv) and metrics
//!   (as the Python package estimates rows), one wide CSV — beside the streamed path (blocks
//!   parsed in parallel, estimated, written as long rows).
//!
//! `cargo bench -p spdcam --bench estimate [-- --quick]`.

use spdcam_core::builtin::DataDir;
use spdcam_core::spectral::{Grid, SpectralSet};
use spdcam_infer::stream::{long_header, long_rows, FeatureStream};
use spdcam_infer::{Estimator, FeatureRows, ModelSet};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Writes `rows` feature rows for the model's columns: values 20–235 with two decimals.
fn write_features(path: &Path, names: &[String], rows: usize) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).expect("features file"));
    writeln!(out, "{}", names.join(",")).expect("write");
    let mut line = String::new();
    for r in 0..rows {
        line.clear();
        for j in 0..names.len() {
            let phase = (r as f64 * 0.618_034 + j as f64 * 0.381_966).fract();
            let channel = [1.0, 0.9, 0.75][j % 3];
            if j > 0 {
                line.push(',');
            }
            line.push_str(&format!("{:.2}", 20.0 + 215.0 * phase * channel));
        }
        writeln!(out, "{line}").expect("write");
    }
    out.flush().expect("flush");
}

/// Peak resident memory of finished child processes (Linux), in MB.
fn children_peak_mb() -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let mut usage = std::mem::MaybeUninit::<libc::rusage>::uninit();
        // SAFETY: getrusage fills the struct it is given.
        if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, usage.as_mut_ptr()) } == 0 {
            // SAFETY: filled by the successful call above.
            return Some(unsafe { usage.assume_init() }.ru_maxrss as f64 / 1024.0);
        }
    }
    None
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let big = if quick { 100_000 } else { 1_000_000 };
    let dir = std::env::temp_dir().join(format!("spdcam-bench-estimate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let models = ModelSet::shipped().expect("shipped models");
    let model = models
        .models()
        .iter()
        .find(|m| m.model.feature_names().len() == 288)
        .expect("the shipped ColorChecker SG model");
    let names = model.model.feature_names().to_vec();
    let grid = Grid::ESTIMATION;
    let estimator =
        Estimator::new(models.clone(), DataDir::new(None), grid).expect("the estimator");

    // The in-memory path against the streamed one, in the process, on the same rows.
    let small = 2_000;
    let features = dir.join("small.csv");
    write_features(&features, &names, small);
    let t = Instant::now();
    let rows = FeatureRows::read_csv(&features).expect("features");
    let estimates = estimator.estimate_rows(&rows, "bench").expect("estimates");
    let set = SpectralSet::on_grid(
        &grid,
        estimates.iter().map(|e| e.name.clone()).collect(),
        estimates.iter().map(|e| e.spd.to_vec()).collect(),
    )
    .expect("set");
    std::fs::write(dir.join("wide.csv"), set.to_csv_string()).expect("write");
    let previous = t.elapsed().as_secs_f64();
    drop((rows, estimates, set));
    let t = Instant::now();
    let mut stream = estimator
        .stream(FeatureStream::open(&features).expect("features"), "bench")
        .expect("stream");
    let mut out =
        std::io::BufWriter::new(std::fs::File::create(dir.join("long.csv")).expect("out"));
    out.write_all(long_header(&grid).as_bytes()).expect("write");
    while let Some(block) = stream.next_block().expect("block") {
        out.write_all(&long_rows(&block.spds, grid.count, block.first_row))
            .expect("write");
    }
    out.flush().expect("flush");
    let streamed = t.elapsed().as_secs_f64();
    println!(
        "{small} rows in the process: streamed {:.3} s ({:.1} µs a row); in-memory path (all in \
         memory, every row judged with its colorimetry, wide CSV): {previous:.3} s → {:.2}×",
        streamed,
        streamed / small as f64 * 1e6,
        previous / streamed
    );

    // The command on 40,000 rows (issue 52's goal), then on many.
    let forty = the_command(&dir, &names, 40_000);
    println!(
        "40,000 rows, spdcam estimate --features -o (long): {:.2} s (goal ≤ 1 s on two cores)",
        forty.seconds
    );
    let run = the_command(&dir, &names, big);
    let memory = children_peak_mb()
        .map(|mb| format!(", peak memory {mb:.0} MB"))
        .unwrap_or_default();
    let label = if big == 1_000_000 {
        "1,000,000".to_string()
    } else {
        big.to_string()
    };
    println!(
        "{label} rows, spdcam estimate --features ({:.0} MB in) -o ({:.0} MB out, long): \
         {:.2} s ({:.1} µs a row; target ≤ 10 s for 1,000,000){memory}",
        run.read_mb,
        run.written_mb,
        run.seconds,
        run.seconds / big as f64 * 1e6
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// One run of the command: its seconds, and the megabytes it read and wrote.
struct CommandRun {
    seconds: f64,
    read_mb: f64,
    written_mb: f64,
}

/// `spdcam estimate --features FILE -o SPDS` on `rows` rows written into `dir` for the model's
/// columns `names`, timed as a whole process.
fn the_command(dir: &Path, names: &[String], rows: usize) -> CommandRun {
    let features = dir.join(format!("rows-{rows}.csv"));
    write_features(&features, names, rows);
    let output = dir.join(format!("spds-{rows}.csv"));
    let t = Instant::now();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(["estimate", "--features"])
        .arg(&features)
        .arg("-o")
        .arg(&output)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("spdcam runs");
    let seconds = t.elapsed().as_secs_f64();
    assert!(status.success(), "spdcam estimate failed");
    let mb = |path: &Path| std::fs::metadata(path).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
    let run = CommandRun {
        seconds,
        read_mb: mb(&features),
        written_mb: mb(&output),
    };
    std::fs::remove_file(&features).ok();
    std::fs::remove_file(&output).ok();
    run
}
