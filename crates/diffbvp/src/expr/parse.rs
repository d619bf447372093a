//! The parser of the expression language: a recursive descent over the characters of one
//! expression, with positions for the error messages.

use super::tree::{BinOp, CmpOp, Func, Node};
use super::ExprError;

/// Where an expression is used: what it may read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Place {
    /// A right-hand side: `x`, `y[i]`, parameters.
    Rhs,
    /// A boundary condition: `ya[i]`, `yb[i]`, parameters.
    Bc,
}

/// The symbols an expression may name.
pub(crate) struct Symbols<'a> {
    pub n: usize,
    /// Parameter names, index = position in `p`.
    pub params: &'a [String],
    /// Number of entries of `p` (unknowns and model parameters).
    pub np: usize,
    pub constants: &'a [(String, f64)],
}

impl Symbols<'_> {
    /// The symbols of a place, listed for an error message.
    fn known(&self, place: Place) -> String {
        let range = |name: &str, len: usize| match len {
            0 => String::new(),
            1 => format!("{name}[0]"),
            _ => format!("{name}[0]..{name}[{}]", len - 1),
        };
        let mut s = match place {
            Place::Rhs => format!("x, {}", range("y", self.n)),
            Place::Bc => format!("{}, {}", range("ya", self.n), range("yb", self.n)),
        };
        if self.np > 0 {
            s.push_str(", ");
            s.push_str(&range("p", self.np));
        }
        for name in self.params.iter().filter(|n| !n.is_empty()) {
            s.push_str(", ");
            s.push_str(name);
        }
        for (name, _) in self.constants {
            s.push_str(", ");
            s.push_str(name);
        }
        s.push_str(", pi");
        s
    }
}

pub(crate) struct Parser<'a> {
    src: &'a str,
    bytes: &'a [u8],
    pos: usize,
    what: &'a str,
    place: Place,
    sym: &'a Symbols<'a>,
}

const FUNCTIONS: &str = "exp, log (ln), sqrt, sin, cos, tan, sinh, cosh, tanh, asin, acos, atan, \
                         asinh, acosh, atanh, abs, atan2(a, b), min(a, b), max(a, b), pow(a, b), \
                         where(condition, a, b)";

impl<'a> Parser<'a> {
    pub(crate) fn new(src: &'a str, what: &'a str, place: Place, sym: &'a Symbols<'a>) -> Self {
        Parser {
            src,
            bytes: src.as_bytes(),
            pos: 0,
            what,
            place,
            sym,
        }
    }

    fn err(&self, pos: usize, message: String) -> ExprError {
        ExprError {
            what: self.what.to_string(),
            expression: self.src.to_string(),
            position: pos,
            message,
        }
    }

    fn skip_ws(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.bytes.get(self.pos).copied()
    }

    fn eat(&mut self, s: &str) -> bool {
        self.skip_ws();
        if self.src[self.pos..].starts_with(s) {
            self.pos += s.len();
            true
        } else {
            false
        }
    }

    /// Consumes the token `s`, or fails naming what was found instead (an error, never a panic).
    fn require(&mut self, s: &str) -> Result<(), ExprError> {
        if self.eat(s) {
            Ok(())
        } else {
            let found = self.found();
            Err(self.err(self.pos, format!("expected '{s}', found {found}")))
        }
    }

    fn found(&self) -> String {
        match self.src[self.pos..].chars().next() {
            Some(c) => format!("'{c}'"),
            None => "the end of the expression".into(),
        }
    }

    /// The whole expression.
    pub(crate) fn parse(mut self) -> Result<Node, ExprError> {
        if self.peek().is_none() {
            return Err(self.err(0, "the expression is empty".into()));
        }
        let node = self.comparison()?;
        if self.peek().is_some() {
            let found = self.found();
            return Err(self.err(
                self.pos,
                format!("unexpected {found} after a complete expression"),
            ));
        }
        Ok(node.fold())
    }

    fn comparison(&mut self) -> Result<Node, ExprError> {
        let a = self.sum()?;
        let op = if self.eat("<=") {
            CmpOp::Le
        } else if self.eat(">=") {
            CmpOp::Ge
        } else if self.eat("<") {
            CmpOp::Lt
        } else if self.eat(">") {
            CmpOp::Gt
        } else {
            return Ok(a);
        };
        let b = self.sum()?;
        Ok(Node::Cmp(op, Box::new(a), Box::new(b)))
    }

    fn sum(&mut self) -> Result<Node, ExprError> {
        let mut a = self.term()?;
        loop {
            let op = match self.peek() {
                Some(b'+') => BinOp::Add,
                Some(b'-') => BinOp::Sub,
                _ => return Ok(a),
            };
            self.pos += 1;
            let b = self.term()?;
            a = Node::Bin(op, Box::new(a), Box::new(b));
        }
    }

    fn term(&mut self) -> Result<Node, ExprError> {
        let mut a = self.unary()?;
        loop {
            self.skip_ws();
            let op = if self.src[self.pos..].starts_with("**") {
                return Ok(a);
            } else {
                match self.peek() {
                    Some(b'*') => BinOp::Mul,
                    Some(b'/') => BinOp::Div,
                    _ => return Ok(a),
                }
            };
            self.pos += 1;
            let b = self.unary()?;
            a = Node::Bin(op, Box::new(a), Box::new(b));
        }
    }

    fn unary(&mut self) -> Result<Node, ExprError> {
        match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Ok(Node::Neg(Box::new(self.unary()?)))
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, ExprError> {
        let a = self.atom()?;
        if self.eat("**") || self.eat("^") {
            // right-associative, and -x**2 = -(x**2) as in Python: the exponent is a unary
            let b = self.unary()?;
            return Ok(Node::Bin(BinOp::Pow, Box::new(a), Box::new(b)));
        }
        Ok(a)
    }

    fn number(&mut self) -> Result<Node, ExprError> {
        let start = self.pos;
        let b = self.bytes;
        let mut i = self.pos;
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
            i += 1;
        }
        if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
            let mut j = i + 1;
            if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                j += 1;
            }
            if j < b.len() && b[j].is_ascii_digit() {
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                i = j;
            }
        }
        let text = &self.src[start..i];
        match text.parse::<f64>() {
            Ok(v) => {
                self.pos = i;
                Ok(Node::Const(v))
            }
            Err(_) => Err(self.err(start, format!("malformed number '{text}'"))),
        }
    }

    fn ident(&mut self) -> &'a str {
        let start = self.pos;
        let b = self.bytes;
        while self.pos < b.len() && (b[self.pos].is_ascii_alphanumeric() || b[self.pos] == b'_') {
            self.pos += 1;
        }
        &self.src[start..self.pos]
    }

    fn index(&mut self, name: &str, start: usize, len: usize) -> Result<usize, ExprError> {
        self.require("[")?;
        self.skip_ws();
        let istart = self.pos;
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_digit() {
            self.pos += 1;
        }
        let text = &self.src[istart..self.pos];
        let i: usize = text.parse().map_err(|_| {
            self.err(
                istart,
                format!("{name}[...] needs a non-negative integer index"),
            )
        })?;
        self.require("]")?;
        if i >= len {
            return Err(self.err(
                start,
                format!(
                    "index out of range: {name}[{i}], but {name} has {len} entr{} ({name}[0]..{name}[{}])",
                    if len == 1 { "y" } else { "ies" },
                    len.saturating_sub(1)
                ),
            ));
        }
        Ok(i)
    }

    fn args(&mut self, name: &str, start: usize, count: usize) -> Result<Vec<Node>, ExprError> {
        self.require("(")?;
        let mut out = vec![self.comparison()?];
        while self.eat(",") {
            out.push(self.comparison()?);
        }
        self.require(")")?;
        if out.len() != count {
            return Err(self.err(
                start,
                format!(
                    "{name}() takes {count} argument{}, got {}",
                    if count == 1 { "" } else { "s" },
                    out.len()
                ),
            ));
        }
        Ok(out)
    }

    fn atom(&mut self) -> Result<Node, ExprError> {
        let start = match self.peek() {
            None => {
                return Err(self.err(
                    self.pos,
                    "the expression ends where a value is expected".into(),
                ))
            }
            Some(_) => self.pos,
        };
        let c = self.bytes[start];
        if c == b'(' {
            self.pos += 1;
            let e = self.comparison()?;
            self.require(")")?;
            return Ok(e);
        }
        if c.is_ascii_digit() || c == b'.' {
            return self.number();
        }
        if !(c.is_ascii_alphabetic() || c == b'_') {
            let found = self.found();
            return Err(self.err(
                start,
                format!("unexpected {found} where a value is expected"),
            ));
        }
        let name = self.ident();
        let is_call = self.peek() == Some(b'(');
        if is_call {
            return self.call(name, start);
        }
        self.symbol(name, start)
    }

    /// A call of the function `name` (at `start`): its arguments, checked against its arity.
    fn call(&mut self, name: &'a str, start: usize) -> Result<Node, ExprError> {
        if let Some(f) = Func::from_name(name) {
            let mut a = self.args(name, start, 1)?;
            return Ok(Node::Call(f, Box::new(a.remove(0))));
        }
        let bin = match name {
            "atan2" => Some(BinOp::Atan2),
            "min" | "Min" => Some(BinOp::Min),
            "max" | "Max" => Some(BinOp::Max),
            "pow" | "Pow" => Some(BinOp::Pow),
            _ => None,
        };
        if let Some(op) = bin {
            let a = self.args(name, start, 2)?;
            let count = a.len();
            let Ok([a, b]) = <[Node; 2]>::try_from(a) else {
                return Err(self.err(start, format!("{name} takes 2 arguments, got {count}")));
            };
            return Ok(Node::Bin(op, Box::new(a), Box::new(b)));
        }
        if name == "where" {
            let a = self.args(name, start, 3)?;
            let count = a.len();
            let Ok([c, t, b]) = <[Node; 3]>::try_from(a) else {
                return Err(self.err(start, format!("where takes 3 arguments, got {count}")));
            };
            return Ok(Node::Where(Box::new(c), Box::new(t), Box::new(b)));
        }
        Err(self.err(
            start,
            format!("unknown function '{name}' (known: {FUNCTIONS})"),
        ))
    }

    /// The symbol `name` (at `start`) that is not a call: a variable of the place, a parameter,
    /// a constant, or an error naming what is known here.
    fn symbol(&mut self, name: &'a str, start: usize) -> Result<Node, ExprError> {
        let (n, np) = (self.sym.n, self.sym.np);
        match (name, self.place) {
            ("x", Place::Rhs) => return Ok(Node::X),
            ("y", Place::Rhs) => return Ok(Node::Y(self.index("y", start, n)?)),
            ("ya", Place::Bc) => return Ok(Node::Ya(self.index("ya", start, n)?)),
            ("yb", Place::Bc) => return Ok(Node::Yb(self.index("yb", start, n)?)),
            ("x" | "y", Place::Bc) => {
                return Err(self.err(
                    start,
                    format!(
                        "'{name}' is not available in a boundary condition (use ya[i] and yb[i], \
                         the states at the two ends)"
                    ),
                ))
            }
            ("ya" | "yb", Place::Rhs) => {
                return Err(self.err(
                    start,
                    format!(
                        "'{name}' is not available in a right-hand side (use x and y[i]; ya and \
                         yb are for boundary conditions)"
                    ),
                ))
            }
            ("p", _) => return Ok(Node::P(self.index("p", start, np)?)),
            ("pi", _) => return Ok(Node::Const(std::f64::consts::PI)),
            _ => {}
        }
        if let Some(i) = self.sym.params.iter().position(|s| s == name) {
            return Ok(Node::P(i));
        }
        if let Some((_, v)) = self.sym.constants.iter().find(|(s, _)| s == name) {
            return Ok(Node::Const(*v));
        }
        if Func::from_name(name).is_some() || matches!(name, "atan2" | "min" | "max" | "where") {
            return Err(self.err(
                start,
                format!("'{name}' is a function: call it as {name}(...)"),
            ));
        }
        Err(self.err(
            start,
            format!(
                "unknown symbol '{name}' (known here: {})",
                self.sym.known(self.place)
            ),
        ))
    }
}
