//! The expression tree and its evaluation, generic over dual numbers.

use num_dual::DualNum;

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Func {
    Exp,
    Ln,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Sinh,
    Cosh,
    Tanh,
    Asin,
    Acos,
    Atan,
    Asinh,
    Acosh,
    Atanh,
    Abs,
}

impl Func {
    /// The function of a name of the expression language (`log` and `ln` are both the natural
    /// logarithm).
    pub(crate) fn from_name(name: &str) -> Option<Func> {
        Some(match name {
            "exp" => Func::Exp,
            "log" | "ln" => Func::Ln,
            "sqrt" => Func::Sqrt,
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "sinh" => Func::Sinh,
            "cosh" => Func::Cosh,
            "tanh" => Func::Tanh,
            "asin" => Func::Asin,
            "acos" => Func::Acos,
            "atan" => Func::Atan,
            "asinh" => Func::Asinh,
            "acosh" => Func::Acosh,
            "atanh" => Func::Atanh,
            "abs" => Func::Abs,
            _ => return None,
        })
    }

    fn apply<D: DualNum<Primitive = f64> + Copy>(self, a: D) -> D {
        match self {
            Func::Exp => a.exp(),
            Func::Ln => a.ln(),
            Func::Sqrt => a.sqrt(),
            Func::Sin => a.sin(),
            Func::Cos => a.cos(),
            Func::Tan => a.tan(),
            Func::Sinh => a.sinh(),
            Func::Cosh => a.cosh(),
            Func::Tanh => a.tanh(),
            Func::Asin => a.asin(),
            Func::Acos => a.acos(),
            Func::Atan => a.atan(),
            Func::Asinh => a.asinh(),
            Func::Acosh => a.acosh(),
            Func::Atanh => a.atanh(),
            // the derivative of the branch taken (sign(a)); at a = 0 the right one
            Func::Abs => {
                if a.re() < 0.0 {
                    -a
                } else {
                    a
                }
            }
        }
    }

    fn apply_f64(self, a: f64) -> f64 {
        self.apply(a)
    }
}

/// A binary arithmetic operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    /// `a^b` with both sides variable: `exp(b ln a)`.
    Pow,
    Atan2,
    Min,
    Max,
}

/// A comparison (value 1 when true, 0 when false; no derivative).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CmpOp {
    Lt,
    Le,
    Gt,
    Ge,
}

/// A node of an expression tree.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Node {
    Const(f64),
    X,
    Y(usize),
    Ya(usize),
    Yb(usize),
    P(usize),
    Neg(Box<Node>),
    Bin(BinOp, Box<Node>, Box<Node>),
    PowI(Box<Node>, i32),
    PowF(Box<Node>, f64),
    Call(Func, Box<Node>),
    Cmp(CmpOp, Box<Node>, Box<Node>),
    /// `where(c, a, b)`: `a` where `c` is nonzero, else `b` (each branch with its own exact
    /// derivative: piecewise smooth).
    Where(Box<Node>, Box<Node>, Box<Node>),
}

/// The values an expression reads: the position, the states (or the boundary states) and the
/// parameters.
pub(crate) struct Vars<'a, D> {
    pub x: f64,
    pub y: &'a [D],
    pub ya: &'a [D],
    pub yb: &'a [D],
    pub p: &'a [D],
}

impl Node {
    /// Evaluates the tree (recursively: no allocation).
    pub(crate) fn eval<D: DualNum<Primitive = f64> + Copy>(&self, v: &Vars<'_, D>) -> D {
        match self {
            Node::Const(c) => D::from(*c),
            Node::X => D::from(v.x),
            Node::Y(i) => v.y[*i],
            Node::Ya(i) => v.ya[*i],
            Node::Yb(i) => v.yb[*i],
            Node::P(i) => v.p[*i],
            Node::Neg(a) => -a.eval(v),
            Node::Bin(op, a, b) => {
                let (a, b) = (a.eval(v), b.eval(v));
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => a / b,
                    BinOp::Pow => a.powd(b),
                    BinOp::Atan2 => a.atan2(b),
                    BinOp::Min => {
                        if b.re() < a.re() {
                            b
                        } else {
                            a
                        }
                    }
                    BinOp::Max => {
                        if b.re() > a.re() {
                            b
                        } else {
                            a
                        }
                    }
                }
            }
            Node::PowI(a, k) => a.eval(v).powi(*k),
            Node::PowF(a, e) => a.eval(v).powf(*e),
            Node::Call(f, a) => f.apply(a.eval(v)),
            Node::Cmp(op, a, b) => {
                let (a, b) = (a.eval(v).re(), b.eval(v).re());
                let t = match op {
                    CmpOp::Lt => a < b,
                    CmpOp::Le => a <= b,
                    CmpOp::Gt => a > b,
                    CmpOp::Ge => a >= b,
                };
                D::from(if t { 1.0 } else { 0.0 })
            }
            Node::Where(c, a, b) => {
                if c.eval(v).re() != 0.0 {
                    a.eval(v)
                } else {
                    b.eval(v)
                }
            }
        }
    }

    /// Adds the inputs this tree reads, as indices into `[y, p]` for `n` states, to `deps`
    /// (unsorted, possibly repeated).
    pub(crate) fn inputs(&self, n: usize, deps: &mut Vec<usize>) {
        match self {
            Node::Y(i) => deps.push(*i),
            Node::P(i) => deps.push(n + i),
            Node::Const(_) | Node::X | Node::Ya(_) | Node::Yb(_) => {}
            Node::Neg(a) | Node::PowI(a, _) | Node::PowF(a, _) | Node::Call(_, a) => {
                a.inputs(n, deps)
            }
            Node::Bin(_, a, b) | Node::Cmp(_, a, b) => {
                a.inputs(n, deps);
                b.inputs(n, deps);
            }
            Node::Where(c, a, b) => {
                c.inputs(n, deps);
                a.inputs(n, deps);
                b.inputs(n, deps);
            }
        }
    }

    /// The node with constant subtrees folded into constants.
    pub(crate) fn fold(self) -> Node {
        let c = |n: &Node| match n {
            Node::Const(v) => Some(*v),
            _ => None,
        };
        match self {
            Node::Neg(a) => {
                let a = a.fold();
                match c(&a) {
                    Some(v) => Node::Const(-v),
                    None => Node::Neg(Box::new(a)),
                }
            }
            Node::Bin(op, a, b) => {
                let (a, b) = (a.fold(), b.fold());
                if let (Some(x), Some(y)) = (c(&a), c(&b)) {
                    let v = Vars::<f64> {
                        x: 0.0,
                        y: &[],
                        ya: &[],
                        yb: &[],
                        p: &[],
                    };
                    let folded =
                        Node::Bin(op, Box::new(Node::Const(x)), Box::new(Node::Const(y))).eval(&v);
                    // x^y with a negative x folds to NaN by exp(y ln x); powf knows better
                    let folded = if op == BinOp::Pow { x.powf(y) } else { folded };
                    return Node::Const(folded);
                }
                if op == BinOp::Pow {
                    if let Some(e) = c(&b) {
                        return if e == e.trunc() && e.abs() <= 64.0 {
                            Node::PowI(Box::new(a), e as i32)
                        } else {
                            Node::PowF(Box::new(a), e)
                        };
                    }
                }
                Node::Bin(op, Box::new(a), Box::new(b))
            }
            Node::PowI(a, k) => {
                let a = a.fold();
                match c(&a) {
                    Some(v) => Node::Const(v.powi(k)),
                    None => Node::PowI(Box::new(a), k),
                }
            }
            Node::PowF(a, e) => {
                let a = a.fold();
                match c(&a) {
                    Some(v) => Node::Const(v.powf(e)),
                    None => Node::PowF(Box::new(a), e),
                }
            }
            Node::Call(f, a) => {
                let a = a.fold();
                match c(&a) {
                    Some(v) => Node::Const(f.apply_f64(v)),
                    None => Node::Call(f, Box::new(a)),
                }
            }
            Node::Cmp(op, a, b) => Node::Cmp(op, Box::new(a.fold()), Box::new(b.fold())),
            Node::Where(cnd, a, b) => {
                let cnd = cnd.fold();
                let (a, b) = (a.fold(), b.fold());
                match &cnd {
                    Node::Const(v) => {
                        if *v != 0.0 {
                            a
                        } else {
                            b
                        }
                    }
                    _ => Node::Where(Box::new(cnd), Box::new(a), Box::new(b)),
                }
            }
            other => other,
        }
    }
}
