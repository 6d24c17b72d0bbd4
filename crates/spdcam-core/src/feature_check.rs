//! Whether a row of chart features (mean encoded sRGB of each patch, `p01_r,p01_g,p01_b,…`)
//! can say anything about the light, before a model turns it into an SPD.
//!
//! A model maps any numbers to some spectrum; these checks keep it from answering nonsense
//! with a confident SPD: values outside the encoding's range, a black chart, and a chart
//! without colour (a greyscale photo), whose patches are all the same mixture of R, G and B
//! and so carry no information about the spectrum.

use crate::error::{short_number, Error, Result};

/// Below this share of the scale, a patch's largest channel difference is no colour: a
/// greyscale JPEG saved as RGB keeps about one level of chroma noise on 0–255.
const MIN_CHROMA_SHARE: f64 = 0.01;
/// Below this share of the scale, the brightest feature is black.
const MIN_LEVEL_SHARE: f64 = 0.005;

/// Checks one feature row on `0…scale` (255 for 8-bit levels, 1 for fractions); `names` are
/// its column names (`p01_r`, …), used in messages. Refuses non-finite values, values
/// outside `0…scale`, an all-black chart, and a chart without colour.
pub fn check_feature_row(values: &[f64], names: &[String], scale: f64) -> Result<()> {
    let name = |i: usize| {
        names
            .get(i)
            .map_or_else(|| format!("#{}", i + 1), String::clone)
    };
    for (i, &v) in values.iter().enumerate() {
        if !v.is_finite() {
            return Err(Error::invalid(format!(
                "feature {}: {} is not a finite number",
                name(i),
                short_number(v)
            )));
        }
        if v < 0.0 || v > scale * (1.0 + 1e-9) {
            return Err(Error::invalid(format!(
                "feature {}: {} is outside 0–{scale}, the range of encoded sRGB",
                name(i),
                short_number(v)
            )));
        }
    }
    let brightest = values.iter().cloned().fold(0.0f64, f64::max);
    if brightest <= MIN_LEVEL_SHARE * scale {
        return Err(Error::invalid(format!(
            "every feature is black (at most {} of 0–{scale}): the chart shows no light",
            short_number(brightest)
        )));
    }
    let chroma = values
        .chunks_exact(3)
        .map(|p| {
            p.iter().cloned().fold(f64::MIN, f64::max) - p.iter().cloned().fold(f64::MAX, f64::min)
        })
        .fold(0.0f64, f64::max);
    if values.len() >= 3 && chroma <= MIN_CHROMA_SHARE * scale {
        return Err(Error::invalid(format!(
            "no patch has colour (R, G and B differ by at most {chroma:.3} of 0–{scale}): a \
             greyscale photo or grey features say nothing about the light's spectrum"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: usize) -> Vec<String> {
        (1..=n / 3)
            .flat_map(|k| ["r", "g", "b"].map(|c| format!("p{k:02}_{c}")))
            .collect()
    }

    #[test]
    fn a_coloured_chart_passes() {
        let row = [200.0, 120.0, 40.0, 30.0, 90.0, 180.0];
        check_feature_row(&row, &names(6), 255.0).unwrap();
        let unit: Vec<f64> = row.iter().map(|v| v / 255.0).collect();
        check_feature_row(&unit, &names(6), 1.0).unwrap();
    }

    #[test]
    fn nonsense_rows_are_refused_naming_the_column() {
        // Issue 15: all-zero features printed "CCT 6744 K"; negative ones were accepted; a
        // greyscale photo got an SPD.
        let n = names(6);
        let e = |row: &[f64]| check_feature_row(row, &n, 255.0).unwrap_err().to_string();
        assert!(e(&[0.0; 6]).contains("black"));
        // Issue 39: a 300-digit number in the message.
        let tiny = e(&[1e-300, 2e-300, 0.0, 0.0, 0.0, 0.0]);
        assert!(tiny.contains("at most 2e-300 of"), "{tiny}");
        let neg = e(&[200.0, -3.0, 40.0, 30.0, 90.0, 180.0]);
        assert!(neg.contains("p01_g") && neg.contains("-3"), "{neg}");
        let high = e(&[200.0, 120.0, 40.0, 30.0, 90.0, 300.0]);
        assert!(high.contains("p02_b") && high.contains("0–255"), "{high}");
        let nan = e(&[200.0, 120.0, 40.0, f64::NAN, 90.0, 180.0]);
        assert!(nan.contains("p02_r") && nan.contains("NaN"), "{nan}");
        let grey = e(&[120.0, 120.5, 120.2, 60.0, 60.0, 60.4]);
        assert!(grey.contains("greyscale"), "{grey}");
    }
}
