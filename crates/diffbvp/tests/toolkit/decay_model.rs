//! `y = a e^{−b x}`, the exponential decay the least-squares tests fit: its residuals
//! `a e^{−b x} − y` and their Jacobian (row-major, columns `a` and `b`).

/// The residuals at `p = (a, b)` of the data `(x, y)`, each plus `extra(i)` (a model error the
/// test adds; 0 for the exact model), and the Jacobian of the exact model.
pub fn residuals(
    x: &[f64],
    y: &[f64],
    p: &[f64],
    extra: impl Fn(usize) -> f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut r = Vec::with_capacity(x.len());
    let mut j = Vec::with_capacity(2 * x.len());
    for (i, (&x, &y)) in x.iter().zip(y).enumerate() {
        let e = (-p[1] * x).exp();
        r.push(p[0] * e - y + extra(i));
        j.push(e);
        j.push(-p[0] * x * e);
    }
    (r, j)
}
