//! `spdcam list`: what is built in, and what the data directory offers.

use anyhow::Result;
use clap::{Args, ValueEnum};
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::noise::NoiseParams;
use spdcam_core::chart::KnownChart;
use spdcam_core::illuminant::StandardIlluminant;
use spdcam_core::light::SPD_FORMS;
use spdcam_core::lighting;

/// What to list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Topic {
    Cameras,
    Charts,
    Illuminants,
    Lighting,
    Presets,
}

/// Options of `spdcam list`.
#[derive(Debug, Args)]
pub struct ListArgs {
    /// One topic; all when omitted.
    topic: Option<Topic>,
}

/// Runs `spdcam list`.
pub fn run(args: ListArgs, data_dir: &DataDir) -> Result<()> {
    let all = args.topic.is_none();
    let want = |t: Topic| all || args.topic == Some(t);
    if want(Topic::Cameras) {
        println!("cameras (built in):");
        for c in builtin::CAMERAS {
            println!("  {:<28} {}", c.name, c.description);
        }
        let more = data_dir.list_csv(&["cameras", "thesis"]);
        if !more.is_empty() {
            println!("in the data directory (cameras and thesis tables; any r,g,b CSV works):");
            for name in more {
                println!("  {name}");
            }
        }
    }
    if want(Topic::Charts) {
        println!("charts:");
        for chart in KnownChart::ALL {
            println!("  {:<28} {}", chart.name(), chart.description());
        }
        println!(
            "  {:<28} a reflectance CSV with --layout ROWSxCOLS",
            "FILE.csv"
        );
    }
    if want(Topic::Illuminants) {
        println!("illuminants:");
        for ill in StandardIlluminant::ALL {
            println!("  {}", ill.name());
        }
        println!("  forms: {SPD_FORMS}");
    }
    if want(Topic::Lighting) {
        println!("lighting recipes (spdcam generate --lighting):");
        for (form, what) in lighting::catalogue() {
            println!("  {form:<28} {what}");
        }
        println!("lamp families (lamp:NAME), fitted to measured lamps:");
        for family in lighting::LampFamily::ALL {
            println!(
                "  {:<28} {}",
                format!("lamp:{}", family.name()),
                family.describe()
            );
        }
    }
    if want(Topic::Presets) {
        println!("noise presets:");
        for (name, p) in NoiseParams::PRESETS {
            println!(
                "  {name:<10} {} ADU/e-, read noise {} e-, black level {} ADU, {} bits",
                p.gain_adu_per_e, p.read_noise_e, p.black_level_adu, p.bit_depth
            );
        }
        println!("  off");
        println!("demosaicing: menon2007 (default), malvar2004, bilinear");
        println!("white balance: shades-of-grey:6 (default), grey-world, white-patch, grey-edge:p:sigma, none");
    }
    Ok(())
}
