//! Virtual lighting: families of lights named by a recipe (`gaussian:7`, `telelumen:config1`,
//! `daylight`, `mix:…`), each drawn at random but reproducibly: draw `i` of a recipe depends
//! only on (seed, i). Every SPD is on the simulation grid and normalised by its maximum.

pub mod bands;
mod channels;
pub mod coverage;
pub mod fit;
pub mod lamp_families;
pub mod lamp_library;
pub mod light_kind;
mod luminaire;
mod measured;
mod parametric;
pub mod validation_split;

pub use channels::{Channels, WeightRule};
pub use lamp_families::{LampDraws, LampFits};
pub use lamp_library::{LampLibrary, LampType};
pub use light_kind::LightKind;
pub use luminaire::{Luminaire, PowerBudget, TELELUMEN_BUDGET, TELELUMEN_FILE};
pub use measured::MeasuredSpds;
pub use parametric::{fluorescent, normalised_daylight, normalised_planck, CctRange, PhosphorLeds};
pub use validation_split::ValidationSplit;

use crate::builtin::DataDir;
use crate::cie_illuminant::{DAYLIGHT_CCT_MAX_K, DAYLIGHT_CCT_MIN_K};
use crate::colorimetry::Observer;
use crate::error::{Error, Result};
use crate::seed;
use crate::spectral::{normalise_peak, Grid, Spd};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// One drawn light.
#[derive(Debug, Clone, PartialEq)]
pub struct LightDraw {
    /// The SPD on the lighting's grid, maximum 1.
    pub spd: Spd,
    /// The family it came from (`gaussian`, `leds`, `daylight`, …).
    pub family: String,
    /// The channel weights, for families that have them (in [`Lighting::weight_names`] order).
    pub weights: Option<Vec<f64>>,
    /// Lights drawn for this one, itself included (> 1 when a power budget rejected some).
    pub attempts: u32,
}

/// A lighting recipe, parsed and ready to draw from.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    spec: String,
    grid: Grid,
    family: Family,
}

/// Random-stream index that separates light draws from the camera noise of the same sample.
const LIGHT_STREAM: u64 = 0x4C49_4748_5400_0001;

/// The recipes `spdcam generate --lighting` accepts, with what they draw.
pub fn catalogue() -> Vec<(&'static str, &'static str)> {
    vec![
        ("gaussian:N", "N Gaussian channels (N = 4–7: the thesis's centres and widths; others evenly over 400–700 nm), weights uniform on [0, 1) in steps of 0.01"),
        ("leds:FILE[:OPTION]…", "channels of a multi-channel LED luminaire (spectral CSV); options lit=3-19 (channels that may light, 1-based, ranges joined by /), k=7 (how many light at once), max=1 (weights uniform on [0, max)), step=0.01, budget=B with power=uniform|optical (reject settings with Σ wᵢ·powerᵢ > B)"),
        ("telelumen:PRESET", "the thesis's 24-channel Telelumen luminaire (data directory: thesis/telelumen_24_channels.csv): config1 (7 of the 17 visible, max 1), config2 (9, max 0.75), config3 (17, max 0.4), each under the calibrated power budget; h1 (7 of 24), h2 (all 24)"),
        ("daylight[:MIN-MAX]", "CIE daylight at a CCT uniform in mired, default 4000-25000 K"),
        ("planck[:MIN-MAX]", "Planckian radiator at a CCT uniform in mired, default 1500-10000 K"),
        ("phosphor", "phosphor-converted white LED: blue pump 440–460 nm + yellow-green and red phosphor bands, heights set for a CCT of 2700–6500 K and |Duv| ≤ 0.006"),
        ("fluorescent", "fluorescent-like lamp: mercury lines and tri-phosphor bands of random strength on a broad Planckian base"),
        ("lamp:FAMILY[:spread=S][:fits=FILE]", "real-lamp families fitted to measured lamps (`spdcam lamps fit`): phosphor-led, hybrid-led, mixed-led, fluorescent, hid, incandescent; each draw is a fitted lamp moved by a kernel step of the fitted parameters' spread (Scott's rule × S, default 1; 0 = the fitted lamps themselves); fits=FILE uses another fit"),
        ("blend:RECIPE[+RECIPE]", "two sources at once (a window and a lamp): a·A + (1 − a)·B with A and B drawn from the two recipes (or twice from one), scaled to equal luminance, a uniform on [0, 1), e.g. blend:daylight+lamp:phosphor-led; a recipe may be a mix: (the blend then cannot sit inside a mix:)"),
        ("spds:FILE[:mix]", "measured SPDs from a spectral CSV: one at random, or with :mix a random mixture of two"),
        ("mix:RECIPE=P,RECIPE=P,…", "a mixture of recipes drawn with the given proportions, e.g. mix:telelumen:config1=0.5,daylight=0.3,planck=0.2"),
    ]
}

#[derive(Debug, Clone, PartialEq)]
enum Family {
    Gaussian(Channels),
    Leds(Luminaire),
    Daylight(CctRange),
    Planck(CctRange),
    Phosphor(PhosphorLeds),
    Fluorescent,
    Measured(MeasuredSpds),
    Lamp(LampDraws),
    Blend(Box<Blend>),
    Mix(Vec<(Lighting, f64)>),
}

/// Two recipes lighting the scene at once.
#[derive(Debug, Clone, PartialEq)]
struct Blend {
    first: Lighting,
    second: Lighting,
    observer: Observer,
}

impl Lighting {
    /// Parses a recipe (see [`catalogue`]) for lights on `grid`; files are paths or names
    /// under the data directory.
    ///
    /// ```
    /// use spdcam_core::builtin::DataDir;
    /// use spdcam_core::light_families::Lighting;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let grid = Grid::SIMULATION;
    /// let daylight = Lighting::parse("daylight:5000-6500", &DataDir::new(None), &grid)?;
    /// let mixed = Lighting::parse("mix:planck=0.5,phosphor=0.5", &DataDir::new(None), &grid)?;
    /// assert_eq!(mixed.mix_members().unwrap().len(), 2);
    /// assert!(Lighting::parse("candles", &DataDir::new(None), &grid).is_err());
    /// # let _ = daylight;
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn parse(spec: &str, data_dir: &DataDir, grid: &Grid) -> Result<Lighting> {
        let (head, rest) = spec.split_once(':').unwrap_or((spec, ""));
        let family = match head {
            "gaussian" => {
                let n: usize = rest.parse().map_err(|_| {
                    Error::invalid(format!(
                        "'{spec}': the number of Gaussian channels must be a whole number, e.g. gaussian:7"
                    ))
                })?;
                Family::Gaussian(Channels::gaussian(n, grid)?)
            }
            "leds" => Family::Leds(Luminaire::parse(rest, spec, data_dir, grid)?),
            "telelumen" => Family::Leds(Luminaire::telelumen(rest, spec, data_dir, grid)?),
            "daylight" => Family::Daylight(CctRange::parse(
                rest,
                CctRange {
                    min_k: DAYLIGHT_CCT_MIN_K,
                    max_k: DAYLIGHT_CCT_MAX_K,
                },
                CctRange {
                    min_k: DAYLIGHT_CCT_MIN_K,
                    max_k: DAYLIGHT_CCT_MAX_K,
                },
                spec,
            )?),
            "planck" => Family::Planck(CctRange::parse(
                rest,
                CctRange {
                    min_k: 1500.0,
                    max_k: 10000.0,
                },
                CctRange {
                    min_k: 500.0,
                    max_k: 100_000.0,
                },
                spec,
            )?),
            "phosphor" | "fluorescent" if !rest.is_empty() => {
                return Err(Error::invalid(format!(
                    "'{spec}': {head} takes no parameters"
                )))
            }
            "phosphor" => Family::Phosphor(PhosphorLeds::new(grid)?),
            "fluorescent" => Family::Fluorescent,
            "spds" => Family::Measured(MeasuredSpds::parse(rest, spec, data_dir, grid)?),
            "lamp" => Family::Lamp(parse_lamp(rest, spec, grid)?),
            "blend" => {
                let (a, b) = rest.split_once('+').unwrap_or((rest, rest));
                if [a, b].iter().any(|r| r.starts_with("blend:")) {
                    return Err(Error::invalid(format!(
                        "'{spec}': a blend cannot contain a blend"
                    )));
                }
                Family::Blend(Box::new(Blend {
                    first: Lighting::parse(a, data_dir, grid)?,
                    second: Lighting::parse(b, data_dir, grid)?,
                    observer: Observer::cie1931(grid)?,
                }))
            }
            "mix" => Family::Mix(parse_mix(rest, spec, data_dir, grid)?),
            _ => {
                let forms: Vec<&str> = catalogue().iter().map(|(form, _)| *form).collect();
                return Err(Error::UnknownName {
                    kind: "lighting family",
                    name: head.to_string(),
                    valid: forms.join(", "),
                });
            }
        };
        Ok(Lighting {
            spec: spec.to_string(),
            grid: *grid,
            family,
        })
    }

    /// The grid the lights are drawn on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The recipe as given.
    pub fn spec(&self) -> &str {
        &self.spec
    }

    /// The members of a `mix:` recipe with their shares; `None` for other recipes.
    pub fn mix_members(&self) -> Option<Vec<(&Lighting, f64)>> {
        match &self.family {
            Family::Mix(members) => Some(members.iter().map(|(m, p)| (m, *p)).collect()),
            _ => None,
        }
    }

    /// The channels whose weights make the light, for the Gaussian and LED families.
    pub fn channels(&self) -> Option<&Channels> {
        match &self.family {
            Family::Gaussian(c) => Some(c),
            Family::Leds(l) => Some(&l.channels),
            _ => None,
        }
    }

    /// Names of the weights every draw records, or `None` when the recipe has none. A
    /// mixture concatenates its members' names (prefixed by the member's position when
    /// more than one member has weights); members without weights record zeros.
    pub fn weight_names(&self) -> Option<Vec<String>> {
        match &self.family {
            Family::Mix(members) => {
                let named: Vec<(usize, Vec<String>)> = members
                    .iter()
                    .enumerate()
                    .filter_map(|(i, (m, _))| m.weight_names().map(|n| (i, n)))
                    .collect();
                match named.len() {
                    0 => None,
                    1 => Some(named.into_iter().next().map(|(_, n)| n).unwrap_or_default()),
                    _ => Some(
                        named
                            .into_iter()
                            .flat_map(|(i, names)| {
                                names.into_iter().map(move |n| format!("m{}_{n}", i + 1))
                            })
                            .collect(),
                    ),
                }
            }
            _ => self.channels().map(|c| c.names.clone()),
        }
    }

    /// A readable account of the recipe, for manifests.
    pub fn describe(&self) -> String {
        match &self.family {
            Family::Gaussian(c) => format!(
                "{} Gaussian channels, weights uniform on [0, 1) in steps of 0.01",
                c.len()
            ),
            Family::Leds(l) => l.describe(),
            Family::Daylight(r) => format!(
                "CIE daylight, CCT {}–{} K uniform in mired",
                r.min_k, r.max_k
            ),
            Family::Planck(r) => format!(
                "Planckian radiator, CCT {}–{} K uniform in mired",
                r.min_k, r.max_k
            ),
            Family::Phosphor(_) => {
                "phosphor-converted white LEDs, 2700–6500 K, |Duv| ≤ 0.006".to_string()
            }
            Family::Fluorescent => "fluorescent-like line spectra on a broad base".to_string(),
            Family::Measured(m) => m.describe(),
            Family::Lamp(d) => format!(
                "{} ({} fitted lamps)",
                d.family().describe_model(),
                d.lamp_count()
            ),
            Family::Blend(b) => format!(
                "blend of equal-luminance {} and {}, share uniform",
                b.first.describe(),
                b.second.describe()
            ),
            Family::Mix(members) => {
                let parts: Vec<String> = members
                    .iter()
                    .map(|(m, p)| format!("{:.3} × {}", p, m.describe()))
                    .collect();
                format!("mixture: {}", parts.join("; "))
            }
        }
    }

    /// Draw `index` of this recipe under `seed`: the same (seed, index) always gives the same
    /// light, whatever the order or the machine of the draws.
    ///
    /// ```
    /// use spdcam_core::builtin::DataDir;
    /// use spdcam_core::light_families::Lighting;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let leds = Lighting::parse("gaussian:7", &DataDir::new(None), &Grid::SIMULATION)?;
    /// let light = leds.draw(42, 3)?;
    /// assert_eq!(light, leds.draw(42, 3)?); // reproducible
    /// assert_ne!(light.spd, leds.draw(42, 4)?.spd);
    /// // Peak 1, one weight per channel.
    /// assert_eq!(light.spd.iter().copied().fold(0.0, f64::max), 1.0);
    /// assert_eq!(light.weights.unwrap().len(), 7);
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn draw(&self, seed: u64, index: u64) -> Result<LightDraw> {
        let mut rng =
            SmallRng::seed_from_u64(seed::derive(seed::derive(seed, index), LIGHT_STREAM));
        self.draw_with(&mut rng)
    }

    fn draw_with(&self, rng: &mut SmallRng) -> Result<LightDraw> {
        let grid = self.grid;
        let simple = |family: &str, spd: Vec<f64>| -> Result<LightDraw> {
            Ok(LightDraw {
                spd: Spd::new(grid, spd)?,
                family: family.to_string(),
                weights: None,
                attempts: 1,
            })
        };
        Ok(match &self.family {
            Family::Gaussian(channels) => {
                let weights = WeightRule::all(channels.len()).draw(channels.len(), rng);
                LightDraw {
                    spd: Spd::new(grid, channels.combine(&weights)?)?,
                    family: "gaussian".to_string(),
                    weights: Some(weights),
                    attempts: 1,
                }
            }
            Family::Leds(luminaire) => {
                let (weights, attempts) = luminaire.draw(rng, &self.spec)?;
                LightDraw {
                    spd: Spd::new(grid, luminaire.channels.combine(&weights)?)?,
                    family: "leds".to_string(),
                    weights: Some(weights),
                    attempts,
                }
            }
            Family::Daylight(range) => {
                simple("daylight", normalised_daylight(range.draw(rng), &grid)?)?
            }
            Family::Planck(range) => simple("planck", normalised_planck(range.draw(rng), &grid)?)?,
            Family::Phosphor(leds) => simple("phosphor", leds.draw(rng)?)?,
            Family::Fluorescent => simple("fluorescent", fluorescent(&grid, rng)?)?,
            Family::Measured(set) => simple("spds", set.draw(rng))?,
            Family::Lamp(draws) => simple(draws.family().name(), draws.draw(rng))?,
            Family::Blend(b) => {
                let first = b.first.draw_with(rng)?;
                let second = b.second.draw_with(rng)?;
                let share = rng.random::<f64>();
                let luminance = |s: &[f64]| b.observer.spd_to_xyz(s)[1].max(1e-12);
                let (ya, yb) = (luminance(&first.spd), luminance(&second.spd));
                let mut spd: Vec<f64> = first
                    .spd
                    .iter()
                    .zip(second.spd.iter())
                    .map(|(x, y)| share * x / ya + (1.0 - share) * y / yb)
                    .collect();
                normalise_peak(&mut spd)?;
                LightDraw {
                    spd: Spd::new(grid, spd)?,
                    family: "blend".to_string(),
                    weights: None,
                    attempts: first.attempts + second.attempts,
                }
            }
            Family::Mix(members) => self.draw_member(members, rng)?,
        })
    }

    fn draw_member(&self, members: &[(Lighting, f64)], rng: &mut SmallRng) -> Result<LightDraw> {
        let u = rng.random::<f64>();
        let mut cumulative = 0.0;
        let chosen = members
            .iter()
            .position(|(_, p)| {
                cumulative += p;
                u < cumulative
            })
            .unwrap_or(members.len() - 1);
        let mut draw = members[chosen].0.draw_with(rng)?;
        if let Some(names) = self.weight_names() {
            let mut weights = vec![0.0; names.len()];
            let offset: usize = members[..chosen]
                .iter()
                .filter_map(|(m, _)| m.weight_names().map(|n| n.len()))
                .sum();
            if let Some(own) = &draw.weights {
                weights[offset..offset + own.len()].copy_from_slice(own);
            }
            draw.weights = Some(weights);
        }
        Ok(draw)
    }
}

/// Parses `FAMILY[:spread=S][:fits=FILE]` of a `lamp:` recipe.
fn parse_lamp(rest: &str, spec: &str, grid: &Grid) -> Result<LampDraws> {
    let mut parts = rest.split(':');
    let name = parts.next().unwrap_or_default();
    let family = LampType::from_name(name)
        .filter(|t| t.has_model())
        .ok_or_else(|| Error::UnknownName {
            kind: "lamp family",
            name: name.to_string(),
            valid: LampType::MODELLED
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(", "),
        })?;
    let mut spread = 1.0;
    let mut fits = None;
    for option in parts {
        match option.split_once('=') {
            Some(("spread", v)) => {
                spread = v.parse().map_err(|_| {
                    Error::invalid(format!("'{spec}': spread '{v}' is not a number"))
                })?
            }
            Some(("fits", path)) => {
                let text = crate::fsio::read_text(std::path::Path::new(path))?;
                fits = Some(LampFits::from_json(&text, path)?);
            }
            _ => {
                return Err(Error::invalid(format!(
                    "'{spec}': unknown option '{option}' (spread=S, fits=FILE)"
                )))
            }
        }
    }
    let fits = match fits {
        Some(f) => f,
        None => LampFits::shipped()?,
    };
    LampDraws::new(&fits, family, grid, spread)
}

fn parse_mix(
    rest: &str,
    spec: &str,
    data_dir: &DataDir,
    grid: &Grid,
) -> Result<Vec<(Lighting, f64)>> {
    let mut members = Vec::new();
    for part in rest.split(',') {
        let (member, share) = part.rsplit_once('=').ok_or_else(|| {
            Error::invalid(format!(
                "'{spec}': mixture member '{part}' needs a proportion, e.g. daylight=0.3"
            ))
        })?;
        let share: f64 = share
            .parse()
            .ok()
            .filter(|p: &f64| *p > 0.0 && p.is_finite())
            .ok_or_else(|| {
                Error::invalid(format!(
                "'{spec}': the proportion of '{member}' must be a positive number, not '{share}'"
            ))
            })?;
        if member.starts_with("mix:") {
            return Err(Error::invalid(format!(
                "'{spec}': a mixture cannot contain a mixture"
            )));
        }
        members.push((Lighting::parse(member, data_dir, grid)?, share));
    }
    // Scaled by the largest first, so that the sum of proportions near f64::MAX (1e308 +
    // 1e308) does not overflow to infinity and turn every share but the largest into 0.
    let largest = members.iter().map(|(_, p)| *p).fold(0.0, f64::max);
    members.iter_mut().for_each(|(_, p)| *p /= largest);
    let total: f64 = members.iter().map(|(_, p)| p).sum();
    members.iter_mut().for_each(|(_, p)| *p /= total);
    Ok(members)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proportions_near_the_largest_number_are_shared_without_overflow() {
        // Issue 39, item 14: 1e308 + 1e308 overflowed, and planck took every draw.
        let grid = Grid::SIMULATION;
        let mix = Lighting::parse(
            "mix:daylight=1e308,planck=1e308",
            &DataDir::new(None),
            &grid,
        )
        .unwrap();
        let shares: Vec<f64> = mix.mix_members().unwrap().iter().map(|m| m.1).collect();
        assert_eq!(shares, [0.5, 0.5]);
        let tiny = Lighting::parse(
            "mix:daylight=1e-320,planck=3e-320",
            &DataDir::new(None),
            &grid,
        )
        .unwrap();
        let shares: Vec<f64> = tiny.mix_members().unwrap().iter().map(|m| m.1).collect();
        assert!(
            (shares[0] - 0.25).abs() < 1e-3 && (shares[1] - 0.75).abs() < 1e-3,
            "{shares:?}"
        );
    }
}
