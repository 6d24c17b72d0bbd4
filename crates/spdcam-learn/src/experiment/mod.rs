//! The thesis's model-selection experiment (section 4.6, Tables 4.2–4.4) on its own virtual
//! datasets — Gaussian G1–G4 (4–7 channels) and the 24-channel Telelumen set, ColorChecker
//! 24 — with our models, beside the thesis's numbers (`spdcam experiment thesis`).
//!
//! Each set's `_train` part trains (a seeded 10 % of it selects the epoch), its `_val` part
//! is the test set (the thesis's own test parts are kept aside). SPDs are made from the
//! weights with the thesis's channels (`THESIS-PARAMETERS.md`), then normalised to a maximum
//! of 1.
//!
//! - [`sets`]: the sets, their channels and parts.
//! - [`thesis`]: training and scoring one model on one set, as a row of the results.

pub mod sets;
pub mod thesis;
