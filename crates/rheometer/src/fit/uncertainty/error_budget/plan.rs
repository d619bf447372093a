//! Which sources of the error budget take which column: the effects the fit's model frees
//! for them, and the gauge's columns where no effect represents a source.

use super::SourceStatus;
use crate::data::uncertainty::{GaugeColumn, Source};
use crate::fit::data::Rheometer;
use crate::fit::identify::gauss_newton::Identification;
use crate::model::catalog::EffectId;
use crate::model::effects::{Effect, EffectSetting, ModelSpec};

/// How a source's column is obtained.
pub(super) enum Column {
    /// Column `usize` of the augmented objective's Jacobian.
    Effect(usize),
    Gauge(GaugeColumn),
    None(SourceStatus),
}

/// Which sources need which effect: the fit's model with the sources' effects freed (fixed
/// ones at their fixed strengths, absent ones added as candidates), and per source the effect
/// whose column it takes or why it has none.
pub(super) struct SourcePlan {
    /// The augmented model.
    pub(super) spec: ModelSpec,
    /// The effects it frees beyond the fit's own.
    pub(super) free: Vec<String>,
    /// Start strengths by effect name: the fit's fitted strengths, the fixed ones.
    pub(super) strengths: Vec<(String, f64)>,
    /// Per source: the effect whose column it takes, or its status.
    pub(super) status: Vec<Result<String, SourceStatus>>,
}

impl SourcePlan {
    pub(super) fn new(rh: &Rheometer, id: &Identification, sources: &[Source]) -> Self {
        let strengths: Vec<(String, f64)> = id
            .effects
            .iter()
            .filter(|s| s.column.is_some())
            .map(|s| {
                (
                    s.effect.name().to_string(),
                    s.effect.strength_of(id.local_params[s.local]),
                )
            })
            .collect();
        let mut plan = SourcePlan {
            spec: rh.spec.clone(),
            free: Vec::new(),
            strengths,
            status: Vec::new(),
        };
        for s in sources {
            let applies = rh.experiments.iter().any(|e| (s.per_unit)(e).is_some());
            let status = if applies {
                plan.column_of(s.effect)
            } else {
                Err(SourceStatus::NotApplicable)
            };
            plan.status.push(status);
        }
        plan
    }

    /// The effect `effect` whose column a source takes: fitted already (no column needed),
    /// fixed (freed at its strength), a candidate (freed), or added to the model.
    fn column_of(&mut self, id: EffectId) -> Result<String, SourceStatus> {
        let free = &mut self.free;
        let effect = id.name();
        if let Some(set) = self.spec.effects.iter_mut().find(|x| x.effect.id() == id) {
            match set.value {
                None if !free.iter().any(|f| f == effect) => Err(SourceStatus::Fitted),
                None => Ok(effect.to_string()),
                Some(v) => {
                    // a fixed effect: its column at the fixed strength
                    *set = EffectSetting::fitted(set.effect.clone());
                    self.strengths.push((effect.to_string(), v));
                    free.push(effect.to_string());
                    Ok(effect.to_string())
                }
            }
        } else if self.spec.candidates.iter().any(|c| c.id() == id) {
            if !free.iter().any(|f| f == effect) {
                free.push(effect.to_string());
            }
            Ok(effect.to_string())
        } else {
            match effect.parse::<Effect>() {
                Ok(e) => {
                    self.spec = self.spec.clone().with_candidates(&[e]);
                    free.push(effect.to_string());
                    Ok(effect.to_string())
                }
                Err(_) => Err(SourceStatus::NotAvailable),
            }
        }
    }
}

/// How each source's column is obtained, from its plan and the augmented Jacobian's columns.
pub(super) fn source_columns(
    sources: &[Source],
    plan: &[Result<String, SourceStatus>],
    aug: &Option<(Vec<f64>, usize, Vec<String>)>,
    principled: bool,
) -> Vec<Column> {
    sources
        .iter()
        .zip(plan)
        .map(|(s, p)| match (p, aug) {
            (Ok(name), Some((_, _, names))) => names
                .iter()
                .position(|n| n == name)
                .map_or(Column::None(SourceStatus::NotAvailable), Column::Effect),
            (Err(SourceStatus::NotAvailable), _) => match s.fallback {
                Some(g) if principled => Column::Gauge(g),
                _ => Column::None(SourceStatus::NotAvailable),
            },
            (Err(st), _) => Column::None(*st),
            (Ok(_), None) => Column::None(SourceStatus::NotAvailable),
        })
        .collect()
}
