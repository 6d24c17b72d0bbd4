//! `render --scene … --place …`: several charts photographed in one scene, each under its
//! own light (or one light at different levels), the truth of each written beside.

use super::parse::{parse_numbers, parse_share};
use super::scene_photo::{scene_camera, write_scene};
use super::RenderArgs;
use crate::messages::Messages;
use anyhow::{bail, Context, Result};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::Camera;
use spdcam_core::chart::{shown_chart_name, Chart, KnownChart};
use spdcam_core::photo::pocket::{page_camera, PassportPage};
use spdcam_core::photo::quad_centre;
use spdcam_core::photo::scene::{SceneOptions, Tilt, TiltAxis};
use spdcam_core::photo::scene_places::{photograph_places, ScenePlace, MAX_PLACES};
use spdcam_core::spectral::{Grid, Spd, SpectralSet};
use spdcam_core::{fsio, named_light};

/// One `--place`: a chart, where it lies and its light.
#[derive(Debug, Clone, PartialEq)]
struct PlaceSpec {
    chart: Option<String>,
    centre: [f64; 2],
    width: f64,
    light: Option<String>,
    level: f64,
    rotation: f64,
    tilt: Option<Tilt>,
    passport: Option<PassportPage>,
}

/// Reads one `--place` value: space-separated KEY=VALUE (see `RenderArgs::places`).
fn parse_place(text: &str) -> Result<PlaceSpec> {
    let mut spec = PlaceSpec {
        chart: None,
        centre: [f64::NAN; 2],
        width: 0.2,
        light: None,
        level: 1.0,
        rotation: 0.0,
        tilt: None,
        passport: None,
    };
    let mut axis = TiltAxis::Vertical;
    let mut tilt = None;
    for item in text.split_whitespace() {
        let (key, value) = item.split_once('=').with_context(|| {
            format!("--place '{text}': '{item}' is not KEY=VALUE (e.g. centre=0.3,0.5)")
        })?;
        let number = |v: &str| -> Result<f64> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .with_context(|| format!("--place '{text}': {key}={v} is not a number"))
        };
        match key {
            "chart" => spec.chart = Some(value.to_string()),
            "centre" | "center" => match parse_numbers(value, "--place centre")?.as_slice() {
                &[x, y] => spec.centre = [x, y],
                _ => bail!("--place '{text}': centre needs two shares X,Y (0.5,0.5 is the middle)"),
            },
            "width" => spec.width = parse_share(value, "--place width")?,
            "light" => spec.light = Some(value.to_string()),
            "level" => spec.level = number(value)?,
            "rotation" => spec.rotation = number(value)?,
            "tilt" => tilt = Some(number(value)?),
            "tilt-axis" => {
                axis = match value {
                    "horizontal" => TiltAxis::Horizontal,
                    "vertical" => TiltAxis::Vertical,
                    _ => bail!("--place '{text}': tilt-axis is horizontal or vertical"),
                }
            }
            "passport" => {
                spec.passport = Some(PassportPage::from_name(value).with_context(|| {
                    format!(
                        "--place '{text}': passport={value} names no page of the Passport; \
                         give passport={}",
                        PassportPage::ALL
                            .map(PassportPage::name)
                            .join(" or passport=")
                    )
                })?)
            }
            _ => bail!(
                "--place '{text}': unknown key '{key}' (the keys: chart, centre, width, light, \
                 level, rotation, tilt, tilt-axis, passport)"
            ),
        }
    }
    if spec.centre.iter().any(|v| v.is_nan()) {
        bail!("--place '{text}' needs centre=X,Y (shares of the photo's width and height)");
    }
    if spec.level <= 0.0 {
        bail!(
            "--place '{text}': level {} must be above 0 (1: the light as given, 0.5: half as \
             bright)",
            spec.level
        );
    }
    spec.tilt = tilt.map(|degrees| Tilt { degrees, axis });
    Ok(spec)
}

/// `render --scene WxH --place … [--place …]`: the charts photographed in one scene, the
/// photo written as JPEG or DNG, and with `--spd-out` each chart's light (peak 1) as one
/// column, in the order `estimate` numbers the charts (left to right).
pub(super) fn render_places(
    args: &RenderArgs,
    default_light: &Spd,
    default_name: &str,
    (width, height): (usize, usize),
    data_dir: &DataDir,
    messages: Messages,
) -> Result<()> {
    let grid = Grid::SIMULATION;
    if args.places.len() > MAX_PLACES {
        bail!(
            "{} --place given: a scene holds at most {MAX_PLACES} charts",
            args.places.len()
        );
    }
    let specs = args
        .places
        .iter()
        .map(|t| parse_place(t))
        .collect::<Result<Vec<_>>>()?;
    let mut cameras: Vec<Camera> = Vec::with_capacity(specs.len());
    let mut pages: Vec<Option<Camera>> = Vec::with_capacity(specs.len());
    let mut lights: Vec<(String, Spd)> = Vec::with_capacity(specs.len());
    for spec in &specs {
        let name = spec.chart.as_deref().unwrap_or(&args.camera.chart);
        let chart = Chart::resolve(name, None, data_dir, &grid)?;
        let camera = scene_camera(args, chart, data_dir)?;
        pages.push(match spec.passport {
            Some(page) => {
                let chart = &camera.chart().name;
                if KnownChart::from_name(chart) != Some(KnownChart::ColorChecker24) {
                    bail!(
                        "--place passport={}: a ColorChecker Passport holds the {}, not {}",
                        page.name(),
                        KnownChart::ColorChecker24.shown_name(),
                        shown_chart_name(chart)
                    );
                }
                let sensitivities = Sensitivities::resolve(&args.camera.camera, data_dir, &grid)?;
                Some(page_camera(page, &sensitivities, &camera)?)
            }
            None => None,
        });
        cameras.push(camera);
        lights.push(match &spec.light {
            Some(text) => {
                let resolved = named_light::resolve_spd(text, data_dir, &grid)?;
                for note in &resolved.notes {
                    eprintln!("note: {note}");
                }
                (resolved.name, resolved.spd)
            }
            None => (default_name.to_string(), default_light.clone()),
        });
    }
    let places: Vec<ScenePlace> = specs
        .iter()
        .zip(&cameras)
        .zip(&lights)
        .zip(&pages)
        .map(|(((spec, camera), (_, light)), page)| ScenePlace {
            camera,
            light,
            level: spec.level,
            placing: SceneOptions {
                width_share: (spec.width, spec.width),
                centre: Some(spec.centre),
                rotation_deg: Some(spec.rotation),
                tilt: spec.tilt,
                perspective: 0.0,
                ..SceneOptions::default()
            },
            case: page.as_ref(),
        })
        .collect();
    let options = SceneOptions {
        width,
        height,
        ..SceneOptions::default()
    };
    let shot = photograph_places(&places, args.seed, &options)?;
    write_scene(
        args,
        (&cameras[0], &lights[0].1),
        &shot.jpeg,
        shot.mosaic.as_ref(),
        "a three-sensor camera",
    )?;
    // Left to right, as `estimate` numbers the charts it finds.
    let mut order: Vec<usize> = (0..places.len()).collect();
    order.sort_by(|&a, &b| {
        let (ca, cb) = (
            quad_centre(&shot.places[a].corners),
            quad_centre(&shot.places[b].corners),
        );
        ca[0].total_cmp(&cb[0]).then(ca[1].total_cmp(&cb[1]))
    });
    if let Some(path) = &args.spd_out {
        let names = (1..=order.len()).map(|k| format!("place {k}")).collect();
        let values = order
            .iter()
            .map(|&k| lights[k].1.normalised_by_max().into_values())
            .collect();
        let set = SpectralSet::on_grid(&grid, names, values)?;
        fsio::write_output(path, set.to_csv_string().as_bytes())?;
        if !fsio::is_stdout(path) {
            messages.say(format_args!(
                "light SPDs (one column per place): {}",
                path.display()
            ))?;
        }
    }
    if fsio::is_stdout(&args.output) {
        return Ok(());
    }
    messages.say(format_args!(
        "photographed {} charts with {} in a {width}×{height} scene: {}",
        places.len(),
        cameras[0].camera_name(),
        args.output.display()
    ))?;
    for (number, &k) in order.iter().enumerate() {
        let truth = &shot.places[k];
        let c = quad_centre(&truth.corners);
        messages.say(format_args!(
            "  place {}: {} under {} at {:.0}, {:.0} px, light level {:.3} of the first --place",
            number + 1,
            truth.chart,
            lights[k].0,
            c[0],
            c[1],
            truth.relative_illuminance
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_place_reads_every_key() {
        let p = parse_place(
            "chart=colorchecker24 centre=0.3,0.6 width=0.15 light=cct:3000 level=0.5 \
             rotation=12 tilt=40 tilt-axis=horizontal",
        )
        .unwrap();
        assert_eq!(p.chart.as_deref(), Some("colorchecker24"));
        assert_eq!(p.centre, [0.3, 0.6]);
        assert_eq!((p.width, p.level, p.rotation), (0.15, 0.5, 12.0));
        assert_eq!(p.light.as_deref(), Some("cct:3000"));
        assert_eq!(
            p.tilt,
            Some(Tilt {
                degrees: 40.0,
                axis: TiltAxis::Horizontal
            })
        );
        let defaults = parse_place("centre=0.5,0.5").unwrap();
        assert_eq!(
            (defaults.width, defaults.level, defaults.tilt),
            (0.2, 1.0, None)
        );
    }

    #[test]
    fn a_bad_place_is_named() {
        for (text, says) in [
            ("width=0.2", "needs centre"),
            ("centre=0.5", "two shares"),
            ("centre=0.5,0.5 level=0", "must be above 0"),
            ("centre=0.5,0.5 colour=red", "unknown key 'colour'"),
            ("centre=0.5,0.5 width", "not KEY=VALUE"),
            ("centre=0.5,0.5 width=2", "between 0 and 1"),
        ] {
            let e = parse_place(text).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
    }
}
