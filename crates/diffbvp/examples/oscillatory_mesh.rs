//! The mesh control on an oscillatory family with tens of periods (the problems of
//! benches/peers/scipy_oscillatory.py and tests/oscillatory_mesh.rs): for each problem, ε and
//! tolerance, whether the default options, scipy's refinement rule
//! (`MeshOptions::scipy()`) and `ResidualScale::Auto` converge, with their node counts and mesh
//! passes. `cargo run --release --example oscillatory_mesh` (`-- -v`: the solver's progress
//! lines of the default options).

use diffbvp::mesh::{linspace, MeshOptions};
use diffbvp::{solve, Guess, ResidualScale, SolveOptions};

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Oscillatory, OscillatoryKind};

fn main() {
    let verbose = std::env::args().any(|a| a == "-v");
    println!(
        "{:<9} {:>6} {:>6}  {:>22}  {:>22}  {:>22}",
        "problem", "eps", "tol", "default nodes/meshes", "scipy rule", "scale Auto"
    );
    for kind in [
        OscillatoryKind::Linear,
        OscillatoryKind::Pendulum,
        OscillatoryKind::Airy,
    ] {
        for eps in [0.01, 0.015, 0.02, 0.03, 0.04] {
            for tol in [1e-3, 1e-6] {
                let p = Oscillatory { kind, eps };
                let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
                let base = SolveOptions::with_tol(tol);
                let variants = [
                    SolveOptions {
                        verbose: u8::from(verbose),
                        ..base.clone()
                    },
                    SolveOptions {
                        mesh: MeshOptions::scipy(),
                        ..base.clone()
                    },
                    SolveOptions {
                        scale: ResidualScale::Auto,
                        ..base.clone()
                    },
                ];
                let cells: Vec<String> = variants
                    .iter()
                    .map(|o| match solve(&p, &[], &g, o) {
                        Ok(s) => format!(
                            "{} / {} y(.5)={:.5}",
                            s.nodes(),
                            s.stats.mesh_refinements + 1,
                            s.eval(0.5)[0]
                        ),
                        Err(e) => {
                            let m = e.to_string();
                            format!("FAIL {}", &m[..m.len().min(40)])
                        }
                    })
                    .collect();
                println!(
                    "{:<9} {:>6} {:>6}  {:>22}  {:>22}  {:>22}",
                    format!("{kind:?}"),
                    eps,
                    tol,
                    cells[0],
                    cells[1],
                    cells[2]
                );
            }
        }
    }
}
