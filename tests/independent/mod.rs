//! An independent test-data generator for the missing-physics diagnosis (issue 11): its own
//! implementation of the paper's stationary fiber-spinning model with hidden effects written
//! directly into the balances ([`model`]), solved with the crate's generic collocation solver
//! ([`solve`]), its own noise ([`rng`]) and data sets written in the project's TOML + CSV
//! input format ([`dataset`], [`scenarios`]); a concentrated line force ([`line_force`]) as a
//! hidden effect no candidate has. Nothing here calls `rheometer`.
#![allow(dead_code)]

pub mod dataset;
pub mod line_force;
pub mod model;
pub mod rng;
pub mod scenarios;
pub mod solve;
