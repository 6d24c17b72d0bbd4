//! `spdcam render` of the chart alone (no `--scene`): the chart's image as PNG, or its
//! mosaic as a raw DNG, with the stages and the feature row when asked.

use super::RenderArgs;
use crate::messages::Messages;
use anyhow::Result;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::Camera;
use spdcam_core::fsio;
use spdcam_core::imageio;
use spdcam_core::photo::raw::dng::{virtual_camera_dng, virtual_exposure};
use spdcam_core::photo::Exposure;
use spdcam_core::spectral::{Grid, Spd};
use std::path::Path;

/// Renders the chart of `args` under `spd` (named `light_name`) on `grid` and writes it:
/// as a raw DNG when `dng`, else as PNG.
pub(super) fn render_chart(
    args: &RenderArgs,
    spd: &Spd,
    light_name: &str,
    grid: &Grid,
    data_dir: &DataDir,
    messages: Messages,
    dng: bool,
) -> Result<()> {
    let camera = args.camera.camera(data_dir, grid)?;
    let rendering = camera.render(spd, args.seed, args.stages.is_some() || dng)?;
    let depth = camera.config().colour.bit_depth;
    if let Some(dir) = &args.stages {
        write_stages(dir, &rendering.stages)?;
        messages.say(format_args!(
            "stages (linear raw, 16-bit): {}",
            dir.display()
        ))?;
    }
    if let Some(path) = &args.features {
        let names = camera.chart().feature_names();
        let values: Vec<String> = rendering.features.iter().map(|v| format!("{v}")).collect();
        let text = format!("{}\n{}\n", names.join(","), values.join(","));
        fsio::write_output(path, text.as_bytes())?;
        if !fsio::is_stdout(path) {
            messages.say(format_args!("features: {}", path.display()))?;
        }
    }
    if dng {
        let mosaic = rendering.stages.cfa.as_ref().ok_or_else(|| {
            anyhow::anyhow!("a three-sensor camera has no mosaic to write as a DNG")
        })?;
        let exposure = args
            .illuminance
            .map(|lux| dng_exposure(&camera, spd, lux))
            .transpose()?;
        fsio::write_output(
            &args.output,
            &virtual_camera_dng(&camera, spd, mosaic, exposure)?,
        )?;
    } else {
        fsio::write_output(&args.output, &imageio::encode_png(&rendering.image, depth)?)?;
    }
    if fsio::is_stdout(&args.output) {
        return Ok(());
    }
    let l = &camera.chart().layout;
    messages.say(format_args!(
        "rendered {} under {} with {} ({}×{} px, {}): {}",
        camera.chart().name,
        light_name,
        camera.camera_name(),
        l.width,
        l.height,
        if dng {
            "raw DNG".to_string()
        } else {
            format!("{depth}-bit sRGB")
        },
        args.output.display()
    ))?;
    Ok(())
}

/// The EXIF exposure of a DNG `camera` took under `spd` lighting its chart at `lux`
/// (`--illuminance`): at the exposure the camera metered
/// ([`spdcam_core::photo::raw::dng::virtual_exposure`]).
pub(super) fn dng_exposure(camera: &Camera, spd: &Spd, lux: f64) -> Result<Exposure> {
    let scale = camera.exposed_chart_at(&[spd], None)?.1;
    Ok(virtual_exposure(camera, spd, scale, lux)?)
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
