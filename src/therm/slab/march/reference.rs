//! The full-system Newton step (before issue 12), kept as the test
//! reference of the surface-only Newton iteration.

use super::*;

/// The full-system Newton step (before issue 12), kept as the reference
/// of the surface-only Newton's test.
struct FullWork {
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    r: Vec<f64>,
    x: Vec<f64>,
    cp: Vec<f64>,
    dp: Vec<f64>,
}

impl FullWork {
    fn new(n: usize) -> FullWork {
        FullWork {
            a: vec![0.0; n],
            b: vec![0.0; n],
            c: vec![0.0; n],
            r: vec![0.0; n],
            x: vec![0.0; n],
            cp: vec![0.0; n],
            dp: vec![0.0; n],
        }
    }

    /// Thomas algorithm for the leading `n` rows of the tridiagonal system
    /// `a_i x_{i−1} + b_i x_i + c_i x_{i+1} = r_i` (no pivoting: the systems
    /// here are diagonally dominant M-matrices). False on a zero pivot.
    fn solve(&mut self, n: usize) -> bool {
        thomas(
            &self.a[..n],
            &self.b[..n],
            &self.c[..n],
            &self.r[..n],
            &mut self.x[..n],
            &mut self.cp[..n],
            &mut self.dp[..n],
        )
    }
}

fn thomas(
    a: &[f64],
    b: &[f64],
    c: &[f64],
    r: &[f64],
    x: &mut [f64],
    cp: &mut [f64],
    dp: &mut [f64],
) -> bool {
    let n = b.len();
    let mut beta = b[0];
    if beta == 0.0 || !beta.is_finite() {
        return false;
    }
    cp[0] = c[0] / beta;
    dp[0] = r[0] / beta;
    for i in 1..n {
        beta = b[i] - a[i] * cp[i - 1];
        if beta == 0.0 || !beta.is_finite() {
            return false;
        }
        cp[i] = c[i] / beta;
        dp[i] = (r[i] - a[i] * dp[i - 1]) / beta;
    }
    x[n - 1] = dp[n - 1];
    for i in (0..n - 1).rev() {
        x[i] = dp[i] - cp[i] * x[i + 1];
    }
    true
}

impl SlabModel {
    /// The implicit step as it was before issue 12: Newton's method on the
    /// whole tridiagonal system (the test reference of [`Self::implicit_step`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn implicit_step_full(
        &self,
        old: &[f64],
        new: &mut [f64],
        h: f64,
        g: &[f64],
        drive: &SurfaceDrive,
        deep: Option<f64>,
    ) -> bool {
        let mut w = FullWork::new(old.len());
        let w = &mut w;
        let n = old.len();
        let fixed_back = deep.is_some();
        let nf = if fixed_back { n - 1 } else { n };
        if fixed_back {
            new[n - 1] = deep.unwrap();
        }
        let cap = &self.mesh.cap_j_m2k;
        let sw = drive.absorbed_shortwave_w_m2();
        let inv_h = if h.is_finite() { 1.0 / h } else { 0.0 };
        // Snow: once the free solution lies above the melt cap, node 0 is
        // held there (its row becomes T₀ = cap) and the rest re-solved.
        let mut held = false;
        for iter in 0..120 {
            // Residual r = rhs − lhs (we solve J·δ = r with J = −∂r/∂T).
            for i in 0..nf {
                let t = new[i];
                let mut r = -cap[i] * inv_h * (t - old[i]);
                let mut diag = cap[i] * inv_h;
                if i > 0 {
                    r += g[i - 1] * (new[i - 1] - t);
                    diag += g[i - 1];
                }
                if i + 1 < n {
                    r += g[i] * (new[i + 1] - t);
                    diag += g[i];
                }
                if i == 0 {
                    let (sf, ds) = balance::surface_fluxes(
                        drive,
                        self.material.thermal_emissivity,
                        &self.settings.convection,
                        t,
                    );
                    // The shortwave absorbed below the skin (water) goes
                    // to the deeper nodes.
                    r += sf.net_w_m2 - (1.0 - self.sw_fraction[0]) * sw;
                    diag -= ds;
                } else {
                    r += self.sw_fraction[i] * sw;
                }
                if i == n - 1 && !fixed_back {
                    let (q, dq) = self.back_flux(drive, t, deep, 0.0);
                    r += q;
                    diag -= dq;
                }
                w.r[i] = r;
                w.b[i] = diag;
                w.a[i] = if i > 0 { -g[i - 1] } else { 0.0 };
                w.c[i] = if i + 1 < nf { -g[i] } else { 0.0 };
                if i == 0 && held {
                    w.r[0] = self.melt_cap_k().unwrap_or(t) - t;
                    w.b[0] = 1.0;
                    w.c[0] = 0.0;
                }
            }
            if !w.solve(nf) {
                return false;
            }
            let mut max_d = 0.0f64;
            // Damped after 30 iterations: the turbulent exchange has kinks
            // (capped stability factors) where plain Newton can cycle.
            let damp = if iter < 30 { 1.0 } else { 0.5 };
            for (t, &d) in new[..nf].iter_mut().zip(&w.x[..nf]) {
                if !d.is_finite() {
                    return false;
                }
                // Keep the iterate physical; the root is always > 0 K.
                *t = (*t + damp * d).max(1.0);
                max_d = max_d.max(d.abs());
            }
            if max_d < 1e-9 {
                match self.melt_cap_k() {
                    Some(cap) if !held && new[0] > cap => held = true,
                    _ => return true,
                }
            }
        }
        false
    }
}
