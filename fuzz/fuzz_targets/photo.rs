//! Image decoding and chart detection: any bytes give a photo or a clear error, and a photo
//! gives an analysis or a clear error — never a panic or a runaway allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use spdcam_core::chart::Chart;
use spdcam_core::photo::{analyse, decode_photo, AnalyseOptions, ChartTemplate};
use spdcam_core::spectral::Grid;
use std::sync::OnceLock;

fn options() -> &'static AnalyseOptions {
    static OPTIONS: OnceLock<AnalyseOptions> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        // Keep each input quick: a header may declare up to the pixel limit, and decoding
        // 150 Mpx takes seconds. One megapixel still reaches every decoder path.
        std::env::set_var("SPDCAM_MAX_IMAGE_PIXELS", "1000000");
        let chart = Chart::colorchecker24(&Grid::SIMULATION).expect("built-in chart");
        AnalyseOptions {
            templates: vec![ChartTemplate::from_chart(&chart).expect("template")],
            ..AnalyseOptions::default()
        }
    })
}

fuzz_target!(|data: &[u8]| {
    let options = options();
    if let Ok(photo) = decode_photo(data, "fuzz") {
        assert!(photo.width >= 16 && photo.height >= 16);
        let _ = analyse(&photo, options);
    }
});
