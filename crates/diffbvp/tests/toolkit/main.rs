//! The toolkit tests in one binary (one link instead of 9): each file is a module
//! named after its former test binary; run one with `cargo test --release --test toolkit NAME::`.

#[path = "../common/mod.rs"]
mod common;

mod block_least_squares;
mod continuation;
mod core_accuracy;
mod decay_model;
mod growth_limit;
mod integral_functionals;
mod kept_newton_matrix;
mod least_squares;
mod library_contracts;
mod library_edges;
mod linear_solvers;
mod mesh_passes;
mod oscillatory_mesh;
mod partial_linearisation;
mod problem_classes;
mod relative_offset;
mod scipy_problems;
mod sensitivities;
mod x_scale;
