//! Whether a lighting metric means anything for a light: a correlated colour temperature
//! (and TM-30, whose reference is built on it) only near the Planckian locus, CIE 13.3's
//! colour rendering indices only nearer still. What the meter, the presentation and the
//! chromaticity diagram all ask before they show such a number.

use spdcam_core::quality::CRI_MAX_DUV;
use spdcam_infer::estimate::{Estimate, MAX_CCT_DUV};

/// Whether the CCT (and what is built on it, TM-30's reference) is meaningful.
pub fn cct_meaningful(estimate: &Estimate) -> Result<(), String> {
    near_white(estimate, MAX_CCT_DUV, "")
}

/// Whether CIE 13.3's Ra and R1–R14 are meaningful.
pub fn cri_meaningful(estimate: &Estimate) -> Result<(), String> {
    near_white(estimate, CRI_MAX_DUV, "CIE 13.3's ")
}

/// Whether the estimate's light lies within `limit` (|Duv|) of the Planckian locus; the
/// reason why not, naming the limit as `whose` it is. Where Duv's calibrated 95 % interval
/// reaches back within the limit, the photo does not tell whether the metric means anything,
/// and the reason says so rather than quote a |Duv| it does not determine.
fn near_white(estimate: &Estimate, limit: f64, whose: &str) -> Result<(), String> {
    let duv_half95 = estimate
        .trust
        .as_ref()
        .and_then(|t| t.uncertainty.as_ref())
        .and_then(|u| u.metrics.get("duv"))
        .map(|i| i.half95);
    match estimate.metrics.duv {
        Some(duv) if duv.abs() > limit && duv_half95.is_some_and(|h| duv.abs() - h <= limit) => {
            Err(format!(
                "perhaps not meaningful: the light may lie farther than {whose}|Duv| {limit} \
                 from white, where this means nothing (Duv {:+.3} ± {:.3}, 95 %)",
                duv,
                duv_half95.unwrap_or_default()
            ))
        }
        Some(duv) if duv.abs() > limit => Err(format!(
            "not meaningful this far from white: |Duv| {:.3} is beyond {whose}{limit}",
            duv.abs()
        )),
        Some(_) => Ok(()),
        None => Err("not meaningful: the light has no colour temperature".into()),
    }
}
