//! A multi-channel LED luminaire read from a CSV of channel SPDs, the rules of the thesis for
//! which channels light and how strongly, and the power budget beyond which the real
//! luminaire refuses a setting.

use super::channels::{Channels, WeightRule};
use crate::builtin::{self, DataDir};
use crate::error::{Error, Result};
use crate::spectral::{Extrapolation, Grid, Interpolation};
use rand::rngs::SmallRng;

/// Where the Telelumen luminaire of the thesis is found under the data directory.
pub const TELELUMEN_FILE: &str = "thesis/telelumen_24_channels.csv";

/// Power budget of the Telelumen luminaire, in units of the mean visible channel at full
/// drive, each channel drawing power in proportion to its radiant output (`power=optical`):
/// a setting is valid when Σ wᵢ·powerᵢ ≤ budget. Calibrated by Monte Carlo so the valid
/// ratios of the thesis's configurations 1–3 come near its Table 5.1 (2167, 2395 and 2631
/// of 3170); the test `telelumen_valid_ratios_match_the_thesis` measures them.
pub const TELELUMEN_BUDGET: f64 = 3.915;

/// A power limit: channel `i` at weight `wᵢ` draws `wᵢ·power[i]`; the sum must stay within
/// `budget`.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerBudget {
    /// Power each channel draws at weight 1 (the luminaire's units, e.g. optical power).
    pub power: Vec<f64>,
    /// The most the channels may draw together, in the same units.
    pub budget: f64,
}

impl PowerBudget {
    /// Whether a setting stays within the budget.
    pub fn allows(&self, weights: &[f64]) -> bool {
        let drawn: f64 = weights.iter().zip(&self.power).map(|(w, p)| w * p).sum();
        drawn <= self.budget + 1e-12
    }
}

/// A luminaire with its draw rule and, optionally, its power budget.
#[derive(Debug, Clone, PartialEq)]
pub struct Luminaire {
    /// The luminaire's name (`telelumen`, `gaussian`, a file).
    pub name: String,
    /// Its channel spectra.
    pub channels: Channels,
    /// How a draw chooses the channel weights.
    pub rule: WeightRule,
    /// A power limit that draws must respect; `None`: no limit.
    pub budget: Option<PowerBudget>,
}

/// Draw limit for one sample: a budget that rejects (almost) everything must not hang.
const MAX_ATTEMPTS: u32 = 100_000;

impl Luminaire {
    /// Parses `FILE[:key=value]…` (keys `lit`, `k`, `max`, `step`, `budget`, `power`) or, for
    /// the `telelumen` family, a preset name.
    pub fn parse(rest: &str, spec: &str, data_dir: &DataDir, grid: &Grid) -> Result<Luminaire> {
        let mut parts = rest.split(':');
        let file = parts.next().unwrap_or_default();
        if file.is_empty() {
            return Err(Error::invalid(format!(
                "'{spec}': name the luminaire's channel CSV, e.g. leds:channels.csv:k=7"
            )));
        }
        let channels = load_channels(file, data_dir, grid)?;
        let n = channels.len();
        let mut rule = WeightRule::all(n);
        let mut budget = None;
        let mut power = PowerKind::Uniform;
        let mut k_given = false;
        for option in parts {
            let (key, value) = option.split_once('=').ok_or_else(|| {
                Error::invalid(format!(
                    "'{spec}': option '{option}' is not key=value (keys: lit, k, max, step, budget, power)"
                ))
            })?;
            match key {
                "lit" => rule.lit = parse_channel_list(value, spec)?,
                "k" => rule.k = parse_number(value, key, spec)?,
                "max" => rule.max = parse_number(value, key, spec)?,
                "step" => rule.step = parse_number(value, key, spec)?,
                "budget" => budget = Some(parse_number::<f64>(value, key, spec)?),
                "power" => {
                    power = match value {
                        "uniform" => PowerKind::Uniform,
                        "optical" => PowerKind::Optical,
                        _ => {
                            return Err(Error::invalid(format!(
                                "'{spec}': power = {value}; use uniform or optical"
                            )))
                        }
                    }
                }
                _ => {
                    return Err(Error::invalid(format!(
                        "'{spec}': unknown option '{key}' (keys: lit, k, max, step, budget, power)"
                    )))
                }
            }
            k_given |= key == "k";
        }
        if !k_given {
            rule.k = rule.lit.len();
        }
        rule.validate(n, spec)?;
        let budget = match budget {
            Some(b) if !(b > 0.0 && b.is_finite()) => {
                return Err(Error::invalid(format!(
                    "'{spec}': budget = {b} must be a positive number"
                )))
            }
            Some(b) => Some(PowerBudget {
                power: power.per_channel(&channels, &rule.lit),
                budget: b,
            }),
            None => None,
        };
        Ok(Luminaire {
            name: file.to_string(),
            channels,
            rule,
            budget,
        })
    }

    /// The thesis's Telelumen set-ups: `config1`–`config3` (k of the 17 visible channels
    /// with max 1.0, 0.75, 0.4 and the calibrated power budget; datasets D1–D3 / S1–S3),
    /// `h1` (7 random channels of the 24) and `h2` (all 24 channels).
    pub fn telelumen(
        preset: &str,
        spec: &str,
        data_dir: &DataDir,
        grid: &Grid,
    ) -> Result<Luminaire> {
        let visible = "3-19";
        let budget = format!("power=optical:budget={TELELUMEN_BUDGET}");
        let options = match preset {
            "config1" => format!("lit={visible}:k=7:max=1:{budget}"),
            "config2" => format!("lit={visible}:k=9:max=0.75:{budget}"),
            "config3" => format!("lit={visible}:k=17:max=0.4:{budget}"),
            "h1" => "k=7".to_string(),
            "h2" => String::new(),
            _ => {
                return Err(Error::UnknownName {
                    kind: "Telelumen preset",
                    name: preset.to_string(),
                    valid: "config1, config2, config3, h1, h2".to_string(),
                })
            }
        };
        let file = data_dir
            .root()
            .map(|root| root.join(TELELUMEN_FILE))
            .filter(|path| path.is_file())
            .ok_or_else(|| {
                Error::invalid(format!(
                    "'{spec}': the Telelumen presets read {TELELUMEN_FILE} under the data directory; set --data-dir or {}",
                    builtin::DATA_DIR_ENV
                ))
            })?;
        let mut rest = file.to_string_lossy().into_owned();
        if !options.is_empty() {
            rest = format!("{rest}:{options}");
        }
        Luminaire::parse(&rest, spec, data_dir, grid)
    }

    /// Draws weights until the luminaire accepts them; returns them with the number of
    /// draws made (the accepted one included).
    pub fn draw(&self, rng: &mut SmallRng, spec: &str) -> Result<(Vec<f64>, u32)> {
        for attempt in 1..=MAX_ATTEMPTS {
            let weights = self.rule.draw(self.channels.len(), rng);
            if self.budget.as_ref().is_none_or(|b| b.allows(&weights)) {
                return Ok((weights, attempt));
            }
        }
        Err(Error::invalid(format!(
            "'{spec}': no setting within the power budget in {MAX_ATTEMPTS} draws; raise the budget"
        )))
    }

    /// One line for manifests and `spdcam dataset info`.
    pub fn describe(&self) -> String {
        let lit: Vec<String> = self.rule.lit.iter().map(|i| (i + 1).to_string()).collect();
        let mut text = format!(
            "LED luminaire {} ({} channels): {} of channels [{}] lit, weights uniform on [0, {}) in steps of {}",
            self.name,
            self.channels.len(),
            self.rule.k,
            lit.join(","),
            self.rule.max,
            self.rule.step
        );
        if let Some(b) = &self.budget {
            text.push_str(&format!(", power budget {} (Σ wᵢ·powerᵢ)", b.budget));
        }
        text
    }
}

/// How much power a channel draws per unit weight.
#[derive(Debug, Clone, Copy)]
enum PowerKind {
    /// Every channel the same (a driver limiting the total current).
    Uniform,
    /// In proportion to the channel's radiant power on the grid, relative to the mean of the
    /// channels that may light.
    Optical,
}

impl PowerKind {
    fn per_channel(self, channels: &Channels, lit: &[usize]) -> Vec<f64> {
        match self {
            PowerKind::Uniform => vec![1.0; channels.len()],
            PowerKind::Optical => {
                let sums: Vec<f64> = channels.spds.iter().map(|c| c.iter().sum()).collect();
                let mean = lit.iter().map(|&i| sums[i]).sum::<f64>() / lit.len() as f64;
                sums.iter().map(|s| s / mean).collect()
            }
        }
    }
}

/// Reads a luminaire's channel CSV (file path or a name under the data directory) onto
/// `grid`: linear interpolation, zero outside the measured range, small negative
/// measurement noise clamped to 0.
fn load_channels(file: &str, data_dir: &DataDir, grid: &Grid) -> Result<Channels> {
    let (name, set) = builtin::resolve_table(file, "luminaire", &[], data_dir, &["leds"])?;
    let set = set.require_non_negative(&format!("{name} channel"), 0.05)?;
    let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
    if let Some((i, _)) = set
        .items()
        .iter()
        .enumerate()
        .find(|(_, v)| v.iter().all(|&x| x == 0.0))
    {
        return Err(Error::invalid(format!(
            "luminaire {name}: channel {} emits nothing on {grid}",
            set.names()[i]
        )));
    }
    Ok(Channels {
        names: set.names().to_vec(),
        spds: set.items().to_vec(),
    })
}

/// Parses `3-19` or `1,4,7-9` (1-based channel numbers) into 0-based indices.
fn parse_channel_list(value: &str, spec: &str) -> Result<Vec<usize>> {
    let bad = || {
        Error::invalid(format!(
            "'{spec}': lit = {value} is not a list of channel numbers like 3-19 or 1/4/7-9"
        ))
    };
    let mut out = Vec::new();
    for part in value.split('/') {
        let (a, b) = part.split_once('-').unwrap_or((part, part));
        let (a, b): (usize, usize) = (a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?);
        if a == 0 || b < a {
            return Err(bad());
        }
        out.extend(a - 1..b);
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

fn parse_number<T: std::str::FromStr>(value: &str, key: &str, spec: &str) -> Result<T> {
    value
        .parse()
        .map_err(|_| Error::invalid(format!("'{spec}': {key} = {value} is not a valid number")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_lists() {
        assert_eq!(parse_channel_list("3-5", "s").unwrap(), vec![2, 3, 4]);
        assert_eq!(
            parse_channel_list("1/4/7-8", "s").unwrap(),
            vec![0, 3, 6, 7]
        );
        assert!(parse_channel_list("0-3", "s").is_err());
        assert!(parse_channel_list("5-3", "s").is_err());
        assert!(parse_channel_list("x", "s").is_err());
    }

    #[test]
    fn budget_counts_power() {
        let b = PowerBudget {
            power: vec![1.0, 2.0],
            budget: 2.0,
        };
        assert!(b.allows(&[1.0, 0.5]));
        assert!(!b.allows(&[1.0, 0.6]));
    }
}
