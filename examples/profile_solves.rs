//! Repeats one benchmark solve for instruction counting (`perf stat -e instructions` or
//! callgrind): `cargo run --release --example profile_solves --
//! shock|troesch|bratu|fiber|fiber_warm|fiber_candidates [reps]`. Prints the nodes, meshes,
//! Newton iterations and factorisations of one solve. `fiber` is the cold start of
//! `benches/fiber.rs` (`fiber_cold_v0p53_p2_tol1e-6`), `fiber_warm` its warm re-solve from the
//! tangent predictor of a nearby linearised solution (`fiber_warm_tangent_v0p53_p2_tol1e-6`,
//! what a fit does), `fiber_candidates` the fiber with every built-in candidate effect carried
//! at neutral strength, as `diagnose` solves it.

use diffbvp::mesh::linspace;
use diffbvp::sensitivity::Sensitivities;
use diffbvp::{solve, Guess, Solution, SolveOptions};
use rheometer::model::simulate_from;
use rheometer::model::{Air, Experiment, Material};
use rheometer::model::{Effect, ModelSpec};
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::Physics, model::SimulateOptions,
};
use std::hint::black_box;

#[path = "../crates/diffbvp/tests/common/mod.rs"]
mod common;
use common::{Bratu, CoupledTroesch, Shock};

fn stats(name: &str, s: &Solution) {
    let st = &s.stats;
    // a fingerprint of the values (changes with any bit of the solution)
    let bits = s.y.iter().fold(0u64, |a, v| a.rotate_left(5) ^ v.to_bits());
    println!("{name}: fingerprint {bits:016x}");
    println!(
        "{name}: {} nodes, {} meshes, {} Newton iterations, {} factorisations, {} rhs + {} dual evaluations",
        s.nodes(),
        st.mesh_refinements + 1,
        st.newton_iterations,
        st.jacobian_factorizations,
        st.rhs_evaluations,
        st.rhs_dual_evaluations
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("shock", String::as_str);
    let reps: usize = args.get(2).map_or(Ok(1), |s| s.parse())?;
    let mut opts = SolveOptions::with_tol(1e-6);
    // PROFILE_VERBOSE=1 or 2: the solver's progress lines (stderr)
    // PROFILE_MESH="max_pieces,max_growth,smooth,target": other mesh options (experiments)
    if let Ok(v) = std::env::var("PROFILE_MESH") {
        let f: Vec<&str> = v.split(',').collect();
        if f.len() == 4 {
            opts.mesh.max_pieces = f[0].parse()?;
            opts.mesh.max_growth = f[1].parse()?;
            opts.mesh.smooth = f[2] == "1";
            opts.mesh.target = f[3].parse()?;
        }
    }
    opts.verbose = std::env::var("PROFILE_VERBOSE").map_or(Ok(0), |v| v.parse())?;
    match which {
        "shock" => {
            let g = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
            let p = Shock { eps: 1e-3 };
            stats(which, &solve(&p, &[], &g, &opts)?);
            for _ in 0..reps {
                black_box(solve(&p, &[], black_box(&g), &opts)?);
            }
        }
        "troesch" => {
            let g = Guess::from_fn(linspace(0.0, 1.0, 11), 4, |x, y| {
                y[0] = x;
                y[1] = 1.0;
                y[2] = 0.0;
                y[3] = 0.0;
            });
            stats(which, &solve(&CoupledTroesch, &[5.0, 1.0], &g, &opts)?);
            for _ in 0..reps {
                black_box(solve(&CoupledTroesch, &[5.0, 1.0], black_box(&g), &opts)?);
            }
        }
        "bratu" => {
            let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
            let p = Bratu { k: 1.0 };
            stats(which, &solve(&p, &[], &g, &opts)?);
            for _ in 0..reps {
                black_box(solve(&p, &[], black_box(&g), &opts)?);
            }
        }
        "fiber" | "fiber_warm" | "fiber_candidates" => {
            let exp = Experiment::pmma7n_v0p53_p2();
            let physics = match which {
                "fiber" | "fiber_warm" => Physics::paper(),
                _ => ModelSpec::default()
                    .with_candidates(&Effect::builtin())
                    .physics()?,
            };
            let m = FiberModel::new(
                &Material::pmma7n(),
                &Air::paper(),
                &exp,
                CarreauLike::new(),
                physics,
            )?;
            let fopts = SimulateOptions::with_tol(1e-6);
            if which == "fiber_warm" {
                let near = simulate(&m, &[0.79, 11.70], &fopts)?;
                Sensitivities::compute(&m, &near.solution)?;
                let s = simulate_from(&m, &[0.8, 11.71], &near, &fopts)?;
                stats(which, &s.solution);
                for _ in 0..reps {
                    black_box(simulate_from(&m, black_box(&[0.8, 11.71]), &near, &fopts)?);
                }
                return Ok(());
            }
            let s = simulate(&m, &[0.8, 11.71], &fopts)?;
            stats(which, &s.solution);
            for _ in 0..reps {
                black_box(simulate(&m, black_box(&[0.8, 11.71]), &fopts)?);
            }
        }
        other => return Err(format!("unknown problem {other}").into()),
    }
    Ok(())
}
