//! Argument groups several commands share: the photo options (`estimate`) and the held-out
//! lamp library and cameras (`lamps validate`, `trust`).

pub mod held_out;
pub mod photo;
