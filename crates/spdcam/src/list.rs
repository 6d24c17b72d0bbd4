//! `spdcam list`: what is built in, and what the data directory offers.

use crate::outln;
use anyhow::Result;
use clap::{Args, ValueEnum};
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::noise::NoiseParams;
use spdcam_core::chart::KnownChart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::light_families;
use spdcam_core::named_light::SPD_FORMS;

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
        outln!("cameras (built in):")?;
        for c in builtin::CAMERAS {
            outln!("  {:<28} {}", c.name, c.description)?;
        }
        let more = data_dir.list_csv(&["cameras", "thesis"]);
        if !more.is_empty() {
            outln!("in the data directory (cameras and thesis tables; any r,g,b CSV works):")?;
            for name in more {
                outln!("  {name}")?;
            }
        }
    }
    if want(Topic::Charts) {
        outln!("charts:")?;
        for chart in KnownChart::ALL {
            outln!("  {:<28} {}", chart.name(), chart.description())?;
        }
        outln!(
            "  {:<28} a reflectance CSV with --layout ROWSxCOLS",
            "FILE.csv"
        )?;
    }
    if want(Topic::Illuminants) {
        outln!("illuminants:")?;
        for ill in StandardIlluminant::ALL {
            outln!("  {}", ill.name())?;
        }
        outln!("  forms: {SPD_FORMS}")?;
    }
    if want(Topic::Lighting) {
        outln!("lighting recipes (spdcam generate --lighting):")?;
        for (form, what) in light_families::catalogue() {
            outln!("  {form:<28} {what}")?;
        }
        outln!("lamp families (lamp:NAME), fitted to measured lamps:")?;
        for family in light_families::LampType::MODELLED {
            outln!(
                "  {:<28} {}",
                format!("lamp:{}", family.name()),
                family.describe_model()
            )?;
        }
    }
    if want(Topic::Presets) {
        outln!("noise presets:")?;
        for (name, p) in NoiseParams::PRESETS {
            outln!(
                "  {name:<10} {} ADU/e-, read noise {} e-, black level {} ADU, {} bits",
                p.gain_adu_per_e,
                p.read_noise_e,
                p.black_level_adu,
                p.bit_depth
            )?;
        }
        outln!("  off")?;
        outln!("demosaicing: menon2007 (default), malvar2004, bilinear")?;
        outln!("white balance: shades-of-grey:6 (default), grey-world, white-patch, grey-edge:p:sigma, none")?;
    }
    Ok(())
}
