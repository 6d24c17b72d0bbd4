//! The parsers of what users type: light specs, lighting recipes, white balance,
//! wavelength ranges, shards, sensors, demosaicing and noise presets. Any text gives a value
//! or a clear error; a parsed lighting recipe draws a light.
#![no_main]

use libfuzzer_sys::fuzz_target;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::demosaic::DemosaicMethod;
use spdcam_core::camera::noise::NoiseParams;
use spdcam_core::camera::white_balance::WhiteBalance;
use spdcam_core::dataset::Shard;
use spdcam_core::light_families::Lighting;
use spdcam_core::raster::CfaPattern;
use spdcam_core::spectral::Grid;
use spdcam_core::{builtin, named_light};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let grid = Grid::SIMULATION;
    let _ = Grid::parse(text);
    let _ = text.parse::<WhiteBalance>();
    let _ = Shard::parse(text);
    let _ = text.parse::<CfaPattern>();
    let _ = text.parse::<DemosaicMethod>();
    let _ = NoiseParams::preset(text);
    // Specs may name files; the fuzzer must not read the machine's files (/dev/zero), so
    // anything that could name one is left out. An empty data directory holds no names.
    if builtin::looks_like_path(text) || text.contains(".csv") {
        return;
    }
    let data_dir = DataDir::new(None);
    let _ = named_light::resolve_spd(text, &data_dir, &grid);
    if let Ok(lighting) = Lighting::parse(text, &data_dir, &grid) {
        for i in 0..3 {
            let _ = lighting.draw(1, i);
        }
    }
});
