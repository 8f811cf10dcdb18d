//! Non-negative least squares: `min ‖A x − b‖ subject to x ≥ 0`
//! (Lawson & Hanson 1974, *Solving Least Squares Problems*, ch. 23).
//!
//! For the small dense systems of contact statics (6 rows, a few dozen
//! columns). The active-set method terminates in finitely many steps in
//! exact arithmetic; a cap on the iterations guards against cycling in
//! floating point.

use nalgebra::{DMatrix, DVector};

/// The active-set iterations ran out before the optimality conditions held
/// (cycling in floating point).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the non-negative least-squares solve did not converge in {iterations} iterations")]
pub struct NotConverged {
    pub iterations: usize,
}

/// The solution `x ≥ 0` of `min ‖A x − b‖` and its residual `‖A x − b‖`,
/// or the best point reached if the iterations run out (see [`checked`]).
/// Columns with a non-finite entry are ignored (their `x` is 0).
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> (DVector<f64>, f64) {
    let (x, residual, _) = solve(a, b, iteration_cap(a.ncols()));
    (x, residual)
}

/// [`nnls`], or [`NotConverged`] when the iterations ran out.
pub fn checked(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<(DVector<f64>, f64), NotConverged> {
    let cap = iteration_cap(a.ncols());
    match solve(a, b, cap) {
        (x, residual, true) => Ok((x, residual)),
        (_, _, false) => Err(NotConverged { iterations: cap }),
    }
}

/// Outer and inner iterations allowed for `n` columns: every column can
/// enter and leave the passive set a few times.
fn iteration_cap(n: usize) -> usize {
    3 * n + 10
}

/// The iterations, at most `cap` outer and `cap` inner per outer; whether
/// they converged.
fn solve(a: &DMatrix<f64>, b: &DVector<f64>, cap: usize) -> (DVector<f64>, f64, bool) {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let usable: Vec<bool> = (0..n)
        .map(|j| a.column(j).iter().all(|v| v.is_finite()))
        .collect();
    if !b.iter().all(|v| v.is_finite()) {
        return (x, f64::INFINITY, true);
    }
    // Unusable columns take no part (zeroed, so 0 · NaN never appears).
    let a = &DMatrix::from_fn(a.nrows(), n, |i, j| if usable[j] { a[(i, j)] } else { 0.0 });
    let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
    let tol = 1e-12 * scale * b.norm().max(1e-300) * (n.max(1) as f64);
    let mut passive = vec![false; n];
    let mut converged = false;
    let mut stuck = false;
    for _ in 0..cap {
        let w = a.transpose() * (b - a * &x);
        let entering = (0..n)
            .filter(|&j| usable[j] && !passive[j])
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = entering.filter(|&j| w[j] > tol) else {
            converged = true;
            break;
        };
        passive[j] = true;
        // Inner loop: keep the passive least-squares solution feasible.
        let mut feasible = false;
        for _ in 0..cap {
            let s = passive_solution(a, b, &passive);
            let infeasible: Vec<usize> = (0..n).filter(|&i| passive[i] && s[i] <= 0.0).collect();
            if infeasible.is_empty() {
                x = s;
                feasible = true;
                break;
            }
            let alpha = infeasible
                .iter()
                .map(|&i| x[i] / (x[i] - s[i]))
                .fold(1.0_f64, f64::min)
                .clamp(0.0, 1.0);
            x += (s - &x) * alpha;
            for i in 0..n {
                if passive[i] && x[i] <= 1e-15 * scale {
                    passive[i] = false;
                    x[i] = 0.0;
                }
            }
        }
        if !feasible {
            stuck = true;
            break;
        }
    }
    if !converged && !stuck {
        // The last iteration allowed may have reached the optimum.
        let w = a.transpose() * (b - a * &x);
        converged = (0..n).all(|j| !usable[j] || passive[j] || w[j] <= tol);
    }
    let residual = (a * &x - b).norm();
    (x, residual, converged)
}

/// Least squares on the passive columns, zero elsewhere.
fn passive_solution(a: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> DVector<f64> {
    let cols: Vec<usize> = (0..a.ncols()).filter(|&j| passive[j]).collect();
    let mut out = DVector::zeros(a.ncols());
    if cols.is_empty() {
        return out;
    }
    let sub = DMatrix::from_fn(a.nrows(), cols.len(), |r, c| a[(r, cols[c])]);
    let svd = sub.svd(true, true);
    let eps = 1e-12 * svd.singular_values.max();
    if let Ok(s) = svd.solve(b, eps) {
        for (k, &j) in cols.iter().enumerate() {
            out[j] = s[k];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unconstrained_solution_inside_the_orthant_is_the_least_squares_solution() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 2.0, 1.0, 1.0]);
        let x0 = DVector::from_vec(vec![0.5, 0.25]);
        let b = &a * &x0;
        let (x, r) = nnls(&a, &b);
        assert!((x - x0).norm() < 1e-12 && r < 1e-12);
    }

    #[test]
    fn a_negative_least_squares_component_is_clamped_to_zero() {
        // Least squares would take x = (1, -1); with x ≥ 0 the best is
        // x₂ = 0 and x₁ the projection of b on the first column.
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let b = DVector::from_vec(vec![1.0, -1.0]);
        let (x, r) = nnls(&a, &b);
        assert_eq!(x.as_slice(), &[1.0, 0.0]);
        assert!((r - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_residual_is_no_larger_than_at_any_sampled_feasible_point() {
        // A fixed pseudo-random 6 × 12 system; compare with a grid search
        // over a few random non-negative points.
        let mut seed = 7_u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let a = DMatrix::from_fn(6, 12, |_, _| rnd());
        let b = DVector::from_fn(6, |_, _| rnd());
        let (x, r) = nnls(&a, &b);
        assert!(x.iter().all(|v| *v >= 0.0));
        assert!(((&a * &x - &b).norm() - r).abs() < 1e-12);
        for _ in 0..2000 {
            let y = DVector::from_fn(12, |_, _| rnd().abs());
            assert!((&a * &y - &b).norm() >= r - 1e-12);
        }
        // KKT: the gradient is ≤ 0 on zero components and ≈ 0 on positive ones.
        let w = a.transpose() * (&b - &a * &x);
        for j in 0..12 {
            if x[j] > 0.0 {
                assert!(w[j].abs() < 1e-9, "w[{j}] = {}", w[j]);
            } else {
                assert!(w[j] < 1e-9, "w[{j}] = {}", w[j]);
            }
        }
    }

    #[test]
    fn running_out_of_iterations_is_not_converged() {
        // Two columns must enter: one outer iteration is not enough.
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let b = DVector::from_vec(vec![1.0, 2.0]);
        assert!(!solve(&a, &b, 1).2);
        let (x, r, converged) = solve(&a, &b, iteration_cap(2));
        assert!(converged && r < 1e-12, "{x}");
        assert_eq!(checked(&a, &b).map(|(x, _)| x), Ok(x));
    }

    #[test]
    fn non_finite_input_gives_no_solution_and_no_nan() {
        let a = DMatrix::from_row_slice(1, 2, &[f64::NAN, 1.0]);
        let b = DVector::from_vec(vec![2.0]);
        let (x, r) = nnls(&a, &b);
        assert_eq!(x.as_slice(), &[0.0, 2.0]);
        assert!(r.abs() < 1e-12);
        let (x, r) = nnls(&a, &DVector::from_vec(vec![f64::INFINITY]));
        assert!(x.iter().all(|v| *v == 0.0) && r == f64::INFINITY);
    }
}
