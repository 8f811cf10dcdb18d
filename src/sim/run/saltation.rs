//! The saltation update: the Jacobian through an impulse (docs/design.md §5).

use super::*;

/// The saltation result: post-impulse Jacobian rows of the parties,
/// `dt_c/du`, and the grazing ratio.
type Saltation = (DMatrix<f64>, DVector<f64>, f64);

impl Sim<'_> {
    /// `J⁺ = Φ_q J⁻ + Φ_u + (Φ_q F⁻ − F⁺) dt_c/du` with
    /// `dt_c/du = −E_q J⁻ / (E_q F⁻)`. A frozen party's flow before is
    /// zero; `b_still`: party b is held still after it (it freezes, or is
    /// an anchored support), so its flow after and velocity rows are zero.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn saltation(
        &self,
        tc: f64,
        index: usize,
        pair: Pair,
        sa: &BodyState,
        sb: Option<&BodyState>,
        post_a: &BodyState,
        post_b: Option<&BodyState>,
        mode: &Mode,
        b_still: bool,
        ctx: &ImpulseCtx,
    ) -> Result<Saltation, (TangentError, f64)> {
        let m = self.traj.m;
        let a = pair.a;
        let ns = if sb.is_some() { 24 } else { 12 };
        let nonfinite = |ratio| (TangentError::NonFinite { t: tc }, ratio);
        let mut jpre = DMatrix::zeros(ns, m);
        jpre.rows_mut(0, 12).copy_from(
            &self
                .traj
                .jacobian(a, tc, Side::Post)
                .map_err(|e| (e, f64::NAN))?,
        );
        let mut fpre = DVector::zeros(ns);
        fpre.rows_mut(0, 12)
            .copy_from(&self.traj.flow(a, sa, self.frozen(a)));
        let mut fpost = DVector::zeros(ns);
        let post_flow = match mode {
            Mode::Rest => DVector::zeros(12),
            Mode::Slide { slide, .. } => {
                let f = slide.flow(post_a, self.traj.dynamics[a].drag_k);
                DVector::from_iterator(12, f.iter().flat_map(|v| v.iter().cloned()))
            }
            Mode::Bounce => self.traj.flow(a, post_a, false),
        };
        fpost.rows_mut(0, 12).copy_from(&post_flow);
        if let (Some(j), Some(sb), Some(pb)) = (pair.b_body(), sb, post_b) {
            jpre.rows_mut(12, 12).copy_from(
                &self
                    .traj
                    .jacobian(j, tc, Side::Post)
                    .map_err(|e| (e, f64::NAN))?,
            );
            fpre.rows_mut(12, 12)
                .copy_from(&self.traj.flow(j, sb, self.frozen(j)));
            fpost
                .rows_mut(12, 12)
                .copy_from(&self.traj.flow(j, pb, b_still));
        }
        // Φ_u: event parameters, masses and inertias.
        let p0 = ctx.param_offset();
        let mut params: Vec<(usize, usize)> = Vec::new();
        let (normal_col, rest_col) = self.controls.event_columns(index);
        if let Some(c) = normal_col.filter(|_| self.opts.tangent) {
            params.push((p0, c));
            params.push((p0 + 1, c + 1));
        }
        if let Some(c) = rest_col.filter(|_| self.opts.tangent) {
            params.push((p0 + 2, c));
        }
        if let Some(c) = self.traj.mass_cols[a] {
            params.push((p0 + 3, c));
        }
        if let Some(c) = self.traj.inertia_cols[a] {
            for k in 0..3 {
                params.push((p0 + 4 + k, c + k));
            }
        }
        if let Some(j) = pair.b_body() {
            if let Some(c) = self.traj.mass_cols[j] {
                params.push((p0 + 7, c));
            }
            if let Some(c) = self.traj.inertia_cols[j] {
                for k in 0..3 {
                    params.push((p0 + 8 + k, c + k));
                }
            }
        }
        let jac = ctx.jacobian_with(params.iter().any(|&(_, c)| c < m));
        // The event function's gradient E_q: that of the touching features,
        // or, where two or more corners of a patch touch at once, each of
        // theirs. A flat landing like that (a level plank's end face meeting
        // a support's edge) has an event time `min_i t_i(u)` with a kink,
        // and the feature pair the search happened to end on gives one of
        // its one-sided derivatives at best (a vertex–vertex pair at zero
        // distance has no normal at all), so the tangent would depend on
        // the search's steps. The corners give every one-sided derivative;
        // separating corners do not bound the event.
        let dot =
            |e: &[f64], f: &DVector<f64>| e.iter().zip(f.iter()).map(|(e, f)| e * f).sum::<f64>();
        let mut rows: Vec<(Vec<f64>, f64)> = ctx
            .touching_corners(10.0 * self.tol.root)
            .into_iter()
            .map(|row| {
                let den = dot(&row, &fpre);
                (row, den)
            })
            .filter(|(_, den)| *den < 0.0)
            .collect();
        if rows.len() < 2 {
            // No kink: the touching features, as the search found them.
            rows.clear();
            let eq: Vec<f64> = jac.view((0, 0), (1, ns)).iter().copied().collect();
            let den = dot(&eq, &fpre);
            rows.push((eq, den));
        }
        // Grazing measure: the cosine between E_q and the configuration part
        // of F (velocities; E does not depend on them, so including the
        // accelerations would only mix units into the ratio), the smallest
        // of the touching corners'.
        let config: f64 = (0..ns)
            .filter(|r| r % 12 < 6)
            .map(|r| fpre[r] * fpre[r])
            .sum::<f64>()
            .sqrt();
        let ratios: Vec<f64> = rows
            .iter()
            .map(|(e, den)| den.abs() / (e.iter().map(|v| v * v).sum::<f64>().sqrt() * config))
            .collect();
        let ratio = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        if !ratios.iter().all(|r| r.is_finite()) {
            return Err(nonfinite(ratio));
        }
        if ratio < self.opts.graze_tol {
            return Err((
                TangentError::Grazing {
                    event: index,
                    t: tc,
                    ratio,
                },
                ratio,
            ));
        }
        // dt_c/du = −E_q J⁻ / (E_q F⁻), 1 × m; at a kink, column by column
        // the midpoint of the extreme one-sided derivatives: what central
        // differences converge to, whichever corner the search named.
        let dt: Vec<f64> = (0..m)
            .map(|c| {
                let (lo, hi) = rows
                    .iter()
                    .map(|(e, den)| {
                        -e.iter()
                            .zip(jpre.column(c).iter())
                            .map(|(e, j)| e * j)
                            .sum::<f64>()
                            / den
                    })
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                        (lo.min(s), hi.max(s))
                    });
                0.5 * (lo + hi)
            })
            .collect();
        // Φ_q is the identity but for the velocity rows of each body (the
        // impulse changes velocities, not positions): only those rows of
        // Φ_q J⁻ and Φ_q F⁻ need a product. J⁻ becomes J⁺ in place, one
        // column at a time (each column's new rows read only that column).
        let velocity_rows: &[(usize, usize)] = if ns == 24 {
            &[(6, 1), (18, 7)]
        } else {
            &[(6, 1)]
        };
        let phi = |row: usize, x: &[f64]| -> f64 {
            x.iter().enumerate().map(|(k, v)| jac[(row, k)] * v).sum()
        };
        let mut mismatch = &fpre - &fpost; // Φ_q F⁻ − F⁺
        for &(row, jac_row) in velocity_rows {
            for i in 0..6 {
                mismatch[row + i] += phi(jac_row + i, fpre.as_slice()) - fpre[row + i];
            }
        }
        let mut jpost = jpre;
        let mut rows = [0.0; 12];
        for c in 0..m {
            for (b, &(_, jac_row)) in velocity_rows.iter().enumerate() {
                for i in 0..6 {
                    rows[6 * b + i] = phi(jac_row + i, jpost.column(c).as_slice());
                }
            }
            for (b, &(row, _)) in velocity_rows.iter().enumerate() {
                for i in 0..6 {
                    jpost[(row + i, c)] = rows[6 * b + i];
                }
            }
            for r in 0..ns {
                jpost[(r, c)] += mismatch[r] * dt[c];
            }
        }
        for (p, c) in params {
            if c >= m {
                continue;
            }
            for r in 0..6 {
                jpost[(6 + r, c)] += jac[(1 + r, p)];
                if ns == 24 {
                    jpost[(18 + r, c)] += jac[(7 + r, p)];
                }
            }
        }
        // Rest and slide project the post-impulse velocities; their flows
        // already lie in the projections' ranges, so projecting the rows
        // of J⁺ is the exact derivative of the composed map.
        match mode {
            Mode::Rest => jpost.rows_mut(6, 6).fill(0.0),
            Mode::Slide { proj_v, proj_w, .. } => {
                let jv = proj_v * jpost.rows(6, 3);
                let jw = proj_w * jpost.rows(9, 3);
                jpost.rows_mut(6, 3).copy_from(&jv);
                jpost.rows_mut(9, 3).copy_from(&jw);
            }
            Mode::Bounce => {}
        }
        if b_still && ns == 24 {
            jpost.rows_mut(18, 6).fill(0.0);
        }
        if !jpost.iter().chain(dt.iter()).all(|v| v.is_finite()) {
            return Err(nonfinite(ratio));
        }
        Ok((jpost, DVector::from_vec(dt), ratio))
    }
}
