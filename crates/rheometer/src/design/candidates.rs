//! The candidate experiments of a design: a grid over the mass flow (the extruder's stencil
//! velocity) and the take-up condition (diameter or speed), each a copy of a template
//! experiment of the data set measured at the template's positions.

use crate::model::setup::{Experiment, TakeUp};
use serde::Serialize;
use std::time::Instant;

/// The take-up axis of the grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "values")]
pub enum TakeUpAxis {
    /// Take-up diameters \[m\].
    Diameter(Vec<f64>),
    /// Take-up speeds \[m/s\].
    Velocity(Vec<f64>),
}

impl TakeUpAxis {
    /// The values (diameters \[m\] or speeds \[m/s\]).
    pub fn values(&self) -> &[f64] {
        match self {
            TakeUpAxis::Diameter(v) | TakeUpAxis::Velocity(v) => v,
        }
    }

    /// The take-up condition of value `v`.
    pub fn condition(&self, v: f64) -> TakeUp {
        match self {
            TakeUpAxis::Diameter(_) => TakeUp::Diameter(v),
            TakeUpAxis::Velocity(_) => TakeUp::Velocity(v),
        }
    }

    /// `"take-up diameter"` or `"take-up speed"`.
    pub fn label(&self) -> &'static str {
        match self {
            TakeUpAxis::Diameter(_) => "take-up diameter",
            TakeUpAxis::Velocity(_) => "take-up speed",
        }
    }

    /// The unit of the values.
    pub fn unit(&self) -> &'static str {
        match self {
            TakeUpAxis::Diameter(_) => "m",
            TakeUpAxis::Velocity(_) => "m/s",
        }
    }
}

/// The grid of candidate experiments.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateGrid {
    /// Index of the template experiment in the data set (material, inlet, temperatures,
    /// spin-line length and measurement positions are the template's).
    pub template: usize,
    /// Mass flows \[kg/s\] (first axis).
    pub mass_flows: Vec<f64>,
    /// Take-up conditions (second axis).
    pub take_up: TakeUpAxis,
    /// Measurement positions \[m\] of a candidate (`None`: the template's).
    pub positions: Option<Vec<f64>>,
}

/// One candidate experiment: its place in the grid and its process conditions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Candidate {
    /// Index along the mass-flow axis.
    pub i: usize,
    /// Index along the take-up axis.
    pub j: usize,
    /// Mass flow \[kg/s\].
    pub mass_flow: f64,
    /// Take-up value (diameter \[m\] or speed \[m/s\], as the axis).
    pub take_up: f64,
}

impl CandidateGrid {
    /// Checks the axes: non-empty, finite and positive values.
    pub fn validate(&self) -> Result<(), String> {
        let check = |what: &str, unit: &str, v: &[f64]| {
            if v.is_empty() {
                return Err(format!("the candidate grid has no {what} values"));
            }
            match v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                Some(x) => Err(format!(
                    "candidate {what} {x} {unit} is not a positive finite value"
                )),
                None => Ok(()),
            }
        };
        check("mass flow", "kg/s", &self.mass_flows)?;
        check(
            self.take_up.label(),
            self.take_up.unit(),
            self.take_up.values(),
        )?;
        if let Some(p) = &self.positions {
            if p.is_empty() || p.iter().any(|s| !(s.is_finite() && *s >= 0.0)) {
                return Err(
                    "candidate measurement positions must be finite and non-negative (m)".into(),
                );
            }
        }
        Ok(())
    }

    /// The candidates, mass flow varying slowest.
    pub fn candidates(&self) -> Vec<Candidate> {
        let mut out = Vec::with_capacity(self.mass_flows.len() * self.take_up.values().len());
        for (i, &q) in self.mass_flows.iter().enumerate() {
            for (j, &t) in self.take_up.values().iter().enumerate() {
                out.push(Candidate {
                    i,
                    j,
                    mass_flow: q,
                    take_up: t,
                });
            }
        }
        out
    }

    /// The experiment of candidate `c` made from `template` (named after its conditions).
    pub fn experiment(&self, template: &Experiment, c: &Candidate) -> Experiment {
        let name = match self.take_up {
            TakeUpAxis::Diameter(_) => {
                format!("Q{:.3e}_d{:.1}um", c.mass_flow, c.take_up * 1e6)
            }
            TakeUpAxis::Velocity(_) => format!("Q{:.3e}_u{:.3}m_s", c.mass_flow, c.take_up),
        };
        Experiment {
            name,
            mass_flow: c.mass_flow,
            take_up: Some(self.take_up.condition(c.take_up)),
            ..template.clone()
        }
    }
}

/// How long the candidates of a design will take, measured on its first rows (one per thread,
/// run before the others): what a long design says before it runs on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignEstimate {
    /// Candidates in the grid.
    pub candidates: usize,
    /// Rows of the grid (one per mass flow; a row sweeps the take-up axis).
    pub rows: usize,
    /// Rows measured.
    pub rows_measured: usize,
    /// Wall time of the measured rows \[s\].
    pub measured_s: f64,
    /// Threads the rows run on.
    pub threads: usize,
    /// Predicted wall time of the rows not yet run \[s\].
    pub remaining_s: f64,
}

/// `row` applied to every row of `all` (rows of `nt` candidates, each a warm-started sweep) in
/// parallel, the outcomes in the grid's order. When the grid has more than two rows per
/// thread, the first row of each thread runs first, timed, and `report` gets the estimate
/// before the rest runs; the outcomes do not depend on it.
pub(crate) fn rows_in_order<T: Send>(
    all: &[Candidate],
    nt: usize,
    row: impl Fn(&[Candidate]) -> Vec<T> + Sync,
    report: &(dyn Fn(&DesignEstimate) + Sync),
) -> Vec<T> {
    use rayon::prelude::*;
    let nt = nt.max(1);
    let rows = all.len().div_ceil(nt);
    let threads = rayon::current_num_threads().max(1);
    if rows <= 2 * threads {
        return all.par_chunks(nt).flat_map_iter(&row).collect();
    }
    let (first, rest) = all.split_at(threads * nt);
    let t0 = Instant::now();
    let mut out: Vec<T> = first.par_chunks(nt).flat_map_iter(&row).collect();
    let measured_s = t0.elapsed().as_secs_f64();
    report(&DesignEstimate {
        candidates: all.len(),
        rows,
        rows_measured: threads,
        measured_s,
        threads,
        remaining_s: measured_s * (rows - threads).div_ceil(threads) as f64,
    });
    out.extend(rest.par_chunks(nt).flat_map_iter(&row).collect::<Vec<T>>());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lists_every_pair_and_refuses_bad_axes() {
        let g = CandidateGrid {
            template: 0,
            mass_flows: vec![1e-5, 2e-5],
            take_up: TakeUpAxis::Diameter(vec![5e-5, 8e-5, 1e-4]),
            positions: None,
        };
        g.validate().unwrap();
        let c = g.candidates();
        assert_eq!(c.len(), 6);
        assert_eq!((c[4].i, c[4].j, c[4].take_up), (1, 1, 8e-5));
        let e = g.experiment(&Experiment::pmma7n_v0p53_p2(), &c[4]);
        assert_eq!(e.take_up, Some(TakeUp::Diameter(8e-5)));
        assert_eq!(e.mass_flow, 2e-5);
        let bad = CandidateGrid {
            take_up: TakeUpAxis::Velocity(vec![1.0, -2.0]),
            ..g
        };
        assert!(bad.validate().unwrap_err().contains("take-up speed -2"));
    }
}
#[cfg(test)]
mod rows_tests {
    use super::*;
    use std::sync::Mutex;

    fn grid(rows: usize, nt: usize) -> Vec<Candidate> {
        (0..rows * nt)
            .map(|k| Candidate {
                i: k / nt,
                j: k % nt,
                mass_flow: 1.0 + (k / nt) as f64,
                take_up: 1.0 + (k % nt) as f64,
            })
            .collect()
    }

    fn run(rows: usize, threads: usize) -> (Vec<(usize, usize)>, Vec<DesignEstimate>) {
        let all = grid(rows, 3);
        let seen = Mutex::new(Vec::new());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool of 2 or 3 threads");
        let out = pool.install(|| {
            rows_in_order(
                &all,
                3,
                |row| row.iter().map(|c| (c.i, c.j)).collect(),
                &|e| seen.lock().expect("not poisoned").push(*e),
            )
        });
        (out, seen.into_inner().expect("not poisoned"))
    }

    #[test]
    fn a_long_grid_is_estimated_once_from_its_first_rows_and_keeps_its_order() {
        let (out, estimates) = run(11, 2);
        let expected: Vec<(usize, usize)> = (0..33).map(|k| (k / 3, k % 3)).collect();
        assert_eq!(out, expected);
        assert_eq!(estimates.len(), 1);
        let e = estimates[0];
        assert_eq!(
            (e.candidates, e.rows, e.rows_measured, e.threads),
            (33, 11, 2, 2)
        );
        // 9 rows left on 2 threads: 5 rounds of the measured one
        assert!((e.remaining_s - 5.0 * e.measured_s).abs() <= 1e-12 * e.measured_s.max(1.0));
    }

    #[test]
    fn a_short_grid_runs_at_once_without_an_estimate() {
        let (out, estimates) = run(6, 3);
        assert_eq!(out.len(), 18);
        assert_eq!(out[17], (5, 2));
        assert!(estimates.is_empty());
    }
}
