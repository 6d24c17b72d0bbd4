//! A DNG's `OpcodeList2` (Adobe, *Digital Negative Specification* 1.6, chapter 7, "Opcode
//! List Processing"): the corrections the camera asks a reader to apply to the raw values
//! once they are linear, before demosaicing. Phones use it for lens shading: a `GainMap`
//! (opcode 9) per colour-filter position, a smooth grid of gains that lifts the corners,
//! and more in red than in blue. Left out, the chart's grey patches read redder or bluer
//! the further they lie from the middle of the frame, and so does the light.
//!
//! The list is big-endian whatever the file's byte order: a count, then per opcode its ID,
//! the DNG version it needs, flags (bit 0: optional) and the length of its parameters.
//! Gain maps are applied here as the DNG SDK applies them (`dng_gain_map.cpp`): a pixel at
//! row r of an image H rows high sits at (r + 0.5) / H, the map's rows lie at
//! origin + i · spacing, bilinear between the nearest map points, the nearest beyond them.
//! Every other opcode of the list is named in the reading as not applied.

use super::RawMosaic;
use crate::error::{Error, Result};
use rayon::prelude::*;

/// The `GainMap` opcode's ID.
const GAIN_MAP: u32 = 9;
/// Opcodes read from one list at most, against a damaged count.
const MAX_OPCODES: u32 = 1024;
/// Gains one map may hold at most (rows × columns × planes), against a damaged size.
const MAX_MAP_GAINS: u64 = 4_000_000;

/// One `GainMap`: where it applies (rows `top..bottom`, columns `left..right` of the active
/// area, every `row_pitch`-th row and `col_pitch`-th column from the first; planes
/// `plane..plane + planes`) and its grid of gains.
#[derive(Debug, Clone, PartialEq)]
pub struct GainMap {
    /// First row, first column, end row and end column (exclusive) of the area.
    pub area: [u32; 4],
    /// First plane and number of planes it applies to.
    pub planes: (u32, u32),
    /// Row and column step within the area.
    pub pitch: (u32, u32),
    /// Map points down and across.
    pub points: (u32, u32),
    /// Spacing of the map points, as a share of the image's height and width.
    pub spacing: (f64, f64),
    /// Position of the first map point, as a share of the image's height and width.
    pub origin: (f64, f64),
    /// Planes of gains per map point.
    pub map_planes: u32,
    /// The gains, row by row, then column, then plane.
    pub gains: Vec<f32>,
}

/// What an opcode list holds that spdcam acts on: its gain maps, and the names of the
/// opcodes it leaves out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OpcodeList {
    /// The gain maps, in the list's order.
    pub gain_maps: Vec<GainMap>,
    /// Every other opcode, by name (the specification's, or "opcode N").
    pub skipped: Vec<String>,
}

/// The name of opcode `id` (DNG 1.6, table of opcodes).
fn opcode_name(id: u32) -> String {
    match id {
        1 => "WarpRectilinear".into(),
        2 => "WarpFisheye".into(),
        3 => "FixVignetteRadial".into(),
        4 => "FixBadPixelsConstant".into(),
        5 => "FixBadPixelsList".into(),
        6 => "TrimBounds".into(),
        7 => "MapTable".into(),
        8 => "MapPolynomial".into(),
        9 => "GainMap".into(),
        10 => "DeltaPerRow".into(),
        11 => "DeltaPerColumn".into(),
        12 => "ScalePerRow".into(),
        13 => "ScalePerColumn".into(),
        14 => "WarpRectilinear2".into(),
        other => format!("opcode {other}"),
    }
}

/// A big-endian reader over an opcode list that fails with what it was reading.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(Error::invalid(format!(
                "the DNG's opcode list ends inside its {what} (damaged file?)"
            )));
        };
        let b = self.bytes[self.at..end].try_into().expect("N bytes");
        self.at = end;
        Ok(b)
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        self.take::<4>(what).map(u32::from_be_bytes)
    }
    fn f64(&mut self, what: &str) -> Result<f64> {
        self.take::<8>(what).map(f64::from_be_bytes)
    }
    fn f32(&mut self, what: &str) -> Result<f32> {
        self.take::<4>(what).map(f32::from_be_bytes)
    }
}

impl OpcodeList {
    /// Reads an opcode list's bytes; a list that ends early, claims too much or holds a gain
    /// map that makes no sense is an error saying so.
    pub fn parse(bytes: &[u8]) -> Result<OpcodeList> {
        let mut r = Reader { bytes, at: 0 };
        let count = r.u32("opcode count")?;
        if count > MAX_OPCODES {
            return Err(Error::invalid(format!(
                "the DNG's opcode list claims {count} opcodes (damaged file?)"
            )));
        }
        let mut list = OpcodeList::default();
        for _ in 0..count {
            let id = r.u32("opcode ID")?;
            let _version = r.u32("opcode version")?;
            let _flags = r.u32("opcode flags")?;
            let length = r.u32("opcode length")? as usize;
            let start = r.at;
            let end = start.checked_add(length).filter(|&e| e <= bytes.len());
            let Some(end) = end else {
                return Err(Error::invalid(format!(
                    "the DNG's {} opcode claims more bytes than its list holds (damaged file?)",
                    opcode_name(id)
                )));
            };
            if id == GAIN_MAP {
                let mut inner = Reader {
                    bytes: &bytes[start..end],
                    at: 0,
                };
                list.gain_maps.push(GainMap::read(&mut inner)?);
            } else {
                list.skipped.push(opcode_name(id));
            }
            r.at = end;
        }
        Ok(list)
    }
}

impl GainMap {
    /// Reads a `GainMap`'s parameters (DNG 1.6, "GainMap": the area, then the map).
    fn read(r: &mut Reader) -> Result<GainMap> {
        let w = "gain map";
        let area = [r.u32(w)?, r.u32(w)?, r.u32(w)?, r.u32(w)?];
        let planes = (r.u32(w)?, r.u32(w)?);
        let pitch = (r.u32(w)?, r.u32(w)?);
        let points = (r.u32(w)?, r.u32(w)?);
        let mut spacing = (r.f64(w)?, r.f64(w)?);
        let mut origin = (r.f64(w)?, r.f64(w)?);
        let map_planes = r.u32(w)?;
        // A single map point down or across: its spacing and origin do not matter (the SDK
        // sets them to 1 and 0).
        if points.0 == 1 {
            (spacing.0, origin.0) = (1.0, 0.0);
        }
        if points.1 == 1 {
            (spacing.1, origin.1) = (1.0, 0.0);
        }
        let n = u64::from(points.0) * u64::from(points.1) * u64::from(map_planes);
        let sound = points.0 >= 1
            && points.1 >= 1
            && map_planes >= 1
            && n <= MAX_MAP_GAINS
            && spacing.0 > 0.0
            && spacing.1 > 0.0
            && origin.0.is_finite()
            && origin.1.is_finite()
            && pitch.0 >= 1
            && pitch.1 >= 1
            && planes.1 >= 1;
        if !sound {
            return Err(Error::invalid(
                "the DNG's lens-shading gain map has no points, a zero pitch or a size \
                 beyond reason (damaged file?)",
            ));
        }
        let gains = (0..n).map(|_| r.f32(w)).collect::<Result<Vec<f32>>>()?;
        if gains.iter().any(|g| !g.is_finite() || *g < 0.0) {
            return Err(Error::invalid(
                "the DNG's lens-shading gain map holds a gain that is negative or not a number",
            ));
        }
        Ok(GainMap {
            area,
            planes,
            pitch,
            points,
            spacing,
            origin,
            map_planes,
            gains,
        })
    }

    /// The map's position index along one axis for pixel `i` of an image `size` long:
    /// the lower map point, the upper one and the weight of the upper one.
    fn index(i: usize, size: usize, origin: f64, spacing: f64, points: u32) -> (usize, usize, f32) {
        let f = (((i as f64 + 0.5) / size as f64) - origin) / spacing;
        let last = points as usize - 1;
        if f <= 0.0 {
            (0, 0, 0.0)
        } else if f as usize >= last {
            (last, last, 0.0)
        } else {
            let low = f as usize;
            (low, low + 1, (f - low as f64) as f32)
        }
    }

    /// The gain of map plane `p` at map row `row` (already interpolated between rows by
    /// the caller's weights) and column index `col`.
    #[inline]
    fn at(&self, row: usize, col: usize, p: usize) -> f32 {
        self.gains[(row * self.points.1 as usize + col) * self.map_planes as usize + p]
    }

    /// Multiplies the photosites it covers in `mosaic` by its gains, in linear units above
    /// black (clipped photosites stay clipped; a value is kept within the stored range).
    pub fn apply(&self, mosaic: &mut RawMosaic) {
        let (width, height, channels) = (mosaic.width, mosaic.height, mosaic.channels);
        let [top, left, bottom, right] = self.area.map(|v| v as usize);
        let (bottom, right) = (bottom.min(height), right.min(width));
        if top >= bottom || left >= right {
            return;
        }
        let (row_pitch, col_pitch) = (self.pitch.0 as usize, self.pitch.1 as usize);
        let first_plane = self.planes.0 as usize;
        let last_plane = (first_plane + self.planes.1 as usize).min(channels);
        let columns: Vec<(usize, (usize, usize, f32))> = (left..right)
            .step_by(col_pitch)
            .map(|x| {
                let index = Self::index(x, width, self.origin.1, self.spacing.1, self.points.1);
                (x, index)
            })
            .collect();
        let (cw, ch) = mosaic.cell_size();
        let mut values = std::mem::take(&mut mosaic.values);
        let reader: &RawMosaic = mosaic;
        values
            .par_chunks_mut(width * channels)
            .enumerate()
            .skip(top)
            .take(bottom - top)
            .filter(|(y, _)| (y - top) % row_pitch == 0)
            .for_each(|(y, row)| {
                let (r1, r2, fr) =
                    Self::index(y, height, self.origin.0, self.spacing.0, self.points.0);
                for k in first_plane..last_plane {
                    let p = k.min(self.map_planes as usize - 1);
                    for &(x, (c1, c2, fc)) in &columns {
                        let low = self.at(r1, c1, p) * (1.0 - fr) + self.at(r2, c1, p) * fr;
                        let high = self.at(r1, c2, p) * (1.0 - fr) + self.at(r2, c2, p) * fr;
                        let gain = low * (1.0 - fc) + high * fc;
                        let levels = reader.levels_at(x, y, x % cw, y % ch, k);
                        let v = &mut row[x * channels + k];
                        let stored = f32::from(*v);
                        // A clipped photosite stays clipped; one lifted past white is.
                        if stored < levels.clip {
                            let corrected = levels.black + (stored - levels.black) * gain;
                            let white = levels.black + levels.range;
                            *v = corrected.round().clamp(0.0, white.min(65535.0)) as u16;
                        }
                    }
                }
            });
        mosaic.values = values;
    }

    /// Appends the opcode as a DNG writes it: ID, version 1.3, flags 0 (not optional), the
    /// parameters' length, then the parameters.
    pub fn write(&self, out: &mut Vec<u8>) {
        let mut params = Vec::new();
        for v in self.area {
            params.extend(v.to_be_bytes());
        }
        for v in [self.planes.0, self.planes.1, self.pitch.0, self.pitch.1] {
            params.extend(v.to_be_bytes());
        }
        params.extend(self.points.0.to_be_bytes());
        params.extend(self.points.1.to_be_bytes());
        for v in [self.spacing.0, self.spacing.1, self.origin.0, self.origin.1] {
            params.extend(v.to_be_bytes());
        }
        params.extend(self.map_planes.to_be_bytes());
        for g in &self.gains {
            params.extend(g.to_be_bytes());
        }
        out.extend(GAIN_MAP.to_be_bytes());
        out.extend([1u8, 3, 0, 0]);
        out.extend(0u32.to_be_bytes());
        out.extend((params.len() as u32).to_be_bytes());
        out.extend(params);
    }
}

/// The bytes of an opcode list holding `maps`.
pub fn gain_map_list(maps: &[GainMap]) -> Vec<u8> {
    let mut out = (maps.len() as u32).to_be_bytes().to_vec();
    maps.iter().for_each(|m| m.write(&mut out));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 3 map over the whole image, one plane, every photosite.
    fn map() -> GainMap {
        GainMap {
            area: [0, 0, 4, 6],
            planes: (0, 1),
            pitch: (1, 1),
            points: (2, 3),
            spacing: (1.0, 0.5),
            origin: (0.0, 0.0),
            map_planes: 1,
            gains: vec![1.0, 2.0, 3.0, 2.0, 4.0, 6.0],
        }
    }

    #[test]
    fn a_written_list_reads_back_and_other_opcodes_are_named() {
        let maps = vec![map(), map()];
        let mut bytes = gain_map_list(&maps);
        // A third opcode, MapPolynomial (8), with 4 parameter bytes.
        bytes[..4].copy_from_slice(&3u32.to_be_bytes());
        bytes.extend(8u32.to_be_bytes());
        bytes.extend([1u8, 3, 0, 0]);
        bytes.extend(1u32.to_be_bytes());
        bytes.extend(4u32.to_be_bytes());
        bytes.extend([0u8; 4]);
        let list = OpcodeList::parse(&bytes).unwrap();
        assert_eq!(list.gain_maps, maps);
        assert_eq!(list.skipped, ["MapPolynomial"]);
    }

    #[test]
    fn a_damaged_list_is_an_error_at_every_cut_never_a_panic() {
        let bytes = gain_map_list(&[map()]);
        for cut in 0..bytes.len() {
            let e = OpcodeList::parse(&bytes[..cut]).unwrap_err().to_string();
            assert!(e.contains("opcode") || e.contains("gain map"), "{cut}: {e}");
        }
        let mut huge = bytes.clone();
        huge[..4].copy_from_slice(&u32::MAX.to_be_bytes());
        assert!(OpcodeList::parse(&huge).is_err());
        // Map points of 65536 × 65536: refused before reading gains.
        let mut big = bytes.clone();
        big[52..60].copy_from_slice(&[0, 1, 0, 0, 0, 1, 0, 0]);
        let e = OpcodeList::parse(&big).unwrap_err().to_string();
        assert!(e.contains("beyond reason"), "{e}");
    }

    #[test]
    fn gains_interpolate_bilinearly_at_pixel_centres_as_the_dng_sdk_does() {
        let m = map();
        // Row 1 of 4: (1.5 / 4 − 0) / 1 = 0.375 between map rows 0 and 1.
        assert_eq!(GainMap::index(1, 4, 0.0, 1.0, 2), (0, 1, 0.375));
        // Column 0 of 6: 0.5 / 6 / 0.5 = 1/6 between map columns 0 and 1; column 5: 11/6.
        let (c1, c2, f) = GainMap::index(5, 6, 0.0, 0.5, 3);
        assert_eq!((c1, c2), (1, 2));
        assert!((f - 5.0 / 6.0).abs() < 1e-6);
        // Beyond the last map point: the last one.
        assert_eq!(GainMap::index(3, 4, 0.0, 0.25, 2), (1, 1, 0.0));
        // Before the first: the first.
        assert_eq!(GainMap::index(0, 4, 0.5, 0.25, 3), (0, 0, 0.0));
        // At row 1, column 5: rows mix 0.625·(2, 3) + 0.375·(4, 6) = (2.75, 4.125), then
        // columns 1/6·2.75 + 5/6·4.125.
        let low = m.at(0, 1, 0) * 0.625 + m.at(1, 1, 0) * 0.375;
        let high = m.at(0, 2, 0) * 0.625 + m.at(1, 2, 0) * 0.375;
        assert_eq!((low, high), (2.75, 4.125));
    }

    /// A 6 × 4 RGGB mosaic, black 100, white 1100, every photosite at `value`.
    fn mosaic(value: u16) -> RawMosaic {
        use super::super::{CalibratedMatrix, CfaTile, RawColour};
        RawMosaic {
            camera: "test".into(),
            width: 6,
            height: 4,
            channels: 1,
            cfa: Some(CfaTile {
                width: 2,
                height: 2,
                colours: vec![0, 1, 1, 2],
            }),
            black: vec![100.0],
            black_tile: (1, 1),
            white: [1100.0; 3],
            colour: RawColour::new(
                vec![CalibratedMatrix::new(
                    "D65",
                    6504.0,
                    nalgebra::Matrix3::identity(),
                )],
                None,
            )
            .unwrap(),
            orientation: 1,
            exposure: None,
            gain_maps_applied: 0,
            opcodes_skipped: Vec::new(),
            values: vec![value; 24],
        }
    }

    #[test]
    fn a_gain_map_multiplies_the_level_above_black_where_its_area_and_pitch_say() {
        let mut m = mosaic(150);
        m.values[5] = 1095; // clipped (at or above 100 + 0.99 · 1000)
        m.values[11] = 1000; // lifted past white: white, so clipped
        map().apply(&mut m);
        // Row 0, column 0: rows 0.875·(1) + 0.125·(2) = 1.125 at column 0 and 2.25 at 1,
        // columns 5/6 · 1.125 + 1/6 · 2.25 = 1.3125: 100 + 50 · 1.3125 = 165.6.
        assert_eq!(m.values[0], 166);
        // Row 1, column 5 (gain 3.9 there, below): 1000 lifted past white reads white.
        assert_eq!(m.values[11], 1100);
        assert_eq!(m.values[5], 1095);
        let mut m = mosaic(150);
        map().apply(&mut m);
        // Row 1, column 5: 1/6 · 2.75 + 5/6 · 4.125 = 3.896: 100 + 50 · 3.896 = 294.8.
        assert_eq!(m.values[6 + 5], 295);
        // Pitch 2 from row 1, column 1: the blue photosites of RGGB only.
        let mut m = mosaic(150);
        let blue = GainMap {
            area: [1, 1, 4, 6],
            pitch: (2, 2),
            points: (1, 1),
            gains: vec![2.0],
            ..map()
        };
        blue.apply(&mut m);
        for y in 0..4 {
            for x in 0..6 {
                let expected = if y % 2 == 1 && x % 2 == 1 { 200 } else { 150 };
                assert_eq!(m.values[y * 6 + x], expected, "({x}, {y})");
            }
        }
    }
}
