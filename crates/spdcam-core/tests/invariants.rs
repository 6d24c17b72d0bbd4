//! Property tests of invariants that hold for any input: resampling keeps a spectrum's
//! values at its own wavelengths, the colour-matrix fit recovers an exact linear map, the
//! features follow the chart's patch order, and a seed fixes every draw.

use proptest::prelude::*;
use spdcam_core::builtin;
use spdcam_core::camera::colour::fit_correction_matrix;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::{Grid, Spd};

/// A spectrum on the 5 nm simulation grid: positive, smooth or spiky.
fn spectrum() -> impl Strategy<Value = Spd> {
    prop::collection::vec(0.0f64..10.0, Grid::SIMULATION.count)
        .prop_map(|values| Spd::new(Grid::SIMULATION, values).expect("one value per wavelength"))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Sprague (1880) interpolation passes through its nodes: onto a 1 nm grid and back to
    /// 5 nm gives the spectrum it started from.
    #[test]
    fn resampling_to_a_finer_grid_and_back_is_the_identity(spd in spectrum()) {
        let fine = Grid::new(380.0, 780.0, 1.0).unwrap();
        let back = spd.resampled(&fine).unwrap().resampled(&Grid::SIMULATION).unwrap();
        for (a, b) in spd.iter().zip(back.iter()) {
            prop_assert!((a - b).abs() <= 1e-9 * a.abs().max(1.0), "{a} became {b}");
        }
    }

    /// The least-squares colour matrix recovers any invertible matrix from exact pairs.
    #[test]
    fn the_colour_matrix_fit_recovers_an_exact_map(
        m in prop::array::uniform9(-2.0f64..2.0),
        rgb in prop::collection::vec(prop::array::uniform3(0.01f64..1.0), 6..30),
    ) {
        let matrix = nalgebra::Matrix3::from_row_slice(&m);
        prop_assume!(matrix.determinant().abs() > 0.05);
        let xyz: Vec<[f64; 3]> = rgb
            .iter()
            .map(|r| {
                let v = matrix * nalgebra::Vector3::from(*r);
                [v[0], v[1], v[2]]
            })
            .collect();
        let gram = rgb.iter().fold(nalgebra::Matrix3::<f64>::zeros(), |g, r| {
            let v = nalgebra::Vector3::from(*r);
            g + v * v.transpose()
        });
        // Well-posed only when the responses span the three channels.
        prop_assume!(gram.determinant() > 1e-6);
        let fitted = fit_correction_matrix(&rgb, &xyz).unwrap();
        prop_assert!((fitted - matrix).abs().max() < 1e-6, "{fitted} vs {matrix}");
    }

    /// Reordering the chart's patches reorders the features the same way, three values a
    /// patch, whatever the order.
    #[test]
    fn features_follow_the_patch_order(order in Just((0..24usize).collect::<Vec<_>>()).prop_shuffle()) {
        let grid = Grid::SIMULATION;
        let measured = builtin::CAMERAS[0].load().unwrap();
        let sensitivities = Sensitivities::new(builtin::CAMERAS[0].name, &measured, &grid).unwrap();
        let reflectances = spdcam_core::chart::registry::COLORCHECKER24_TABLE.load().unwrap();
        let features = |set: &spdcam_core::spectral::SpectralSet| {
            let chart = Chart::from_reflectances("shuffled", set, 4, 6, &grid).unwrap();
            let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).unwrap();
            let light = camera.light(&StandardIlluminant::A.spd(&grid).unwrap()).unwrap();
            let (mut raw, mut out) = (Vec::new(), Vec::new());
            camera.features_fast(&light, &mut raw, &mut out);
            out
        };
        let plain = features(&reflectances);
        let shuffled = features(&reflectances.select(&order));
        prop_assert_eq!(shuffled.len(), 24 * 3);
        for (k, &p) in order.iter().enumerate() {
            // The white balance and exposure see the same patches (summed in another order,
            // so equal up to rounding): each patch's values move with it.
            for c in 0..3 {
                let (moved, was) = (shuffled[3 * k + c], plain[3 * p + c]);
                prop_assert!((moved - was).abs() < 1e-3, "patch {p} channel {c}: {moved} vs {was}");
            }
        }
    }

    /// The same seed and index give the same light, drawn in any order.
    #[test]
    fn a_seed_fixes_every_draw(seed in any::<u64>(), first in 0u64..1000, second in 0u64..1000) {
        let lighting = Lighting::parse(
            "mix:gaussian:7=0.5,planck=0.5",
            &builtin::DataDir::new(None),
            &Grid::SIMULATION,
        )
        .unwrap();
        let a = lighting.draw(seed, first).unwrap();
        let _ = lighting.draw(seed, second).unwrap();
        let again = lighting.draw(seed, first).unwrap();
        prop_assert_eq!(a, again);
    }
}
