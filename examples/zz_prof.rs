use diffbvp::mesh::linspace;
use diffbvp::{Bvp, Guess, SolveOptions, Solver};
use num_dual::DualNum;
struct Shock;
impl Bvp for Shock {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        let (pi, eps) = (std::f64::consts::PI, 1e-3);
        f[0] = y[1];
        f[1] = (y[1] * (-x) - eps * pi * pi * (pi * x).cos() - pi * x * (pi * x).sin()) / eps;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] + 2.0;
        r[1] = yb[0];
    }
}
struct CoupledTroesch;
impl Bvp for CoupledTroesch {
    fn dim(&self) -> usize {
        4
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = (y[0] * p[0]).sinh() * p[0] + y[2];
        f[2] = y[3];
        f[3] = y[2] - y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - p[1];
        r[2] = ya[2];
        r[3] = yb[2];
    }
}
fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let mut o = SolveOptions::with_tol(1e-6);
    if which == "v" {
        o.verbose = 1;
    }
    if std::env::var("LAZY").is_ok() {
        o.factor_at_solution = false;
    }
    let t = std::time::Instant::now();
    let reps = if which == "v" { 1 } else { 2000 };
    for _ in 0..reps {
        let s = diffbvp::solve(
            &Shock,
            &[],
            &Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]),
            &o,
        )
        .unwrap();
        std::hint::black_box(s);
    }
    eprintln!("shock {:?}", t.elapsed() / reps);
    let t = std::time::Instant::now();
    for _ in 0..reps {
        let g = Guess::from_fn(linspace(0.0, 1.0, 11), 4, |x, y| {
            y[0] = x;
            y[1] = 1.0;
            y[2] = 0.0;
            y[3] = 0.0;
        });
        let s = diffbvp::solve(&CoupledTroesch, &[5.0, 1.0], &g, &o).unwrap();
        if which == "v" {
            eprintln!("{:?}", s.stats);
        }
        std::hint::black_box(s);
    }
    eprintln!("troesch {:?}", t.elapsed() / reps);
    let _ = Solver::new(&Shock, o);
}
