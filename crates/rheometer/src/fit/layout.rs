//! Which model parameters a fit frees: the law's `(n, κ)`, effect strengths (see
//! [`effects`](crate::model::effects)) and, for the principled estimator,
//! one take-up factor per experiment.
//!
//! Every experiment's model has the same parameter layout
//! `p = [c, n, κ, strengths..., φ]`; a fit's parameter vector is
//! `[shared free parameters..., φ_1, ..., φ_M]`, the shared ones being `n, κ` (where the law is
//! fitted) followed by the fitted strengths (in model-parameter units, e.g. `1 + s` for
//! `nusselt_scale`).

use super::options::{CarreauFiber, IdentifyOptions, RheometerError};
use crate::model::bvp::ParamLayout;
use crate::model::effects::{Effect, LawChoice, ModelSpec, ShapeParameter, NEWTONIAN_LAW};
use crate::model::material_law::CarreauLike;
use diffbvp::solution::Solution;

/// Start of a fit.
#[derive(Debug, Clone)]
pub struct FitStart {
    /// `(n, κ)` start (where fitted; a Newtonian model uses `n = 1`).
    pub law: [f64; 2],
    /// Candidates of the model whose strengths this fit frees (by effect name).
    pub free_candidates: Vec<String>,
    /// Start strengths by effect name (default: neutral), and start values of shape parameters
    /// by model-parameter name (e.g. `"air_coflow.decay_length"`, default: the effect's fixed
    /// or default value).
    pub strengths: Vec<(String, f64)>,
    /// Warm-start solutions, one per experiment (default: cold starts).
    pub warm: Option<Vec<Solution>>,
}

impl FitStart {
    /// Start at `(n, κ)`, candidates not freed, cold starts.
    pub fn at(law: [f64; 2]) -> Self {
        FitStart {
            law,
            free_candidates: Vec::new(),
            strengths: Vec::new(),
            warm: None,
        }
    }

    fn strength(&self, name: &str) -> Option<f64> {
        self.strengths
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }
}

/// Where an effect's strength sits.
#[derive(Debug, Clone)]
pub struct EffectSlot {
    /// The effect.
    pub effect: Effect,
    /// Index of its model parameter in the local `p`.
    pub local: usize,
    /// Its column in the fit's parameter vector (`None` if fixed).
    pub column: Option<usize>,
    /// Its shape parameters (decay lengths, onset), fixed or fitted.
    pub shapes: Vec<ShapeSlot>,
}

/// Where a shape parameter of an effect sits.
#[derive(Debug, Clone)]
pub struct ShapeSlot {
    /// The shape parameter.
    pub parameter: ShapeParameter,
    /// Index of its model parameter in the local `p`.
    pub local: usize,
    /// Its column in the fit's parameter vector (`None` if fixed).
    pub column: Option<usize>,
}

/// The column of a parameter after column `i` was removed (`None` for `i` itself).
fn drop_column(c: &mut Option<usize>, i: usize) {
    *c = match *c {
        Some(x) if x == i => None,
        Some(x) if x > i => Some(x - 1),
        other => other,
    };
}

/// Fraction of an effect parameter's search range that is one unit of the fit's trust region
/// ([`Layout::x_scale`]): a co-flow searched over −100…600 m/s moves up to 70 m/s per iteration,
/// not 1 m/s as with a unit scale, so that a refit that must travel far reaches its optimum
/// within its iteration limit.
pub const EFFECT_SCALE_FRACTION: f64 = 0.1;

/// The parameter layout of one fit.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Local model parameters with the start (or fixed) values; `φ = 1`.
    pub template: Vec<f64>,
    /// Local indices of the shared free parameters, in fit order.
    pub free: Vec<usize>,
    /// Names of the shared free parameters (`"n"`, `"kappa"`, effect names).
    pub names: Vec<String>,
    /// Lower bounds of the shared free parameters (model-parameter units).
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
    /// The effects of the model (fixed or fitted; neutral candidates not freed are left out).
    pub effects: Vec<EffectSlot>,
    /// Where `n`, `κ`, the strengths and `φ` sit in the local parameters (the same for every
    /// experiment's model).
    pub params: ParamLayout,
}

impl Layout {
    /// The layout for `spec` (the model `model` was built from) and `start`.
    pub fn new(
        model: &CarreauFiber,
        spec: &ModelSpec,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Self, RheometerError> {
        spec.validate().map_err(RheometerError::Data)?;
        let mut b = Builder::new(model, spec, start)?;
        let settings = spec.effects.iter().map(|s| (&s.effect, s.value)).chain(
            spec.candidates
                .iter()
                .filter(|c| start.free_candidates.iter().any(|n| n == c.name()))
                .map(|c| (c, None)),
        );
        for (e, value) in settings {
            if e.installs_in_law() {
                b.law_effect(e, value, start, options);
            } else {
                b.effect(model, e, value, start)?;
            }
        }
        if spec.law == LawChoice::Carreau {
            b.k_free = true;
        }
        let mut layout = b.law_first(options);
        layout.hold(&options.hold)?;
        Ok(layout)
    }

    /// Holds the shared free parameters named in `hold` at their values: out of the fit, the
    /// columns after them moved down.
    fn hold(&mut self, hold: &[(String, f64)]) -> Result<(), RheometerError> {
        for (name, v) in hold {
            let Some(i) = self.names.iter().position(|n| n == name) else {
                return Err(RheometerError::Data(format!(
                    "cannot hold {name}: not a fitted parameter of this model ({})",
                    self.names.join(", ")
                )));
            };
            self.template[self.free[i]] = *v;
            self.free.remove(i);
            self.names.remove(i);
            self.lower.remove(i);
            self.upper.remove(i);
            for slot in &mut self.effects {
                drop_column(&mut slot.column, i);
                for sh in &mut slot.shapes {
                    drop_column(&mut sh.column, i);
                }
            }
        }
        Ok(())
    }

    /// Number of shared free parameters.
    pub fn num_shared(&self) -> usize {
        self.free.len()
    }

    /// The trust region's scale of each shared free parameter
    /// ([`FitOptions::x_scale`](diffbvp::least_squares::FitOptions::x_scale)): 1 for `n` and
    /// `κ`; for an effect's strength or shape, `EFFECT_SCALE_FRACTION` of its search range
    /// where that exceeds 1 in the parameter's unit (an air speed in m/s, a temperature in
    /// K), else 1 (radii of O(1) parameters stay as they were).
    pub fn x_scale(&self) -> Vec<f64> {
        self.names
            .iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(name, (&lo, &hi))| match name.as_str() {
                "n" | "kappa" => 1.0,
                _ if (hi - lo).is_finite() => (EFFECT_SCALE_FRACTION * (hi - lo)).max(1.0),
                _ => 1.0,
            })
            .collect()
    }

    /// The shared free values of the template.
    pub fn shared_start(&self) -> Vec<f64> {
        self.free.iter().map(|&i| self.template[i]).collect()
    }

    /// `(n, κ)` of local parameters `local`.
    pub fn law_of(&self, local: &[f64]) -> [f64; 2] {
        [
            local[self.params.law_param(CarreauLike::N)],
            local[self.params.law_param(CarreauLike::KAPPA)],
        ]
    }

    /// Sets `(n, κ)` of the template (overriding the start or fixed values).
    pub fn set_law(&mut self, n: f64, kappa: f64) {
        self.template[self.params.law_param(CarreauLike::N)] = n;
        self.template[self.params.law_param(CarreauLike::KAPPA)] = kappa;
    }

    /// The local parameters for shared values `shared` and take-up factor `phi` (at
    /// `phi_index`, [`ParamLayout::take_up_factor`]).
    pub fn local(&self, shared: &[f64], phi: f64, phi_index: usize) -> Vec<f64> {
        let mut p = self.template.clone();
        for (&i, &v) in self.free.iter().zip(shared) {
            p[i] = v;
        }
        p[phi_index] = phi;
        p
    }
}

/// The index of the model parameter `name` of `model`.
fn param_index(model: &CarreauFiber, name: &str) -> Result<usize, RheometerError> {
    model
        .param_index(name)
        .ok_or_else(|| RheometerError::Data(format!("the model has no parameter {name}")))
}

/// A layout while its effects are added: the template and the shared free parameters other
/// than the law's (these go first, see [`Builder::law_first`]).
struct Builder {
    template: Vec<f64>,
    params: ParamLayout,
    /// Local indices of `n` and `κ`.
    ni: usize,
    ki: usize,
    /// Whether `n`, `κ` are fitted, and whether an effect installed in the law fits its
    /// strength in `n`'s place.
    n_free: bool,
    k_free: bool,
    st_free: bool,
    free: Vec<usize>,
    names: Vec<String>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    effects: Vec<EffectSlot>,
    /// Spin-line length bounding the shape parameters (the longest of the experiments'
    /// models is not known here: the first model's).
    length: f64,
}

impl Builder {
    /// The template at the start `(n, κ)` (Newtonian values for a Newtonian law), no effects.
    fn new(
        model: &CarreauFiber,
        spec: &ModelSpec,
        start: &FitStart,
    ) -> Result<Self, RheometerError> {
        let mut template = model.parameters(1.0, &start.law).map_err(|e| {
            RheometerError::Data(format!("start (n, kappa) = {:?}: {e}", start.law))
        })?;
        let params = model.param_layout();
        let (ni, ki) = (
            params.law_param(CarreauLike::N),
            params.law_param(CarreauLike::KAPPA),
        );
        if spec.law == LawChoice::Newtonian {
            [template[ni], template[ki]] = NEWTONIAN_LAW;
        }
        Ok(Builder {
            template,
            params,
            ni,
            ki,
            n_free: spec.law == LawChoice::Carreau,
            k_free: false,
            st_free: false,
            free: Vec::new(),
            names: Vec::new(),
            lower: Vec::new(),
            upper: Vec::new(),
            effects: Vec::new(),
            length: model.experiment.spinline_length,
        })
    }

    /// An effect installed in the law (its strength in `n`'s place): at its fixed strength,
    /// or fitted from its start strength with `κ`.
    fn law_effect(
        &mut self,
        e: &Effect,
        value: Option<f64>,
        start: &FitStart,
        options: &IdentifyOptions,
    ) {
        let (ni, ki) = (self.ni, self.ki);
        match value {
            Some(v) => self.template[ni] = e.param_value(v),
            None => {
                self.n_free = true;
                self.st_free = true;
                let s = start
                    .strength(e.name())
                    .unwrap_or(e.strength_of(start.law[0]));
                self.template[ni] = e.param_value(s).clamp(options.lower[0], options.upper[0]);
                self.template[ki] = start.law[1];
            }
        }
        self.k_free = true;
        self.effects.push(EffectSlot {
            effect: e.clone(),
            local: ni,
            column: None,
            shapes: Vec::new(),
        });
    }

    /// An effect with its own model parameter: at its fixed strength, or fitted (with its
    /// free shape parameters) from its start strength; its shape parameters at their fixed or
    /// default values otherwise.
    fn effect(
        &mut self,
        model: &CarreauFiber,
        e: &Effect,
        value: Option<f64>,
        start: &FitStart,
    ) -> Result<(), RheometerError> {
        let li = param_index(model, e.model_param())?;
        // shape parameters: at their fixed or default values in the template
        let mut shapes = Vec::new();
        for (sp, v) in e.shape_values() {
            let si = param_index(model, sp.model_param)?;
            self.template[si] = v;
            shapes.push(ShapeSlot {
                parameter: sp,
                local: si,
                column: None,
            });
        }
        let column = match value {
            Some(v) => {
                self.template[li] = e.param_value(v);
                None
            }
            None => {
                let s = start.strength(e.name()).unwrap_or(e.neutral());
                self.template[li] = e.param_value(s);
                let (lo, hi) = e.bounds();
                let (a, b) = (e.param_value(lo), e.param_value(hi));
                let column = Some(self.free.len());
                self.push_free(li, e.name().to_string(), a.min(b), a.max(b));
                self.free_shapes(e, &mut shapes, start);
                column
            }
        };
        self.effects.push(EffectSlot {
            effect: e.clone(),
            local: li,
            column,
            shapes,
        });
        Ok(())
    }

    /// The shape parameters of the fitted effect `e` fitted with its strength (unless fixed).
    fn free_shapes(&mut self, e: &Effect, shapes: &mut [ShapeSlot], start: &FitStart) {
        let free_shapes = e.free_shapes();
        for slot in shapes {
            if !free_shapes.contains(&slot.parameter) {
                continue;
            }
            let sp = &slot.parameter;
            if let Some(v) = start.strength(sp.model_param) {
                self.template[slot.local] = v;
            }
            let (slo, shi) = sp.bounds_for_length(self.length);
            slot.column = Some(self.free.len());
            self.push_free(slot.local, sp.model_param.to_string(), slo, shi);
        }
    }

    /// A shared free parameter: local index, name and bounds.
    fn push_free(&mut self, local: usize, name: String, lower: f64, upper: f64) {
        self.free.push(local);
        self.names.push(name);
        self.lower.push(lower);
        self.upper.push(upper);
    }

    /// The layout with the law's free parameters first (the effects' columns shifted after
    /// them) and the template clamped to the bounds.
    fn law_first(self, options: &IdentifyOptions) -> Layout {
        let (ni, ki) = (self.ni, self.ki);
        let mut head = Vec::new();
        if self.n_free {
            head.push((ni, "n", options.lower[0], options.upper[0]));
        }
        if self.k_free {
            head.push((ki, "kappa", options.lower[1], options.upper[1]));
        }
        let shift = head.len();
        let mut effects = self.effects;
        for slot in &mut effects {
            if let Some(c) = slot.column.as_mut() {
                *c += shift;
            }
            for sh in &mut slot.shapes {
                if let Some(c) = sh.column.as_mut() {
                    *c += shift;
                }
            }
            if self.st_free && slot.effect.installs_in_law() {
                slot.column = Some(0);
            }
        }
        let mut f2: Vec<usize> = head.iter().map(|h| h.0).collect();
        let mut n2: Vec<String> = head.iter().map(|h| h.1.to_string()).collect();
        let mut l2: Vec<f64> = head.iter().map(|h| h.2).collect();
        let mut u2: Vec<f64> = head.iter().map(|h| h.3).collect();
        f2.extend(self.free);
        n2.extend(self.names);
        l2.extend(self.lower);
        u2.extend(self.upper);
        let mut template = self.template;
        for (i, &li) in f2.iter().enumerate() {
            template[li] = template[li].clamp(l2[i], u2[i]);
        }
        Layout {
            template,
            free: f2,
            names: n2,
            lower: l2,
            upper: u2,
            effects,
            params: self.params,
        }
    }
}
