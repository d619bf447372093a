//! The law the diagnosis reports when it is the user's own fit: on a melt that shows no strain
//! thinning over the data's strain rates, the likelihood-ratio test against the Newtonian law
//! (as `fit` runs it) makes that fit's law "Newtonian within the data's strain rates", `n` and
//! `κ` not estimates, rather than a `(n, κ)` in the corner passed on as a result.

use crate::diagnostics::detection::DetectionLimits;
use crate::diagnostics::diagnosis::DiagnosisRun;
use crate::fit::uncertainty::profile::newtonian_test_of;
use crate::fit::{IdentifyOptions, Rheometer};
use crate::model::effects::ModelSpec;
use crate::model::setup::ExperimentSet;

/// The detection limits without the shifts of `n` and `κ` an undetected effect would cause:
/// they are linearised at a point in the Newtonian corner and counted in standard errors of
/// numbers that are not estimates (the limits themselves keep their meaning).
fn withhold_law_shifts(limits: &mut DetectionLimits) {
    for l in &mut limits.limits {
        l.shift_n_at_s95 = None;
        l.shift_kappa_at_s95 = None;
        l.shift_n_se = None;
        l.shift_kappa_se = None;
    }
    limits.shifts_withheld = Some(
        "the law is Newtonian within the data's strain rates, and n and kappa are not \
         estimates"
            .into(),
    );
}

/// Where the reported law is the user's fit (no effect found) and the Newtonian law fits as
/// well, attaches the test to the base fit, drops its warnings about `n` and `κ` as estimates
/// and withholds the detection limits' shifts of them. The test is the fit's (same model `spec` with its candidates, same `options`);
/// where it cannot be run the report stays as it was (nothing of the diagnosis depends on it).
pub(super) fn newtonian_law(
    set: &ExperimentSet,
    spec: &ModelSpec,
    options: &IdentifyOptions,
    run: &mut DiagnosisRun,
) {
    if run.diagnosis.final_fit.is_some() || !run.diagnosis.base_fit.law_fitted() {
        return;
    }
    let Ok(rh) = Rheometer::with_spec(set, spec.clone()) else {
        return;
    };
    if let Ok(Some(test)) = newtonian_test_of(&rh, &run.base, options) {
        if test.law_not_estimated.is_some() {
            let base = &mut run.diagnosis.base_fit;
            base.newtonian_test = Some(test);
            base.drop_law_estimate_warnings();
            withhold_law_shifts(&mut run.diagnosis.detection);
        }
    }
}
