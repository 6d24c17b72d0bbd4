//! Plots of spectra as SVG (plotters), shared by the estimate and the model evaluation.

use crate::error::{InferError, Result};
use crate::trust::Uncertainty;
use plotters::prelude::*;
use spdcam_core::spectral::Grid;

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
    spds_band_svg(title, grid, series, &[])
}

/// [`spds_svg`] with the uncertainty bands of some series shaded in their colour:
/// `bands[i]` belongs to series `i`, `None` for a series without one.
pub fn spds_band_svg(
    title: &str,
    grid: &Grid,
    series: &[(String, Vec<f64>)],
    bands: &[Option<&Uncertainty>],
) -> Result<String> {
    let top = bands
        .iter()
        .flatten()
        .flat_map(|u| u.band95.upper.iter().copied())
        .fold(1.0f64, f64::max)
        * 1.05;
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
                    .map(|(k, v)| (grid.wavelength(k), *v))
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
            .draw()
            .map_err(plot_error)?;
        for (i, (name, values)) in series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let points: Vec<(f64, f64)> = values
                .iter()
                .enumerate()
                .map(|(k, v)| (grid.wavelength(k), *v))
                .collect();
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
        if series.len() <= 12 {
            chart
                .configure_series_labels()
                .border_style(BLACK)
                .background_style(WHITE.mix(0.8))
                .draw()
                .map_err(plot_error)?;
        }
        Ok(())
    })
}
