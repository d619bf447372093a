//! The book's tutorial examples, run as tests: each example's `run()` is compiled here from the
//! example's own source file, and the claims the book makes about its output are checked.

#[path = "../examples/tutorial_custom_term.rs"]
mod tutorial_custom_term;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn custom_term_matches_builtin_radiation() {
    let s = tutorial_custom_term::run().unwrap();
    let [paper, mine, builtin] = &s.diameters;
    let [t_paper, t_mine, t_builtin] = &s.temperatures;
    for i in 0..paper.len() {
        // the user's SI term and the built-in term are the same physics: same solution up to
        // round-off (measured: identical)
        assert!(rel(mine[i], builtin[i]) < 1e-12, "d at {i}");
        assert!(rel(t_mine[i], t_builtin[i]) < 1e-12, "T at {i}");
        assert!(s.user_term[i] < 0.0, "radiation cools");
    }
    // radiation cools the fiber: colder below the nozzle than without it
    assert!(
        t_mine[3] < t_paper[3] - 1.0,
        "{} vs {}",
        t_mine[3],
        t_paper[3]
    );
    // near the nozzle it is of the order of convection (model-closure.md)
    let ratio = s.user_term[0] / s.convection[0];
    assert!(ratio > 0.3 && ratio < 3.0, "radiation/convection = {ratio}");
}
