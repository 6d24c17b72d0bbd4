//! Plots of spectra as SVG (plotters), shared by the estimate and the model evaluation.

use plotters::prelude::*;
use spdcam_core::spectral::Grid;
use spdcam_infer::error::{InferError, Result};
use spdcam_infer::trust::Uncertainty;

/// The error of a failed drawing step.
pub fn plot_error(e: impl std::fmt::Display) -> InferError {
    InferError::invalid(format!("drawing a plot: {e}"))
}

/// Draws into an SVG string of `size`.
pub fn svg(
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        draw(root.clone())?;
        root.present().map_err(plot_error)?;
    }
    Ok(out)
}

/// SPDs on `grid`, each a named series (`(name, values)`), max-normalised.
pub fn spds_svg(title: &str, grid: &Grid, series: &[(String, Vec<f64>)]) -> Result<String> {
    spds_band_svg(title, grid, series, &[], &[])
}

/// Height of one legend entry as a share of the plot's value range: the range is raised
/// by this per entry so the legend (upper right) sits above the curves, not on them.
const LEGEND_ROOM: f64 = 0.065;

/// [`spds_svg`] with, per series `i`, its 68 % and 95 % uncertainty bands shaded in its
/// colour (`bands[i]`) and its true SPD dashed, scaled to peak 1 (`truths[i]`); `None` (or
/// a missing entry) for a series without one. Every kind drawn has a legend entry, the
/// wavelengths are labelled in whole nanometres.
pub fn spds_band_svg(
    title: &str,
    grid: &Grid,
    series: &[(String, Vec<f64>)],
    bands: &[Option<&Uncertainty>],
    truths: &[Option<&[f64]>],
) -> Result<String> {
    let truths: Vec<Option<Vec<f64>>> = truths
        .iter()
        .map(|t| {
            t.and_then(|t| {
                let peak = t.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (t.len() == grid.count && peak > 0.0).then(|| t.iter().map(|v| v / peak).collect())
            })
        })
        .collect();
    let banded = bands.iter().flatten().count();
    let legend_shown = series.len() <= 12;
    let entries = series.len() + truths.iter().flatten().count() + if banded > 0 { 2 } else { 0 };
    let highest = bands
        .iter()
        .flatten()
        .flat_map(|u| u.band95.upper.iter().copied())
        .chain(truths.iter().flatten().flatten().copied())
        .filter(|v| v.is_finite())
        .fold(1.0f64, f64::max);
    let top = highest
        * (1.05
            + if legend_shown {
                LEGEND_ROOM * entries as f64
            } else {
                0.0
            });
    svg((900, 520), |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(56)
            .build_cartesian_2d(grid.start_nm..grid.end_nm(), 0.0..top)
            .map_err(plot_error)?;
        for (i, band) in bands.iter().enumerate() {
            let Some(u) = band else { continue };
            let colour = Palette99::pick(i).to_rgba();
            for (b, alpha) in [(&u.band95, 0.15), (&u.band68, 0.3)] {
                let mut outline: Vec<(f64, f64)> = b
                    .upper
                    .iter()
                    .enumerate()
                    .map(|(k, v)| (grid.wavelength(k), v.min(top)))
                    .collect();
                outline.extend(
                    b.lower
                        .iter()
                        .enumerate()
                        .rev()
                        .map(|(k, v)| (grid.wavelength(k), *v)),
                );
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        outline,
                        colour.mix(alpha).filled(),
                    )))
                    .map_err(plot_error)?;
            }
        }
        chart
            .configure_mesh()
            .x_desc("wavelength (nm)")
            .y_desc("relative power")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.1}"))
            .draw()
            .map_err(plot_error)?;
        let points = |values: &[f64]| -> Vec<(f64, f64)> {
            values
                .iter()
                .enumerate()
                .map(|(k, v)| (grid.wavelength(k), *v))
                .collect()
        };
        for (i, (name, values)) in series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(points(values), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
            if let Some(Some(truth)) = truths.get(i) {
                let dashed = DashedLineSeries::new(points(truth), 6, 4, colour.stroke_width(1));
                chart
                    .draw_series(dashed)
                    .map_err(plot_error)?
                    .label(if series.len() == 1 {
                        "true SPD".to_string()
                    } else {
                        format!("{name}: true SPD")
                    })
                    .legend(move |(x, y)| {
                        plotters::element::DashedPathElement::new(
                            vec![(x, y), (x + 20, y)],
                            4,
                            3,
                            colour,
                        )
                    });
            }
        }
        if banded > 0 {
            // One entry per band level, in the first banded series' colour.
            let first = bands.iter().position(Option::is_some).unwrap_or(0);
            let colour = Palette99::pick(first).to_rgba();
            for (label, alpha) in [("68 % band", 0.3), ("95 % band", 0.15)] {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), u32>>())
                    .map_err(plot_error)?
                    .label(label)
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 20, y + 5)], colour.mix(alpha).filled())
                    });
            }
        }
        if legend_shown {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .border_style(BLACK)
                .background_style(WHITE.mix(0.8))
                .draw()
                .map_err(plot_error)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_infer::trust::{Band, Uncertainty};
    use std::collections::BTreeMap;

    #[test]
    fn truth_bands_and_whole_nanometres_are_drawn_and_labelled() {
        let grid = Grid::new(400.0, 700.0, 10.0).unwrap();
        let spd: Vec<f64> = (0..grid.count).map(|k| 0.5 + 0.01 * k as f64).collect();
        let band = |d: f64| Band {
            lower: spdcam_core::spectral::Spd::new(grid, spd.iter().map(|v| v - d).collect())
                .unwrap(),
            upper: spdcam_core::spectral::Spd::new(grid, spd.iter().map(|v| v + d).collect())
                .unwrap(),
        };
        let u = Uncertainty {
            band68: band(0.05),
            band95: band(0.1),
            expected_gfc: 0.99,
            gfc_at_least95: 0.97,
            gfc_margin_factor: 2.0,
            gfc_margin_local: true,
            difficulty: 0.01,
            widening: 1.0,
            metrics: BTreeMap::new(),
        };
        let truth: Vec<f64> = spd.iter().map(|v| 2.0 * v).collect();
        let svg = spds_band_svg(
            "t",
            &grid,
            &[("photo.jpg".into(), spd.clone())],
            &[Some(&u)],
            &[Some(&truth)],
        )
        .unwrap();
        for label in [
            "photo.jpg",
            "true SPD",
            "68 % band",
            "95 % band",
            ">\n400\n</text>",
            ">\n700\n</text>",
        ] {
            assert!(svg.contains(label), "no {label} in the plot");
        }
        assert!(!svg.contains("400.0"), "a tick reads 400.0");
        // Without truth and bands, no such legend entries.
        let plain = spds_svg("t", &grid, &[("photo.jpg".into(), spd)]).unwrap();
        assert!(!plain.contains("true SPD") && !plain.contains("% band"));
    }
}
