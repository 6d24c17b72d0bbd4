//! The camera and chart options every command that renders shares (`--camera`, `--chart`,
//! the chart's geometry, the camera's settings), and the camera they describe.

use super::parse::parse_pair;
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::aberration::LateralAberration;
use spdcam_core::camera::demosaic::DemosaicMethod;
use spdcam_core::camera::noise::NoiseParams;
use spdcam_core::camera::sensor::{Sensitivities, SensorMode};
use spdcam_core::camera::white_balance::WhiteBalance;
use spdcam_core::camera::{
    too_low_exposure, Camera, CameraConfig, WhiteBalanceStatistics, MAX_EXPOSURE, MIN_EXPOSURE,
};
use spdcam_core::chart::{Chart, KnownChart, Layout};
use spdcam_core::error::short_number;
use spdcam_core::spectral::Grid;

/// The help of `--chart`, every known chart's name from the chart registry:
/// `Chart: colorchecker24, …, or a reflectance CSV`.
fn chart_help() -> String {
    let names: Vec<&str> = KnownChart::ALL.iter().map(|c| c.name()).collect();
    format!("Chart: {}, or a reflectance CSV", names.join(", "))
}

/// Camera and chart options shared by every command that renders.
#[derive(Debug, Args, Clone)]
pub struct CameraArgs {
    /// Camera sensitivities: a built-in name, a data-directory name or FILE.csv (r,g,b).
    #[arg(long, default_value = "nikon_d5100_npl")]
    pub camera: String,
    /// Chart: a known chart's name or a reflectance CSV (its help names the known ones).
    #[arg(long, default_value = KnownChart::ColorChecker24.name(), help = chart_help())]
    pub chart: String,
    /// Layout ROWSxCOLS of a chart given as a reflectance CSV.
    #[arg(long, value_name = "ROWSxCOLS")]
    pub layout: Option<String>,
    /// Patch size in pixels (the thesis: 24).
    #[arg(long, default_value_t = 24)]
    pub patch_px: usize,
    /// Gap between patches in pixels.
    #[arg(long, default_value_t = 0)]
    pub gap_px: usize,
    /// Border around the patches in pixels.
    #[arg(long, default_value_t = 0)]
    pub border_px: usize,
    /// Image size WxH: fit the chart into it (overrides --patch-px, --gap-px, --border-px).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Sensor: a Bayer pattern (rggb, bggr, grbg, gbrg) or `three` for three sensors.
    #[arg(long, default_value = "rggb")]
    pub sensor: SensorMode,
    /// Brightest raw value as a fraction of full scale (0 < e ≤ 100; above 1 clips).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub exposure: f64,
    /// Noise preset: thesis, phone, or off.
    #[arg(long, default_value = "thesis")]
    pub noise: String,
    /// Demosaicing: menon2007, malvar2004, bilinear.
    #[arg(long, default_value = "menon2007")]
    pub demosaic: DemosaicMethod,
    /// White balance: none, grey-world, white-patch, shades-of-grey[:p], grey-edge[:p[:sigma]].
    #[arg(long, default_value = "shades-of-grey:6")]
    pub white_balance: WhiteBalance,
    /// White-balance statistics from the 2×2-binned raw mosaic (`raw`, as camera ISPs) or
    /// the demosaiced image (`demosaiced`, as the thesis).
    #[arg(long, default_value = "raw")]
    pub white_balance_statistics: WhiteBalanceStatistics,
    /// Lateral chromatic aberration strength, or `off` (the thesis: 0.005 = 20/4000).
    #[arg(long, default_value = "0.005")]
    pub aberration: String,
    /// Skip the D65-fitted colour-correction matrix.
    #[arg(long)]
    pub no_colour_correction: bool,
    /// Output bits per channel: 8 or 16.
    #[arg(long, default_value_t = 8)]
    pub bit_depth: u32,
}

impl CameraArgs {
    /// The camera settings these options describe.
    pub fn config(&self) -> Result<CameraConfig> {
        if !(self.exposure > 0.0 && self.exposure <= MAX_EXPOSURE) {
            bail!(
                "--exposure {} is not a positive fraction of full scale up to {MAX_EXPOSURE} \
                 (e.g. 0.8, or 1.5 to clip)",
                short_number(self.exposure)
            );
        }
        if self.exposure < MIN_EXPOSURE {
            bail!("--{}", too_low_exposure(self.exposure));
        }
        let noise = match self.noise.as_str() {
            "off" | "none" => None,
            name => Some(NoiseParams::preset(name)?),
        };
        let aberration = match self.aberration.as_str() {
            "off" | "none" => None,
            s => {
                let strength: f64 = s
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite() && v.abs() < 0.5)
                    .with_context(|| {
                        format!("aberration '{s}' is not a strength in (-0.5, 0.5) or 'off'")
                    })?;
                Some(LateralAberration { strength })
            }
        };
        let mut config = CameraConfig {
            noise,
            demosaic: self.demosaic,
            white_balance: self.white_balance,
            white_balance_statistics: self.white_balance_statistics,
            aberration,
            ..CameraConfig::default()
        };
        config.sensor.mode = self.sensor;
        config.sensor.exposure = self.exposure;
        config.colour.correction = !self.no_colour_correction;
        config.colour.bit_depth = self.bit_depth;
        Ok(config)
    }

    /// The chart with the requested geometry.
    pub fn chart(&self, data_dir: &DataDir, grid: &Grid) -> Result<Chart> {
        let layout = self
            .layout
            .as_deref()
            .map(|l| parse_pair(l, "layout"))
            .transpose()?;
        let chart = Chart::resolve(&self.chart, layout, data_dir, grid)?;
        let (rows, cols) = (chart.layout.rows, chart.layout.cols);
        let geometry = match &self.size {
            Some(size) => {
                let (w, h) = parse_pair(size, "size")?;
                Layout::fit(rows, cols, w, h, 0.1, 0.3)?
            }
            None => Layout::grid(rows, cols, self.patch_px, self.gap_px, self.border_px),
        };
        Ok(chart.with_layout(geometry)?)
    }

    /// The camera: sensitivities, chart and settings.
    pub fn camera(&self, data_dir: &DataDir, grid: &Grid) -> Result<Camera> {
        self.camera_for(self.chart(data_dir, grid)?, data_dir, grid)
    }

    /// The camera with these sensitivities and settings, photographing `chart`.
    pub fn camera_for(&self, chart: Chart, data_dir: &DataDir, grid: &Grid) -> Result<Camera> {
        let sensitivities = Sensitivities::resolve(&self.camera, data_dir, grid)?;
        Ok(Camera::new(&sensitivities, chart, self.config()?, grid)?)
    }
}
