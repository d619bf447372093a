//! Which experiment next: optimal experimental design for the spinning line from the exact
//! sensitivities of the BVP.
//!
//! * `information`: the Fisher information one experiment carries about the fitted
//!   parameters (exact forward sensitivities of the predicted gauge readings, take-up factor
//!   profiled out);
//! * `criteria`: predicted covariance, standard errors, correlation of `(n, κ)`, and the D-,
//!   A- and E-criteria;
//! * `candidates`: the grid of candidate experiments (mass flow × take-up condition) made
//!   from a template experiment;
//! * `estimation`: the design for estimation, ranking the candidates in parallel;
//! * `discrimination`: the design for discrimination, ranking the candidates by how well
//!   they tell rival explanations (the base model plus one effect or another) apart;
//! * `report`, `discrimination_report`: the designs as text.

pub(crate) mod candidates;
pub(crate) mod criteria;
pub(crate) mod discrimination;
pub(crate) mod discrimination_report;
pub(crate) mod estimation;
pub(crate) mod information;
pub(crate) mod report;

pub use criteria::Reference;
pub use estimation::NoiseSource;

pub use candidates::{Candidate, CandidateGrid, DesignEstimate, TakeUpAxis};
pub use criteria::{Criterion, Prediction};
pub use discrimination::{design_for_discrimination, Discrimination, DiscriminationRequest, Rival};
pub use estimation::{design_for_estimation, noise_level, CandidateOutcome, Design, DesignRequest};
