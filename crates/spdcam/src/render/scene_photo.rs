//! `render --scene`: the chart photographed in a scene, and the scene options that
//! `render`'s flags describe.

use super::parse::{parse_numbers, parse_share};
use super::{RenderArgs, TiltAxisArg};
use crate::messages::Messages;
use anyhow::{bail, Result};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::Camera;
use spdcam_core::chart::Chart;
use spdcam_core::photo::raw::dng::virtual_camera_dng;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions, Shadow, Tilt, TiltAxis};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::raster::Mosaic;
use spdcam_core::spectral::{Grid, Spd};
use spdcam_core::{fsio, named_light};

impl RenderArgs {
    /// The scene options of a `width × height` scene these arguments describe.
    pub(super) fn scene_options(&self, width: usize, height: usize) -> Result<SceneOptions> {
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

/// `render --scene`: the chart rendered at the scene pitch and photographed in a scene.
pub(super) fn render_scene(
    args: &RenderArgs,
    spd: &Spd,
    light_name: &str,
    (width, height): (usize, usize),
    data_dir: &DataDir,
    messages: Messages,
) -> Result<()> {
    let grid = Grid::SIMULATION;
    let camera = scene_camera(args, args.camera.chart(data_dir, &grid)?, data_dir)?;
    let options = args.scene_options(width, height)?;
    let right = args
        .right_light
        .as_deref()
        .map(|spec| named_light::resolve_spd(spec, data_dir, &grid))
        .transpose()?;
    for note in right.iter().flat_map(|r| &r.notes) {
        eprintln!("note: {note}");
    }
    let light = SceneLight {
        spd,
        right_half: right.as_ref().map(|r| &r.spd),
    };
    let shot = scene::photograph(&camera, light, args.seed, &options)?;
    let chart = camera.chart();
    write_scene(
        args,
        (&camera, spd),
        &shot.jpeg,
        shot.mosaic.as_ref(),
        "a three-sensor camera, or two halves developed apart",
    )?;
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
    ))?;
    Ok(())
}

/// The camera of the render's options photographing `chart` laid out for a scene
/// ([`scene::scene_layout`]).
pub(super) fn scene_camera(args: &RenderArgs, chart: Chart, data_dir: &DataDir) -> Result<Camera> {
    let template = ChartTemplate::from_chart(&chart)?;
    let chart = chart.with_layout(scene::scene_layout(&template))?;
    args.camera.camera_for(chart, data_dir, &Grid::SIMULATION)
}

/// Writes a scene photo to `--output`: its JPEG, or for FILE.dng the sensor's `mosaic` as
/// `camera` under `light` would write it, with the EXIF exposure of `--illuminance` when
/// given (`no_mosaic` says why a scene has none).
pub(super) fn write_scene(
    args: &RenderArgs,
    (camera, light): (&Camera, &Spd),
    jpeg: &[u8],
    mosaic: Option<&Mosaic>,
    no_mosaic: &str,
) -> Result<()> {
    let dng = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("dng"));
    if !dng {
        return Ok(fsio::write_output(&args.output, jpeg)?);
    }
    let mosaic = mosaic.ok_or_else(|| {
        anyhow::anyhow!("this scene has no single mosaic to write as a DNG ({no_mosaic})")
    })?;
    let exposure = args
        .illuminance
        .map(|lux| super::chart_photo::dng_exposure(camera, light, lux))
        .transpose()?;
    Ok(fsio::write_output(
        &args.output,
        &virtual_camera_dng(camera, light, mosaic, exposure)?,
    )?)
}
