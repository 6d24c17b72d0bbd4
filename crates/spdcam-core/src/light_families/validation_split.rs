//! The fixed validation split of the real lamps and the camera pool, made once, before any
//! result is looked at, and stored as data (names only): lamps to fit the lamp families on,
//! lamps to choose models on, lamps only to report on, and cameras never used in training.
//!
//! Lamps are split per type (stratified), whole products at a time: settings of one product
//! (see [`product_key`]) and near-identical measurements (GFC ≥ [`NEAR_IDENTICAL_GFC`] on
//! 400–700 nm) fall on the same side, so a held-out lamp is never a re-measurement of a
//! fitted one. Cameras are held out by model: the measurements of one camera model from
//! different sources (`nikon_d200__camspec`, `nikon_d200__rawtoaces`) fall on the same side.

use super::lamp_library::{product_key, LampLibrary, LampType};
use crate::error::{Error, Result};
use crate::{seed, spectral_error};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Lamps whose SPDs agree this closely (GFC on 400–700 nm) count as one lamp for the split.
pub const NEAR_IDENTICAL_GFC: f64 = 0.9999;
/// Shares of each lamp type for fitting, validation and test.
pub const LAMP_SHARES: [f64; 3] = [0.5, 0.25, 0.25];
/// Share of the camera models held out of training.
pub const HELD_OUT_CAMERA_SHARE: f64 = 0.25;
/// Random stream of the split's shuffles.
const SPLIT_STREAM: u64 = 0x5350_4C49_5400_0001;

/// The lamps of each part of the split, by name.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LampSplit {
    /// Lamps the lamp families' parameters are fitted to.
    pub fit: Vec<String>,
    /// Lamps models are chosen on.
    pub validation: Vec<String>,
    /// Lamps only reported on.
    pub test: Vec<String>,
}

/// The cameras of the pool, by name (file stem).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CameraSplit {
    /// Cameras training data may be rendered with.
    pub training: Vec<String>,
    /// Cameras never used in training: validation and test photos are rendered with them.
    pub held_out: Vec<String>,
}

/// The whole split, as stored in the repository.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidationSplit {
    /// How the split was made.
    pub method: String,
    /// The seed of the split's shuffles.
    pub seed: u64,
    /// The lamps of each part.
    pub lamps: LampSplit,
    /// The cameras for training and held out.
    pub cameras: CameraSplit,
}

/// Which part of the lamp split.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LampPart {
    /// The lamps the lamp families' parameters are fitted to.
    Fit,
    /// The lamps models are chosen on.
    Validation,
    /// The lamps only reported on.
    Test,
}

impl ValidationSplit {
    /// Splits `library` (stratified by type, whole products at a time) and the camera
    /// names `cameras` (whole camera models at a time) under `seed`.
    pub fn make(library: &LampLibrary, cameras: &[String], seed: u64) -> Result<ValidationSplit> {
        if library.names.is_empty() {
            return Err(Error::invalid("the lamp library is empty"));
        }
        if cameras.len() < 2 {
            return Err(Error::invalid(format!(
                "splitting the camera pool needs at least two cameras; {} given",
                cameras.len()
            )));
        }
        let mut rng = SmallRng::seed_from_u64(seed::derive(seed, SPLIT_STREAM));
        let groups = lamp_groups(library);
        let mut parts: [Vec<usize>; 3] = Default::default();
        for kind in LampType::ALL {
            let mut of_kind: Vec<&Vec<usize>> = groups
                .iter()
                .filter(|g| library.types[g[0]] == kind)
                .collect();
            of_kind.shuffle(&mut rng);
            let mut counts = [0usize; 3];
            for group in of_kind {
                // The part furthest below its share takes the next product.
                let deficit = |k: usize| 1.0 - counts[k] as f64 / LAMP_SHARES[k];
                let part = (0..3).fold(0, |b, k| if deficit(k) > deficit(b) { k } else { b });
                counts[part] += group.len();
                parts[part].extend(group.iter().copied());
            }
        }
        let names = |part: &mut Vec<usize>| -> Vec<String> {
            part.sort_unstable();
            part.iter().map(|&i| library.names[i].clone()).collect()
        };
        let lamps = LampSplit {
            fit: names(&mut parts[0]),
            validation: names(&mut parts[1]),
            test: names(&mut parts[2]),
        };
        let mut models: BTreeMap<&str, Vec<&String>> = BTreeMap::new();
        for c in cameras {
            models.entry(camera_model(c)).or_default().push(c);
        }
        let mut keys: Vec<&str> = models.keys().copied().collect();
        keys.shuffle(&mut rng);
        let held =
            ((keys.len() as f64 * HELD_OUT_CAMERA_SHARE).round() as usize).clamp(1, keys.len() - 1);
        let mut held_out: Vec<String> = keys[..held]
            .iter()
            .flat_map(|k| models[k].iter().map(|c| c.to_string()))
            .collect();
        let mut training: Vec<String> = keys[held..]
            .iter()
            .flat_map(|k| models[k].iter().map(|c| c.to_string()))
            .collect();
        held_out.sort();
        training.sort();
        Ok(ValidationSplit {
            method: format!(
                "lamps: per type, whole products (same name up to a setting suffix, or GFC ≥ \
                 {NEAR_IDENTICAL_GFC} on 400–700 nm) in seeded random order, each to the part \
                 furthest below its share (fit {}, validation {}, test {}); cameras: whole \
                 camera models (name before '__') in seeded random order, the first {:.0} % \
                 held out",
                LAMP_SHARES[0],
                LAMP_SHARES[1],
                LAMP_SHARES[2],
                HELD_OUT_CAMERA_SHARE * 100.0
            ),
            seed,
            lamps,
            cameras: CameraSplit { training, held_out },
        })
    }

    /// The lamp names of one part.
    pub fn lamps(&self, part: LampPart) -> &[String] {
        match part {
            LampPart::Fit => &self.lamps.fit,
            LampPart::Validation => &self.lamps.validation,
            LampPart::Test => &self.lamps.test,
        }
    }

    /// Reads a split written by [`ValidationSplit::write`].
    pub fn read(path: &Path) -> Result<ValidationSplit> {
        let text = crate::fsio::read_text(path)?;
        let split: ValidationSplit = serde_json::from_str(&text).map_err(|e| {
            Error::parse(
                path.display().to_string(),
                format!("not a validation split: {e}"),
            )
        })?;
        split.check(&path.display().to_string())?;
        Ok(split)
    }

    /// Refuses a split whose parts share a lamp or a camera.
    fn check(&self, source: &str) -> Result<()> {
        let mut seen = std::collections::HashSet::new();
        for name in self
            .lamps
            .fit
            .iter()
            .chain(&self.lamps.validation)
            .chain(&self.lamps.test)
        {
            if !seen.insert(name) {
                return Err(Error::parse(
                    source,
                    format!("lamp '{name}' is in more than one part"),
                ));
            }
        }
        if let Some(c) = self
            .cameras
            .held_out
            .iter()
            .find(|c| self.cameras.training.contains(c))
        {
            return Err(Error::parse(
                source,
                format!("camera '{c}' is both held out and for training"),
            ));
        }
        Ok(())
    }

    /// Writes the split as pretty JSON, atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid(format!("encoding the split: {e}")))?;
        text.push('\n');
        crate::fsio::write_atomic(path, text.as_bytes())
    }

    /// Whether `camera` (a name or a file stem) may be used in training: its camera model is
    /// not one the split holds out ([`same_camera_model`]), so that a pool from another
    /// source (the predicted sensitivities name cameras without a `__source` suffix and
    /// spell models their own way) cannot bring a held-out camera back.
    pub fn allows_training_camera(&self, camera: &str) -> bool {
        !self
            .cameras
            .held_out
            .iter()
            .any(|c| same_camera_model(c, camera))
    }
}

/// A camera's model: its name before the `__source` suffix.
pub fn camera_model(name: &str) -> &str {
    name.split_once("__").map_or(name, |(m, _)| m)
}

/// One camera model sold under several names (the key of [`model_key`], then the key it
/// stands for): Canon's EOS 300D is the Digital Rebel and the Kiss Digital, its EOS 400D
/// the Digital Rebel XTi and the Kiss Digital X (Canon Camera Museum, EOS digital
/// cameras), which the measured sets name `canon_xti`.
const CAMERA_ALIASES: &[(&str, &str)] = &[
    ("canonxti", "canoneos400d"),
    ("canondigitalrebelxti", "canoneos400d"),
    ("canoneosdigitalrebelxti", "canoneos400d"),
    ("canonkissdigitalx", "canoneos400d"),
    ("canoneoskissdigitalx", "canoneos400d"),
    ("canondigitalrebel", "canoneos300d"),
    ("canoneosdigitalrebel", "canoneos300d"),
    ("canonkissdigital", "canoneos300d"),
    ("canoneoskissdigital", "canoneos300d"),
];

/// A camera's model as a key that ignores how a source spells it: the name before its
/// `__source` suffix and before a perturbed copy's `~seed`, lower case, letters and digits
/// only (`pentax_ist_dl` and `pentax_istdl` are one model), an alias replaced by the name it
/// stands for.
fn model_key(name: &str) -> String {
    let model = camera_model(name);
    let model = model.split_once('~').map_or(model, |(m, _)| m);
    let key: String = model
        .chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase())
        .collect();
    CAMERA_ALIASES
        .iter()
        .find(|(alias, _)| *alias == key)
        .map_or(key, |(_, model)| (*model).to_string())
}

/// Whether two camera names (names or file stems, from any source) name one camera model.
pub fn same_camera_model(a: &str, b: &str) -> bool {
    model_key(a) == model_key(b)
}

/// The library's lamps joined into products (lists of positions, in library order of their
/// first lamp): same [`product_key`], or near-identical SPDs.
fn lamp_groups(library: &LampLibrary) -> Vec<Vec<usize>> {
    let n = library.names.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let visible: Vec<Vec<f64>> = library
        .spds
        .iter()
        .map(|s| {
            (0..s.len())
                .filter(|&k| (400.0..=700.0).contains(&library.grid.wavelength(k)))
                .map(|k| s[k])
                .collect()
        })
        .collect();
    let keys: Vec<String> = library.names.iter().map(|n| product_key(n)).collect();
    for i in 0..n {
        for j in 0..i {
            let same = keys[i] == keys[j]
                || spectral_error::gfc(&visible[i], &visible[j]).unwrap_or(0.0)
                    >= NEAR_IDENTICAL_GFC;
            if same {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    groups.into_values().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::{Grid, Spd};

    /// A toy library: per type, lamps with distinct peaks; two settings of one product and
    /// one re-measurement.
    fn library() -> LampLibrary {
        let grid = Grid::SIMULATION;
        let mut names = Vec::new();
        let mut types = Vec::new();
        let mut spds = Vec::new();
        let mut add = |name: &str, kind: LampType, peak: f64| {
            names.push(name.to_string());
            types.push(kind);
            let values = (0..grid.count)
                .map(|k| (-((grid.wavelength(k) - peak) / 15.0).powi(2)).exp() + 1e-3)
                .collect();
            spds.push(Spd::new(grid, values).unwrap());
        };
        for k in 0..12 {
            add(
                &format!("white {k}"),
                LampType::PhosphorLed,
                420.0 + 20.0 * k as f64,
            );
        }
        // Peaks apart from the whites' (a lamp identical to a white would join it).
        add("RGBA 3K-A", LampType::MixedLed, 431.0);
        add("RGBA 3K-B", LampType::MixedLed, 503.0);
        add("RGB one", LampType::MixedLed, 607.0);
        add("RGB two", LampType::MixedLed, 653.0);
        add("tube", LampType::Fluorescent, 547.0);
        add("tube again", LampType::Fluorescent, 547.0);
        add("other tube", LampType::Fluorescent, 613.0);
        add("third tube", LampType::Fluorescent, 483.0);
        LampLibrary {
            names,
            types,
            spds,
            grid,
        }
    }

    #[test]
    fn split_is_stratified_disjoint_and_keeps_products_together() {
        let lib = library();
        let cameras: Vec<String> = [
            "a__camspec",
            "a__rawtoaces",
            "b__camspec",
            "c__npl",
            "d__camspec",
            "e__x",
            "f__y",
            "g__z",
        ]
        .map(String::from)
        .to_vec();
        let split = ValidationSplit::make(&lib, &cameras, 3).unwrap();
        let all: Vec<&String> = split
            .lamps
            .fit
            .iter()
            .chain(&split.lamps.validation)
            .chain(&split.lamps.test)
            .collect();
        assert_eq!(all.len(), lib.names.len());
        // Phosphor whites: 12 lamps, shares 6 / 3 / 3.
        let count = |part: &[String]| part.iter().filter(|n| n.starts_with("white")).count();
        assert_eq!(count(&split.lamps.fit), 6);
        assert_eq!(count(&split.lamps.validation), 3);
        assert_eq!(count(&split.lamps.test), 3);
        // Settings of one product, and re-measurements, stay together.
        let side = |name: &str| {
            [LampPart::Fit, LampPart::Validation, LampPart::Test]
                .into_iter()
                .find(|&p| split.lamps(p).iter().any(|n| n == name))
                .unwrap()
        };
        assert_eq!(side("RGBA 3K-A"), side("RGBA 3K-B"));
        assert_eq!(side("tube"), side("tube again"));
        // Camera models are held out whole: 7 models, 2 held out.
        let held = &split.cameras.held_out;
        assert_eq!(
            held.iter()
                .map(|c| camera_model(c))
                .collect::<std::collections::BTreeSet<_>>()
                .len(),
            2
        );
        assert_eq!(
            held.contains(&"a__camspec".to_string()),
            held.contains(&"a__rawtoaces".to_string())
        );
        assert_eq!(held.len() + split.cameras.training.len(), cameras.len());
        // The same seed gives the same split; another seed another one.
        assert_eq!(split, ValidationSplit::make(&lib, &cameras, 3).unwrap());
        let other = ValidationSplit::make(&lib, &cameras, 4).unwrap();
        assert!(other.lamps != split.lamps || other.cameras != split.cameras);
    }

    #[test]
    fn held_out_models_stay_out_under_any_spelling() {
        let lib = library();
        let cameras: Vec<String> = [
            "canon_xti__rawtoaces",
            "pentax_ist_dl__ilia3101",
            "nikon_d50__camspec",
        ]
        .map(String::from)
        .to_vec();
        let mut split = ValidationSplit::make(&lib, &cameras, 1).unwrap();
        split.cameras.held_out = cameras.clone();
        split.cameras.training.clear();
        for name in [
            "canon_eos_400d",
            "Canon EOS Kiss Digital X",
            "canon_xti__camspec",
            "pentax_istdl",
            "nikon_d50",
            "nikon_d50__ssfdata_spectroscope~123",
        ] {
            assert!(!split.allows_training_camera(name), "{name} is held out");
        }
        for name in [
            "canon_eos_450d",
            "pentax_istdl2",
            "nikon_d500",
            "nikon_d5",
            "canon_eos_300d",
        ] {
            assert!(split.allows_training_camera(name), "{name} is not held out");
        }
        assert!(same_camera_model("canon_eos_300d", "canon_digital_rebel"));
        assert!(!same_camera_model("sony_ilce_7", "sony_ilce_7m2"));
    }

    #[test]
    fn a_split_round_trips_and_overlaps_are_refused() {
        let lib = library();
        let cameras: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let split = ValidationSplit::make(&lib, &cameras, 1).unwrap();
        let dir = std::env::temp_dir().join(format!("spdcam-split-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("split.json");
        split.write(&path).unwrap();
        assert_eq!(ValidationSplit::read(&path).unwrap(), split);
        let mut bad = split.clone();
        bad.lamps.test.push(bad.lamps.fit[0].clone());
        bad.write(&path).unwrap();
        let err = ValidationSplit::read(&path).unwrap_err().to_string();
        assert!(err.contains("more than one part"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
