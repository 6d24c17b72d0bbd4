//! `spdcam._native`: the Python binding of spdcam's libraries. Thin on purpose: every step
//! is a library call (`spdcam_infer`, `spdcam_core`; `spdcam_learn` in `train`, built with
//! that feature); this module only converts Python values, releases the GIL for the work,
//! reports progress to a Python callback, and turns errors into `spdcam.SpdcamError` with
//! the command line's messages. The typed API is the Python package `spdcam` around it.
//!
//! Estimating needs no training stack: training and fine-tuning (burn, through
//! `spdcam-learn`) are built only with the cargo feature `train`, so a package that only
//! estimates installs in a fraction of the time.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart, Layout, THESIS_PATCH_PX};
use spdcam_core::dataset::randomise::RandomiseRequest;
use spdcam_core::dataset::{GenerateEvent, GenerateOptions, GenerateRequest, Pipeline};
use spdcam_core::light_families::LightKind;
use spdcam_core::named_light;
use spdcam_core::photo::{load_photo, Photo};
use spdcam_core::quality::registry::METRICS;
use spdcam_core::spectral::Grid;
use spdcam_core::spectral::{Extrapolation, Interpolation, SpectralSet};
use spdcam_infer::error::unusable_photo;
use spdcam_infer::{Estimate, Estimator, FeatureRows, Model, ModelSet, PhotoOptions};
use spdcam_present::presentation::Presentation;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

#[cfg(feature = "train")]
mod train;

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

/// A set of models an estimate chooses from by the chart a photo shows, held by the
/// estimator every estimate goes through (calibrations and chart checks made once, when the
/// models are loaded).
#[pyclass(module = "spdcam._native", frozen)]
struct Models {
    estimator: Estimator,
}

impl Models {
    /// The estimator of `set` on the default 400–700 nm grid (charts from `SPDCAM_DATA`).
    fn of(set: ModelSet) -> spdcam_infer::Result<Models> {
        Ok(Models {
            estimator: Estimator::new(set, DataDir::new(None), Grid::ESTIMATION)?,
        })
    }

    /// The estimator on the grid `range` names (the models shared), told the kind of light
    /// `light` names (`unknown`: none).
    fn on(&self, range: &str, light: &str) -> PyResult<Estimator> {
        let grid = Grid::parse(range).map_err(py_err)?;
        let kind = LightKind::parse(light).map_err(py_err)?;
        self.estimator
            .on_grid(grid)
            .and_then(|e| e.for_light(kind))
            .map_err(py_err)
    }
}

#[pymethods]
impl Models {
    /// The models shipped inside spdcam, one per chart, with their raw models (raw photos
    /// of a chart that has one get its spectrum, as on the command line).
    #[staticmethod]
    fn shipped() -> PyResult<Models> {
        Ok(Models {
            estimator: Estimator::shipped(DataDir::new(None), Grid::ESTIMATION).map_err(py_err)?,
        })
    }

    /// One model from a `.spdm` file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Models> {
        let model = Model::load(&path).map_err(py_err)?;
        Models::of(ModelSet::single(model, path.display().to_string())).map_err(py_err)
    }

    /// `(name, chart, feature names, wavelength grid label)` of each model.
    fn describe(&self) -> Vec<(String, Option<String>, Vec<String>, String)> {
        self.estimator
            .models()
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

/// An estimate as a Python dict: `Estimate::to_json` with its `presentation` (the numbers as
/// the command line, the report and the web page write them, for `repr`), converted value by
/// value (pythonize), never through JSON text.
fn estimate_dict<'py>(py: Python<'py>, estimate: &Estimate) -> PyResult<Bound<'py, PyAny>> {
    let mut value = estimate.to_json().map_err(py_err)?;
    value["presentation"] = serde_json::to_value(Presentation::of(estimate)).map_err(py_err)?;
    pythonize::pythonize(py, &value).map_err(py_err)
}

/// A photo as Python hands it over.
#[derive(FromPyObject)]
enum PhotoInput<'py> {
    /// A photo file's bytes (JPEG, PNG, TIFF, or camera raw).
    Encoded(Bound<'py, PyBytes>),
    /// Interleaved RGB pixels (`height × width × 3`, encoded sRGB) as native-endian bytes of
    /// `u8` values, or of `u16` values when `bits` is 16: `(pixels, width, height, bits)`.
    Pixels(Bound<'py, PyBytes>, usize, usize, u32),
    /// A photo file.
    Path(PathBuf),
}

/// A [`PhotoInput`] with its bytes borrowed from Python's objects, for work without the GIL.
enum PhotoData<'a> {
    Encoded(&'a [u8]),
    Pixels(&'a [u8], usize, usize, u32),
    Path(&'a PathBuf),
}

impl PhotoInput<'_> {
    fn data(&self) -> PhotoData<'_> {
        match self {
            PhotoInput::Encoded(b) => PhotoData::Encoded(b.as_bytes()),
            PhotoInput::Pixels(b, w, h, bits) => PhotoData::Pixels(b.as_bytes(), *w, *h, *bits),
            PhotoInput::Path(p) => PhotoData::Path(p),
        }
    }
}

/// One photo's estimate, or the message of why it cannot be used (the command line's).
fn estimate_one(
    estimator: &Estimator,
    photo: &PhotoData<'_>,
    source: &str,
    options: &PhotoOptions,
) -> Result<Estimate, String> {
    match photo {
        PhotoData::Path(path) => estimator
            .estimate_photo(path, options)
            .map_err(|e| unusable_photo(path, &e)),
        PhotoData::Encoded(data) => estimator
            .estimate_photo_bytes(data, source, options)
            .map_err(|e| e.to_string()),
        PhotoData::Pixels(pixels, width, height, bits) => {
            pixels_photo(source, pixels, *width, *height, *bits)
                .map_err(spdcam_infer::InferError::from)
                .and_then(|p| estimator.estimate_decoded(&p, options))
                .map_err(|e| e.to_string())
        }
    }
}

/// A photo of interleaved RGB pixels: `u8` values, or native-endian `u16` when `bits` is 16.
fn pixels_photo(
    source: &str,
    pixels: &[u8],
    width: usize,
    height: usize,
    bits: u32,
) -> spdcam_core::error::Result<Photo> {
    if bits == 16 {
        let values = pixels
            .chunks_exact(2)
            .map(|c| u16::from_ne_bytes([c[0], c[1]]))
            .collect();
        Photo::from_rgb16(source, width, height, values)
    } else {
        Photo::from_rgb8(source, width, height, pixels.to_vec())
    }
}

/// Estimates the light from photos, each a file path, an encoded photo's bytes, or a tuple
/// `(pixels, width, height, bits)` of RGB pixels, named in messages by `sources`; several
/// at once on every core, without the GIL, `progress(done, total)` told after each batch.
/// The estimates as dicts, in order; the first photo that cannot be used raises its
/// message.
#[pyfunction]
#[pyo3(signature = (photos, sources, models, chart=None, corners=None, range="400-700:5", light="unknown", progress=None))]
#[allow(clippy::too_many_arguments)]
fn estimate_photos<'py>(
    py: Python<'py>,
    photos: Vec<PhotoInput<'py>>,
    sources: Vec<String>,
    models: &Models,
    chart: Option<String>,
    corners: Option<Vec<[f64; 2]>>,
    range: &str,
    light: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if sources.len() != photos.len() {
        return Err(py_err(format!(
            "{} photos and {} names for them",
            photos.len(),
            sources.len()
        )));
    }
    let estimator = models.on(range, light)?;
    let options = PhotoOptions {
        chart,
        corners,
        ..PhotoOptions::default()
    };
    let data: Vec<PhotoData<'_>> = photos.iter().map(PhotoInput::data).collect();
    // Batches of a few photos per core: parallel within, progress told between them.
    let batch = 2 * rayon::current_num_threads().max(1);
    let mut out = Vec::with_capacity(data.len());
    for (chunk, names) in data.chunks(batch).zip(sources.chunks(batch)) {
        let estimates: Vec<Result<Estimate, String>> = py.allow_threads(|| {
            chunk
                .par_iter()
                .zip(names)
                .map(|(photo, name)| estimate_one(&estimator, photo, name, &options))
                .collect()
        });
        for e in estimates {
            out.push(estimate_dict(py, &e.map_err(py_err)?)?);
        }
        if let Some(callback) = &progress {
            callback.call1(py, (out.len(), data.len()))?;
        }
    }
    Ok(out)
}

/// Estimates the light at every chart one photo shows (a file path, an encoded photo's
/// bytes, or `(pixels, width, height, bits)`, named in messages by `source`): one dict per
/// chart, numbered from left to right, each with its place and the comparison across
/// places (`photo.place`, `across_places`, as `spdcam estimate --json` writes them);
/// `corners`, four per chart, place the charts instead of detecting them. A chart whose
/// patches are refused is left out; a photo that gives no estimate raises its message.
#[pyfunction]
#[pyo3(signature = (photo, source, models, chart=None, corners=None, range="400-700:5", light="unknown"))]
#[allow(clippy::too_many_arguments)]
fn estimate_places<'py>(
    py: Python<'py>,
    photo: PhotoInput<'py>,
    source: String,
    models: &Models,
    chart: Option<String>,
    corners: Option<Vec<[f64; 2]>>,
    range: &str,
    light: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let estimator = models.on(range, light)?;
    let options = PhotoOptions {
        chart,
        corners,
        ..PhotoOptions::default()
    };
    let data = photo.data();
    let results: Result<Vec<Estimate>, String> = py.allow_threads(|| {
        let decoded = match &data {
            PhotoData::Path(path) => {
                spdcam_core::photo::load_photo(path).map_err(|e| unusable_photo(path, &e))
            }
            PhotoData::Encoded(bytes) => {
                spdcam_core::photo::decode_photo(bytes, &source).map_err(|e| e.to_string())
            }
            PhotoData::Pixels(pixels, width, height, bits) => {
                pixels_photo(&source, pixels, *width, *height, *bits).map_err(|e| e.to_string())
            }
        }?;
        // A file's estimates are labelled with its name, as `estimate` labels them.
        let label = match &data {
            PhotoData::Path(path) => path
                .file_name()
                .map_or_else(|| source.clone(), |n| n.to_string_lossy().into_owned()),
            _ => source.clone(),
        };
        let mut made = Vec::new();
        let mut first_error = None;
        for place in estimator.photo_places(&decoded, &label, &options) {
            match place.into_estimate() {
                Ok(e) => made.push(e),
                Err(e) => {
                    first_error.get_or_insert(e.to_string());
                }
            }
        }
        match (made.is_empty(), first_error) {
            (true, Some(e)) => Err(e),
            _ => Ok(made),
        }
    });
    results
        .map_err(py_err)?
        .iter()
        .map(|e| estimate_dict(py, e))
        .collect()
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
/// the SPDs (rows × wavelengths), xy (rows × 2), CCT and Duv (NaN where undefined), then
/// the judgement of each row (a list of dicts with the keys of [`JUDGEMENT_KEYS`], as
/// `spdcam estimate --json` writes them).
type RowsResult<'py> = (
    String,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyAny>,
);

/// The keys of an estimate's JSON that say how far it can be trusted.
const JUDGEMENT_KEYS: [&str; 8] = [
    "verdict",
    "reasons",
    "self_check",
    "expected_gfc",
    "band_widening",
    "band68",
    "band95",
    "metric_uncertainty",
];

/// The judgements of `estimates` as a list of dicts (see [`RowsResult`]).
fn judgements<'py>(py: Python<'py>, estimates: &[Estimate]) -> PyResult<Bound<'py, PyAny>> {
    let judged = estimates
        .iter()
        .map(|e| {
            let v = e.to_json().map_err(py_err)?;
            Ok(JUDGEMENT_KEYS
                .iter()
                .map(|&k| (k.to_string(), v[k].clone()))
                .collect::<serde_json::Map<_, _>>())
        })
        .collect::<PyResult<Vec<_>>>()?;
    pythonize::pythonize(py, &judged).map_err(py_err)
}

/// Estimates the light for feature rows, each judged as `spdcam estimate --features`
/// judges it: `values` native-endian `f64` bytes of `rows` rows, one column per name of
/// `names` (default: the columns of the model that reads that many).
#[pyfunction]
#[pyo3(signature = (values, rows, models, names=None, source="features", range="400-700:5", light="unknown"))]
#[allow(clippy::too_many_arguments)]
fn estimate_rows<'py>(
    py: Python<'py>,
    values: &[u8],
    rows: usize,
    models: &Models,
    names: Option<Vec<String>>,
    source: &str,
    range: &str,
    light: &str,
) -> PyResult<RowsResult<'py>> {
    let estimator = models.on(range, light)?;
    let features = feature_rows(values, rows, estimator.models(), names, source)?;
    let estimates = py
        .allow_threads(|| estimator.estimate_rows(&features, source))
        .map_err(py_err)?;
    let grid = *estimator.grid();
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
        judgements(py, &estimates)?,
    ))
}

/// Feature rows from `values` (native-endian `f64` bytes of `rows` rows), one column per
/// name of `names` (default: the columns of the model that reads that many).
fn feature_rows(
    values: &[u8],
    rows: usize,
    models: &ModelSet,
    names: Option<Vec<String>>,
    source: &str,
) -> PyResult<FeatureRows> {
    let values = f64_values(values);
    let names = match names {
        Some(n) => n,
        None => default_names(models, values.len() / rows.max(1), source)?,
    };
    FeatureRows::from_values(names, values, source).map_err(py_err)
}

/// The feature names of the model that reads `columns` columns.
fn default_names(models: &ModelSet, columns: usize, source: &str) -> PyResult<Vec<String>> {
    models
        .models()
        .iter()
        .find(|m| m.model.feature_names().len() == columns)
        .map(|m| m.model.feature_names().to_vec())
        .ok_or_else(|| {
            let known = models.known();
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

/// The chart `name` laid out as `spdcam render` and `spdcam generate` lay it out by
/// default: a grid of `patch_px` patches without gaps or border.
fn grid_chart(
    name: &str,
    patch_px: usize,
    data_dir: &DataDir,
    grid: &Grid,
) -> spdcam_core::Result<Chart> {
    let chart = Chart::resolve(name, None, data_dir, grid)?;
    let layout = Layout::grid(chart.layout.rows, chart.layout.cols, patch_px, 0, 0);
    chart.with_layout(layout)
}

/// What `render` returns: width, height, the image as native-endian `f32` bytes (encoded
/// sRGB 0–1, interleaved RGB), the feature names, and the features (mean sRGB 0–255).
type RenderResult<'py> = (usize, usize, Bound<'py, PyBytes>, Vec<String>, Vec<f32>);

/// Renders `chart` photographed by `camera` (the command line's default settings) under a
/// light: `spd` names one (D65, A, cct:T, daylight:T, planck:T, a spectral CSV) or, with
/// `wavelengths`, is its values; `spdcam render` with the same light and seed gives the
/// same image and features.
#[pyfunction]
#[pyo3(signature = (spd, wavelengths=None, values=None, camera="nikon_d5100_npl", chart=None, patch_px=24, seed=0))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    spd: &str,
    wavelengths: Option<Vec<f64>>,
    values: Option<Vec<f64>>,
    camera: &str,
    chart: Option<&str>,
    patch_px: usize,
    seed: u64,
) -> PyResult<RenderResult<'py>> {
    let chart = chart.unwrap_or(DEFAULT_CHART.name());
    let rendering = py
        .allow_threads(|| -> spdcam_core::Result<_> {
            let grid = Grid::SIMULATION;
            let data_dir = DataDir::new(None);
            let light = match (wavelengths, values) {
                (Some(w), Some(v)) => {
                    let set = SpectralSet::new(w, vec![spd.to_string()], vec![v])?;
                    let (set, _) =
                        set.resample(&grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
                    set.spd(0)?
                }
                _ => named_light::resolve_spd(spd, &data_dir, &grid)?.spd,
            };
            let chart = grid_chart(chart, patch_px, &data_dir, &grid)?;
            let sensitivities = Sensitivities::resolve(camera, &data_dir, &grid)?;
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

/// Progress of long work for a Python callback `(done, total)`, called with the GIL taken
/// and with counts that only grow; the first exception the callback raises is kept and
/// raised by [`Reporter::finish`] once the work is over.
struct Reporter {
    callback: Option<Py<PyAny>>,
    state: Mutex<Reported>,
}

/// What a [`Reporter`] has reported.
#[derive(Default)]
struct Reported {
    done: u64,
    total: u64,
    error: Option<PyErr>,
}

impl Reporter {
    fn new(callback: Option<Py<PyAny>>) -> Reporter {
        Reporter {
            callback,
            state: Mutex::new(Reported::default()),
        }
    }

    /// Calls the callback with `done` (when more than before) of `total`.
    fn report(&self, done: impl FnOnce(u64) -> u64, total: Option<u64>) {
        let Some(callback) = &self.callback else {
            return;
        };
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(total) = total {
            state.total = total;
        }
        let done = done(state.done).min(state.total);
        if done <= state.done || state.error.is_some() {
            return;
        }
        state.done = done;
        let total = state.total;
        if let Err(e) = Python::with_gil(|py| callback.call1(py, (done, total))) {
            state.error = Some(e);
        }
    }

    /// Reports `done` of `total`.
    fn at(&self, done: u64, total: u64) {
        self.report(|_| done, Some(total));
    }

    /// Reports `n` more done.
    fn add(&self, n: u64) {
        self.report(|done| done + n, None);
    }

    /// Reports the work complete; the callback's first exception, if it raised one.
    fn finish(self) -> PyResult<()> {
        self.report(|_| u64::MAX, None);
        let state = self.state.into_inner().unwrap_or_else(|e| e.into_inner());
        state.error.map_or(Ok(()), Err)
    }
}

/// Generates a dataset into `output` as `spdcam generate` does with the default camera
/// settings (same library run, same files): `count` samples under the `lighting` recipe,
/// sample `i` depending only on `(seed, i)`. Returns the samples the directory holds.
#[pyfunction]
#[pyo3(signature = (output, lighting, count, seed=0, chart=None, camera="nikon_d5100_npl", spd_grid="380-780:5", fast=false, randomise=Vec::new(), cameras=None, force=false, progress=None))]
#[allow(clippy::too_many_arguments)]
fn generate(
    py: Python<'_>,
    output: PathBuf,
    lighting: String,
    count: u64,
    seed: u64,
    chart: Option<&str>,
    camera: &str,
    spd_grid: &str,
    fast: bool,
    randomise: Vec<String>,
    cameras: Option<String>,
    force: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<u64> {
    let chart = chart.unwrap_or(DEFAULT_CHART.name());
    let reporter = Reporter::new(progress);
    let manifest = py
        .allow_threads(|| -> spdcam_core::Result<_> {
            let grid = Grid::SIMULATION;
            let data_dir = DataDir::new(None);
            let request = GenerateRequest {
                lighting,
                camera: camera.to_string(),
                chart: grid_chart(chart, THESIS_PATCH_PX, &data_dir, &grid)?,
                config: CameraConfig::default(),
                randomise: RandomiseRequest {
                    groups: randomise,
                    cameras,
                    ..RandomiseRequest::default()
                },
                options: GenerateOptions {
                    pipeline: if fast { Pipeline::Fast } else { Pipeline::Full },
                    spd_grid: Grid::parse(spd_grid)?,
                    ..GenerateOptions::new(count, seed)
                },
            };
            request.run(
                &output,
                force,
                &data_dir,
                &mut |event| {
                    if let GenerateEvent::Planned(plan) = event {
                        reporter.at(0, plan.total() - plan.done());
                    }
                },
                &|n| reporter.add(n),
            )
        })
        .map_err(py_err)?;
    reporter.finish()?;
    Ok(manifest.samples)
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
    let options = PhotoOptions::default();
    py.allow_threads(|| {
        let start = Instant::now();
        for _ in 0..repeats {
            models.estimator.estimate_photo(&path, &options)?;
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
    let features = feature_rows(values, rows, models.estimator.models(), None, "features")?;
    py.allow_threads(|| {
        let start = Instant::now();
        for _ in 0..repeats {
            models.estimator.estimate_rows(&features, "features")?;
        }
        Ok(start.elapsed().as_secs_f64())
    })
    .map_err(|e: spdcam_infer::InferError| py_err(e))
}

/// The metric registry (`spdcam_core::quality::registry::METRICS`) as a list of dicts: each
/// metric's `key` (as in an estimate's `metrics` and `metric_uncertainty`), `symbol`,
/// `label`, `unit`, `group`, `explanation` and whether it has a `calibrated` interval.
#[pyfunction]
fn metric_registry(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let rows: Vec<serde_json::Value> = METRICS
        .iter()
        .map(|m| {
            serde_json::json!({
                "key": m.key,
                "symbol": m.symbol,
                "label": m.label,
                "unit": m.unit,
                "group": m.group.title(),
                "explanation": m.explanation,
                "calibrated": m.calibrated,
            })
        })
        .collect();
    pythonize::pythonize(py, &rows).map_err(py_err)
}

/// The names of the kinds of light `estimate(light=…)` takes, `unknown` first.
#[pyfunction]
fn light_kinds() -> Vec<&'static str> {
    LightKind::ALL.iter().map(|k| k.name()).collect()
}

/// The chart `render` and `generate` draw when none is named, as the command line's.
const DEFAULT_CHART: KnownChart = KnownChart::ColorChecker24;

/// The charts spdcam knows by name, from the chart registry: `(name, shown name,
/// description)` of each, the name as `chart` arguments and results give it, the shown name
/// as people know the chart.
#[pyfunction]
fn charts() -> Vec<(&'static str, &'static str, String)> {
    KnownChart::ALL
        .into_iter()
        .map(|c| (c.name(), c.shown_name(), c.description()))
        .collect()
}

/// The name people know the chart called `name` by (`ColorChecker Digital SG` for
/// `colorchecker_sg140`); any other chart by its own name.
#[pyfunction]
fn shown_chart_name(name: &str) -> String {
    spdcam_core::chart::shown_chart_name(name)
}

/// The compiled part of the `spdcam` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SpdcamError", m.py().get_type::<SpdcamError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Models>()?;
    m.add_function(wrap_pyfunction!(estimate_photos, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_places, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_rows, m)?)?;
    m.add_function(wrap_pyfunction!(read_photo, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(metric_registry, m)?)?;
    m.add_function(wrap_pyfunction!(light_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(charts, m)?)?;
    m.add_function(wrap_pyfunction!(shown_chart_name, m)?)?;
    m.add("DEFAULT_CHART", DEFAULT_CHART.name())?;
    #[cfg(feature = "train")]
    train::register(m)?;
    m.add_function(wrap_pyfunction!(library_seconds_photo, m)?)?;
    m.add_function(wrap_pyfunction!(library_seconds_rows, m)?)?;
    Ok(())
}
