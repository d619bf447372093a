//! Object-safe dispatch of functions written generically over dual numbers.
//!
//! Rust closures cannot be generic and trait objects cannot have generic methods, yet a user
//! who plugs a function into a model (an extra force, a heat flux, ...) wants to write it once,
//! generically over [`DualNum`], so that the solver can differentiate it exactly. This module
//! bridges the two:
//!
//! 1. the user implements [`DualScalarFn`] (one generic method);
//! 2. a blanket impl makes every such type a [`DynDualScalarFn`], an object-safe trait with one
//!    method per concrete number type the toolkit uses (`f64`, [`Dual64`], `DualSVec64<1|2|4|8>`,
//!    [`DenseDual64<1|2|4|8>`](crate::dense_dual::DenseDual64));
//! 3. inside generic code, [`eval_dyn`] calls a `&dyn DynDualScalarFn` with the number type `D`
//!    at hand, selecting the matching method by `TypeId` (via [`std::any::Any`] downcasts; no
//!    `unsafe`).
//!
//! A number type outside that list yields `NaN`, which the solver reports as a non-finite
//! value rather than silently dropping derivatives.
//!
//! ```
//! use diffbvp::dyn_dual::{eval_dyn, DualScalarFn, DynDualScalarFn};
//! use diffbvp::DualNum;
//! use num_dual::{Dual64, DualNum as _};
//! struct Square;
//! impl DualScalarFn for Square {
//!     fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, args: &[D]) -> D {
//!         args[0] * args[0]
//!     }
//! }
//! let f: Box<dyn DynDualScalarFn> = Box::new(Square);
//! let v = eval_dyn(f.as_ref(), 0.0, &[Dual64::from_re(3.0).derivative()]);
//! assert_eq!((v.re, v.eps), (9.0, 6.0));
//! ```

use crate::dense_dual::DenseDual64;
use num_dual::{Dual64, DualNum, DualSVec64};
use std::any::Any;

/// Largest number of arguments [`eval_dyn`] forwards.
pub const MAX_ARGS: usize = 16;

/// A scalar function `g(x, args)` of a position `x` and a slice of arguments, written once
/// generically over the number type.
pub trait DualScalarFn {
    /// Evaluates the function.
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, args: &[D]) -> D;
}

/// Object-safe form of [`DualScalarFn`]: one method per supported number type. Implemented for
/// every `DualScalarFn + Send + Sync` by a blanket impl; call it through [`eval_dyn`].
pub trait DynDualScalarFn: Send + Sync {
    /// `f64` values.
    fn eval_f64(&self, x: f64, args: &[f64]) -> f64;
    /// Scalar first derivatives.
    fn eval_dual64(&self, x: f64, args: &[Dual64]) -> Dual64;
    /// One directional derivative.
    fn eval_dual1(&self, x: f64, args: &[DualSVec64<1>]) -> DualSVec64<1>;
    /// Two directional derivatives.
    fn eval_dual2(&self, x: f64, args: &[DualSVec64<2>]) -> DualSVec64<2>;
    /// Four directional derivatives.
    fn eval_dual4(&self, x: f64, args: &[DualSVec64<4>]) -> DualSVec64<4>;
    /// Eight directional derivatives.
    fn eval_dual8(&self, x: f64, args: &[DualSVec64<8>]) -> DualSVec64<8>;
    /// One directional derivative, always stored (the solver's Jacobians).
    fn eval_dense1(&self, x: f64, args: &[DenseDual64<1>]) -> DenseDual64<1>;
    /// Two directional derivatives, always stored.
    fn eval_dense2(&self, x: f64, args: &[DenseDual64<2>]) -> DenseDual64<2>;
    /// Four directional derivatives, always stored.
    fn eval_dense4(&self, x: f64, args: &[DenseDual64<4>]) -> DenseDual64<4>;
    /// Eight directional derivatives, always stored.
    fn eval_dense8(&self, x: f64, args: &[DenseDual64<8>]) -> DenseDual64<8>;
}

impl<T: DualScalarFn + Send + Sync> DynDualScalarFn for T {
    fn eval_f64(&self, x: f64, args: &[f64]) -> f64 {
        self.eval(x, args)
    }
    fn eval_dual64(&self, x: f64, args: &[Dual64]) -> Dual64 {
        self.eval(x, args)
    }
    fn eval_dual1(&self, x: f64, args: &[DualSVec64<1>]) -> DualSVec64<1> {
        self.eval(x, args)
    }
    fn eval_dual2(&self, x: f64, args: &[DualSVec64<2>]) -> DualSVec64<2> {
        self.eval(x, args)
    }
    fn eval_dual4(&self, x: f64, args: &[DualSVec64<4>]) -> DualSVec64<4> {
        self.eval(x, args)
    }
    fn eval_dual8(&self, x: f64, args: &[DualSVec64<8>]) -> DualSVec64<8> {
        self.eval(x, args)
    }
    fn eval_dense1(&self, x: f64, args: &[DenseDual64<1>]) -> DenseDual64<1> {
        self.eval(x, args)
    }
    fn eval_dense2(&self, x: f64, args: &[DenseDual64<2>]) -> DenseDual64<2> {
        self.eval(x, args)
    }
    fn eval_dense4(&self, x: f64, args: &[DenseDual64<4>]) -> DenseDual64<4> {
        self.eval(x, args)
    }
    fn eval_dense8(&self, x: f64, args: &[DenseDual64<8>]) -> DenseDual64<8> {
        self.eval(x, args)
    }
}

/// Calls `f` with the number type `D` of the caller. Supported: `f64`, [`Dual64`],
/// `DualSVec64<1|2|4|8>`, [`DenseDual64<1|2|4|8>`](DenseDual64) (the solver's); any other type, or more than [`MAX_ARGS`] arguments, gives `NaN`.
pub fn eval_dyn<D: DualNum<Primitive = f64> + Copy>(
    f: &dyn DynDualScalarFn,
    x: f64,
    args: &[D],
) -> D {
    let k = args.len();
    if k > MAX_ARGS {
        return D::from(f64::NAN);
    }
    let mut buf = [D::zero(); MAX_ARGS];
    buf[..k].copy_from_slice(args);
    let any: &dyn Any = &buf;
    macro_rules! dispatch {
        ($t:ty, $m:ident) => {
            if let Some(a) = any.downcast_ref::<[$t; MAX_ARGS]>() {
                let r = f.$m(x, &a[..k]);
                if let Some(r) = (&r as &dyn Any).downcast_ref::<D>() {
                    return *r;
                }
            }
        };
    }
    dispatch!(f64, eval_f64);
    dispatch!(DenseDual64<4>, eval_dense4);
    dispatch!(DenseDual64<8>, eval_dense8);
    dispatch!(DenseDual64<1>, eval_dense1);
    dispatch!(DenseDual64<2>, eval_dense2);
    dispatch!(DualSVec64<4>, eval_dual4);
    dispatch!(DualSVec64<8>, eval_dual8);
    dispatch!(DualSVec64<1>, eval_dual1);
    dispatch!(DualSVec64<2>, eval_dual2);
    dispatch!(Dual64, eval_dual64);
    D::from(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Prod;
    impl DualScalarFn for Prod {
        fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, args: &[D]) -> D {
            args[0] * args[1] * x
        }
    }

    #[test]
    fn dispatch_matches_generic_call_for_every_type() {
        let f: &dyn DynDualScalarFn = &Prod;
        assert_eq!(eval_dyn(f, 2.0, &[3.0, 4.0]), 24.0);
        let a = DualSVec64::<2>::from_re(3.0).derivative(0);
        let b = DualSVec64::<2>::from_re(4.0).derivative(1);
        let r = eval_dyn(f, 2.0, &[a, b]);
        let g = Prod.eval(2.0, &[a, b]);
        assert_eq!(r.re, 24.0);
        assert_eq!(r.eps, g.eps);
        let r = eval_dyn(
            f,
            2.0,
            &[Dual64::from_re(3.0).derivative(), Dual64::from_re(4.0)],
        );
        assert_eq!((r.re, r.eps), (24.0, 8.0));
        // the solver's number types reach the function, not the NaN fallback
        let a = DenseDual64::<4>::from_re(3.0).derivative(0);
        let b = DenseDual64::<4>::from_re(4.0).derivative(3);
        let r = eval_dyn(f, 2.0, &[a, b]);
        assert_eq!((r.re, r.slopes()), (24.0, [8.0, 0.0, 0.0, 6.0]));
        let a = DenseDual64::<8>::from_re(3.0).derivative(7);
        let r = eval_dyn(f, 2.0, &[a, a]);
        assert_eq!(r.slopes()[7], 12.0);
        let r = eval_dyn(f, 2.0, &[DenseDual64::<1>::from_re(3.0).derivative(0); 2]);
        assert_eq!(r.slopes(), [12.0]);
        let r = eval_dyn(f, 2.0, &[DenseDual64::<2>::from_re(3.0).derivative(1); 2]);
        assert_eq!(r.slopes(), [0.0, 12.0]);
    }

    #[test]
    fn unsupported_type_gives_nan() {
        use num_dual::Dual;
        let f: &dyn DynDualScalarFn = &Prod;
        let a = Dual::new(Dual64::from_re(1.0), Dual64::from_re(0.0));
        assert!(eval_dyn(f, 1.0, &[a, a]).re.re.is_nan());
    }
}
