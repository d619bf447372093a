//! Model diagnostics: where and how a fitted fiber model misses the measurements, which
//! physical effect is missing, adding it, and watching the error fall.
//!
//! * [`compare`]: measured vs simulated diameters per experiment, residual statistics
//!   (noise level, χ²/dof, runs test, lag-1 autocorrelation), systematic segments along the
//!   spin line, text/JSON summaries and figures;
//! * the candidate effects themselves (canonical names, strength parameters, neutral values,
//!   the model specification a rheometer fit uses) live below the model, in
//!   `effects`;
//! * [`diagnose`]: the stages of a diagnosis (fit the base, linearise, test the noise,
//!   search, choose shapes, judge, rank, ties), ranking the candidates by the excess misfit
//!   they explain;
//! * `candidate`: the record of one candidate and how candidates are judged and ranked;
//! * `diagnosis`: the result of a diagnosis (JSON) and what figures need besides;
//! * `calibration`: the look-elsewhere calibration of a diagnosis as a value (the null
//!   distribution of the best `ΔBIC`), computed by the stage `diagnose::linear::calibrate`;
//! * `report`: the diagnosis in words and its figures;
//! * `detection`: the detection limit of each candidate (the strength the data would reveal)
//!   and the shift of `(n, κ)` an effect just below it would cause;
//! * `refits`: the refits behind a diagnosis — `refits::scan`, the global search of one
//!   candidate's strength (and shape): the profile of `J` and the refits of its best points;
//!   `refits::pair`, two candidates fitted jointly; and `refits::consistency`, whether a
//!   fitted effect has one strength in every experiment (a score test of the fit; the
//!   diagnosis' stage 10 and `fit --with` both use it);
//! * `ties`: candidates about as consistent with the data as the named one (alternatives).

pub(crate) mod calibration;
pub(crate) mod candidate;
pub(crate) mod compare;
pub(crate) mod detection;
pub(crate) mod diagnose;
pub(crate) mod diagnosis;
pub(crate) mod refits;
pub(crate) mod report;
pub(crate) mod scores;
pub(crate) mod ties;

pub use candidate::{
    earns_its_place, Candidate, Indistinguishable, ShapeAlternative, StrengthStatus,
};
pub use compare::{
    compare, compare_set, simulate_experiments, CompareError, CompareOptions, ComparedExperiment,
    ComparedPoint, Comparison, ModelSetup, SimulatedExperiment, Trend,
};
pub use detection::{detection_limits, DetectionContext, DetectionLimit, DetectionLimits};
pub use diagnose::verdict::{Help, Unexplained, Verdict};
pub use diagnose::{
    diagnose, DiagnoseOptions, Diagnosis, DiagnosisRun, ForwardStep, ResidualProfiles,
    RobustWeights, StageTimes,
};
pub use diagnosis::DiagnosisJson;
pub use refits::pair::PairFound;
pub use refits::scan::{
    physical, physical_range, Profile, ProfilePoint, Refit, ScanOptions, ShapeParameter,
};
pub use report::residual_figure;
pub use ties::{alternatives, Alternative};
