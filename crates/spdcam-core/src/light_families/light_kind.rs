//! The kinds of light a person can name when they know what lights the room (a colour
//! meter's or a meter app's first question): each kind with the lighting recipe its prior is
//! drawn from, and the kind of each real lamp type.

use super::LampType;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// What lights the scene, as the person taking the photo knows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightKind {
    /// Not known: every kind of light the models were trained on.
    #[default]
    Unknown,
    /// Daylight: sun and sky, through a window or outdoors.
    Daylight,
    /// Incandescent and halogen filaments.
    Incandescent,
    /// Fluorescent tubes and compact fluorescent lamps.
    Fluorescent,
    /// White LEDs: phosphor-converted, also with added coloured LEDs.
    WhiteLed,
    /// High-intensity discharge: metal halide, sodium, mercury.
    Hid,
    /// Colour-mixing LED lamps (RGB, RGBW, RGBA: smart bulbs and strips).
    RgbLed,
    /// Multi-channel LED luminaires (many narrow channels, as in studios and labs).
    Luminaire,
}

impl LightKind {
    /// Every kind, `Unknown` first.
    pub const ALL: [LightKind; 8] = [
        LightKind::Unknown,
        LightKind::Daylight,
        LightKind::Incandescent,
        LightKind::Fluorescent,
        LightKind::WhiteLed,
        LightKind::Hid,
        LightKind::RgbLed,
        LightKind::Luminaire,
    ];

    /// The name the command line, the page and Python take (`white-led`, …).
    pub fn name(self) -> &'static str {
        match self {
            LightKind::Unknown => "unknown",
            LightKind::Daylight => "daylight",
            LightKind::Incandescent => "incandescent",
            LightKind::Fluorescent => "fluorescent",
            LightKind::WhiteLed => "white-led",
            LightKind::Hid => "hid",
            LightKind::RgbLed => "rgb-led",
            LightKind::Luminaire => "luminaire",
        }
    }

    /// The kind as a noun in a sentence ("does not look like {label}").
    pub fn label(self) -> &'static str {
        match self {
            LightKind::Unknown => "any light",
            LightKind::Daylight => "daylight",
            LightKind::Incandescent => "incandescent or halogen light",
            LightKind::Fluorescent => "fluorescent light",
            LightKind::WhiteLed => "white LED light",
            LightKind::Hid => "metal halide, sodium or mercury light",
            LightKind::RgbLed => "colour-mixing LED light",
            LightKind::Luminaire => "a multi-channel LED luminaire",
        }
    }

    /// What the kind holds, in a person's words.
    pub fn describe(self) -> &'static str {
        match self {
            LightKind::Unknown => "don't know (any light)",
            LightKind::Daylight => "daylight (sun and sky, also through a window)",
            LightKind::Incandescent => "incandescent or halogen bulb",
            LightKind::Fluorescent => "fluorescent tube or compact fluorescent",
            LightKind::WhiteLed => "white LED (bulbs, panels, most LED lamps)",
            LightKind::Hid => "metal halide, sodium or mercury (street and hall lamps)",
            LightKind::RgbLed => "colour-mixing LED (RGB/RGBW smart bulbs and strips)",
            LightKind::Luminaire => "multi-channel LED luminaire (many narrow LED channels)",
        }
    }

    /// The kind named `text` (its [`LightKind::name`], any case; `halogen`, `led`,
    /// `don't know` and `auto` are understood too), or an error listing the kinds.
    ///
    /// ```
    /// use spdcam_core::light_families::LightKind;
    ///
    /// assert_eq!(LightKind::parse("White-LED")?, LightKind::WhiteLed);
    /// assert_eq!(LightKind::parse("halogen")?, LightKind::Incandescent);
    /// assert!(LightKind::parse("candle").unwrap_err().to_string().contains("daylight"));
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn parse(text: &str) -> Result<LightKind> {
        let t = text.trim().to_ascii_lowercase().replace(['_', ' '], "-");
        if let Some(kind) = LightKind::ALL.into_iter().find(|k| k.name() == t) {
            return Ok(kind);
        }
        Ok(match t.as_str() {
            "halogen" | "tungsten" => LightKind::Incandescent,
            "led" => LightKind::WhiteLed,
            "don't-know" | "dont-know" | "auto" | "any" => LightKind::Unknown,
            _ => {
                let names: Vec<&str> = LightKind::ALL.iter().map(|k| k.name()).collect();
                return Err(Error::invalid(format!(
                    "'{text}' is not a kind of light; the kinds are {}",
                    names.join(", ")
                )));
            }
        })
    }

    /// The lighting recipe (`spdcam list lighting`) the kind's prior is drawn from: the
    /// families of the training mix that make lights of this kind; `None` for `Unknown`,
    /// whose prior is the training mix itself.
    pub fn recipe(self) -> Option<&'static str> {
        Some(match self {
            LightKind::Unknown => return None,
            LightKind::Daylight => "daylight",
            LightKind::Incandescent => "mix:planck:1800-3600=0.5,lamp:incandescent=0.5",
            LightKind::Fluorescent => "mix:lamp:fluorescent=0.7,fluorescent=0.3",
            LightKind::WhiteLed => {
                "mix:lamp:phosphor-led=0.6,lamp:hybrid-led=0.15,phosphor=0.25"
            }
            LightKind::Hid => "lamp:hid",
            LightKind::RgbLed => "lamp:mixed-led",
            LightKind::Luminaire => {
                "mix:telelumen:config1=0.3,telelumen:config2=0.3,telelumen:config3=0.25,gaussian:7=0.15"
            }
        })
    }

    /// The kind a real lamp of type `lamp` is (`None` for [`LampType::Other`]).
    pub fn of_lamp_type(lamp: LampType) -> Option<LightKind> {
        Some(match lamp {
            LampType::PhosphorLed | LampType::HybridLed => LightKind::WhiteLed,
            LampType::MixedLed => LightKind::RgbLed,
            LampType::Fluorescent => LightKind::Fluorescent,
            LampType::Hid => LightKind::Hid,
            LampType::Incandescent => LightKind::Incandescent,
            LampType::Daylight => LightKind::Daylight,
            LampType::Other => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::DataDir;
    use crate::light_families::Lighting;
    use crate::spectral::Grid;

    #[test]
    fn every_name_parses_back_to_its_kind() {
        for kind in LightKind::ALL {
            assert_eq!(LightKind::parse(kind.name()).unwrap(), kind);
            assert_eq!(LightKind::parse(&kind.name().to_uppercase()).unwrap(), kind);
        }
        assert_eq!(LightKind::parse("don't know").unwrap(), LightKind::Unknown);
        assert_eq!(LightKind::default(), LightKind::Unknown);
    }

    #[test]
    fn recipes_without_a_data_directory_parse() {
        // The luminaire's channels live in the data directory; every other kind's recipe is
        // built into the program.
        for kind in LightKind::ALL {
            match (kind, kind.recipe()) {
                (LightKind::Unknown, r) => assert!(r.is_none()),
                (LightKind::Luminaire, Some(_)) => {}
                (_, Some(recipe)) => {
                    Lighting::parse(recipe, &DataDir::new(None), &Grid::SIMULATION)
                        .unwrap_or_else(|e| panic!("{kind:?}: {e}"));
                }
                (_, None) => panic!("{kind:?} has no recipe"),
            }
        }
    }

    #[test]
    fn every_lamp_type_but_other_has_a_kind() {
        for t in LampType::ALL {
            assert_eq!(LightKind::of_lamp_type(t).is_none(), t == LampType::Other);
        }
    }
}
