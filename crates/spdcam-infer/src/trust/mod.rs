//! How far an estimate can be trusted: a self-check that re-renders the chart under the
//! estimated light, per-wavelength uncertainty bands with an expected GFC, and one verdict.
//!
//! ```text
//! features ─► model ─► SPD ─┬─► chart reflectances × SPD × camera ─► 3×3 + offset + gradient
//!                           │     fitted to the photo (tone curve undone) ─► residual and
//!                           │     half-to-half residual (self-check)
//! features ± 2 % ─► model ──┴─► spread of the SPDs ─► × calibrated quantiles ─► bands, GFC
//!            detection, clipping, self-check, spread ─► verdict: ok / doubtful / unusable
//! ```
//!
//! Before any of it, [`chart_identity`] tests that the patches are the chart at all, and
//! refuses them when not. Then one module per job, in that order: [`self_check`] (the chart
//! re-rendered under the estimate), [`spread`] (the estimates of perturbed copies of the
//! features), [`calibration`]
//! (bands, expected GFC — its margin among the calibration photos most like the photo,
//! [`local_margin`] — and the doubtful levels, from a calibration file per model measured
//! on held-out virtual photos of held-out lamps: `spdcam trust calibrate`, docs/trust.md) and
//! [`verdict`] (every check weighed into ok / doubtful / unusable).

pub mod calibration;
pub mod chart_identity;
pub mod local_margin;
pub mod self_check;
pub mod spread;
pub mod verdict;

pub use calibration::{
    calibration_for, widening, Band, GfcModel, MetricCalibration, MetricInterval, TrustCalibration,
    Uncertainty,
};
pub use chart_identity::{ChartIdentity, Identity};
pub use local_margin::{conformal_quantile, photo_coordinates, LocalMargin};
pub use self_check::{ChartCheck, SelfCheck, Veil};
pub use spread::{clipped_patch, feature_scale, Perturbed, JITTER_COPIES, JITTER_SIGMA};
pub use verdict::{
    assess, clipped_features, clipped_patches, flag_patches, photo_flags, skipped_patches, weigh,
    weigh_read_by, PhotoFlags, ReadBy, Trust, Verdict, Weighed, DOUBTFUL_GFC, POOR_GFC,
    SURE_DETECTION, UNUSABLE_CLIPPED_SHARE, UNUSABLE_SELF_CHECK_FACTOR,
};
