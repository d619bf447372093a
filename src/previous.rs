//! `--from FILE` of `fit` and `diagnose`: the previous result (a fit report or a diagnosis)
//! a fit continues from, its effects joined with the ones `--with` adds.

use crate::*;
use rheometer::fit::ContinuedEffects;

/// A previous result `fit --from` or `diagnose --from` continues from.
pub struct Previous {
    /// The file.
    pub path: PathBuf,
    /// Its fit (a diagnosis' final fit).
    pub fit: FitSummary,
}

/// The law of a fit: `model` where given, else the previous result's, else Carreau-type.
pub fn law(model: Option<LawChoice>, previous: Option<&Previous>) -> LawChoice {
    model.or(previous.map(|p| p.fit.law)).unwrap_or_default()
}

impl Previous {
    /// The start `(n, κ)` of a fit of `law` from the file's law, checked against the fit's
    /// bounds; none unless both are Carreau-type (a Newtonian fit's n = 1 is no start: the
    /// heuristic is).
    pub fn start(
        &self,
        law: LawChoice,
        opts: &IdentifyOptions,
    ) -> Result<Option<(f64, f64)>, String> {
        if law != LawChoice::Carreau || self.fit.law != LawChoice::Carreau {
            return Ok(None);
        }
        let s = (self.fit.n.value, self.fit.kappa.value);
        checks::check_start(s, opts).map_err(|e| {
            format!(
                "--from {}: its law cannot start this fit ({e})",
                self.path.display()
            )
        })?;
        Ok(Some(s))
    }

    /// Checks that the file is a fit of the experiments of `loaded`, in their order, and
    /// warns when its data digest says it was made on other numbers.
    pub fn check_experiments(&self, loaded: &LoadedExperiments, g: &Global) -> Result<(), String> {
        self.fit
            .check_experiments(&loaded.set.names(), &self.path.display().to_string())?;
        warn_other_data(
            g,
            &self.fit,
            loaded,
            &format!("--from {}", self.path.display()),
        );
        Ok(())
    }

    /// The model's effects: the file's (continued) and then `with`, each effect once; the
    /// start values of the file's fitted strengths and shapes.
    pub fn joined_with(&self, with: Vec<EffectSetting>) -> Result<ContinuedEffects, String> {
        let source = format!("--from {}", self.path.display());
        self.fit.continued_with(with, "--with", &source)
    }
}

/// Reads the file of `--from`: a fit report or a diagnosis (`-`: standard input).
pub fn read_previous(path: &Path, g: &Global) -> Result<Previous, Box<dyn Error>> {
    let fit = read_fit_file(g, path, "--from")?;
    Ok(Previous {
        path: path.to_path_buf(),
        fit,
    })
}
