//! `spdcam._native`: the Python binding of spdcam's libraries. Thin on purpose: every step
//! is a library call (`spdcam_infer`, `spdcam_core`); this module only converts Python
//! values, releases the GIL for the work, and turns errors into `spdcam.SpdcamError` with
//! the command line's messages. The typed API is the Python package `spdcam` around it.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, Layout};
use spdcam_core::light;
use spdcam_core::photo::{decode_photo, load_photo, Photo};
use spdcam_core::spectral::Grid;
use spdcam_core::spectral::{Extrapolation, Interpolation, SpectralSet};
use spdcam_infer::estimate::estimate_decoded;
use spdcam_infer::{
    estimate_features, estimate_photo, Estimate, FeatureRows, Model, ModelSet, PhotoOptions,
};
use std::path::PathBuf;
use std::time::Instant;

create_exception!(
    spdcam,
    SpdcamError,
    PyValueError,
    "An input spdcam cannot use; the message is the command line's."
);

/// Any library error as a `SpdcamError` with the library's message.
fn py_err(e: impl std::fmt::Display) -> PyErr {
    SpdcamError::new_err(e.to_string())
}

/// A set of models an estimate chooses from by the chart a photo shows.
#[pyclass(module = "spdcam._native", frozen)]
struct Models {
    set: ModelSet,
}

#[pymethods]
impl Models {
    /// The models shipped inside spdcam, one per chart.
    #[staticmethod]
    fn shipped() -> PyResult<Models> {
        Ok(Models {
            set: ModelSet::shipped().map_err(py_err)?,
        })
    }

    /// One model from a `.spdm` file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Models> {
        let model = Model::load(&path).map_err(py_err)?;
        Ok(Models {
            set: ModelSet::single(model, path.display().to_string()),
        })
    }

    /// `(name, chart, feature names, wavelength grid label)` of each model.
    fn describe(&self) -> Vec<(String, Option<String>, Vec<String>, String)> {
        self.set
            .models()
            .iter()
            .map(|m| {
                (
                    m.name.clone(),
                    m.model.header().chart.clone(),
                    m.model.feature_names().to_vec(),
                    m.model.grid().label(),
                )
            })
            .collect()
    }
}

/// The library's photo options from the Python arguments.
fn photo_options(chart: Option<String>, corners: Option<Vec<[f64; 2]>>) -> PhotoOptions {
    PhotoOptions {
        chart,
        corners,
        debug: None,
    }
}

/// An estimate as the JSON text of `Estimate::to_json`.
fn estimate_json(estimate: &Estimate) -> PyResult<String> {
    let value = estimate.to_json().map_err(py_err)?;
    serde_json::to_string(&value).map_err(py_err)
}

/// Estimates the light from the photo file at `path`; the result as JSON text.
#[pyfunction]
#[pyo3(signature = (path, models, chart=None, corners=None, range="400-700:5"))]
fn estimate_file(
    py: Python<'_>,
    path: PathBuf,
    models: &Models,
    chart: Option<String>,
    corners: Option<Vec<[f64; 2]>>,
    range: &str,
) -> PyResult<String> {
    let grid = Grid::parse(range).map_err(py_err)?;
    let options = photo_options(chart, corners);
    py.allow_threads(|| {
        estimate_photo(&path, &models.set, &options, &DataDir::new(None), &grid)
            .map_err(|e| format!("cannot use photo {}: {e}", path.display()))
    })
    .map_err(SpdcamError::new_err)
    .and_then(|e| estimate_json(&e))
}

/// Estimates the light from an encoded photo (JPEG, PNG, TIFF bytes) named `source`.
#[pyfunction]
#[pyo3(signature = (data, source, models, chart=None, corners=None, range="400-700:5"))]
fn estimate_encoded(
    py: Python<'_>,
    data: &[u8],
    source: &str,
    models: &Models,
    chart: Option<String>,
    corners: Option<Vec<[f64; 2]>>,
    range: &str,
) -> PyResult<String> {
    let grid = Grid::parse(range).map_err(py_err)?;
    let options = photo_options(chart, corners);
    let estimate = py
        .allow_threads(|| {
            let photo = decode_photo(data, source)?;
            estimate_decoded(&photo, &models.set, &options, &DataDir::new(None), &grid)
        })
        .map_err(py_err)?;
    estimate_json(&estimate)
}

/// Estimates the light from interleaved RGB pixels (`height × width × 3`, encoded sRGB) as
/// native-endian bytes of `u8` values, or of `u16` values when `bits` is 16.
#[pyfunction]
#[pyo3(signature = (pixels, width, height, bits, source, models, chart=None, corners=None, range="400-700:5"))]
#[allow(clippy::too_many_arguments)]
fn estimate_pixels(
    py: Python<'_>,
    pixels: &[u8],
    width: usize,
    height: usize,
    bits: u32,
    source: &str,
    models: &Models,
    chart: Option<String>,
    corners: Option<Vec<[f64; 2]>>,
    range: &str,
) -> PyResult<String> {
    let grid = Grid::parse(range).map_err(py_err)?;
    let options = photo_options(chart, corners);
    let estimate = py
        .allow_threads(|| {
            let photo = if bits == 16 {
                let values = pixels
                    .chunks_exact(2)
                    .map(|c| u16::from_ne_bytes([c[0], c[1]]))
                    .collect();
                Photo::from_rgb16(source, width, height, values)?
            } else {
                Photo::from_rgb8(source, width, height, pixels.to_vec())?
            };
            estimate_decoded(&photo, &models.set, &options, &DataDir::new(None), &grid)
        })
        .map_err(py_err)?;
    estimate_json(&estimate)
}

/// Native-endian `f64` bytes as numbers.
fn f64_values(bytes: &[u8]) -> Vec<f64> {
    bytes
        .chunks_exact(8)
        .map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_ne_bytes(b)
        })
        .collect()
}

/// Numbers as native-endian `f64` bytes, for `numpy.frombuffer`.
fn f64_bytes<'py>(py: Python<'py>, values: impl Iterator<Item = f64>) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.flat_map(f64::to_ne_bytes).collect();
    PyBytes::new(py, &bytes)
}

/// What `estimate_rows` returns: the model's name, then as `f64` bytes the wavelengths,
/// the SPDs (rows × wavelengths), xy (rows × 2), CCT and Duv (NaN where undefined).
type RowsResult<'py> = (
    String,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
);

/// Estimates the light for feature rows: `values` native-endian `f64` bytes of `rows`
/// rows, one column per name of `names` (default: the columns of the model that reads
/// that many).
#[pyfunction]
#[pyo3(signature = (values, rows, models, names=None, source="features", range="400-700:5"))]
fn estimate_rows<'py>(
    py: Python<'py>,
    values: &[u8],
    rows: usize,
    models: &Models,
    names: Option<Vec<String>>,
    source: &str,
    range: &str,
) -> PyResult<RowsResult<'py>> {
    let grid = Grid::parse(range).map_err(py_err)?;
    let values = f64_values(values);
    let columns = if rows == 0 { 0 } else { values.len() / rows };
    let names = match names {
        Some(n) => n,
        None => default_names(&models.set, columns, source)?,
    };
    let estimates = py
        .allow_threads(|| {
            let features = FeatureRows::from_values(names, values, source)?;
            estimate_features(&models.set, &features, source, &grid)
        })
        .map_err(py_err)?;
    let model = estimates
        .first()
        .map(|e| e.model.clone())
        .unwrap_or_default();
    let nan = f64::NAN;
    Ok((
        model,
        f64_bytes(py, grid.wavelengths().into_iter()),
        f64_bytes(py, estimates.iter().flat_map(|e| e.spd.iter().copied())),
        f64_bytes(py, estimates.iter().flat_map(|e| e.colorimetry.xy)),
        f64_bytes(
            py,
            estimates.iter().map(|e| e.colorimetry.cct.unwrap_or(nan)),
        ),
        f64_bytes(
            py,
            estimates.iter().map(|e| e.colorimetry.duv.unwrap_or(nan)),
        ),
    ))
}

/// The feature names of the model that reads `columns` columns.
fn default_names(models: &ModelSet, columns: usize, source: &str) -> PyResult<Vec<String>> {
    models
        .models()
        .iter()
        .find(|m| m.model.feature_names().len() == columns)
        .map(|m| m.model.feature_names().to_vec())
        .ok_or_else(|| {
            let known = models
                .models()
                .iter()
                .map(|m| {
                    format!(
                        "{} ({} features)",
                        m.model.header().chart.as_deref().unwrap_or("unknown chart"),
                        m.model.feature_names().len()
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            SpdcamError::new_err(format!(
                "{source}: no model reads {columns} feature columns; the models are for {known}"
            ))
        })
}

/// Decodes the photo file at `path` as spdcam does (EXIF orientation applied):
/// `(width, height, bits per channel, interleaved RGB values as native-endian bytes)`.
#[pyfunction]
fn read_photo(py: Python<'_>, path: PathBuf) -> PyResult<(usize, usize, u32, Bound<'_, PyBytes>)> {
    let photo = py.allow_threads(|| load_photo(&path)).map_err(py_err)?;
    let bytes: Vec<u8> = match (photo.rgb8(), photo.rgb16()) {
        (Some(d), _) => d.to_vec(),
        (None, Some(d)) => d.iter().flat_map(|v| v.to_ne_bytes()).collect(),
        (None, None) => Vec::new(),
    };
    Ok((
        photo.width,
        photo.height,
        photo.bit_depth(),
        PyBytes::new(py, &bytes),
    ))
}

/// What `render` returns: width, height, the image as native-endian `f32` bytes (encoded
/// sRGB 0–1, interleaved RGB), the feature names, and the features (mean sRGB 0–255).
type RenderResult<'py> = (usize, usize, Bound<'py, PyBytes>, Vec<String>, Vec<f32>);

/// Renders `chart` photographed by `camera` (the command line's default settings) under a
/// light: `spd` names one (D65, A, cct:T, daylight:T, planck:T, a spectral CSV) or, with
/// `wavelengths`, is its values; `spdcam render` with the same light and seed gives the
/// same image and features.
#[pyfunction]
#[pyo3(signature = (spd, wavelengths=None, values=None, camera="nikon_d5100_npl", chart="colorchecker24", patch_px=24, seed=0))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    spd: &str,
    wavelengths: Option<Vec<f64>>,
    values: Option<Vec<f64>>,
    camera: &str,
    chart: &str,
    patch_px: usize,
    seed: u64,
) -> PyResult<RenderResult<'py>> {
    let rendering = py
        .allow_threads(|| -> spdcam_core::Result<_> {
            let grid = Grid::SIMULATION;
            let data_dir = DataDir::new(None);
            let light = match (wavelengths, values) {
                (Some(w), Some(v)) => {
                    let set = SpectralSet::new(w, vec![spd.to_string()], vec![v])?;
                    let (set, _) =
                        set.resample(&grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
                    set.item(0).to_vec()
                }
                _ => light::resolve_spd(spd, &data_dir, &grid)?.values,
            };
            let chart = Chart::resolve(chart, None, &data_dir, &grid)?;
            let layout = Layout::grid(chart.layout.rows, chart.layout.cols, patch_px, 0, 0);
            let chart = chart.with_layout(layout)?;
            let (name, measured) = builtin::resolve_table(
                camera,
                "camera",
                builtin::CAMERAS,
                &data_dir,
                &["cameras", "thesis"],
            )?;
            let sensitivities = Sensitivities::new(&name, &measured, &grid)?;
            let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
            let rendering = camera.render(&light, seed, false)?;
            Ok((rendering, camera.chart().feature_names()))
        })
        .map_err(py_err)?;
    let (rendering, names) = rendering;
    let image = &rendering.image;
    let bytes: Vec<u8> = (0..image.height)
        .flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .flat_map(|(x, y)| image.pixel(x, y))
        .flat_map(f32::to_ne_bytes)
        .collect();
    Ok((
        image.width,
        image.height,
        PyBytes::new(py, &bytes),
        names,
        rendering.features,
    ))
}

/// Seconds the library alone takes for `repeats` estimates from the photo file at `path`
/// (no Python conversions): the baseline of `python/bench.py`.
#[pyfunction]
fn library_seconds_photo(
    py: Python<'_>,
    path: PathBuf,
    models: &Models,
    repeats: usize,
) -> PyResult<f64> {
    let grid = Grid::parse("400-700:5").map_err(py_err)?;
    let options = PhotoOptions::default();
    py.allow_threads(|| {
        let start = Instant::now();
        for _ in 0..repeats {
            estimate_photo(&path, &models.set, &options, &DataDir::new(None), &grid)?;
        }
        Ok(start.elapsed().as_secs_f64())
    })
    .map_err(|e: spdcam_infer::InferError| py_err(e))
}

/// Seconds the library alone takes for `repeats` estimates of the feature rows in `values`
/// (`rows` rows, the columns of the model that reads that many): the baseline of
/// `python/bench.py`.
#[pyfunction]
fn library_seconds_rows(
    py: Python<'_>,
    values: &[u8],
    rows: usize,
    models: &Models,
    repeats: usize,
) -> PyResult<f64> {
    let grid = Grid::parse("400-700:5").map_err(py_err)?;
    let values = f64_values(values);
    let names = default_names(&models.set, values.len() / rows.max(1), "features")?;
    let features = FeatureRows::from_values(names, values, "features").map_err(py_err)?;
    py.allow_threads(|| {
        let start = Instant::now();
        for _ in 0..repeats {
            estimate_features(&models.set, &features, "features", &grid)?;
        }
        Ok(start.elapsed().as_secs_f64())
    })
    .map_err(|e: spdcam_infer::InferError| py_err(e))
}

/// The compiled part of the `spdcam` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SpdcamError", m.py().get_type::<SpdcamError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Models>()?;
    m.add_function(wrap_pyfunction!(estimate_file, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_encoded, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_pixels, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_rows, m)?)?;
    m.add_function(wrap_pyfunction!(read_photo, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(library_seconds_photo, m)?)?;
    m.add_function(wrap_pyfunction!(library_seconds_rows, m)?)?;
    Ok(())
}
