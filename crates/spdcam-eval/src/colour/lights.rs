//! The lights the colour protocol photographs: the split's validation and test lamps, and a
//! fixed set of white references built by the program's own illuminant code.

use crate::error::Result;
use crate::held_out::GRID;
use spdcam_core::cie_illuminant::{daylight, planck, StandardIlluminant};
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::{LampLibrary, LampType, LightKind, ValidationSplit};
use spdcam_core::spectral::Spd;

/// Which set a light belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LightSet {
    /// The split's validation lamps: choose on these.
    Validation,
    /// The split's test lamps: report only.
    Test,
    /// The white references ([`references`]).
    References,
}

impl LightSet {
    /// Every set, in report order.
    pub const ALL: [LightSet; 3] = [LightSet::Validation, LightSet::Test, LightSet::References];

    /// `validation lamps`, `test lamps` or `white references`.
    pub fn label(self) -> &'static str {
        match self {
            LightSet::Validation => "validation lamps",
            LightSet::Test => "test lamps",
            LightSet::References => "white references",
        }
    }
}

/// One light photographed.
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    /// The lamp's name in the library, or the reference's.
    pub name: String,
    /// The set it belongs to.
    pub set: LightSet,
    /// The light's type: the library's for a lamp; incandescent or daylight for a
    /// reference.
    pub kind: LampType,
    /// The SPD on the simulation grid, peak 1: what the camera sees and what the truth is.
    pub spd: Spd,
}

impl Light {
    /// The kind of light a person who knows it would name ([`LightKind::of_lamp_type`]).
    pub fn light_kind(&self) -> LightKind {
        LightKind::of_lamp_type(self.kind).unwrap_or_default()
    }
}

/// The white references, on [`GRID`], peak 1: CIE A, D50 and D65 (the CIE 015 tables),
/// Planckian radiators at 2,700, 3,000 and 4,000 K (Planck's law) and CIE daylight at 5,000
/// and 6,500 K (the CIE 015 daylight formulas): the whites people light rooms and take
/// photos under, from the program's own illuminant code.
pub fn references() -> Result<Vec<Light>> {
    let mut out = Vec::new();
    for (s, kind) in [
        (StandardIlluminant::A, LampType::Incandescent),
        (StandardIlluminant::D50, LampType::Daylight),
        (StandardIlluminant::D65, LampType::Daylight),
    ] {
        out.push((format!("CIE {}", s.name()), s.spd(&GRID)?, kind));
    }
    for t in [2700.0, 3000.0, 4000.0] {
        out.push((
            format!("Planckian {t} K"),
            planck(t, &GRID)?,
            LampType::Incandescent,
        ));
    }
    for t in [5000.0, 6500.0] {
        out.push((
            format!("CIE daylight {t} K"),
            daylight(t, &GRID)?,
            LampType::Daylight,
        ));
    }
    Ok(out
        .into_iter()
        .map(|(name, spd, kind)| Light {
            name,
            set: LightSet::References,
            kind,
            spd: spd.normalised_by_max(),
        })
        .collect())
}

/// The lights of `set`: the lamps of the split's part, in its order, or the references.
pub fn lights(library: &LampLibrary, split: &ValidationSplit, set: LightSet) -> Result<Vec<Light>> {
    let (part, what) = match set {
        LightSet::Validation => (LampPart::Validation, "the split's validation lamps"),
        LightSet::Test => (LampPart::Test, "the split's test lamps"),
        LightSet::References => return references(),
    };
    let ids = library.positions(split.lamps(part), what)?;
    Ok(ids
        .into_iter()
        .map(|i| Light {
            name: library.names[i].clone(),
            set,
            kind: library.types[i],
            spd: library.spds[i].normalised_by_max(),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::score::LightColour;

    #[test]
    fn the_references_are_white_at_their_temperatures() {
        let refs = references().unwrap();
        assert_eq!(refs.len(), 8);
        let expected = [
            2856.0, 5003.0, 6504.0, 2700.0, 3000.0, 4000.0, 5000.0, 6500.0,
        ];
        for (light, want) in refs.iter().zip(expected) {
            let (cct, duv) = LightColour::of(&light.spd).unwrap().cct_duv.unwrap();
            // Within 0.3 % (the 5 nm grid); every one near the locus.
            assert!((cct / want - 1.0).abs() < 0.003, "{}: {cct}", light.name);
            assert!(duv.abs() < 0.006, "{}: {duv}", light.name);
            assert_eq!(light.spd.values().iter().cloned().fold(0.0, f64::max), 1.0);
        }
    }
}
