//! The fiber tests in one binary (one link instead of 15): each file is a module
//! named after its former test binary; run one with `cargo test --release --test fiber NAME::`.

#[path = "../independent/mod.rs"]
mod independent;
#[path = "../probe/mod.rs"]
mod probe;

mod cold_start;
mod compare;
mod design;
mod design_noise;
mod discrimination;
mod effect_scale;
mod effects_families;
mod error_budget;
mod fiber_physics;
mod fiber_reference;
mod fiber_terms;
mod fit_warnings;
mod flow_curve_intervals;
mod independent_model;
mod landscape;
mod linear_solvers;
mod nested_fit;
mod newtonian_corner;
mod noisy_data;
mod rheometer_blocks;
mod rheometer_fit;
mod robust_statistics;
mod smoothing;
mod tolerance_schedule;
mod workflows;
