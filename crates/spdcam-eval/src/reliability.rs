//! The reliability diagram of `spdcam trust report` (docs/trust-reliability.svg): how often
//! the bands hold the truth at each nominal level, and whether estimates reach the GFC they
//! were expected to, per photo set. A calibrated set follows the diagonal in both panels
//! (DeGroot & Fienberg 1983, "The comparison and evaluation of forecasters", The
//! Statistician 32: 12–22; for intervals, Kuleshov et al. 2018, "Accurate uncertainties for
//! deep learning using calibrated regression", ICML, fig. 1).

use crate::error::Result;
use plotters::prelude::*;
use spdcam_present::plot::{plot_error, svg};

/// The nominal levels of the bands the diagram measures.
pub const LEVELS: [f64; 11] = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.68, 0.8, 0.9, 0.95, 0.99];
/// Equal-count bins of the expected GFC per set.
const GFC_BINS: usize = 5;
/// The smallest 1 − GFC drawn (the log axis starts there).
const GAP_FLOOR: f64 = 1e-3;

/// One photo set's points in the diagram.
pub struct SetReliability {
    /// The set's name in the legend.
    pub label: String,
    /// Per level of [`LEVELS`], the share of true values inside the band of that level.
    pub coverage: Vec<f64>,
    /// Per bin of photos sorted by expected GFC: the median expected and the median actual
    /// 1 − GFC.
    pub gaps: Vec<(f64, f64)>,
}

impl SetReliability {
    /// The set `label` from the share inside the band per level and each photo's expected
    /// and actual GFC.
    pub fn new(label: String, coverage: Vec<f64>, expected_actual: &[(f64, f64)]) -> Self {
        let mut pairs = expected_actual.to_vec();
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
        let n = pairs.len();
        let gaps = (0..GFC_BINS.min(n))
            .map(|b| {
                let bin = &pairs[b * n / GFC_BINS.min(n)..(b + 1) * n / GFC_BINS.min(n)];
                let gap = |f: fn(&(f64, f64)) -> f64| {
                    let mut v: Vec<f64> = bin.iter().map(|p| (1.0 - f(p)).max(GAP_FLOOR)).collect();
                    v.sort_by(f64::total_cmp);
                    v[v.len() / 2]
                };
                (gap(|p| p.0), gap(|p| p.1))
            })
            .collect();
        SetReliability {
            label,
            coverage,
            gaps,
        }
    }
}

/// The two-panel diagram of `sets` as SVG: left, observed against nominal coverage of the
/// bands; right, actual against expected 1 − GFC (log axes).
pub fn diagram_svg(sets: &[SetReliability]) -> Result<String> {
    let drawn = svg((1100, 520), |root| {
        let (left, right) = root.split_horizontally(550);
        let mut bands = ChartBuilder::on(&left)
            .caption("bands: true values inside", ("sans-serif", 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(48)
            .build_cartesian_2d(0.0..1.0f64, 0.0..1.0f64)
            .map_err(plot_error)?;
        bands
            .configure_mesh()
            .x_desc("nominal level")
            .y_desc("observed share")
            .draw()
            .map_err(plot_error)?;
        bands
            .draw_series(LineSeries::new([(0.0, 0.0), (1.0, 1.0)], BLACK.mix(0.4)))
            .map_err(plot_error)?;
        for (i, set) in sets.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let points: Vec<(f64, f64)> =
                LEVELS.iter().copied().zip(set.coverage.clone()).collect();
            bands
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(set.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
                });
            bands
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        bands
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .label_font(("sans-serif", 11))
            .draw()
            .map_err(plot_error)?;
        let mut gfc = ChartBuilder::on(&right)
            .caption("GFC: actual against expected (1 − GFC)", ("sans-serif", 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(
                (GAP_FLOOR..1.0f64).log_scale(),
                (GAP_FLOOR..1.0f64).log_scale(),
            )
            .map_err(plot_error)?;
        gfc.configure_mesh()
            .x_desc("expected 1 − GFC (bin median)")
            .y_desc("actual 1 − GFC (bin median)")
            .draw()
            .map_err(plot_error)?;
        gfc.draw_series(LineSeries::new(
            [(GAP_FLOOR, GAP_FLOOR), (1.0, 1.0)],
            BLACK.mix(0.4),
        ))
        .map_err(plot_error)?;
        for (i, set) in sets.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            gfc.draw_series(LineSeries::new(set.gaps.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?;
            gfc.draw_series(set.gaps.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        Ok(())
    })?;
    Ok(drawn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_hold_the_medians_of_the_photos_sorted_by_expected_gfc() {
        // Ten photos: expected 1 − GFC 0.01…0.10, actual twice that.
        let pairs: Vec<(f64, f64)> = (1..=10)
            .map(|i| (1.0 - 0.01 * i as f64, 1.0 - 0.02 * i as f64))
            .collect();
        let set = SetReliability::new("s".into(), vec![0.5; LEVELS.len()], &pairs);
        assert_eq!(set.gaps.len(), GFC_BINS);
        for (b, &(expected, actual)) in set.gaps.iter().enumerate() {
            // Bin b holds photos 2b+1 and 2b+2; the upper median is taken.
            let want = 0.01 * (2 * b + 2) as f64;
            assert!((expected - want).abs() < 1e-12, "bin {b}: {expected}");
            assert!((actual - 2.0 * want).abs() < 1e-12, "bin {b}: {actual}");
        }
    }

    #[test]
    fn the_diagram_draws_every_set() {
        let sets: Vec<SetReliability> = ["a", "b"]
            .iter()
            .map(|l| {
                SetReliability::new(
                    l.to_string(),
                    LEVELS.to_vec(),
                    &[(0.99, 0.98), (0.95, 0.9), (0.9, 0.8)],
                )
            })
            .collect();
        let svg = diagram_svg(&sets).unwrap();
        assert!(svg.starts_with("<svg"));
        for label in ["a", "b", "nominal level", "expected 1 − GFC"] {
            assert!(svg.contains(label), "{label}");
        }
    }
}
