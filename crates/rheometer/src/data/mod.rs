//! The data: the measured experiments as loaded, smoothed and judged for their noise, and
//! synthetic data sets.
//!
//! * [`input`]: loading experiments from the project's TOML + CSV format;
//! * [`uncertainty`]: declared standard uncertainties of process conditions, instrument and
//!   material data (the `[uncertainty]` table);
//! * [`smoothing`]: the velocity-ansatz smoothing of measured diameters (paper eq. 5);
//! * [`take_up`]: the take-up condition a model uses (the data set's, a given diameter, or
//!   `d_fit(L)` of the smoothed data);
//! * [`statistics`]: noise estimates, runs test, autocorrelation and rank correlation of
//!   residuals;
//! * [`noise_model`]: the noise of the measurements along the spin line;
//! * `noise_summary`: the one noise level a misfit is judged against;
//! * [`synthetic`]: reproducible measurement noise for synthetic data sets.

pub mod input;
pub mod noise_model;
pub(crate) mod noise_summary;
pub mod smoothing;
pub mod statistics;
pub mod synthetic;
pub mod take_up;
pub mod uncertainty;

pub use noise_summary::NoiseSource;
