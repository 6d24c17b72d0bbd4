//! Lighting-quality speed (issue target): every metric (CCT/Duv, CIE 13.3 Ra and R1–R14,
//! CIE 2017 / TM-30 Rf, Rg and hue bins, CIE S 026 α-opic, S/P, PPF, blue-light hazard) of
//! 10,000 SPDs on one core in ≤ 1 s. The SPDs are 380–780 nm at 5 nm (as measured lamps come),
//! a deterministic mix of Planckian, daylight, phosphor-LED-like and RGB-LED-like spectra.
//! Prints the wall and CPU time (the machine may be shared; CPU time of the one thread is the
//! steadier measure) and the ratio of the CPU time against the target; when python3 with colour-science is
//! present (`SPDCAM_PYTHON` picks the interpreter), `tools/baseline_quality.py` computes the
//! same metrics on the first SPDs in the same run and the speed-up over it is printed.

use spdcam_core::cie_illuminant::{daylight, planck};
use spdcam_core::quality::{LightSpectrum, LightingMetrics};
use spdcam_core::spectral::{Grid, SpectralSet};
use std::hint::black_box;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

const COUNT: usize = 10_000;
const TARGET: Duration = Duration::from_secs(1);
/// SPDs the colour-science baseline computes (it takes tens of milliseconds per SPD).
const BASELINE_COUNT: usize = 200;

/// A deterministic uniform number in [0, 1) from a 64-bit state (PCG-style LCG).
fn next(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

fn gaussian(grid: &Grid, centre: f64, fwhm: f64) -> Vec<f64> {
    let s = fwhm / 2.354_820_045;
    grid.wavelengths()
        .iter()
        .map(|w| (-0.5 * ((w - centre) / s).powi(2)).exp())
        .collect()
}

fn add(a: &mut [f64], b: &[f64], weight: f64) {
    a.iter_mut().zip(b).for_each(|(a, b)| *a += weight * b);
}

/// The benchmark's SPDs on `grid`.
fn spds(grid: &Grid) -> Vec<Vec<f64>> {
    let mut state = 0x5eed_u64;
    (0..COUNT)
        .map(|i| match i % 4 {
            0 => planck(2000.0 + 6000.0 * next(&mut state), grid)
                .unwrap()
                .into_values(),
            1 => daylight(4000.0 + 16000.0 * next(&mut state), grid)
                .unwrap()
                .into_values(),
            2 => {
                let mut s = gaussian(grid, 445.0 + 15.0 * next(&mut state), 20.0);
                let phosphor = gaussian(grid, 550.0 + 70.0 * next(&mut state), 110.0);
                add(&mut s, &phosphor, 0.5 + 1.5 * next(&mut state));
                s
            }
            _ => {
                let mut s = gaussian(grid, 455.0 + 10.0 * next(&mut state), 25.0);
                add(
                    &mut s,
                    &gaussian(grid, 525.0 + 15.0 * next(&mut state), 35.0),
                    0.8 + next(&mut state),
                );
                add(
                    &mut s,
                    &gaussian(grid, 615.0 + 15.0 * next(&mut state), 20.0),
                    0.8 + next(&mut state),
                );
                s
            }
        })
        .collect()
}

/// CPU time this thread has used (user + system), which a machine shared with other work
/// inflates far less than wall time.
fn thread_cpu_time() -> Duration {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a rusage struct into the pointer it is given.
    let usage = unsafe {
        libc::getrusage(libc::RUSAGE_THREAD, usage.as_mut_ptr());
        usage.assume_init()
    };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

fn all_metrics(wavelengths: &[f64], spds: &[Vec<f64>]) -> usize {
    spds.iter()
        .map(|s| {
            let m = LightingMetrics::from_samples(wavelengths, s);
            usize::from(m.tm30_rf.is_some())
        })
        .sum()
}

fn main() {
    let grid = Grid::SIMULATION;
    let wavelengths = grid.wavelengths();
    let spds = spds(&grid);
    // Warm the lazily built tables.
    black_box(
        LightSpectrum::on_grid(&grid, &spds[0])
            .map(|l| LightingMetrics::of(&l))
            .ok(),
    );

    let runs = 3;
    let mut times: Vec<(Duration, Duration)> = (0..runs)
        .map(|_| {
            let (wall, cpu) = (Instant::now(), thread_cpu_time());
            black_box(all_metrics(&wavelengths, black_box(&spds)));
            (wall.elapsed(), thread_cpu_time() - cpu)
        })
        .collect();
    times.sort();
    let (wall, cpu) = times[0];
    let defined = all_metrics(&wavelengths, &spds);
    println!(
        "quality: all metrics of {COUNT} SPDs on one core: {:.3} s wall, {:.3} s CPU (best of {runs}), \
         {:.1} µs CPU per SPD; {:.2}× the 1 s target ({}); TM-30 defined for {defined}",
        wall.as_secs_f64(),
        cpu.as_secs_f64(),
        cpu.as_secs_f64() * 1e6 / COUNT as f64,
        cpu.as_secs_f64() / TARGET.as_secs_f64(),
        if cpu <= TARGET { "met" } else { "missed" },
    );
    match colour_science_baseline(&grid, &spds[..BASELINE_COUNT]) {
        Some(per_spd) => {
            let ours = cpu.as_secs_f64() / COUNT as f64;
            println!(
                "  colour-science + numpy baseline, same run, {BASELINE_COUNT} SPDs: {:.1} ms CPU per SPD \
                 ({:.0} s for {COUNT}) → spdcam is {:.0}× faster",
                per_spd * 1e3,
                per_spd * COUNT as f64,
                per_spd / ours
            );
        }
        None => println!(
            "  (no colour-science baseline: python3 with colour-science 0.4.7 not found; set SPDCAM_PYTHON)"
        ),
    }
}

/// CPU seconds per SPD of `tools/baseline_quality.py` on `spds`, if Python and colour-science run.
fn colour_science_baseline(grid: &Grid, spds: &[Vec<f64>]) -> Option<f64> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let csv = std::env::temp_dir().join(format!("spdcam-quality-bench-{}.csv", std::process::id()));
    let names = (0..spds.len()).map(|i| format!("s{i:05}")).collect();
    SpectralSet::on_grid(grid, names, spds.to_vec())
        .ok()?
        .write_csv(&csv)
        .ok()?;
    let python = std::env::var("SPDCAM_PYTHON").unwrap_or_else(|_| "python3".into());
    let out = Command::new(python)
        .arg(root.join("tools/baseline_quality.py"))
        .arg(&csv)
        .output()
        .ok();
    let _ = std::fs::remove_file(&csv);
    let out = out?;
    if !out.status.success() {
        return None;
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("cpu_seconds_per_spd ")?.trim().parse().ok())
}
