//! The trust protocols: fitting a model's uncertainty calibration (the file
//! `spdcam_infer::trust::TrustCalibration` reads) and measuring how far its estimates can be
//! trusted on held-out virtual photos, the real photo sets, photos made bad on purpose and
//! scene photos.
//!
//! - [`shots`]: the held-out virtual photos, clean and made bad.
//! - [`judged`]: photos judged as an estimate judges them, and the statistics taken of them.
//! - [`real`]: the real photo sets' split.
//! - [`raw`]: the calibration of a raw model, on raw scene photos.
//! - [`fit`]: the calibration's fit ([`fit::calibrate`]), and [`records`]: its photos one
//!   by one.
//! - [`scenes`] and [`report`]: the measurement ([`report::TrustReport`]).

pub mod fit;
pub mod judged;
pub mod raw;
pub mod real;
pub mod records;
pub mod report;
pub mod scenes;
pub mod shots;
