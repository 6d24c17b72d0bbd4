//! `spdcam render`: one chart under one light through the virtual camera.

mod camera_args;
mod chart_photo;
mod parse;
mod places_photo;
mod scene_photo;

pub use camera_args::CameraArgs;

use crate::messages::Messages;
use anyhow::{bail, Context, Result};
use chart_photo::render_chart;
use clap::Args;
use parse::parse_pair;
use places_photo::render_places;
use scene_photo::render_scene;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::Lighting;
use spdcam_core::photo::scene;
use spdcam_core::spectral::{Grid, SpectralSet};
use spdcam_core::{fsio, limits, named_light};
use std::path::PathBuf;

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
    /// Output PNG (JPEG with --scene), or FILE.dng for a raw DNG of the sensor's mosaic
    /// before any processing (black and white levels, CFA pattern, colour matrices fitted
    /// under A and D65, the light's neutral as shot); `-` writes it to standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// With FILE.dng: the light's illuminance on the chart, lux; the DNG then carries the
    /// EXIF exposure (f/4, ISO 100 as the sensor's ISO 12232 saturation-based speed, and
    /// the time that puts the chart's raw values at that illuminance), from which
    /// `estimate` reads absolute levels. With --place, the first chart's illuminance (each
    /// other chart's is this times its light level relative to the first's, as printed).
    /// Not with --right-light.
    #[arg(long, value_name = "LUX", conflicts_with = "right_light")]
    illuminance: Option<f64>,
    /// Also write the feature row (mean sRGB 0–255 of each patch) as CSV; `-` for standard
    /// output.
    #[arg(long, value_name = "FILE.csv")]
    features: Option<PathBuf>,
    /// Also write every intermediate stage as an image into this directory. The stages are
    /// held beside the image, so each pixel counts twice against SPDCAM_MAX_RENDER_PIXELS.
    /// Not with --scene: a scene photo is developed in one pass, without stage images.
    #[arg(long, value_name = "DIR", conflicts_with = "scene")]
    stages: Option<PathBuf>,
    /// Seed of the noise (and of the scene).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Photograph the chart in a scene of WxH px instead: placed at a random position,
    /// rotation and perspective on a cluttered background under the same light, with blur,
    /// vignetting, noise, written as a JPEG (`-o photo.jpg`) or a raw DNG (`-o photo.dng`).
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
    /// With --scene: one chart of several in the scene instead of the one chart, as
    /// space-separated KEY=VALUE: centre=X,Y (shares of the photo; required), chart=NAME
    /// (default --chart), width=SHARE (of the photo's width, default 0.2), light=SPD (as
    /// --spd; default --spd), level=L (the light's level, default 1; 0.5: half as bright, as
    /// in a shadow), rotation=DEG, tilt=DEG, tilt-axis=horizontal|vertical,
    /// passport=creative|white-balance (held in a Passport's case beside that page). Once
    /// per chart (up to 8), exposed for the first, numbered left to right as `estimate`
    /// numbers them; --spd-out writes one column per chart in that order.
    #[arg(
        long = "place",
        value_name = "KEY=VALUE …",
        requires = "scene",
        conflicts_with_all = ["chart_width", "chart_centre", "chart_rotation", "tilt", "shadow", "right_light"]
    )]
    places: Vec<String>,
    /// Also write the light's SPD (normalised to a maximum of 1) as spectral CSV (`-`: to
    /// standard output), e.g. as the truth beside a scene photo.
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

/// Runs `spdcam render`.
pub fn run(args: RenderArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    // The command line's output guard has checked that at most one of them is `-`.
    let files = || {
        std::iter::once(&args.output)
            .chain(&args.features)
            .chain(&args.spd_out)
    };
    for path in files() {
        if !fsio::is_stdout(path) {
            fsio::check_parent_dir(path)?;
        }
    }
    let messages = Messages::new(files().any(|p| fsio::is_stdout(p)));
    if let Some(dir) = &args.stages {
        let l = args.camera.chart(data_dir, &grid)?.layout;
        limits::RENDER_PIXELS.check(
            limits::product(&[l.width as u64, l.height as u64, 2]),
            &format!(
                "--stages with a {}×{} chart (the stage images are held beside the image, so \
                 each pixel counts twice; render a smaller chart with --size or --patch-px)",
                l.width, l.height
            ),
        )?;
        // Made here, before the render, so a bad place fails at once.
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot make the stages directory {}", dir.display()))?;
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
    let dng = extension.as_deref() == Some("dng");
    match (&scene, extension.as_deref()) {
        (Some(_), Some("jpg" | "jpeg" | "dng")) | (None, Some("png" | "dng")) => {}
        _ if fsio::is_stdout(&args.output) => {}
        (Some(_), _) => bail!(
            "a scene is written as JPEG or as a raw DNG: name the output FILE.jpg or FILE.dng"
        ),
        (None, _) => bail!(
            "the chart is written as PNG or as a raw DNG: name the output FILE.png or FILE.dng"
        ),
    }
    if args.illuminance.is_some() && !dng {
        bail!(
            "--illuminance sets the EXIF exposure of a raw DNG: name the output FILE.dng \
             (a JPEG or PNG has no exposure written)"
        );
    }
    let spd = match (&args.spd, &args.lighting, args.draw) {
        (Some(spec), _, _) => named_light::resolve_spd(spec, data_dir, &grid)?,
        (None, Some(recipe), Some(index)) => {
            let draw = Lighting::parse(recipe, data_dir, &grid)?.draw(args.seed, index)?;
            named_light::ResolvedSpd {
                name: format!("{recipe} draw {index} (seed {})", args.seed),
                spd: draw.spd,
                resampling: None,
                notes: Vec::new(),
            }
        }
        _ => bail!("give the light as --spd, or as --lighting RECIPE --draw INDEX"),
    };
    for note in &spd.notes {
        eprintln!("note: {note}");
    }
    if let Some(report) = spd.resampling.as_ref().filter(|r| r.extrapolated()) {
        eprintln!(
            "warning: {}",
            report.describe(&format!("light {}", spd.name), &grid)
        );
    }
    let several = !args.places.is_empty();
    if let (Some(path), false) = (&args.spd_out, several) {
        let values = spd.spd.normalised_by_max().into_values();
        let set = SpectralSet::on_grid(&grid, vec![spd.name.clone()], vec![values])?;
        fsio::write_output(path, set.to_csv_string().as_bytes())?;
        if !fsio::is_stdout(path) {
            messages.say(format_args!("light SPD: {}", path.display()))?;
        }
    }
    if let Some(size) = scene {
        // Several charts write their own truths, one per place.
        let photograph = if several { render_places } else { render_scene };
        return photograph(&args, &spd.spd, &spd.name, size, data_dir, messages);
    }
    render_chart(&args, &spd.spd, &spd.name, &grid, data_dir, messages, dng)
}
