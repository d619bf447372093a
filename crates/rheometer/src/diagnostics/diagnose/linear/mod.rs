//! The linearised screen of the candidates at the fitted model: the linearisation
//! (`linearise`), the signature of a candidate (`signature`) and the look-elsewhere calibration
//! of the screen (`calibrate`).

pub(crate) mod calibrate;
pub(super) mod linearise;
pub(super) mod signature;
