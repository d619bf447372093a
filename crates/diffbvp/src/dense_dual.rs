//! Dual numbers whose derivative part is always present: the number type of the solver's
//! Jacobians.
//!
//! num-dual's vector duals (`DualSVec64<W>`) store their derivative part as an `Option` so that
//! constants cost nothing; every operation then branches on it, and the compiler moves the
//! tagged values around (`memmove`) where it cannot keep them in registers. In a Jacobian pass
//! almost every intermediate depends on a seeded input, so the `None` case buys little.
//! [`DenseDual`] keeps `W` slopes unconditionally (a plain static vector, zero for constants):
//! straight-line arithmetic the compiler vectorises. The derivative rules themselves are
//! num-dual's (its exported macros), so the two types give the same numbers.
//!
//! ```
//! use diffbvp::dense_dual::DenseDual64;
//! use diffbvp::DualNum;
//! let x = DenseDual64::<2>::from_re(3.0).derivative(0);
//! let y = DenseDual64::<2>::from_re(4.0).derivative(1);
//! let r = (x * x + y * y).sqrt();
//! assert_eq!(r.re, 5.0);
//! let [a, b] = r.slopes();
//! assert!((a - 0.6).abs() < 1e-15 && (b - 0.8).abs() < 1e-15);
//! ```

use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, Dim, OVector, U1};
use num_dual::{
    chain_rule, first, forward_binop, impl_add_sub_rem, impl_assign_ops, impl_comparisons,
    impl_derivatives, impl_dual, impl_dual_struct, impl_first_derivatives, impl_float_const,
    impl_from_f, impl_from_primitive, impl_inv, impl_iterator, impl_neg, impl_num, impl_scalar_op,
    impl_signed, impl_zero_one, second, third, zeroth, DualNum, DualNumFloat, DualStruct,
};
use num_traits::{FloatConst, FromPrimitive, Inv, Num, One, Signed, Zero};
use std::fmt;
use std::iter::{Product, Sum};
use std::ops::{
    Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Rem, RemAssign, Sub, SubAssign,
};

/// The derivative part of a [`DenseDual`]: `D` slopes, always stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Slopes<T: DualNum, D: Dim>(pub OVector<T, D>)
where
    DefaultAllocator: Allocator<D>;

impl<T: DualNum + Copy, const N: usize> Copy for Slopes<T, Const<N>> {}

impl<T: DualNum, D: Dim> Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// All slopes zero. `D` is meant to be a static size (`Const<W>`); a dynamic size has no
    /// length to take and gives no slopes.
    #[inline]
    fn zeros() -> Self {
        let n = D::try_to_usize().unwrap_or(0);
        Self(OVector::from_element_generic(
            D::from_usize(n),
            U1,
            T::zero(),
        ))
    }

    /// `self * a + other * b`, slope by slope.
    #[inline]
    fn combine(&self, a: &T, other: &Self, b: &T) -> Self {
        let mut out = self.clone();
        for (o, v) in out.0.iter_mut().zip(other.0.iter()) {
            *o = o.clone() * a + v.clone() * b;
        }
        out
    }
}

impl<T: DualNum, D: Dim> Add<&Slopes<T, D>> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = Self;
    #[inline]
    fn add(mut self, other: &Self) -> Self {
        self += other.clone();
        self
    }
}

impl<T: DualNum, D: Dim> Sub<&Slopes<T, D>> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = Self;
    #[inline]
    fn sub(mut self, other: &Self) -> Self {
        self -= other.clone();
        self
    }
}

impl<T: DualNum, D: Dim> AddAssign for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn add_assign(&mut self, other: Self) {
        for (o, v) in self.0.iter_mut().zip(other.0.iter()) {
            *o += v.clone();
        }
    }
}

impl<T: DualNum, D: Dim> SubAssign for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn sub_assign(&mut self, other: Self) {
        for (o, v) in self.0.iter_mut().zip(other.0.iter()) {
            *o -= v.clone();
        }
    }
}

impl<T: DualNum, D: Dim> Neg for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = Self;
    #[inline]
    fn neg(mut self) -> Self {
        for o in self.0.iter_mut() {
            *o = -o.clone();
        }
        self
    }
}

impl<T: DualNum, D: Dim> MulAssign<T> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn mul_assign(&mut self, f: T) {
        for o in self.0.iter_mut() {
            *o *= f.clone();
        }
    }
}

impl<T: DualNum, D: Dim> DivAssign<T> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn div_assign(&mut self, f: T) {
        for o in self.0.iter_mut() {
            *o /= f.clone();
        }
    }
}

impl<T: DualNum, D: Dim> Mul<T> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = Self;
    #[inline]
    fn mul(mut self, f: T) -> Self {
        self *= f;
        self
    }
}

impl<T: DualNum, D: Dim> Mul<&T> for Slopes<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = Self;
    #[inline]
    fn mul(mut self, f: &T) -> Self {
        self *= f.clone();
        self
    }
}

/// A forward-mode dual number with `D` directional derivatives that are always stored (see the
/// [module documentation](self)). Use [`DenseDual64<W>`].
#[derive(Clone, Debug)]
pub struct DenseDual<T: DualNum, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Real part.
    pub re: T,
    /// Derivative part.
    pub eps: Slopes<T, D>,
}

impl<T: DualNum + Copy, const N: usize> Copy for DenseDual<T, Const<N>> {}

/// A [`DenseDual`] of `f64` with `W` slopes.
pub type DenseDual64<const W: usize> = DenseDual<f64, Const<W>>;

impl<T: DualNum, D: Dim> DenseDual<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// A dual number from its parts.
    #[inline]
    pub fn new(re: T, eps: Slopes<T, D>) -> Self {
        Self { re, eps }
    }

    /// A constant: real part `re`, all slopes zero.
    #[inline]
    pub fn from_re(re: T) -> Self {
        Self::new(re, Slopes::zeros())
    }

    #[inline]
    fn chain_rule(&self, f0: T, f1: T) -> Self {
        Self::new(f0, self.eps.clone() * f1)
    }
}

impl<T: DualNum + Copy, const N: usize> DenseDual<T, Const<N>> {
    /// This number with slope 1 in direction `index` and 0 in the others.
    #[inline]
    pub fn derivative(mut self, index: usize) -> Self {
        self.eps = Slopes::zeros();
        self.eps.0[index] = T::one();
        self
    }

    /// Slope `index`.
    #[inline]
    pub fn slope(&self, index: usize) -> T {
        self.eps.0[index]
    }
}

impl<const N: usize> DenseDual<f64, Const<N>> {
    /// The slopes as an array.
    #[inline]
    pub fn slopes(&self) -> [f64; N] {
        self.eps.0.into()
    }
}

/* product rule */
impl<T: DualNum, D: Dim> Mul<&DenseDual<T, D>> for &DenseDual<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = DenseDual<T, D>;
    #[inline]
    fn mul(self, other: &DenseDual<T, D>) -> DenseDual<T, D> {
        DenseDual::new(
            self.re.clone() * other.re.clone(),
            self.eps.combine(&other.re, &other.eps, &self.re),
        )
    }
}

/* quotient rule */
impl<T: DualNum, D: Dim> Div<&DenseDual<T, D>> for &DenseDual<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Output = DenseDual<T, D>;
    #[inline]
    fn div(self, other: &DenseDual<T, D>) -> DenseDual<T, D> {
        let inv = other.re.recip();
        let q = self.re.clone() * inv.clone();
        // (a' b - a b') / b² = (a' - q b') / b
        DenseDual::new(
            q.clone(),
            self.eps.combine(&inv, &other.eps, &(-q * inv.clone())),
        )
    }
}

impl<T: DualNum, D: Dim> fmt::Display for DenseDual<T, D>
where
    DefaultAllocator: Allocator<D>,
{
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}", self.re)?;
        for (i, s) in self.eps.0.iter().enumerate() {
            write!(f, " + {s}ε{i}")?;
        }
        Ok(())
    }
}

impl_first_derivatives!(DenseDual, [eps], [D], [D]);
impl_dual!(DenseDual, [eps], [D], [D]);

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::DualSVec64;

    /// A function exercising every kind of operation the models use.
    fn f<T: DualNum<Primitive = f64> + Copy>(x: &[T]) -> T {
        let a = x[0] * x[1] - x[2] / x[0] + 3.0;
        let b = (a.ln_1p() + x[1].exp() * 0.5).powf(1.7) - x[2].sqrt() * x[0].powi(3);
        let c = (b / (x[0] + x[1]).recip() + x[2].ln()).tanh() * x[1].cbrt();
        let mut d = c.abs() + (x[0] * 0.3).sin_cos().0 * x[2].atan();
        d += x[0];
        d -= x[1] * 2.0;
        d *= x[2];
        d /= x[0] + 1.0;
        d + [x[0], x[1], x[2]].iter().copied().sum::<T>() - (-x[1]).exp_m1() * x[2].powd(x[0])
    }

    #[test]
    fn same_values_and_slopes_as_num_dual() {
        for x in [[0.7, 1.3, 2.1], [2.5, 0.2, 0.9], [1.1, 0.45, 3.3]] {
            let dense: Vec<DenseDual64<3>> = (0..3)
                .map(|i| DenseDual64::from_re(x[i]).derivative(i))
                .collect();
            let sparse: Vec<DualSVec64<3>> = (0..3)
                .map(|i| DualSVec64::from_re(x[i]).derivative(i))
                .collect();
            let (a, b) = (f(&dense), f(&sparse));
            assert_eq!(a.re, b.re, "value at {x:?}");
            let bs = b.eps.unwrap_generic(Const::<3>, U1);
            for i in 0..3 {
                let tol = 1e-13 * bs[i].abs().max(1.0);
                assert!(
                    (a.slopes()[i] - bs[i]).abs() <= tol,
                    "slope {i} at {x:?}: {} vs {}",
                    a.slopes()[i],
                    bs[i]
                );
            }
        }
    }

    #[test]
    fn constants_have_zero_slopes_and_nest() {
        let c = DenseDual64::<4>::from_re(2.0);
        assert_eq!(c.slopes(), [0.0; 4]);
        // nested inside num-dual's vector dual, as the viscosity partials use it
        let x = DualSVec64::<2>::from_re(0.0);
        let inner = num_dual::DualSVec::<DenseDual64<2>, 2>::from_re(
            DenseDual64::from_re(1.5).derivative(1),
        )
        .derivative(0);
        let y = inner * inner * 2.0;
        assert_eq!(y.re.re, 4.5);
        assert_eq!(y.re.slopes(), [0.0, 6.0]);
        let e = y.eps.unwrap_generic(Const::<2>, U1);
        assert_eq!(e[0].re, 6.0);
        assert_eq!(e[0].slopes(), [0.0, 4.0]);
        assert_eq!(x.re, 0.0);
        assert_eq!(
            format!("{}", DenseDual64::<2>::from_re(1.0).derivative(1)),
            "1 + 0ε0 + 1ε1"
        );
    }
}
