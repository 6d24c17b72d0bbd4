//! `spdcam render`: one chart under one light through the virtual camera.

use crate::messages::Messages;
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::aberration::LateralAberration;
use spdcam_core::camera::demosaic::DemosaicMethod;
use spdcam_core::camera::noise::NoiseParams;
use spdcam_core::camera::sensor::{Sensitivities, SensorMode};
use spdcam_core::camera::white_balance::WhiteBalance;
use spdcam_core::camera::{Camera, CameraConfig, WhiteBalanceStatistics, MAX_EXPOSURE};
use spdcam_core::chart::{Chart, Layout};
use spdcam_core::error::short_number;
use spdcam_core::lighting::Lighting;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions, Shadow, Tilt, TiltAxis};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::{Grid, Spd, SpectralSet};
use spdcam_core::{fsio, imageio, light};
use std::path::{Path, PathBuf};

/// Camera and chart options shared by every command that renders.
#[derive(Debug, Args, Clone)]
pub struct CameraArgs {
    /// Camera sensitivities: a built-in name, a data-directory name or FILE.csv (r,g,b).
    #[arg(long, default_value = "nikon_d5100_npl")]
    pub camera: String,
    /// Chart: colorchecker24, colorchecker_sg96, colorchecker_sg140, or a reflectance CSV.
    #[arg(long, default_value = "colorchecker24")]
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

fn parse_pair(text: &str, what: &str) -> Result<(usize, usize)> {
    let (a, b) = text
        .split_once(['x', 'X', '×'])
        .with_context(|| format!("{what} '{text}' is not of the form AxB"))?;
    let a: usize = a
        .trim()
        .parse()
        .with_context(|| format!("{what} '{text}'"))?;
    let b: usize = b
        .trim()
        .parse()
        .with_context(|| format!("{what} '{text}'"))?;
    if a == 0 || b == 0 {
        bail!("{what} '{text}' must be positive");
    }
    Ok((a, b))
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

/// Options of `spdcam render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The light: D65, A, D50, cct:T, daylight:T, planck:T, or a spectral CSV (FILE.csv[:COLUMN]).
    #[arg(
        long,
        required_unless_present = "lighting",
        conflicts_with = "lighting"
    )]
    spd: Option<String>,
    /// Instead of --spd: a light drawn from a lighting recipe (`spdcam list lighting`), the
    /// one `spdcam generate --lighting RECIPE --seed SEED` draws for sample --draw.
    #[arg(long, value_name = "RECIPE", requires = "draw")]
    lighting: Option<String>,
    /// Which draw of --lighting (the sample index of a generated dataset).
    #[arg(long, value_name = "INDEX", requires = "lighting")]
    draw: Option<u64>,
    /// Output PNG (JPEG with --scene); `-` writes it to standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the feature row (mean sRGB 0–255 of each patch) as CSV; `-` for standard
    /// output.
    #[arg(long, value_name = "FILE.csv")]
    features: Option<PathBuf>,
    /// Also write every intermediate stage as an image into this directory.
    #[arg(long, value_name = "DIR")]
    stages: Option<PathBuf>,
    /// Seed of the noise (and of the scene).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Photograph the chart in a scene of WxH px instead: placed at a random position,
    /// rotation and perspective on a cluttered background under the same light, with blur,
    /// vignetting, noise, written as a JPEG (`-o photo.jpg`).
    #[arg(long, value_name = "WxH")]
    scene: Option<String>,
    /// With --scene: the patch grid's width as a share of the photo's width (face-on),
    /// e.g. 0.25 or 1/15; default: drawn between 0.3 and 0.6.
    #[arg(long, value_name = "SHARE", requires = "scene")]
    chart_width: Option<String>,
    /// With --scene: the chart's centre as shares of the photo's width and height (0.5,0.5
    /// is the middle); default: anywhere it fits.
    #[arg(long, value_name = "X,Y", requires = "scene")]
    chart_centre: Option<String>,
    /// With --scene: the chart's rotation in its own plane, degrees clockwise; default:
    /// drawn at random.
    #[arg(
        long,
        value_name = "DEG",
        requires = "scene",
        allow_negative_numbers = true
    )]
    chart_rotation: Option<f64>,
    /// With --scene: the chart's plane turned away from the camera by DEG (up to 85; a
    /// perspective view, foreshortened by about cos DEG); default: face-on with a little
    /// random perspective.
    #[arg(
        long,
        value_name = "DEG",
        requires = "scene",
        allow_negative_numbers = true
    )]
    tilt: Option<f64>,
    /// With --tilt: the photo's axis the chart is turned about: horizontal (a chart lying
    /// on a table) or vertical (a chart on a side wall).
    #[arg(
        long,
        value_name = "AXIS",
        default_value = "horizontal",
        requires = "tilt"
    )]
    tilt_axis: TiltAxisArg,
    /// With --scene: a shadow over part of the chart, FACTOR (the light left in it, 0–1)
    /// [,COVER (the share of the chart shaded, default 0.5) [,DIRECTION (degrees clockwise
    /// from the chart's right side it comes from, default 0)]].
    #[arg(long, value_name = "FACTOR[,COVER[,DIR]]", requires = "scene")]
    shadow: Option<String>,
    /// With --scene: a second light on the right half of the chart (as --spd), at the
    /// exposure the first gives; the camera balances the photo as a whole (see
    /// --balance-halves).
    #[arg(long, value_name = "SPD", requires = "scene")]
    right_light: Option<String>,
    /// With --right-light: each half exposed and white-balanced for its own light (two
    /// photos of the scene joined at the chart's middle).
    #[arg(long, requires = "right_light")]
    balance_halves: bool,
    /// Also write the light's SPD (normalised to a maximum of 1) as spectral CSV, e.g. as
    /// the truth beside a scene photo.
    #[arg(long, value_name = "FILE.csv")]
    spd_out: Option<PathBuf>,
    #[command(flatten)]
    camera: CameraArgs,
}

/// The axis a chart is tilted about (`--tilt-axis`).
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum TiltAxisArg {
    /// The photo's horizontal axis.
    Horizontal,
    /// The photo's vertical axis.
    Vertical,
}

/// A share written as a decimal or a fraction (`0.25`, `1/15`).
fn parse_share(text: &str, what: &str) -> Result<f64> {
    let value = match text.split_once('/') {
        Some((a, b)) => {
            let a: f64 = a.trim().parse().ok().context(format!("{what} '{text}'"))?;
            let b: f64 = b.trim().parse().ok().context(format!("{what} '{text}'"))?;
            a / b
        }
        None => text
            .trim()
            .parse()
            .ok()
            .with_context(|| format!("{what} '{text}' is not a number"))?,
    };
    if !(value > 0.0 && value < 1.0) {
        bail!("{what} '{text}' must be a share between 0 and 1 (e.g. 0.25 or 1/15)");
    }
    Ok(value)
}

/// Comma-separated numbers.
fn parse_numbers(text: &str, what: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("{what} '{text}': '{s}' is not a number"))
        })
        .collect()
}

impl RenderArgs {
    /// The scene options of a `width × height` scene these arguments describe.
    fn scene_options(&self, width: usize, height: usize) -> Result<SceneOptions> {
        let mut options = SceneOptions {
            width,
            height,
            ..SceneOptions::default()
        };
        if let Some(text) = &self.chart_width {
            let share = parse_share(text, "--chart-width")?;
            options.width_share = (share, share);
        }
        if let Some(text) = &self.chart_centre {
            match parse_numbers(text, "--chart-centre")?.as_slice() {
                &[x, y] => options.centre = Some([x, y]),
                _ => bail!("--chart-centre '{text}' needs two shares X,Y (0.5,0.5 is the middle)"),
            }
        }
        options.rotation_deg = self.chart_rotation;
        options.balance_halves = self.balance_halves;
        options.tilt = self.tilt.map(|degrees| Tilt {
            degrees,
            axis: match self.tilt_axis {
                TiltAxisArg::Horizontal => TiltAxis::Horizontal,
                TiltAxisArg::Vertical => TiltAxis::Vertical,
            },
        });
        if let Some(text) = &self.shadow {
            let v = parse_numbers(text, "--shadow")?;
            if v.is_empty() || v.len() > 3 {
                bail!("--shadow '{text}' needs FACTOR[,COVER[,DIRECTION]]");
            }
            options.shadow = Some(Shadow {
                factor: v[0],
                cover: v.get(1).copied().unwrap_or(0.5),
                direction_deg: v.get(2).copied().unwrap_or(0.0),
            });
        }
        Ok(options)
    }
}

/// Runs `spdcam render`.
pub fn run(args: RenderArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    for path in std::iter::once(&args.output).chain(&args.features) {
        if !fsio::is_stdout(path) {
            fsio::check_parent_dir(path)?;
        }
    }
    if fsio::is_stdout(&args.output) && args.features.as_deref().is_some_and(fsio::is_stdout) {
        bail!("only one of -o and --features can go to standard output");
    }
    let messages = Messages::new(
        fsio::is_stdout(&args.output) || args.features.as_deref().is_some_and(fsio::is_stdout),
    );
    if let Some(dir) = &args.stages {
        // Made here, before the render, so a bad place fails at once.
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot make the stages directory {}", dir.display()))?;
    }
    if let Some(path) = &args.spd_out {
        fsio::check_parent_dir(path)?;
    }
    let scene = args
        .scene
        .as_deref()
        .map(|s| parse_pair(s, "scene"))
        .transpose()?;
    if let Some((w, h)) = scene {
        scene::check_scene_size(w, h)?;
        args.scene_options(w, h)?;
    }
    let extension = args
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match (&scene, extension.as_deref()) {
        (Some(_), Some("jpg" | "jpeg")) | (None, Some("png")) => {}
        _ if fsio::is_stdout(&args.output) => {}
        (Some(_), _) => bail!("a scene is written as JPEG: name the output FILE.jpg"),
        (None, _) => bail!("the chart is written as PNG: name the output FILE.png"),
    }
    let spd = match (&args.spd, &args.lighting, args.draw) {
        (Some(spec), _, _) => light::resolve_spd(spec, data_dir, &grid)?,
        (None, Some(recipe), Some(index)) => {
            let draw = Lighting::parse(recipe, data_dir, &grid)?.draw(args.seed, index)?;
            light::ResolvedSpd {
                name: format!("{recipe} draw {index} (seed {})", args.seed),
                spd: draw.spd,
                resampling: None,
            }
        }
        _ => bail!("give the light as --spd, or as --lighting RECIPE --draw INDEX"),
    };
    if let Some(report) = spd.resampling.as_ref().filter(|r| r.extrapolated()) {
        eprintln!(
            "warning: {}",
            report.describe(&format!("light {}", spd.name), &grid)
        );
    }
    if let Some(path) = &args.spd_out {
        let values = spd.spd.normalised_by_max().into_values();
        SpectralSet::on_grid(&grid, vec![spd.name.clone()], vec![values])?.write_csv(path)?;
        messages.say(format_args!("light SPD: {}", path.display()));
    }
    if let Some((width, height)) = scene {
        return render_scene(
            &args,
            &spd.spd,
            &spd.name,
            (width, height),
            data_dir,
            messages,
        );
    }
    let camera = args.camera.camera(data_dir, &grid)?;
    let rendering = camera.render(&spd.spd, args.seed, args.stages.is_some())?;
    let depth = camera.config().colour.bit_depth;
    if let Some(dir) = &args.stages {
        write_stages(dir, &rendering.stages)?;
        messages.say(format_args!(
            "stages (linear raw, 16-bit): {}",
            dir.display()
        ));
    }
    if let Some(path) = &args.features {
        let names = camera.chart().feature_names();
        let values: Vec<String> = rendering.features.iter().map(|v| format!("{v}")).collect();
        let text = format!("{}\n{}\n", names.join(","), values.join(","));
        fsio::write_output(path, text.as_bytes())?;
        if !fsio::is_stdout(path) {
            messages.say(format_args!("features: {}", path.display()));
        }
    }
    fsio::write_output(&args.output, &imageio::encode_png(&rendering.image, depth)?)?;
    if fsio::is_stdout(&args.output) {
        return Ok(());
    }
    let l = &camera.chart().layout;
    messages.say(format_args!(
        "rendered {} under {} with {} ({}×{} px, {}-bit sRGB): {}",
        camera.chart().name,
        spd.name,
        camera.camera_name(),
        l.width,
        l.height,
        depth,
        args.output.display()
    ));
    Ok(())
}

/// `render --scene`: the chart rendered at the scene pitch and photographed in a scene.
fn render_scene(
    args: &RenderArgs,
    spd: &Spd,
    light_name: &str,
    (width, height): (usize, usize),
    data_dir: &DataDir,
    messages: Messages,
) -> Result<()> {
    let grid = Grid::SIMULATION;
    let chart = args.camera.chart(data_dir, &grid)?;
    let template = ChartTemplate::from_chart(&chart)?;
    let chart = chart.with_layout(scene::scene_layout(&template))?;
    let camera = args.camera.camera_for(chart, data_dir, &grid)?;
    let options = args.scene_options(width, height)?;
    let right = args
        .right_light
        .as_deref()
        .map(|spec| light::resolve_spd(spec, data_dir, &grid))
        .transpose()?;
    let light = SceneLight {
        spd,
        right_half: right.as_ref().map(|r| &r.spd),
    };
    let shot = scene::photograph(&camera, light, args.seed, &options)?;
    let chart = camera.chart();
    fsio::write_output(&args.output, &shot.jpeg)?;
    if fsio::is_stdout(&args.output) {
        return Ok(());
    }
    let corners: Vec<String> = shot
        .corners
        .iter()
        .map(|[x, y]| format!("{x:.1},{y:.1}"))
        .collect();
    let light_name = match &right {
        Some(r) => format!("{light_name} (right half: {})", r.name),
        None => light_name.to_string(),
    };
    messages.say(format_args!(
        "photographed {} under {light_name} with {} in a {width}×{height} scene: {} (chart corners {})",
        chart.name,
        camera.camera_name(),
        args.output.display(),
        corners.join(",")
    ));
    Ok(())
}

fn write_stages(dir: &Path, stages: &spdcam_core::camera::Stages) -> Result<()> {
    if let Some(cfa) = &stages.cfa {
        imageio::write_mosaic_png(&dir.join("1_cfa.png"), cfa)?;
    }
    for (name, image) in [
        ("2_demosaiced.png", &stages.demosaiced),
        ("3_white_balanced.png", &stages.white_balanced),
        ("4_aberrated.png", &stages.aberrated),
    ] {
        if let Some(image) = image {
            imageio::write_png(&dir.join(name), image, 16)?;
        }
    }
    Ok(())
}
