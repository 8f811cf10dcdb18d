//! Forward-mode derivatives with matrix-shaped tangents, for the impulse
//! map's Jacobian (`sim::impulse`).
//!
//! A [`Sj`] is a scalar with its gradient (`N` directions); a [`Vj`] is a
//! 3-vector with its `3 × N` Jacobian. Each operation applies its own
//! derivative rule to the whole tangent block at once (`d(a × b) =
//! [a]× db − [b]× da`, …), so a product costs a handful of small dense
//! matrix operations on `f64` instead of one scalar dual-number operation
//! per matrix entry — the reason the hand-written impulse Jacobian is an
//! order of magnitude cheaper than evaluating the generic model with dual
//! numbers, which remains its reference (tests in `sim::impulse`).

use crate::math::{Mat3, Vec3};
use nalgebra::{RowSVector, SMatrix};

/// A scalar and its derivative along `N` input directions.
#[derive(Debug, Clone, Copy)]
pub struct Sj<const N: usize> {
    pub v: f64,
    pub d: RowSVector<f64, N>,
}

/// A 3-vector and its `3 × N` Jacobian.
#[derive(Debug, Clone, Copy)]
pub struct Vj<const N: usize> {
    pub v: Vec3,
    pub d: SMatrix<f64, 3, N>,
}

/// `[a]×`, the cross-product matrix.
pub fn skew(a: &Vec3) -> Mat3 {
    Mat3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

impl<const N: usize> Sj<N> {
    /// A constant.
    pub fn constant(v: f64) -> Self {
        Sj {
            v,
            d: RowSVector::zeros(),
        }
    }

    /// The input number `i`, with value `v` (a constant when the jet does
    /// not carry input `i`: a parameter nothing is differentiated by).
    pub fn input(v: f64, i: usize) -> Self {
        let mut s = Self::constant(v);
        if i < N {
            s.d[i] = 1.0;
        }
        s
    }

    pub fn add(&self, o: &Self) -> Self {
        Sj {
            v: self.v + o.v,
            d: self.d + o.d,
        }
    }

    pub fn sub(&self, o: &Self) -> Self {
        Sj {
            v: self.v - o.v,
            d: self.d - o.d,
        }
    }

    pub fn neg(&self) -> Self {
        Sj {
            v: -self.v,
            d: -self.d,
        }
    }

    pub fn mul(&self, o: &Self) -> Self {
        Sj {
            v: self.v * o.v,
            d: self.d * o.v + o.d * self.v,
        }
    }

    pub fn div(&self, o: &Self) -> Self {
        let q = self.v / o.v;
        Sj {
            v: q,
            d: (self.d - o.d * q) / o.v,
        }
    }

    /// The value alone, as a constant jet of width `M` (`M = 0`: plain
    /// arithmetic through the same code).
    pub fn as_constant<const M: usize>(&self) -> Sj<M> {
        Sj::constant(self.v)
    }

    /// `1 / self`.
    pub fn recip(&self) -> Self {
        let r = 1.0 / self.v;
        Sj {
            v: r,
            d: self.d * (-r * r),
        }
    }
}

impl<const N: usize> Vj<N> {
    /// A constant vector.
    pub fn constant(v: Vec3) -> Self {
        Vj {
            v,
            d: SMatrix::zeros(),
        }
    }

    /// Inputs `i..i+3`, with value `v`.
    pub fn input(v: Vec3, i: usize) -> Self {
        let mut x = Self::constant(v);
        for k in (0..3).filter(|k| i + k < N) {
            x.d[(k, i + k)] = 1.0;
        }
        x
    }

    /// A vector of three scalar jets.
    pub fn from_components(c: [Sj<N>; 3]) -> Self {
        let mut d = SMatrix::<f64, 3, N>::zeros();
        for (r, s) in c.iter().enumerate() {
            d.set_row(r, &s.d);
        }
        Vj {
            v: Vec3::new(c[0].v, c[1].v, c[2].v),
            d,
        }
    }

    /// Component `i`.
    pub fn component(&self, i: usize) -> Sj<N> {
        Sj {
            v: self.v[i],
            d: self.d.row(i).into_owned(),
        }
    }

    /// The value alone, as a constant jet of width `M`.
    pub fn as_constant<const M: usize>(&self) -> Vj<M> {
        Vj::constant(self.v)
    }

    pub fn add(&self, o: &Self) -> Self {
        Vj {
            v: self.v + o.v,
            d: self.d + o.d,
        }
    }

    pub fn sub(&self, o: &Self) -> Self {
        Vj {
            v: self.v - o.v,
            d: self.d - o.d,
        }
    }

    /// `self · s`.
    pub fn scale(&self, s: &Sj<N>) -> Self {
        Vj {
            v: self.v * s.v,
            d: self.d * s.v + self.v * s.d,
        }
    }

    pub fn dot(&self, o: &Self) -> Sj<N> {
        Sj {
            v: self.v.dot(&o.v),
            d: self.v.transpose() * o.d + o.v.transpose() * self.d,
        }
    }

    pub fn cross(&self, o: &Self) -> Self {
        Vj {
            v: self.v.cross(&o.v),
            d: skew(&self.v) * o.d - skew(&o.v) * self.d,
        }
    }

    /// `self × c` for a constant `c`.
    pub fn cross_const(&self, c: &Vec3) -> Self {
        Vj {
            v: self.v.cross(c),
            d: -skew(c) * self.d,
        }
    }

    pub fn normalize(&self) -> Self {
        let len = self.v.norm();
        let u = self.v / len;
        Vj {
            v: u,
            d: (Mat3::identity() - u * u.transpose()) * self.d / len,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each rule against central differences of a composite expression.
    #[test]
    fn every_rule_matches_central_differences() {
        const N: usize = 4;
        let f = |z: &[f64; N]| -> (Sj<N>, Vj<N>) {
            let a = Vj::<N>::input(Vec3::new(z[0], z[1], z[2]), 0);
            let s = Sj::<N>::input(z[3], 3);
            let b = a
                .cross_const(&Vec3::new(0.3, -1.0, 0.7))
                .add(&Vj::constant(Vec3::new(0.1, 0.2, 0.9)));
            let c = a.cross(&b).scale(&s).normalize();
            let k = c
                .add(&a)
                .dot(&a)
                .mul(&s)
                .div(&b.dot(&b))
                .recip()
                .sub(&s)
                .neg();
            let c = Vj::from_components([c.component(2), k, c.component(0)]);
            (k, c.sub(&a).sub(&b).scale(&k).scale(&a.dot(&b)))
        };
        let z0 = [0.4, -0.8, 1.1, 1.7];
        let jet = f(&z0);
        let h = 1e-6;
        for i in 0..N {
            let (mut zp, mut zm) = (z0, z0);
            zp[i] += h;
            zm[i] -= h;
            let ((kp, op), (km, om)) = (f(&zp), f(&zm));
            let dk = (kp.v - km.v) / (2.0 * h);
            assert!((dk - jet.0.d[i]).abs() < 1e-7 * dk.abs().max(1.0), "k/{i}");
            let dout = (op.v - om.v) / (2.0 * h);
            let col = jet.1.d.column(i);
            assert!(
                (dout - col).norm() < 1e-7 * dout.norm().max(1.0),
                "out/{i}: {dout} vs {col}"
            );
        }
    }
}
