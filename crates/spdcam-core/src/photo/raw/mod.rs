//! Camera raw files (DNG, CR2, CR3, NEF, ARW, RAF, ORF, RW2, PEF, …): the sensor's linear
//! values before any white balance, tone curve or colour matrix, with the file's own colour
//! calibration beside them.
//!
//! ```text
//! raw file ─► decode (rawler) ─► RawMosaic ─┬─► preview: half-size sRGB rendering ─► detection
//!                                           └─► patches sampled on the mosaic (sample.rs)
//!                                                 ─► the light's chromaticity from the chart's
//!                                                    neutral patches (colour.rs), and the
//!                                                    patches developed to the feature row
//! ```
//!
//! [`decode`] reads the file with rawler (a maintained decoder of nearly every camera's raw
//! format, LGPL-2.1) and keeps the active area's photosites as stored, with their black and
//! white levels, colour filter layout and orientation. [`RawMosaic::preview`] renders the
//! upright photo the chart is looked for in (one pixel per colour-filter tile, so no
//! demosaicing), and [`RawMosaic::preview_to_sensor`] takes its coordinates back to the
//! mosaic, where [`sample`] reads each patch. A DNG's lens-shading gain maps
//! ([`opcodes`]) are applied to the stored values as the file is read.

pub mod colour;
mod decode;
pub mod dng;
mod header;
pub mod opcodes;
mod sample;

pub use colour::{CalibratedMatrix, RawColour, RawColourUse};
pub use decode::{decode, decode_if_raw, looks_like_raw};
pub use sample::{sample, RawReading};

use crate::camera::colour::srgb_encode_fast;
use crate::error::{Error, Result};
use crate::photo::{Exposure, Photo};
use rayon::prelude::*;

/// The longest side of the preview detection runs on, in pixels; more colour-filter tiles
/// are binned together beyond it.
const PREVIEW_MAX_SIDE: usize = 2000;
/// The preview's brightest 1 % of pixels (by green) is put at this linear level, so that the
/// chart is neither dark nor clipped whatever the raw exposure.
const PREVIEW_WHITE: f64 = 0.9;
/// A photosite at or above this share of the white level counts as clipped.
pub const CLIP_SHARE: f32 = 0.99;

/// The colour-filter layout: the colour (0 red, 1 green, 2 blue) of each photosite of the
/// repeating tile, row-major, from the active area's top-left photosite.
#[derive(Debug, Clone, PartialEq)]
pub struct CfaTile {
    /// Tile width in photosites (2 for Bayer, 6 for X-Trans).
    pub width: usize,
    /// Tile height in photosites.
    pub height: usize,
    /// Colour of each photosite of the tile.
    pub colours: Vec<u8>,
}

/// A raw photo: the active area's photosites as the sensor stored them, and what it takes to
/// read them as light.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMosaic {
    /// The camera as the file names it ("make model").
    pub camera: String,
    /// Active-area width in photosites (sensor orientation).
    pub width: usize,
    /// Active-area height in photosites.
    pub height: usize,
    /// Values per photosite: 1 for a colour-filter mosaic, 3 for a linear (demosaiced) DNG.
    pub channels: usize,
    /// The colour-filter layout of a mosaic (`None` with three values per photosite).
    pub cfa: Option<CfaTile>,
    /// Black level per position of the black-level tile (`black_tile` wide and high) and
    /// channel, in stored units.
    pub black: Vec<f32>,
    /// The black-level tile's width and height.
    pub black_tile: (usize, usize),
    /// White level per channel (stored units): values at it are clipped.
    pub white: [f32; 3],
    /// The file's colour calibration.
    pub colour: RawColour,
    /// EXIF orientation code (1 upright … 8) of the stored image.
    pub orientation: u16,
    /// The exposure from the file's EXIF, when it gives aperture, time and ISO.
    pub exposure: Option<Exposure>,
    /// The DNG's lens-shading gain maps applied to `values` (`OpcodeList2`).
    pub gain_maps_applied: usize,
    /// The opcodes of the DNG's `OpcodeList2` not applied, by name.
    pub opcodes_skipped: Vec<String>,
    /// The stored values of the active area, row-major, `channels` per photosite.
    pub(crate) values: Vec<u16>,
}

impl RawMosaic {
    /// The size of one cell, the unit the preview and the sampler read: the colour-filter
    /// tile, or one photosite of a linear DNG.
    pub fn cell_size(&self) -> (usize, usize) {
        self.cfa.as_ref().map_or((1, 1), |t| (t.width, t.height))
    }

    /// Cells across and down.
    pub fn cells(&self) -> (usize, usize) {
        let (cw, ch) = self.cell_size();
        (self.width / cw, self.height / ch)
    }

    /// The reader of this mosaic's cells ([`CellReader::cell`]).
    pub fn cell_reader(&self) -> CellReader<'_> {
        let (cw, ch) = self.cell_size();
        let (bw, bh) = self.black_tile;
        let repeats = bw > 0 && bh > 0 && cw % bw == 0 && ch % bh == 0;
        let levels = if repeats {
            let mut levels = Vec::with_capacity(cw * ch * self.channels);
            for dy in 0..ch {
                for dx in 0..cw {
                    for k in 0..self.channels {
                        levels.push(self.levels_at(dx, dy, dx, dy, k));
                    }
                }
            }
            levels
        } else {
            Vec::new()
        };
        // A 2 × 2 mosaic (Bayer) reads its four photosites with their weights worked out:
        // 1 / (range · photosites of that colour in the cell).
        let quad = (self.channels == 1 && (cw, ch) == (2, 2) && levels.len() == 4).then(|| {
            let mut per_colour = [0u32; 3];
            levels.iter().for_each(|l| per_colour[l.colour] += 1);
            std::array::from_fn(|k| {
                let l = levels[k];
                (l, 1.0 / (l.range * per_colour[l.colour] as f32))
            })
        });
        CellReader {
            mosaic: self,
            cell_size: (cw, ch),
            levels,
            quad,
        }
    }

    /// The levels of channel `k` of the photosite at (`x`, `y`), which lies at (`dx`, `dy`)
    /// within its cell.
    #[inline]
    fn levels_at(&self, x: usize, y: usize, dx: usize, dy: usize, k: usize) -> Levels {
        let black = self.black_at(x, y, k);
        let colour = self.colour_at(dx, dy, k);
        let white = self.white[colour];
        Levels {
            colour,
            black,
            range: white - black,
            clip: black + CLIP_SHARE * (white - black),
        }
    }

    /// The colour (0 red, 1 green, 2 blue) of channel `k` of the photosite at (`dx`, `dy`)
    /// within its cell.
    #[inline]
    fn colour_at(&self, dx: usize, dy: usize, k: usize) -> usize {
        match &self.cfa {
            Some(t) => t.colours[dy * t.width + dx] as usize,
            None => k,
        }
    }

    #[inline]
    fn black_at(&self, x: usize, y: usize, channel: usize) -> f32 {
        // Called per photosite only where the black-level tile does not repeat within the
        // cell (see `CellReader`).
        let (bw, bh) = self.black_tile;
        let per = self.black.len() / (bw * bh).max(1);
        let i = ((y % bh) * bw + x % bw) * per + channel.min(per.saturating_sub(1));
        self.black.get(i).copied().unwrap_or(0.0)
    }

    /// Cells binned per preview pixel (each way), so its longest side stays within
    /// [`PREVIEW_MAX_SIDE`].
    fn preview_bin(&self) -> usize {
        let (cx, cy) = self.cells();
        cx.max(cy).div_ceil(PREVIEW_MAX_SIDE).max(1)
    }

    /// The upright photo the chart is looked for in and drawn on: one pixel per cell (binned
    /// beyond 2000 pixels a side), white-balanced to the camera's as-shot neutral (or the
    /// mean of the photo where the file gives none) with the file's own matrix, its
    /// brightest 1 % at 0.9 of white, sRGB-encoded at 8 bits.
    pub fn preview(&self, source: &str) -> Result<Photo> {
        let bin = self.preview_bin();
        let (cells_x, cells_y) = self.cells();
        let (w, h) = (cells_x / bin, cells_y / bin);
        let mut linear = vec![[0f32; 3]; w * h];
        let reader = self.cell_reader();
        linear
            .par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(py, row)| match &reader.quad {
                Some(quad) => self.bayer_preview_row(quad, bin, py, row),
                None => {
                    for (px, out) in row.iter_mut().enumerate() {
                        let mut s = [0f32; 3];
                        for by in 0..bin {
                            for bx in 0..bin {
                                let (v, _) = reader.cell(px * bin + bx, py * bin + by);
                                (0..3).for_each(|c| s[c] += v[c]);
                            }
                        }
                        *out = s.map(|v| v / (bin * bin) as f32);
                    }
                }
            });
        let neutral = match self.colour.as_shot_neutral {
            Some(n) => n,
            None => {
                let mut mean = [0f64; 3];
                linear
                    .iter()
                    .for_each(|v| (0..3).for_each(|c| mean[c] += v[c] as f64));
                mean
            }
        };
        let (m, _) = self.colour.development(neutral)?;
        let m: [[f32; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)] as f32));
        linear.par_iter_mut().for_each(|v| {
            *v = std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2]);
        });
        // A non-negative f32's bits order as its value: integers select faster than floats
        // compared (the level below zero is clamped, as the gain's is below).
        let mut greens: Vec<u32> = linear.iter().map(|v| v[1].max(0.0).to_bits()).collect();
        let k = ((greens.len() as f64 * 0.99) as usize).min(greens.len().saturating_sub(1));
        let bright = if greens.is_empty() {
            1.0
        } else {
            f32::from_bits(*greens.select_nth_unstable(k).1)
        };
        let gain = (PREVIEW_WHITE / (bright as f64).max(1e-6)) as f32;
        // Rounding half up: the encoded value is never negative.
        let encode = |v: f32| (srgb_encode_fast(v * gain) * 255.0 + 0.5) as u8;
        let (uw, uh) = self.upright_size(w, h);
        let mut data = vec![0u8; uw * uh * 3];
        data.par_chunks_mut(uw * 3)
            .enumerate()
            .for_each(|(y, row)| {
                for x in 0..uw {
                    let (sx, sy) = self.stored_pixel(x, y, w, h);
                    let v = linear[sy * w + sx];
                    for c in 0..3 {
                        row[x * 3 + c] = encode(v[c]);
                    }
                }
            });
        let mut photo = Photo::from_rgb8(source, uw, uh, data)?;
        photo.exposure = self.exposure;
        Ok(photo)
    }

    /// Preview row `py` of a 2 × 2 (Bayer) mosaic, `bin` cells a pixel each way: each
    /// position's photosites summed as integers over the pixel's cells, then its black
    /// level taken off and its weight applied once (`quad`: [`CellReader`]'s levels and
    /// weights) — the mean of [`CellReader::cell`] over those cells, without reading each
    /// cell's levels.
    fn bayer_preview_row(
        &self,
        quad: &[(Levels, f32); 4],
        bin: usize,
        py: usize,
        row: &mut [[f32; 3]],
    ) {
        let mut sums = vec![[0u32; 4]; row.len()];
        for by in 0..bin {
            let top = 2 * (py * bin + by) * self.width;
            let upper = &self.values[top..top + self.width];
            let lower = &self.values[top + self.width..top + 2 * self.width];
            for (px, sum) in sums.iter_mut().enumerate() {
                let x0 = 2 * px * bin;
                for x in (x0..x0 + 2 * bin).step_by(2) {
                    sum[0] += u32::from(upper[x]);
                    sum[1] += u32::from(upper[x + 1]);
                    sum[2] += u32::from(lower[x]);
                    sum[3] += u32::from(lower[x + 1]);
                }
            }
        }
        let cells = (bin * bin) as f32;
        for (out, sum) in row.iter_mut().zip(&sums) {
            let mut rgb = [0f32; 3];
            for (&total, (levels, weight)) in sum.iter().zip(quad) {
                rgb[levels.colour] += (total as f32 - cells * levels.black) * weight;
            }
            *out = rgb.map(|v| v / cells);
        }
    }

    /// The preview's size once upright, from its stored size.
    fn upright_size(&self, w: usize, h: usize) -> (usize, usize) {
        match self.orientation {
            5..=8 => (h, w),
            _ => (w, h),
        }
    }

    /// The stored preview pixel shown at upright pixel (`x`, `y`) (EXIF orientation; `w`,
    /// `h` the stored preview size).
    fn stored_pixel(&self, x: usize, y: usize, w: usize, h: usize) -> (usize, usize) {
        match self.orientation {
            2 => (w - 1 - x, y),
            3 => (w - 1 - x, h - 1 - y),
            4 => (x, h - 1 - y),
            5 => (y, x),
            6 => (y, h - 1 - x),
            7 => (w - 1 - y, h - 1 - x),
            8 => (w - 1 - y, x),
            _ => (x, y),
        }
    }

    /// Continuous coordinates in the upright preview → photosite coordinates of the active
    /// area, as a 3×3 matrix (an affine map: the orientation undone, then the cells' size).
    pub fn preview_to_sensor(&self) -> [[f64; 3]; 3] {
        let bin = self.preview_bin();
        let (cells_x, cells_y) = self.cells();
        let (w, h) = ((cells_x / bin) as f64, (cells_y / bin) as f64);
        // Upright (X, Y) → stored preview (u, v) = a·X + b·Y + c, d·X + e·Y + f.
        let [a, b, c, d, e, f] = match self.orientation {
            2 => [-1.0, 0.0, w, 0.0, 1.0, 0.0],
            3 => [-1.0, 0.0, w, 0.0, -1.0, h],
            4 => [1.0, 0.0, 0.0, 0.0, -1.0, h],
            5 => [0.0, 1.0, 0.0, 1.0, 0.0, 0.0],
            6 => [0.0, 1.0, 0.0, -1.0, 0.0, h],
            7 => [0.0, -1.0, w, -1.0, 0.0, h],
            8 => [0.0, -1.0, w, 1.0, 0.0, 0.0],
            _ => [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        };
        let (cw, ch) = self.cell_size();
        let (sx, sy) = ((bin * cw) as f64, (bin * ch) as f64);
        [
            [a * sx, b * sx, c * sx],
            [d * sy, e * sy, f * sy],
            [0.0, 0.0, 1.0],
        ]
    }

    /// Checks the mosaic's own consistency: sizes, levels, the colour-filter tile.
    pub(crate) fn validate(&self) -> Result<()> {
        let (cw, ch) = self.cell_size();
        if self.width < cw * crate::photo::MIN_PHOTO_SIDE
            || self.height < ch * crate::photo::MIN_PHOTO_SIDE
        {
            return Err(Error::invalid(format!(
                "the raw image is {}×{} photosites; too small to show a chart",
                self.width, self.height
            )));
        }
        if self.values.len() != self.width * self.height * self.channels {
            return Err(Error::invalid(
                "the raw image's values do not fill its size",
            ));
        }
        if let Some(t) = &self.cfa {
            let mut seen = [false; 3];
            t.colours
                .iter()
                .for_each(|&c| seen[(c as usize).min(2)] = true);
            if t.colours.len() != t.width * t.height
                || t.colours.iter().any(|&c| c > 2)
                || seen != [true; 3]
            {
                return Err(Error::invalid(
                    "the raw file's colour filters are not red, green and blue (e.g. CYGM); \
                     spdcam reads RGB sensors only",
                ));
            }
        }
        let (bw, bh) = self.black_tile;
        if bw == 0 || bh == 0 || self.black.is_empty() {
            return Err(Error::invalid("the raw file gives no black level"));
        }
        for c in 0..3 {
            let black = self.black.iter().cloned().fold(f32::NEG_INFINITY, f32::max);
            if self.white[c].is_nan() || self.white[c] <= black {
                return Err(Error::invalid(format!(
                    "the raw file's white level {} is not above its black level {black}",
                    self.white[c]
                )));
            }
        }
        Ok(())
    }
}

/// A photosite's black level, its range to white (white − black) and the value from which
/// it counts as clipped, for one position and channel of the cell.
#[derive(Debug, Clone, Copy)]
struct Levels {
    colour: usize,
    black: f32,
    range: f32,
    clip: f32,
}

/// Reads a [`RawMosaic`]'s cells with the levels of each position in the cell worked out
/// once (where the black-level tile repeats within the cell, as in every raw file seen),
/// not per photosite: the preview reads every cell of the photo.
pub struct CellReader<'a> {
    mosaic: &'a RawMosaic,
    cell_size: (usize, usize),
    /// Per position in the cell and channel, row by row; empty where the black-level tile
    /// does not repeat within the cell.
    levels: Vec<Levels>,
    /// For a 2 × 2 mosaic with `levels`: each photosite's levels and weight.
    quad: Option<[(Levels, f32); 4]>,
}

impl CellReader<'_> {
    /// Linear camera RGB of cell (`cx`, `cy`): each channel's photosites averaged, black
    /// subtracted, as a share of full scale (white − black); and whether any photosite of
    /// it is clipped.
    #[inline]
    pub fn cell(&self, cx: usize, cy: usize) -> ([f32; 3], bool) {
        let m = self.mosaic;
        if let Some(quad) = &self.quad {
            let top = 2 * cy * m.width + 2 * cx;
            let stored = [top, top + 1, top + m.width, top + m.width + 1].map(|i| m.values[i]);
            let mut rgb = [0f32; 3];
            let mut clipped = false;
            for (&value, (levels, weight)) in stored.iter().zip(quad) {
                let value = f32::from(value);
                clipped |= value >= levels.clip;
                rgb[levels.colour] += (value - levels.black) * weight;
            }
            return (rgb, clipped);
        }
        let (cw, ch) = self.cell_size;
        let mut sum = [0f32; 3];
        let mut count = [0u32; 3];
        let mut clipped = false;
        for dy in 0..ch {
            let y = cy * ch + dy;
            for dx in 0..cw {
                let x = cx * cw + dx;
                let base = (y * m.width + x) * m.channels;
                for k in 0..m.channels {
                    let stored = m.values[base + k] as f32;
                    let levels = match self.levels.get((dy * cw + dx) * m.channels + k) {
                        Some(&levels) => levels,
                        None => m.levels_at(x, y, dx, dy, k),
                    };
                    clipped |= stored >= levels.clip;
                    sum[levels.colour] += (stored - levels.black) / levels.range;
                    count[levels.colour] += 1;
                }
            }
        }
        (
            std::array::from_fn(|c| sum[c] / count[c].max(1) as f32),
            clipped,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::dng::{virtual_camera_dng, DNG_BLACK, DNG_WHITE};
    use crate::builtin;
    use crate::camera::sensor::Sensitivities;
    use crate::camera::{Camera, CameraConfig};
    use crate::chart::Chart;
    use crate::cie_illuminant::StandardIlluminant;
    use crate::colorimetry::Observer;
    use crate::photo::scene::{self, SceneLight, SceneOptions};
    use crate::photo::{analyse, decode_photo, AnalyseOptions, ChartTemplate};
    use crate::spectral::{Grid, Spd};

    /// The built-in camera photographing the ColorChecker 24 in a scene, as `render --scene`.
    fn scene_camera() -> Camera {
        let grid = Grid::SIMULATION;
        let table = &builtin::CAMERAS[0];
        let sensitivities = Sensitivities::new(table.name, &table.load().unwrap(), &grid).unwrap();
        let chart = Chart::colorchecker24(&grid).unwrap();
        let template = ChartTemplate::from_chart(&chart).unwrap();
        let chart = chart.with_layout(scene::scene_layout(&template)).unwrap();
        Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).unwrap()
    }

    /// A DNG of the scene photo of `spd` (seed `seed`).
    fn scene_dng(camera: &Camera, spd: &Spd, seed: u64) -> Vec<u8> {
        let options = SceneOptions {
            width: 1200,
            height: 900,
            ..SceneOptions::default()
        };
        let shot = scene::photograph(camera, SceneLight::single(spd), seed, &options).unwrap();
        let exposure = crate::photo::Exposure::new(4.0, 0.01, 200.0);
        virtual_camera_dng(camera, spd, shot.mosaic.as_ref().unwrap(), exposure).unwrap()
    }

    #[test]
    fn a_written_dng_reads_back_with_its_values_levels_matrices_and_exposure() {
        let camera = scene_camera();
        let spd = StandardIlluminant::D65.spd(camera.grid()).unwrap();
        let bytes = scene_dng(&camera, &spd, 1);
        let raw = super::decode(&bytes, "scene.dng").unwrap();
        assert_eq!((raw.width, raw.height, raw.channels), (1200, 900, 1));
        assert_eq!(raw.white, [f32::from(DNG_WHITE); 3]);
        assert!(
            raw.black.iter().all(|&b| b == f32::from(DNG_BLACK)),
            "{:?}",
            raw.black
        );
        let tile = raw.cfa.as_ref().unwrap();
        assert_eq!(
            (tile.width, tile.height, &tile.colours[..]),
            (2, 2, &[0u8, 1, 1, 2][..])
        );
        let names: Vec<&str> = raw
            .colour
            .matrices
            .iter()
            .map(|m| m.illuminant.as_str())
            .collect();
        assert_eq!(names, ["A", "D65"]);
        let written = camera.dng_colour_matrices().unwrap();
        assert!(
            (raw.colour.matrices[1].xyz_to_camera - written[1].1)
                .abs()
                .max()
                < 1e-4
        );
        let neutral = camera.neutral_under(&spd).unwrap();
        let read = raw.colour.as_shot_neutral.unwrap();
        assert!(
            (0..3).all(|c| (read[c] - neutral[c]).abs() < 1e-4),
            "{read:?} {neutral:?}"
        );
        let exposure = raw.exposure.unwrap();
        assert_eq!(
            (exposure.f_number, exposure.exposure_time_s, exposure.iso),
            (4.0, 0.01, 200.0)
        );
        assert_eq!(raw.orientation, 1);
    }

    #[test]
    fn the_light_read_from_a_raw_scene_is_within_a_colour_meters_reach() {
        let camera = scene_camera();
        let grid = *camera.grid();
        let observer = Observer::cie1931(&grid).unwrap();
        let template = ChartTemplate::from_chart(&Chart::colorchecker24(&grid).unwrap()).unwrap();
        let options = AnalyseOptions {
            templates: vec![template],
            ..AnalyseOptions::default()
        };
        let lights = [
            StandardIlluminant::A.spd(&grid).unwrap(),
            StandardIlluminant::D65.spd(&grid).unwrap(),
            crate::named_light::resolve_spd("planck:4000", &builtin::DataDir::default(), &grid)
                .unwrap()
                .spd,
        ];
        for (k, spd) in lights.iter().enumerate() {
            let photo = decode_photo(&scene_dng(&camera, spd, 10 + k as u64), "scene.dng").unwrap();
            assert!(photo.raw().is_some());
            let analysis = analyse(&photo, &options).unwrap();
            let reading = analysis.raw.unwrap();
            let truth = observer.spd_to_xy(spd.values());
            let uv = |xy: [f64; 2]| {
                crate::quality::uv::xyz_to_uv1976(crate::colorimetry::xy_to_xyz(xy, 1.0))
            };
            let (a, b) = (uv(reading.light_xy), uv(truth));
            let duv = (a[0] - b[0]).hypot(a[1] - b[1]);
            assert!(
                duv < 0.002,
                "light {k}: Δu′v′ {duv} ({:?} vs {truth:?})",
                reading.light_xy
            );
            // Developed like a JPEG: the white patch (19) near neutral, near 240 of 255.
            let white = &analysis.features[54..57];
            assert!(
                white.iter().all(|&v| (200.0..=255.0).contains(&v)),
                "{white:?}"
            );
            assert!((white[0] - white[2]).abs() < 12.0, "{white:?}");
        }
    }

    /// The light's chromaticity a DNG's chart reads, and its Δu′v′ from `truth` (xy).
    fn light_read(bytes: &[u8], truth: [f64; 2]) -> (super::RawReading, f64) {
        let grid = Grid::SIMULATION;
        let template = ChartTemplate::from_chart(&Chart::colorchecker24(&grid).unwrap()).unwrap();
        let options = AnalyseOptions {
            templates: vec![template],
            ..AnalyseOptions::default()
        };
        let photo = decode_photo(bytes, "shading.dng").unwrap();
        let reading = analyse(&photo, &options).unwrap().raw.unwrap();
        let uv = |xy: [f64; 2]| {
            crate::quality::uv::xyz_to_uv1976(crate::colorimetry::xy_to_xyz(xy, 1.0))
        };
        let (a, b) = (uv(reading.light_xy), uv(truth));
        let duv = (a[0] - b[0]).hypot(a[1] - b[1]);
        (reading, duv)
    }

    #[test]
    fn a_dngs_lens_shading_gain_maps_are_applied_before_the_light_is_read() {
        use super::dng::{encode_dng, DngMetadata};
        use super::opcodes::GainMap;
        // A phone-like lens: each colour falls off with the squared distance from the
        // middle (as a share of the half-diagonal), red most, and the DNG carries the gains
        // that undo it, one map per position of the RGGB tile on a 13 × 17 grid.
        let camera = scene_camera();
        let grid = *camera.grid();
        let spd = StandardIlluminant::D65.spd(&grid).unwrap();
        let truth = Observer::cie1931(&grid).unwrap().spd_to_xy(spd.values());
        let scene = SceneOptions {
            width: 1200,
            height: 900,
            width_share: (0.35, 0.35),
            centre: Some([0.3, 0.32]),
            vignetting: (0.0, 0.0),
            ..SceneOptions::default()
        };
        let shot = scene::photograph(&camera, SceneLight::single(&spd), 30, &scene).unwrap();
        let plain = shot.mosaic.unwrap();
        let falloff = [0.45f64, 0.25, 0.35];
        let shading = |x: f64, y: f64, c: usize| {
            // x, y as shares of the width and height.
            let r2 = ((x - 0.5) * 1200.0).powi(2) + ((y - 0.5) * 900.0).powi(2);
            1.0 - falloff[c] * r2 / (600.0f64.powi(2) + 450.0f64.powi(2))
        };
        let mut shaded = plain.clone();
        for y in 0..shaded.height {
            for x in 0..shaded.width {
                let c = shaded.pattern.channel_at(x, y);
                shaded.data[y * 1200 + x] *=
                    shading((x as f64 + 0.5) / 1200.0, (y as f64 + 0.5) / 900.0, c) as f32;
            }
        }
        let (points_v, points_h) = (13u32, 17u32);
        let maps: Vec<GainMap> = [(0, 0), (0, 1), (1, 0), (1, 1)]
            .iter()
            .map(|&(top, left)| {
                let c = shaded.pattern.channel_at(left, top);
                let gains = (0..points_v)
                    .flat_map(|i| (0..points_h).map(move |j| (i, j)))
                    .map(|(i, j)| {
                        let (y, x) = (i as f64 / 12.0, j as f64 / 16.0);
                        (1.0 / shading(x, y, c)) as f32
                    })
                    .collect();
                GainMap {
                    area: [top as u32, left as u32, 900, 1200],
                    planes: (0, 1),
                    pitch: (2, 2),
                    points: (points_v, points_h),
                    spacing: (1.0 / 12.0, 1.0 / 16.0),
                    origin: (0.0, 0.0),
                    map_planes: 1,
                    gains,
                }
            })
            .collect();
        let meta = |gain_maps: Vec<GainMap>| DngMetadata {
            camera: camera.camera_name().to_string(),
            matrices: camera.dng_colour_matrices().unwrap(),
            as_shot_neutral: camera.neutral_under(&spd).unwrap(),
            exposure: None,
            forward_matrices: None,
            analog_balance: None,
            gain_maps,
        };
        let (_, unshaded) = light_read(&encode_dng(&plain, &meta(Vec::new())).unwrap(), truth);
        let (reading, corrected) = light_read(&encode_dng(&shaded, &meta(maps)).unwrap(), truth);
        let (_, uncorrected) = light_read(&encode_dng(&shaded, &meta(Vec::new())).unwrap(), truth);
        assert_eq!(reading.gain_maps_applied, 4);
        assert!(reading
            .describe()
            .contains("4 lens-shading gain maps applied"));
        assert!(
            corrected < unshaded + 0.0005 && uncorrected > 4.0 * corrected.max(0.001),
            "Δu′v′ unshaded {unshaded}, shaded and corrected {corrected}, shaded {uncorrected}"
        );
    }

    #[test]
    fn forward_matrices_and_analog_balance_read_back_from_a_written_dng() {
        use super::dng::{encode_dng, DngMetadata};
        let camera = scene_camera();
        let spd = StandardIlluminant::A.spd(camera.grid()).unwrap();
        let shot = scene::photograph(
            &camera,
            SceneLight::single(&spd),
            31,
            &SceneOptions {
                width: 600,
                height: 450,
                ..SceneOptions::default()
            },
        )
        .unwrap();
        let forward = [
            nalgebra::Matrix3::new(0.6, 0.2, 0.15, 0.25, 0.7, 0.05, 0.02, 0.1, 0.7),
            nalgebra::Matrix3::new(0.65, 0.18, 0.12, 0.28, 0.68, 0.04, 0.01, 0.12, 0.69),
        ];
        let meta = DngMetadata {
            camera: camera.camera_name().to_string(),
            matrices: camera.dng_colour_matrices().unwrap(),
            as_shot_neutral: camera.neutral_under(&spd).unwrap(),
            exposure: None,
            forward_matrices: Some(forward),
            analog_balance: Some([1.25, 1.0, 0.8]),
            gain_maps: Vec::new(),
        };
        let raw = super::decode(
            &encode_dng(shot.mosaic.as_ref().unwrap(), &meta).unwrap(),
            "f.dng",
        )
        .unwrap();
        let balance = raw.colour.analog_balance;
        assert!(
            (0..3).all(|c| (balance[c] - [1.25, 1.0, 0.8][c]).abs() < 1e-6),
            "{balance:?}"
        );
        // Matrix 1 is A (warmest first), as written.
        for (read, written) in raw.colour.matrices.iter().zip(&forward) {
            assert!((read.forward.unwrap() - written).abs().max() < 1e-4);
        }
        assert_eq!(raw.gain_maps_applied, 0);
    }

    #[test]
    fn a_dng_told_its_illuminance_reads_it_back_on_each_grey_patch() {
        // The chart in the middle of the scene (vignetting under 1 % there) under two
        // lights at two levels: each grey patch's green raw value, by the EXIF exposure
        // as ISO 12232 saturation speed, gives the illuminance it was told.
        let camera = scene_camera();
        let grid = *camera.grid();
        let observer = Observer::cie1931(&grid).unwrap();
        let chart = Chart::colorchecker24(&grid).unwrap();
        let template = ChartTemplate::from_chart(&chart).unwrap();
        let options = AnalyseOptions {
            templates: vec![template],
            ..AnalyseOptions::default()
        };
        let scene = SceneOptions {
            width: 1200,
            height: 900,
            width_share: (0.3, 0.3),
            centre: Some([0.5, 0.5]),
            vignetting: (0.0, 0.0),
            ..SceneOptions::default()
        };
        for (k, (spd, lux)) in [
            (StandardIlluminant::A.spd(&grid).unwrap(), 250.0),
            (StandardIlluminant::D65.spd(&grid).unwrap(), 20_000.0),
        ]
        .iter()
        .enumerate()
        {
            let shot =
                scene::photograph(&camera, SceneLight::single(spd), 20 + k as u64, &scene).unwrap();
            let scale = camera.exposed_chart_at(&[spd], None).unwrap().1;
            let exposure = super::dng::virtual_exposure(&camera, spd, scale, *lux).unwrap();
            let bytes =
                virtual_camera_dng(&camera, spd, shot.mosaic.as_ref().unwrap(), Some(exposure))
                    .unwrap();
            let photo = decode_photo(&bytes, "lux.dng").unwrap();
            let read = photo.raw().unwrap().exposure.unwrap();
            assert_eq!((read.f_number, read.iso), (4.0, 100.0));
            assert!(
                (read.exposure_time_s / exposure.exposure_time_s - 1.0).abs() < 1e-6,
                "{read:?} vs {exposure:?}"
            );
            let analysis = analyse(&photo, &options).unwrap();
            let mut greys = 0;
            for (f, _) in chart.neutral_features() {
                let patch = &analysis.patches[chart.feature_patches[f]];
                if patch.clipped || patch.dark {
                    continue;
                }
                let green = f64::from(patch.camera_rgb.unwrap()[1]);
                let factor = observer
                    .reflectance_to_xyz(chart.reflectances.item(chart.feature_patches[f]), spd)[1];
                let found = std::f64::consts::PI * read.luminance_from_raw(green) / factor;
                // The grey's green share of its luminance factor under the light, the noise
                // and the DNG's 14-bit steps: within 3 %.
                assert!(
                    (found / lux - 1.0).abs() < 0.03,
                    "light {k}, grey {}: {found} lx, not {lux}",
                    f + 1
                );
                greys += 1;
            }
            assert!(greys >= 4, "{greys} greys read");
        }
    }

    #[test]
    fn a_damaged_or_truncated_raw_file_is_an_error_naming_it_never_a_crash() {
        let camera = scene_camera();
        let spd = StandardIlluminant::D65.spd(camera.grid()).unwrap();
        let bytes = scene_dng(&camera, &spd, 2);
        for cut in [bytes.len() / 2, bytes.len() / 10, 200, 12] {
            let e = decode_photo(&bytes[..cut], "cut.dng")
                .unwrap_err()
                .to_string();
            assert!(e.contains("cut.dng"), "{cut}: {e}");
        }
        let mut scrambled = bytes.clone();
        for (i, b) in scrambled.iter_mut().enumerate().skip(8).step_by(97) {
            *b = b.wrapping_add(i as u8);
        }
        if let Err(e) = decode_photo(&scrambled, "scrambled.dng") {
            assert!(e.to_string().contains("scrambled.dng"), "{e}");
        }
        let e = decode_photo(b"FUJIFILMCCD-RAW 0201", "short.raf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("short.raf") && e.contains("raw"), "{e}");
    }

    #[test]
    fn the_preview_is_upright_and_maps_back_to_the_mosaic() {
        let camera = scene_camera();
        let spd = StandardIlluminant::D65.spd(camera.grid()).unwrap();
        let mut raw = super::decode(&scene_dng(&camera, &spd, 3), "s.dng").unwrap();
        let upright = raw.preview("s.dng").unwrap();
        for orientation in 1..=8u16 {
            raw.orientation = orientation;
            let preview = raw.preview("s.dng").unwrap();
            let (w, h) = (preview.width as f64, preview.height as f64);
            let m = raw.preview_to_sensor();
            let to_sensor = |x: f64, y: f64| {
                [
                    m[0][0] * x + m[0][1] * y + m[0][2],
                    m[1][0] * x + m[1][1] * y + m[1][2],
                ]
            };
            // The preview's four corners land on the mosaic's four corners.
            let mut corners: Vec<[i64; 2]> = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
                .iter()
                .map(|&[x, y]| to_sensor(x, y).map(|v| v.round() as i64))
                .collect();
            corners.sort();
            assert_eq!(
                corners,
                [[0, 0], [0, 900], [1200, 0], [1200, 900]],
                "orientation {orientation}"
            );
            // Each preview pixel shows the cell its centre maps to: the upright preview's
            // pixel is the stored (orientation 1) preview's pixel at that cell.
            for (px, py) in [
                (0, 0),
                (w as usize / 3, h as usize / 4),
                (w as usize - 1, 7),
            ] {
                let s = to_sensor(px as f64 + 0.5, py as f64 + 0.5);
                let stored = (s[0] / 2.0) as usize + (s[1] / 2.0) as usize * 600;
                assert_eq!(
                    preview.pixel(px, py),
                    upright.pixel(stored % 600, stored / 600),
                    "orientation {orientation} at ({px}, {py})"
                );
            }
            if orientation == 5 || orientation == 6 || orientation == 7 || orientation == 8 {
                assert_eq!((preview.width, preview.height), (450, 600));
            } else {
                assert_eq!((preview.width, preview.height), (600, 450));
            }
        }
    }
}
