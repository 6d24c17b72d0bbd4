//! Synthetic photos of a chart for the photo tests: the chart rendered by the virtual camera
//! under a random light and photographed in a random scene ([`spdcam_core::photo::scene`]).
//! Every random choice comes from the seed.

#![allow(dead_code)]

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::{Sensitivities, SensorConfig, SensorMode};
use spdcam_core::camera::white_balance::WhiteBalance;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::colorimetry::{self, srgb_decode};
use spdcam_core::named_light;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
use spdcam_core::photo::{decode_photo, ChartTemplate, Photo};
use spdcam_core::spectral::{Grid, Spd};

const GRID: Grid = Grid::SIMULATION;

/// One chart the generator can photograph: two ideal cameras (automatic white balance, and
/// none so that coloured light stays coloured) and the chart's template.
pub struct ChartSetup {
    pub template: ChartTemplate,
    cameras: [Camera; 2],
    /// Smallest and largest width of the patch grid as a share of the photo's width.
    pub width_share: (f64, f64),
}

impl ChartSetup {
    /// `chart` laid out with gaps of the physical chart's patch fraction.
    pub fn new(chart: Chart, width_share: (f64, f64)) -> ChartSetup {
        let template = ChartTemplate::from_chart(&chart).unwrap();
        let chart = chart.with_layout(scene::scene_layout(&template)).unwrap();
        let set = builtin::CAMERAS[0].load().unwrap();
        let sens = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
        // An ideal camera (three noise-free sensors, no aberration), so that the features
        // can be compared with the exact truth. A real one departs from it on purpose:
        // under strongly coloured light white balance amplifies the noise of the weak
        // channels until clipping at black biases their means, and on small blurred
        // patches demosaicing's colour-difference assumption fails a few pixels into the
        // patch. Those are properties of the camera (tested with it), not of finding and
        // sampling the chart; scene photos by the full camera are judged in `trust`.
        let quiet = CameraConfig {
            sensor: SensorConfig {
                mode: SensorMode::ThreeSensor,
                ..SensorConfig::default()
            },
            noise: None,
            aberration: None,
            ..CameraConfig::default()
        };
        let auto = Camera::new(&sens, chart.clone(), quiet, &GRID).unwrap();
        let fixed = Camera::new(
            &sens,
            chart,
            CameraConfig {
                white_balance: WhiteBalance::None,
                ..quiet
            },
            &GRID,
        )
        .unwrap();
        ChartSetup {
            template,
            cameras: [auto, fixed],
            width_share,
        }
    }
}

impl ChartSetup {
    /// The ideal camera with automatic white balance, photographing this chart.
    pub fn camera(&self) -> &Camera {
        &self.cameras[0]
    }
}

/// The ColorChecker 24 (built in).
pub fn colorchecker24() -> ChartSetup {
    ChartSetup::new(Chart::colorchecker24(&GRID).unwrap(), (0.1, 0.6))
}

/// The ColorChecker Digital SG (from the data directory).
pub fn colorchecker_sg(data: &DataDir) -> ChartSetup {
    let chart = Chart::resolve("colorchecker_sg140", None, data, &GRID).unwrap();
    ChartSetup::new(chart, (0.2, 0.7))
}

/// A synthetic photo and what is true about it.
pub struct Scene {
    /// The decoded JPEG.
    pub photo: Photo,
    /// The JPEG file's bytes.
    pub jpeg: Vec<u8>,
    /// Outer corners of the patch grid in the photo: the chart's TL, TR, BR, BL.
    pub corners: [[f64; 2]; 4],
    /// Patch side in photo pixels (the mean over the chart).
    pub patch_px: f64,
    /// The features a flat, noise-free, unblurred chart would give (vignetting included).
    pub features: Vec<f32>,
    /// What the light was.
    pub light: String,
}

/// Settings of the generator.
#[derive(Debug, Clone, Copy)]
pub struct SceneSize {
    pub width: usize,
    pub height: usize,
}

/// A 1600 × 1000 photo through a lens with a little blur and vignetting, at a good JPEG
/// quality (the seed draws them within these ranges): the photos of several charts.
pub fn wide_photo_options() -> SceneOptions {
    SceneOptions {
        width: 1600,
        height: 1000,
        blur_sigma: (0.3, 0.8),
        vignetting: (0.0, 0.15),
        jpeg_quality: (88, 92),
        ..SceneOptions::default()
    }
}

/// A random light: a colour temperature, or one to three narrow bands (strongly coloured).
pub fn random_light(rng: &mut SmallRng) -> (String, Spd) {
    if rng.random_bool(0.5) {
        let cct = rng.random_range(2500.0..10000.0f64).round();
        let spec = format!("cct:{cct}");
        let spd = named_light::resolve_spd(&spec, &DataDir::new(None), &GRID)
            .unwrap()
            .spd;
        (spec, spd)
    } else {
        let bands = rng.random_range(1..=3);
        let mut spd = vec![0.02; GRID.count];
        let mut name = String::from("bands");
        for _ in 0..bands {
            let centre = rng.random_range(430.0..650.0f64);
            let width = rng.random_range(12.0..40.0f64);
            let power = rng.random_range(0.3..1.0f64);
            name += &format!(":{centre:.0}/{width:.0}");
            for (i, v) in spd.iter_mut().enumerate() {
                let l = GRID.wavelength(i);
                *v += power * (-0.5 * ((l - centre) / width).powi(2)).exp();
            }
        }
        (name, Spd::new(GRID, spd).unwrap())
    }
}

/// Renders scene `seed` of `setup` at `size`.
pub fn scene(setup: &ChartSetup, seed: u64, size: SceneSize) -> Scene {
    let mut rng = SmallRng::seed_from_u64(seed);
    let (light_name, spd) = random_light(&mut rng);
    let camera = &setup.cameras[rng.random_range(0..2)];
    let options = SceneOptions {
        width: size.width,
        height: size.height,
        width_share: setup.width_share,
        ..SceneOptions::default()
    };
    let shot = scene::photograph(camera, SceneLight::single(&spd), seed, &options).unwrap();
    let photo = decode_photo(&shot.jpeg, &format!("synthetic-{seed}.jpg")).unwrap();
    Scene {
        photo,
        jpeg: shot.jpeg,
        corners: shot.corners,
        patch_px: shot.patch_px,
        features: shot.expected_features,
        light: light_name,
    }
}

/// ΔE2000 between two encoded sRGB colours (0–255), in CIELAB relative to sRGB white.
pub fn delta_e(a: [f32; 3], b: [f32; 3]) -> f64 {
    let white = colorimetry::linear_srgb_to_xyz([1.0, 1.0, 1.0]);
    let lab = |v: [f32; 3]| {
        let lin = v.map(|x| srgb_decode((x as f64 / 255.0).clamp(0.0, 1.0)));
        colorimetry::xyz_to_lab(colorimetry::linear_srgb_to_xyz(lin), white)
    };
    colorimetry::delta_e_2000(lab(a), lab(b))
}
