//! The outlines of the page's chromaticity diagram: the spectral and Planckian loci.

use anyhow::Result;
use spdcam_core::colorimetry::{cct_to_uv_planck, uv1960_to_xy, Observer};
use spdcam_core::spectral::Grid;

/// The spectral locus (CIE 1931 2° observer, 380–780 nm in 5 nm steps) and the Planckian
/// locus (1000–20000 K, Planck's law through the same observer) in CIE 1931 xy, for the
/// page's chromaticity diagram.
pub(super) fn locus_json() -> Result<serde_json::Value> {
    let grid = Grid::parse("380-780:5")?;
    let observer = Observer::cie1931(&grid)?;
    let (xbar, ybar, zbar) = (observer.cmf(0), observer.cmf(1), observer.cmf(2));
    let mut spectral = Vec::new();
    for (i, nm) in grid.wavelengths().into_iter().enumerate() {
        let sum = xbar[i] + ybar[i] + zbar[i];
        if sum > 0.0 {
            spectral.push(serde_json::json!([nm, xbar[i] / sum, ybar[i] / sum]));
        }
    }
    let mut planckian = Vec::new();
    let mut t = 1000.0_f64;
    while t <= 20000.0 {
        let xy = uv1960_to_xy(cct_to_uv_planck(t)?);
        planckian.push(serde_json::json!([t, xy[0], xy[1]]));
        t *= 1.05;
    }
    Ok(serde_json::json!({
        "spectral": spectral,
        "planckian": planckian,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_locus_passes_through_known_points() {
        let locus = locus_json().unwrap();
        // CIE 1931 2° at 520 nm: x 0.0743, y 0.8338 (CIE 015:2018 table).
        let at520 = locus["spectral"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p[0].as_f64() == Some(520.0))
            .unwrap();
        assert!(
            (at520[1].as_f64().unwrap() - 0.0743).abs() < 5e-4,
            "{at520}"
        );
        assert!(
            (at520[2].as_f64().unwrap() - 0.8338).abs() < 5e-4,
            "{at520}"
        );
        // The Planckian radiator near 2856 K (illuminant A): x 0.4476, y 0.4074.
        let near_a = locus["planckian"]
            .as_array()
            .unwrap()
            .iter()
            .min_by(|a, b| {
                let d = |p: &serde_json::Value| (p[0].as_f64().unwrap() - 2856.0).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let t = near_a[0].as_f64().unwrap();
        assert!((t - 2856.0).abs() < 80.0, "{near_a}");
        assert!(
            (near_a[1].as_f64().unwrap() - 0.4476).abs() < 0.006,
            "{near_a}"
        );
    }
}
