//! One diagnosis per data set for the whole test binary: tests that look at the same scenario
//! (the same truth, seed, noise and faults: the scenario's `Debug` text is the key) with the
//! default options share its data set and diagnosis instead of each making and diagnosing it
//! again (issue 27: nothing in the suite repeats a full diagnosis it could reuse). Tests running
//! in parallel that ask for the same scenario wait for the one diagnosis.

use crate::independent;

use independent::dataset::{Generated, Scenario};
use rheometer::data::input::load_experiments;
use rheometer::diagnostics::{diagnose, DiagnoseOptions, DiagnosisRun};
use rheometer::model::ExperimentSet;
use rheometer::model::{LawChoice, ModelSpec};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

/// A scenario's data set and its diagnosis with the default options.
pub struct Diagnosed {
    /// The data set as loaded from the generated TOML + CSV.
    pub set: ExperimentSet,
    /// The diagnosis (Carreau-type law, `DiagnoseOptions::default()`).
    pub run: DiagnosisRun,
    /// Wall time of the diagnosis \[s\] (of the first test that asked for it).
    pub seconds: f64,
}

/// Generates and loads `sc` and diagnoses it with `options` (the Carreau-type law), every
/// call anew: the tests with options of their own and the studies, which diagnose hundreds of
/// sets once each, so that the cache of [`diagnosed`] does not hold them.
pub fn diagnose_with(sc: &Scenario, options: &DiagnoseOptions) -> Diagnosed {
    diagnose_generated(&sc.generate().unwrap(), options)
}

/// Loads the data set `generated` and diagnoses it with `options` (the Carreau-type law): for
/// studies that generate a scenario themselves to tell a set the simulator cannot make from a
/// failed diagnosis.
pub fn diagnose_generated(generated: &Generated, options: &DiagnoseOptions) -> Diagnosed {
    let set = load_experiments(&generated.toml).unwrap();
    let t0 = Instant::now();
    let run = diagnose(&set, &ModelSpec::new(LawChoice::Carreau), options).unwrap();
    Diagnosed {
        set,
        run,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

type Cell = Arc<OnceLock<Arc<Diagnosed>>>;

/// The scenario's data set, generated, loaded and diagnosed with the default options once per
/// test binary.
pub fn diagnosed(sc: &Scenario) -> Arc<Diagnosed> {
    static CACHE: OnceLock<Mutex<HashMap<String, Cell>>> = OnceLock::new();
    let key = format!("{sc:?}");
    let cell: Cell = {
        let mut map = CACHE
            .get_or_init(|| Mutex::new(HashMap::new()))
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        map.entry(key).or_default().clone()
    };
    cell.get_or_init(|| Arc::new(diagnose_with(sc, &DiagnoseOptions::default())))
        .clone()
}

/// An estimate and its 95 % interval with `digits` decimals, as the studies print them:
/// `"0.803 [0.790, 0.818]"`.
pub fn with_interval(e: &rheometer::fit::Estimate, digits: usize) -> String {
    format!(
        "{:.d$} [{:.d$}, {:.d$}]",
        e.value,
        e.ci95[0],
        e.ci95[1],
        d = digits
    )
}
