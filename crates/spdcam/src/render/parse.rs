//! The number forms of `render`'s option values: sizes `AxB`, shares, comma-separated lists.

use anyhow::{bail, Context, Result};

/// Two positive whole numbers written `AxB` (or `AXB`, `A×B`), e.g. a size or a layout.
pub(super) fn parse_pair(text: &str, what: &str) -> Result<(usize, usize)> {
    let (a, b) = text
        .split_once(['x', 'X', '×'])
        .with_context(|| format!("{what} '{text}' is not of the form AxB"))?;
    let a: usize = a
        .trim()
        .parse()
        .with_context(|| format!("{what} '{text}'"))?;
    let b: usize = b
        .trim()
        .parse()
        .with_context(|| format!("{what} '{text}'"))?;
    if a == 0 || b == 0 {
        bail!("{what} '{text}' must be positive");
    }
    Ok((a, b))
}

/// A share written as a decimal or a fraction (`0.25`, `1/15`).
pub(super) fn parse_share(text: &str, what: &str) -> Result<f64> {
    let value = match text.split_once('/') {
        Some((a, b)) => {
            let a: f64 = a.trim().parse().ok().context(format!("{what} '{text}'"))?;
            let b: f64 = b.trim().parse().ok().context(format!("{what} '{text}'"))?;
            a / b
        }
        None => text
            .trim()
            .parse()
            .ok()
            .with_context(|| format!("{what} '{text}' is not a number"))?,
    };
    if !(value > 0.0 && value < 1.0) {
        bail!("{what} '{text}' must be a share between 0 and 1 (e.g. 0.25 or 1/15)");
    }
    Ok(value)
}

/// Comma-separated numbers.
pub(super) fn parse_numbers(text: &str, what: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("{what} '{text}': '{s}' is not a number"))
        })
        .collect()
}
