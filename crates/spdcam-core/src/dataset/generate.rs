//! `spdcam generate`: samples from the virtual camera under lights of a lighting recipe,
//! written file by file so that memory stays flat, shards tile one run and an interrupted
//! run resumes.

use super::batch::{Columns, Counts, Precision, SampleBatch, SampleRow};
use super::lock::DirLock;
use super::manifest::{
    CameraInfo, ChartInfo, FileEntry, GenerateSettings, LightingInfo, Manifest, Origin, Pipeline,
    Shard,
};
use super::randomise::{Randomisation, RandomiseRequest};
use super::reader::read_sample_file;
use super::spd_map::SpdMap;
use super::writer::{
    clear_output, create_dir, ensure_dir, is_empty_dir, remove_partials, sample_file_name,
    write_sample_file, IMAGES_DIR, RUN_FILE, RUN_PARTS, SAMPLES_DIR,
};
use super::DEFAULT_CHUNK_SIZE;
use crate::builtin::DataDir;
use crate::camera::in_camera::InCamera;
use crate::camera::sensor::Sensitivities;
use crate::camera::{Camera, CameraConfig, RenderBuffers};
use crate::chart::Chart;
use crate::colorimetry::srgb_decode;
use crate::error::{Error, Result};
use crate::light_families::Lighting;
use crate::photo::raw::colour::chart_neutral;
use crate::photo::raw::dng::virtual_raw_colour;
use crate::photo::raw::{RawColour, CLIP_SHARE};
use crate::spectral::Grid;
use crate::{fsio, imageio, limits, seed};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Samples one worker renders between progress reports.
const BLOCK: u64 = 64;
/// How often [`Pipeline::Raw`] draws a sample's light again when a raw file's reading
/// cannot read the one drawn.
const RAW_REDRAWS: u64 = 16;

/// What to generate.
#[derive(Debug, Clone, PartialEq)]
pub struct GenerateOptions {
    /// Samples of the whole run (all shards together).
    pub count: u64,
    /// The run's seed: sample `i` depends only on it and `i`.
    pub seed: u64,
    /// Generate only this part of the run.
    pub shard: Option<Shard>,
    /// Full image pipeline or fast patch-level features.
    pub pipeline: Pipeline,
    /// The grid SPDs are stored on (inside the simulation grid).
    pub spd_grid: Grid,
    /// Also write every rendered chart as PNG (full pipeline only).
    pub images: bool,
    /// Samples per file.
    pub chunk_size: u64,
}

impl GenerateOptions {
    /// `count` samples from `seed`: whole run, full pipeline, SPDs on the simulation grid,
    /// no images, [`DEFAULT_CHUNK_SIZE`] samples per file.
    pub fn new(count: u64, seed: u64) -> GenerateOptions {
        GenerateOptions {
            count,
            seed,
            shard: None,
            pipeline: Pipeline::Full,
            spd_grid: Grid::SIMULATION,
            images: false,
            chunk_size: DEFAULT_CHUNK_SIZE,
        }
    }
}

/// A camera, a lighting recipe and the options: renders samples in memory or into a
/// dataset directory.
pub struct Generator<'a> {
    camera: &'a Camera,
    lighting: &'a Lighting,
    options: GenerateOptions,
    columns: Columns,
    spd_map: SpdMap,
    randomisation: Option<&'a Randomisation>,
    /// With [`Pipeline::Raw`]: each camera a sample may be taken with, with the colour
    /// calibration its DNGs carry ([`virtual_raw_colour`]), fitted once per camera.
    raw_colours: Vec<(&'a Camera, RawColour)>,
}

/// The work of one run in one directory: which files are already there. Holds the
/// directory's lock until the run has finished or the plan is dropped.
#[derive(Debug, Clone)]
pub struct Plan {
    dir: PathBuf,
    chunks: Vec<PlannedChunk>,
    lock: Arc<Mutex<Option<DirLock>>>,
}

#[derive(Debug, Clone)]
struct PlannedChunk {
    index: u64,
    samples: Range<u64>,
    /// The file an earlier run finished, checked against its recorded checksum.
    done: Option<FileEntry>,
}

impl Plan {
    /// Samples this run (or shard) holds when finished.
    pub fn total(&self) -> u64 {
        self.chunks
            .iter()
            .map(|c| c.samples.end - c.samples.start)
            .sum()
    }

    /// Samples already written by an earlier, interrupted run.
    pub fn done(&self) -> u64 {
        self.chunks
            .iter()
            .filter(|c| c.done.is_some())
            .map(|c| c.samples.end - c.samples.start)
            .sum()
    }
}

/// The features of [`Pipeline::Raw`]: `camera`'s exposed raw RGB of its chart under `light`
/// (the in-camera stage `ic`'s lighting and glare, exposed below clipping), each feature
/// patch taken to XYZ by the camera's DNG matrices `colour` ([`virtual_raw_colour`]) at the
/// neutral of the chart's grey patches, as a raw file of it is read ([`chart_neutral`],
/// [`RawColour::relative_xyz`]).
///
/// [`RawColour::relative_xyz`]: crate::photo::raw::RawColour::relative_xyz
pub fn raw_features(
    camera: &Camera,
    colour: &RawColour,
    ic: Option<&InCamera>,
    light: &[f32],
    raw: &mut Vec<[f32; 3]>,
    out: &mut Vec<f32>,
) -> Result<()> {
    camera.raw_regions_with(ic, light, raw);
    let chart = camera.chart();
    // The greys a raw file's reading keeps: neither clipped nor nearly black; under a
    // strongly coloured light, where every grey is nearly black in some channel (a photo
    // the raw reading refuses), the unclipped ones, so that every sample has its row.
    let dark_level = srgb_decode(f64::from(crate::photo::DARK_LEVEL)) as f32;
    let greys_where = |keep: &dyn Fn(&[f32; 3]) -> bool| -> Vec<([f32; 3], f64)> {
        chart
            .neutral_features()
            .into_iter()
            .map(|(k, reflectance)| (raw[chart.feature_patches[k]], reflectance))
            .filter(|(v, _)| v.iter().all(|&c| c < CLIP_SHARE) && keep(v))
            .collect()
    };
    let mut greys = greys_where(&|v| v.iter().all(|&c| c > dark_level));
    if greys.is_empty() {
        greys = greys_where(&|_| true);
    }
    let neutral = chart_neutral(&greys)
        .filter(|n| n.iter().all(|&c| c > 0.0))
        .ok_or_else(|| {
            Error::invalid("every grey patch is clipped or black; the light's colour is unread")
        })?;
    let patches: Vec<[f32; 3]> = chart.feature_patches.iter().map(|&p| raw[p]).collect();
    let xyz = colour.relative_xyz(neutral, &patches)?;
    out.extend(xyz.iter().flatten());
    Ok(())
}

/// What identifies a run, kept in the directory while it is unfinished.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RunRecord {
    spdcam_version: String,
    columns: Columns,
    settings: GenerateSettings,
}

/// Per-worker scratch space.
struct Workspace {
    buffers: Option<RenderBuffers>,
    raw: Vec<[f32; 3]>,
    features: Vec<f32>,
    features_f64: Vec<f64>,
    spd: Vec<f64>,
}

impl<'a> Generator<'a> {
    /// Checks the options against the camera and lighting.
    pub fn new(
        camera: &'a Camera,
        lighting: &'a Lighting,
        options: GenerateOptions,
    ) -> Result<Generator<'a>> {
        if options.count == 0 {
            return Err(Error::invalid("the sample count must be at least 1"));
        }
        if options.chunk_size == 0 {
            return Err(Error::invalid("the chunk size must be at least 1 sample"));
        }
        if options.images && options.pipeline != Pipeline::Full {
            return Err(Error::invalid(
                "images need the full pipeline; the fast and raw paths render no image",
            ));
        }
        let sim = camera.grid();
        let g = options.spd_grid;
        if g.start_nm < sim.start_nm - 1e-9 || g.end_nm() > sim.end_nm() + 1e-9 {
            return Err(Error::invalid(format!(
                "the SPD grid {g} reaches outside the simulation grid {sim}"
            )));
        }
        let columns = Columns {
            feature_names: camera.chart().feature_names(),
            feature_precision: Precision::Float32,
            spd_grid: g,
            weight_names: lighting.weight_names().unwrap_or_default(),
        };
        columns.validate()?;
        limits::SAMPLES.check(
            options.count,
            &format!("a run of {} samples", options.count),
        )?;
        let row_values =
            (columns.feature_count() + columns.spd_len() + columns.weight_count()) as u64 + 3;
        limits::CHUNK_BYTES.check(
            limits::product(&[options.chunk_size, row_values, 8]),
            &format!(
                "sample files of {} samples of {row_values} values",
                options.chunk_size
            ),
        )?;
        let spd_map = SpdMap::new(&sim.wavelengths(), &g)?;
        let mut generator = Generator {
            camera,
            lighting,
            options,
            columns,
            spd_map,
            randomisation: None,
            raw_colours: Vec::new(),
        };
        generator.raw_colours = generator.raw_colours_of(std::slice::from_ref(camera))?;
        Ok(generator)
    }

    /// Draws each sample's camera from `randomisation`'s pool and its in-camera parameters
    /// from its ranges; the pool must photograph this generator's chart on its grid.
    pub fn with_randomisation(mut self, randomisation: &'a Randomisation) -> Result<Self> {
        let pool = randomisation.cameras();
        if let Some(c) = pool.iter().find(|c| {
            c.grid() != self.camera.grid()
                || c.chart().feature_names() != self.camera.chart().feature_names()
                || c.chart().layout != self.camera.chart().layout
        }) {
            return Err(Error::invalid(format!(
                "randomisation camera '{}' does not photograph the generator's chart on its grid",
                c.camera_name()
            )));
        }
        if self.options.images {
            return Err(Error::invalid(
                "images are not written with domain randomisation; drop --images",
            ));
        }
        self.randomisation = Some(randomisation);
        self.raw_colours = self.raw_colours_of(pool)?;
        Ok(self)
    }

    /// With [`Pipeline::Raw`], `cameras` each with its DNGs' colour calibration; else none.
    fn raw_colours_of(&self, cameras: &'a [Camera]) -> Result<Vec<(&'a Camera, RawColour)>> {
        if self.options.pipeline != Pipeline::Raw {
            return Ok(Vec::new());
        }
        cameras
            .iter()
            .map(|c| Ok((c, virtual_raw_colour(c)?)))
            .collect()
    }

    /// The columns of the samples.
    pub fn columns(&self) -> &Columns {
        &self.columns
    }

    /// The sample files `[start, end)` this run (or shard) writes.
    fn chunk_range(&self) -> Range<u64> {
        let total = self.options.count.div_ceil(self.options.chunk_size);
        match self.options.shard {
            None => 0..total,
            Some(Shard { index, count }) => {
                let at = |k: u32| (total as u128 * k as u128 / count as u128) as u64;
                at(index)..at(index + 1)
            }
        }
    }

    /// The samples of file `k`.
    fn chunk_samples(&self, k: u64) -> Range<u64> {
        let size = self.options.chunk_size;
        k * size..((k + 1) * size).min(self.options.count)
    }

    /// The settings recorded in the manifest.
    pub fn settings(&self) -> GenerateSettings {
        let chunks = self.chunk_range();
        let start = (chunks.start * self.options.chunk_size).min(self.options.count);
        let end = (chunks.end * self.options.chunk_size).min(self.options.count);
        let chart = self.camera.chart();
        GenerateSettings {
            count: self.options.count,
            seed: self.options.seed,
            shard: self.options.shard,
            sample_range: [start, end],
            pipeline: self.options.pipeline,
            chunk_size: self.options.chunk_size,
            images: self.options.images,
            simulation_grid: *self.camera.grid(),
            seeding: "sample i: light = lighting.draw(seed, i); camera noise seed = \
                      seed::derive(seed, i) (SplitMix64 of seed and i)"
                .to_string(),
            lighting: LightingInfo {
                spec: self.lighting.spec().to_string(),
                description: self.lighting.describe(),
            },
            chart: ChartInfo {
                name: chart.name.clone(),
                layout: chart.layout,
                feature_patches: chart.feature_patches.clone(),
                background_reflectance: chart.background_reflectance,
            },
            camera: CameraInfo {
                name: self.camera.camera_name().to_string(),
                config: *self.camera.config(),
                correction_matrix: self
                    .camera
                    .correction_matrix()
                    .map(|m| std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))),
            },
            randomisation: self.randomisation.map(Randomisation::info),
        }
    }

    fn workspace(&self) -> Workspace {
        Workspace {
            buffers: (self.options.pipeline == Pipeline::Full).then(|| self.camera.buffers()),
            raw: Vec::new(),
            features: Vec::new(),
            features_f64: Vec::new(),
            spd: Vec::new(),
        }
    }

    /// Renders sample `i` and appends it to `out`; writes its image into `images` if given.
    fn sample_into(
        &self,
        i: u64,
        ws: &mut Workspace,
        out: &mut SampleBatch,
        images: Option<&Path>,
    ) -> Result<()> {
        let seed = self.options.seed;
        let (camera, drawn) = match self.randomisation {
            Some(r) => r.draw(seed, i),
            None => (self.camera, None),
        };
        let ic = drawn.as_ref().or(camera.config().in_camera.as_ref());
        let render = |draw: &crate::light_families::LightDraw| {
            camera.light(&draw.spd).map_err(|e| {
                Error::invalid(format!(
                    "sample {i}: lighting '{}' drew a light the camera cannot render: {e}",
                    self.lighting.spec()
                ))
            })
        };
        let mut draw = self.lighting.draw(seed, i)?;
        let mut light = render(&draw)?;
        ws.features.clear();
        match ws.buffers.as_mut() {
            None if self.options.pipeline == Pipeline::Raw => {
                // A light the raw reading cannot read (every grey clipped or black, or a
                // neutral the matrices give no luminance: a deep blue or red light) is
                // drawn again, from seed::derive(seed, i) and the attempt.
                let mut attempt = 0;
                let colour = self
                    .raw_colours
                    .iter()
                    .find(|(c, _)| std::ptr::eq(*c, camera))
                    .map(|(_, colour)| colour)
                    .ok_or_else(|| {
                        Error::invalid(format!("sample {i}: the camera has no raw calibration"))
                    })?;
                while let Err(e) =
                    raw_features(camera, colour, ic, &light, &mut ws.raw, &mut ws.features)
                {
                    attempt += 1;
                    if attempt > RAW_REDRAWS {
                        return Err(Error::invalid(format!(
                            "sample {i}: no light of {RAW_REDRAWS} draws could be read as a \
                             raw file reads it: {e}"
                        )));
                    }
                    ws.features.clear();
                    draw = self
                        .lighting
                        .draw(seed::derive(seed::derive(seed, i), attempt), i)?;
                    light = render(&draw)?;
                }
            }
            None => camera.features_fast_with(ic, &light, &mut ws.raw, &mut ws.features),
            Some(buffers) => {
                let noise_seed = seed::derive(seed, i);
                match images {
                    None => camera.render_features_with(
                        ic,
                        &light,
                        noise_seed,
                        buffers,
                        &mut ws.features,
                    ),
                    Some(dir) => {
                        self.camera.render_into(&light, noise_seed, buffers, None);
                        ws.features.extend(self.camera.features(&buffers.image));
                        let path = dir.join(format!("sample-{i:08}.png"));
                        let depth = self.camera.config().colour.bit_depth;
                        imageio::write_png(&path, &buffers.image, depth)?;
                    }
                }
            }
        }
        ws.features_f64.clear();
        ws.features_f64
            .extend(ws.features.iter().map(|&v| f64::from(v)));
        ws.spd.clear();
        self.spd_map.apply(&draw.spd, &mut ws.spd)?;
        let weights = draw.weights.as_deref().unwrap_or_default();
        if weights.len() != self.columns.weight_count() {
            return Err(Error::invalid(format!(
                "sample {i}: lighting '{}' gave {} weights for its {} weight names",
                self.lighting.spec(),
                weights.len(),
                self.columns.weight_count()
            )));
        }
        out.push(SampleRow {
            sample: i,
            family: &draw.family,
            features: &ws.features_f64,
            spd: &ws.spd,
            weights,
            attempts: draw.attempts,
        })
    }

    /// Renders samples `range` in memory, in parallel, rows in sample order; writes their
    /// images into `images` if given. `progress` is told how many samples were finished.
    pub fn samples(
        &self,
        range: Range<u64>,
        images: Option<&Path>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<SampleBatch> {
        let blocks: Vec<Range<u64>> = range
            .clone()
            .step_by(BLOCK as usize)
            .map(|s| s..(s + BLOCK).min(range.end))
            .collect();
        let parts = blocks
            .into_par_iter()
            .map_init(
                || self.workspace(),
                |ws, block| {
                    let mut part = self.columns.batch();
                    for i in block.clone() {
                        self.sample_into(i, ws, &mut part, images)?;
                    }
                    progress(block.end - block.start);
                    Ok(part)
                },
            )
            .collect::<Result<Vec<SampleBatch>>>()?;
        let mut all = self.columns.batch();
        for part in parts {
            all.append(part);
        }
        Ok(all)
    }

    fn record(&self) -> RunRecord {
        RunRecord {
            spdcam_version: env!("CARGO_PKG_VERSION").to_string(),
            columns: self.columns.clone(),
            settings: self.settings(),
        }
    }

    /// The run an existing directory holds, from its run record or its manifest.
    fn existing_run(dir: &Path) -> Option<RunRecord> {
        let text = std::fs::read_to_string(dir.join(RUN_FILE)).ok();
        if let Some(record) = text.and_then(|t| serde_json::from_str(&t).ok()) {
            return Some(record);
        }
        let manifest = Manifest::read(dir).ok()?;
        match manifest.origin {
            Origin::Generated(settings) => Some(RunRecord {
                spdcam_version: manifest.spdcam_version,
                columns: manifest.columns,
                settings: *settings,
            }),
            _ => None,
        }
    }

    /// Locks `dir` for this run, prepares it and finds the files an earlier run of the same
    /// command finished: those whose bytes match the checksum that run recorded (in its
    /// manifest, or in the journal an interrupted run leaves). A directory holding anything
    /// else is refused unless `overwrite`, which starts afresh; a directory another run is
    /// writing is refused.
    pub fn prepare(&self, dir: &Path, overwrite: bool) -> Result<Plan> {
        let record = self.record();
        ensure_dir(dir)?;
        let lock = DirLock::acquire(dir)?;
        let resuming = !is_empty_dir(dir)?
            && !overwrite
            && match Self::existing_run(dir) {
                Some(previous) if previous == record => true,
                Some(previous) => {
                    let differs = differing_settings(&previous, &record);
                    return Err(Error::invalid(format!(
                        "output directory {} holds a generate run with other settings ({}); \
                         use --force to replace it, or choose another directory",
                        dir.display(),
                        differs.join(", ")
                    )));
                }
                None => false,
            };
        if !resuming {
            clear_output(dir, overwrite)?;
        }
        let finished = finished_parts(dir);
        remove_partials(dir)?;
        let mut text = serde_json::to_string_pretty(&record)
            .map_err(|e| Error::invalid(format!("run record: {e}")))?;
        text.push('\n');
        fsio::write_atomic(&dir.join(RUN_FILE), text.as_bytes())?;
        let mut folders = vec![SAMPLES_DIR];
        if self.options.images {
            folders.push(IMAGES_DIR);
        }
        for folder in folders {
            create_dir(&dir.join(folder))?;
            remove_partials(&dir.join(folder))?;
        }
        let chunks = self
            .chunk_range()
            .map(|index| {
                let samples = self.chunk_samples(index);
                let name = sample_file_name(index);
                let done = finished
                    .get(&name)
                    .filter(|e| e.rows == samples.end - samples.start && e.sha256.is_some())
                    .filter(|e| {
                        std::fs::read(dir.join(&name)).is_ok_and(|b| e.verify(&b, dir).is_ok())
                    })
                    .cloned();
                PlannedChunk {
                    index,
                    samples,
                    done,
                }
            })
            .collect();
        Ok(Plan {
            dir: dir.to_path_buf(),
            chunks,
            lock: Arc::new(Mutex::new(Some(lock))),
        })
    }

    /// Renders the files `plan` still lacks, then writes the manifest. `progress` is told how
    /// many new samples were finished. Files are rendered, encoded and written in parallel,
    /// each by the thread that picks it up, the samples of one file spread over threads that
    /// would otherwise idle; so both rendering and compression use every core, and memory
    /// holds about one file per thread whatever the count.
    pub fn run(&self, plan: &Plan, progress: &(dyn Fn(u64) + Sync)) -> Result<Manifest> {
        let dir = plan.dir.as_path();
        let images = self.options.images.then(|| dir.join(IMAGES_DIR));
        // Resumed runs append to the journal from several threads; one line at a time.
        let journal = std::sync::Mutex::new(());
        let written = plan
            .chunks
            .par_iter()
            .with_max_len(1)
            .map(|chunk| -> Result<(FileEntry, Counts)> {
                let (entry, batch) = match &chunk.done {
                    Some(entry) => (entry.clone(), read_sample_file(dir, entry, &self.columns)?),
                    None => {
                        let name = sample_file_name(chunk.index);
                        let batch =
                            self.samples(chunk.samples.clone(), images.as_deref(), progress)?;
                        let entry = write_sample_file(dir, name, &self.columns, &batch)?;
                        let _line = journal.lock().unwrap_or_else(|e| e.into_inner());
                        append_to_journal(dir, &entry)?;
                        (entry, batch)
                    }
                };
                let mut counts = Counts::default();
                counts.add(&batch);
                Ok((entry, counts))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut counts = Counts::default();
        let mut files = Vec::with_capacity(written.len());
        for (entry, c) in written {
            counts.merge(c);
            files.push(entry);
        }
        let manifest = Manifest::new(
            self.columns.clone(),
            counts,
            files,
            Origin::Generated(Box::new(self.settings())),
        );
        manifest.write(dir)?;
        for name in [RUN_FILE, RUN_PARTS] {
            let path = dir.join(name);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(Error::io(&path, e))
                }
                _ => {}
            }
        }
        if let Ok(mut lock) = plan.lock.lock() {
            lock.take();
        }
        Ok(manifest)
    }
}

/// Records a finished sample file in the run's journal, so that a resumed run trusts it
/// only while its bytes match.
fn append_to_journal(dir: &Path, entry: &FileEntry) -> Result<()> {
    let path = dir.join(RUN_PARTS);
    let line =
        serde_json::to_string(entry).map_err(|e| Error::invalid(format!("run journal: {e}")))?;
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| Error::io(&path, e))?;
    writeln!(file, "{line}")
        .and_then(|()| file.sync_data())
        .map_err(|e| Error::io(&path, e))
}

/// The sample files an earlier run of this directory finished, with their checksums: from
/// its manifest, and from the journal of an interrupted run (a torn last line is skipped).
fn finished_parts(dir: &Path) -> HashMap<String, FileEntry> {
    let mut parts: HashMap<String, FileEntry> = Manifest::read(dir)
        .map(|m| m.files)
        .unwrap_or_default()
        .into_iter()
        .map(|e| (e.name.clone(), e))
        .collect();
    if let Ok(text) = std::fs::read_to_string(dir.join(RUN_PARTS)) {
        for entry in text
            .lines()
            .filter_map(|l| serde_json::from_str::<FileEntry>(l).ok())
        {
            parts.insert(entry.name.clone(), entry);
        }
    }
    parts
}

/// The names of the top-level settings in which two runs differ.
fn differing_settings(a: &RunRecord, b: &RunRecord) -> Vec<String> {
    let (va, vb) = (
        serde_json::to_value(a).unwrap_or_default(),
        serde_json::to_value(b).unwrap_or_default(),
    );
    let mut names = Vec::new();
    if va["spdcam_version"] != vb["spdcam_version"] {
        names.push("spdcam version".to_string());
    }
    if va["columns"] != vb["columns"] {
        names.push("columns".to_string());
    }
    if let (Some(sa), Some(sb)) = (va["settings"].as_object(), vb["settings"].as_object()) {
        names.extend(
            sa.iter()
                .filter(|(k, v)| sb.get(*k) != Some(v))
                .map(|(k, _)| k.clone()),
        );
    }
    names
}

/// A whole generate run as `spdcam generate` describes it: the lighting recipe and the
/// camera by name, the chart and camera settings, the randomisation and the options.
#[derive(Debug, Clone)]
pub struct GenerateRequest {
    /// The lighting recipe (`spdcam list lighting` shows the forms).
    pub lighting: String,
    /// The camera's sensitivities: a built-in name, a data-directory name or a CSV file.
    pub camera: String,
    /// The chart with its layout.
    pub chart: Chart,
    /// The camera's settings.
    pub config: CameraConfig,
    /// Domain randomisation per sample.
    pub randomise: RandomiseRequest,
    /// What to generate.
    pub options: GenerateOptions,
}

/// What a [`GenerateRequest`] run tells its caller before it renders.
#[derive(Debug)]
pub enum GenerateEvent<'a> {
    /// A file of the camera directory was skipped: it is no valid sensitivity set.
    Skipped(&'a Path, &'a Error),
    /// The directory is prepared: how many samples the run has and how many were there.
    Planned(&'a Plan),
}

impl GenerateRequest {
    /// Generates the dataset into `dir` (resuming a run there, or replacing what it holds
    /// with `overwrite`); `events` hears of skipped cameras and the plan, `progress` of the
    /// samples written. Returns the manifest written.
    pub fn run(
        &self,
        dir: &Path,
        overwrite: bool,
        data_dir: &DataDir,
        events: &mut dyn FnMut(GenerateEvent<'_>),
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Manifest> {
        let grid = Grid::SIMULATION;
        let base = Sensitivities::resolve(&self.camera, data_dir, &grid)?;
        let camera = Camera::new(&base, self.chart.clone(), self.config, &grid)?;
        let lighting = Lighting::parse(&self.lighting, data_dir, &grid)?;
        let (randomisation, skipped) = self.randomise.build(
            &base,
            &self.chart,
            self.config,
            self.options.seed,
            data_dir,
            &grid,
        )?;
        for (path, error) in &skipped {
            events(GenerateEvent::Skipped(path, error));
        }
        let mut generator = Generator::new(&camera, &lighting, self.options.clone())?;
        if let Some(r) = &randomisation {
            generator = generator.with_randomisation(r)?;
        }
        let plan = generator.prepare(dir, overwrite)?;
        events(GenerateEvent::Planned(&plan));
        generator.run(&plan, progress)
    }
}
