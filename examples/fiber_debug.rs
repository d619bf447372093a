use diffbvp::fiber::setup::{Air, Experiment, Inlet, Material, TakeUp};
use diffbvp::fiber::simulate::simulate_from;
use diffbvp::fiber::{simulate, CarreauLike, FiberModel, Physics, SimulateOptions};
use std::time::Instant;
fn main() {
    let exp = Experiment { name: "v0p53_p2".into(), mass_flow: 3.08e-5, inlet: Inlet::Diameter(1.134e-3),
        inlet_temperature: 513.15, air_temperature: 293.15, spinline_length: 0.51, take_up: Some(TakeUp::Diameter(9e-5)) };
    let m = FiberModel::new(&Material::pmma7n(), &Air::paper(), &exp, CarreauLike::new(), Physics::paper()).unwrap();
    let opts = SimulateOptions::with_tol(1e-6);
    let near = simulate(&m, &[0.79, 11.70], &opts).unwrap();
    eprintln!("---- warm"); if std::env::var("LOOP").is_ok() { for _ in 0..2000 { simulate_from(&m, &[0.8, 11.71], &near, &opts).unwrap(); } return; }
    let t = Instant::now();
    let w = simulate_from(&m, &[0.8, 11.71], &near, &opts).unwrap();
    eprintln!("warm {:?} {:?}", t.elapsed(), w.solution.stats);
    let t = Instant::now();
    for _ in 0..100 { simulate_from(&m, &[0.8, 11.71], &near, &opts).unwrap(); }
    eprintln!("warm x100 {:?}", t.elapsed());
}
