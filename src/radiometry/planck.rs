//! Planck's law: spectral radiance, its inverse, and exact band integrals.
//!
//! Constants are the exact SI 2019 values (CODATA 2018): h = 6.626 070 15e-34 J s,
//! c = 299 792 458 m/s, k = 1.380 649e-23 J/K. All functions are overflow-free
//! over 0.25-28 µm and 1-6000 K (and far beyond): the exponent is evaluated with
//! `exp_m1` and guarded, so the result is finite and non-negative; it is exactly
//! zero only where the true value is below the smallest f64 (e.g. 0.25 µm at 1 K,
//! whose radiance is about 1e-25000 W m⁻² sr⁻¹ µm⁻¹).

/// Planck constant, J s (exact).
pub const H_J_S: f64 = 6.626_070_15e-34;
/// Speed of light in vacuum, m/s (exact).
pub const C_M_S: f64 = 299_792_458.0;
/// Boltzmann constant, J/K (exact).
pub const K_J_K: f64 = 1.380_649e-23;
/// First radiation constant for radiance, c1L = 2hc², W m² sr⁻¹.
pub const C1L_W_M2_SR: f64 = 2.0 * H_J_S * C_M_S * C_M_S;
/// Second radiation constant, c2 = hc/k, in µm K (≈ 14387.77 µm K).
pub const C2_UM_K: f64 = H_J_S * C_M_S / K_J_K * 1.0e6;

/// exp(x) − 1 guarded for large x: returns +inf only when exp overflows, which
/// callers turn into an exact zero radiance (1/inf = 0), never NaN.
fn expm1_guarded(x: f64) -> f64 {
    if x > 709.0 { f64::INFINITY } else { x.exp_m1() }
}

/// Spectral radiance of a blackbody per unit wavelength, W m⁻² sr⁻¹ µm⁻¹.
///
/// L_λ(λ, T) = c1L / (λ⁵ (exp(c2 / (λ T)) − 1)) (Planck 1901; e.g. Schott,
/// *Remote Sensing: The Image Chain Approach*, eq. 3.32), with λ in metres and the
/// result scaled from per metre to per micrometre. Large exponents are handled as
/// c1L λ⁻⁵ exp(−x) in log space so nothing overflows.
pub fn planck_radiance_w_m2_sr_um(wavelength_um: f64, temp_k: f64) -> f64 {
    if wavelength_um <= 0.0 || temp_k <= 0.0 || !wavelength_um.is_finite() || !temp_k.is_finite() {
        return 0.0;
    }
    let lam_m = wavelength_um * 1.0e-6;
    let x = C2_UM_K / (wavelength_um * temp_k);
    // c1L/λ⁵ in W m⁻² sr⁻¹ m⁻¹, times 1e-6 for per-µm; computed in logs so that
    // λ⁵ underflow or huge prefactors never occur.
    let ln_pref = C1L_W_M2_SR.ln() - 5.0 * lam_m.ln() + (1.0e-6f64).ln();
    if x > 700.0 {
        // exp(x) − 1 = exp(x) to f64 precision
        let ln_l = ln_pref - x;
        return if ln_l < -745.0 { 0.0 } else { ln_l.exp() };
    }
    ln_pref.exp() / expm1_guarded(x)
}

/// Spectral radiance of a blackbody per unit wavenumber, W m⁻² sr⁻¹ (cm⁻¹)⁻¹.
///
/// L_ν(ν, T) = 2 h c² ν³ / (exp(h c ν / (k T)) − 1), ν in m⁻¹ (result per m⁻¹),
/// times 100 to express it per cm⁻¹.
pub fn planck_radiance_w_m2_sr_cm1(wavenumber_cm1: f64, temp_k: f64) -> f64 {
    if wavenumber_cm1 <= 0.0 || temp_k <= 0.0 || !wavenumber_cm1.is_finite() || !temp_k.is_finite()
    {
        return 0.0;
    }
    let nu_m = wavenumber_cm1 * 100.0;
    // c2 ν / T with c2 in cm K = C2_UM_K * 1e-4
    let x = C2_UM_K * 1.0e-4 * wavenumber_cm1 / temp_k;
    let ln_pref = C1L_W_M2_SR.ln() + 3.0 * nu_m.ln() + 100.0f64.ln();
    if x > 700.0 {
        let ln_l = ln_pref - x;
        return if ln_l < -745.0 { 0.0 } else { ln_l.exp() };
    }
    ln_pref.exp() / expm1_guarded(x)
}

/// ∂L_λ/∂T, W m⁻² sr⁻¹ µm⁻¹ K⁻¹: L_λ · x eˣ / ((eˣ − 1) T), x = c2/(λT).
pub fn planck_dt_w_m2_sr_um_k(wavelength_um: f64, temp_k: f64) -> f64 {
    let l = planck_radiance_w_m2_sr_um(wavelength_um, temp_k);
    if l == 0.0 {
        return 0.0;
    }
    let x = C2_UM_K / (wavelength_um * temp_k);
    // x eˣ/(eˣ−1) = x / (1 − e⁻ˣ) = x / −expm1(−x)
    l * x / (-(-x).exp_m1()) / temp_k
}

/// Brightness temperature (inverse Planck) at one wavelength, K.
///
/// T = c2 / (λ ln(1 + c1L/(λ⁵ L))), with ln_1p for accuracy at large L.
/// Returns `None` for a non-positive or non-finite radiance.
pub fn brightness_temp_k(wavelength_um: f64, radiance_w_m2_sr_um: f64) -> Option<f64> {
    if !(radiance_w_m2_sr_um > 0.0) || !radiance_w_m2_sr_um.is_finite() || !(wavelength_um > 0.0) {
        return None;
    }
    let lam_m = wavelength_um * 1.0e-6;
    // ratio = c1L λ⁻⁵ 1e-6 / L, in logs
    let ln_ratio =
        C1L_W_M2_SR.ln() - 5.0 * lam_m.ln() + (1.0e-6f64).ln() - radiance_w_m2_sr_um.ln();
    let ln_term = if ln_ratio > 36.0 {
        // ln(1 + r) = ln r + ln(1 + 1/r)
        ln_ratio + (-ln_ratio).exp().ln_1p()
    } else {
        ln_ratio.exp().ln_1p()
    };
    Some(C2_UM_K / (wavelength_um * ln_term))
}

/// ∫₀ˣ t³/(eᵗ − 1) dt, the dimensionless Planck integral, to ~1e-15 relative.
///
/// For x < 1 the Bernoulli-number series x³/3 − x⁴/8 + Σ B₂ₖ x^(2k+3)/((2k+3)(2k)!)
/// (convergent for |x| < 2π); otherwise π⁴/15 − Σₙ e^(−nx)(x³/n + 3x²/n² + 6x/n³ + 6/n⁴)
/// (Widger & Woodall, Bull. AMS 57 (1976) 1217).
pub fn planck_integral_0_to_x(x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x < 1.0 {
        bernoulli_series(x)
    } else {
        PI4_15 - tail(x)
    }
}

/// π⁴/15 = ∫₀^∞ t³/(eᵗ − 1) dt.
const PI4_15: f64 =
    std::f64::consts::PI * std::f64::consts::PI * std::f64::consts::PI * std::f64::consts::PI
        / 15.0;

/// x³/3 − x⁴/8 + Σₖ B₂ₖ x^(2k+3)/((2k+3)(2k)!), for 0 ≤ x < 2π.
fn bernoulli_series(x: f64) -> f64 {
    // B2k / (2k)! for k = 1.. : B2=1/6, B4=-1/30, B6=1/42, B8=-1/30, B10=5/66,
    // B12=-691/2730, B14=7/6, B16=-3617/510, B18=43867/798, B20=-174611/330
    const B: [f64; 10] = [
        1.0 / 6.0,
        -1.0 / 30.0,
        1.0 / 42.0,
        -1.0 / 30.0,
        5.0 / 66.0,
        -691.0 / 2730.0,
        7.0 / 6.0,
        -3617.0 / 510.0,
        43867.0 / 798.0,
        -174611.0 / 330.0,
    ];
    let mut sum = x * x * x / 3.0 - x * x * x * x / 8.0;
    let mut fact = 1.0f64; // (2k)!
    let mut xp = x * x * x; // x^(2k+3) built incrementally
    for (i, b) in B.iter().enumerate() {
        let k = (i + 1) as f64;
        fact *= (2.0 * k - 1.0) * (2.0 * k);
        xp *= x * x;
        let term = b / fact * xp / (2.0 * k + 3.0);
        sum += term;
        if term.abs() < 1e-18 * sum.abs() {
            break;
        }
    }
    sum
}

/// Blackbody radiance integrated over a wavelength band, W m⁻² sr⁻¹:
/// ∫_{λ1}^{λ2} L_λ(λ, T) dλ, exact (series), via the substitution x = c2/(λT):
/// ∫ = (2 k⁴ T⁴ / (h³ c²)) [F(x(λ1)) − F(x(λ2))], F = [`planck_integral_0_to_x`].
pub fn planck_band_integral_w_m2_sr(lambda1_um: f64, lambda2_um: f64, temp_k: f64) -> f64 {
    if !(temp_k > 0.0) || !(lambda1_um > 0.0) || !(lambda2_um > lambda1_um) {
        return 0.0;
    }
    let x1 = C2_UM_K / (lambda1_um * temp_k); // larger x (shorter wavelength)
    let x2 = C2_UM_K / (lambda2_um * temp_k);
    let pref = 2.0 * K_J_K.powi(4) * temp_k.powi(4) / (H_J_S.powi(3) * C_M_S * C_M_S);
    let diff = if x2 >= 1.0 {
        // both in the exponential regime: subtract tails directly (no cancellation
        // against π⁴/15)
        tail(x2) - tail(x1)
    } else {
        planck_integral_0_to_x(x1) - planck_integral_0_to_x(x2)
    };
    (pref * diff).max(0.0)
}

/// Σₙ e^(−nx)(x³/n + 3x²/n² + 6x/n³ + 6/n⁴) = ∫ₓ^∞ t³/(eᵗ−1) dt, for x ≥ 1.
fn tail(x: f64) -> f64 {
    if x > 740.0 {
        return 0.0;
    }
    let mut s = 0.0;
    let mut n = 1.0f64;
    loop {
        let e = (-n * x).exp();
        let term = e
            * (x * x * x / n
                + 3.0 * x * x / (n * n)
                + 6.0 * x / (n * n * n)
                + 6.0 / (n * n * n * n));
        s += term;
        if term <= 1e-17 * s || n > 200.0 {
            break;
        }
        n += 1.0;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_match_codata() {
        // CODATA 2018: c1L = 1.191 042 972e-16 W m² sr⁻¹, c2 = 1.438 776 877e-2 m K
        assert!((C1L_W_M2_SR / 1.191_042_972e-16 - 1.0).abs() < 1e-9);
        assert!((C2_UM_K / 14_387.768_77 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn per_um_and_per_cm1_agree() {
        // L_ν = L_λ λ² / 1e4 (λ in µm, ν = 1e4/λ cm⁻¹)
        for &(lam, t) in &[(10.0, 300.0), (4.0, 500.0), (0.5, 5800.0), (25.0, 50.0)] {
            let lnu = planck_radiance_w_m2_sr_cm1(1.0e4 / lam, t);
            let llam = planck_radiance_w_m2_sr_um(lam, t);
            assert!(
                (lnu / (llam * lam * lam / 1e4) - 1.0).abs() < 1e-12,
                "{lam} {t}"
            );
        }
    }

    #[test]
    fn known_value_10um_300k() {
        // 9.924 W m⁻² sr⁻¹ µm⁻¹ (standard tabulation, e.g. spectralcalc)
        let l = planck_radiance_w_m2_sr_um(10.0, 300.0);
        assert!((l - 9.9242).abs() < 2e-3, "{l}");
    }

    #[test]
    fn derivative_matches_finite_difference() {
        for &(lam, t) in &[(10.0, 300.0), (4.0, 250.0), (1.0, 3000.0)] {
            let d = planck_dt_w_m2_sr_um_k(lam, t);
            let h = 1e-3;
            let fd = (planck_radiance_w_m2_sr_um(lam, t + h)
                - planck_radiance_w_m2_sr_um(lam, t - h))
                / (2.0 * h);
            assert!((d / fd - 1.0).abs() < 1e-7, "{lam} {t} {d} {fd}");
        }
    }

    #[test]
    fn integral_total_is_stefan_boltzmann() {
        // ∫₀^∞ L dλ = σT⁴/π
        let sigma = 5.670_374_419e-8;
        let t = 300.0;
        let l = planck_band_integral_w_m2_sr(1e-3, 1e7, t);
        assert!(
            (l / (sigma * t.powi(4) / std::f64::consts::PI) - 1.0).abs() < 1e-9,
            "{l}"
        );
    }

    #[test]
    fn series_branches_agree_at_switch() {
        // both series at the switch x = 1 agree with each other and with
        // scipy quad of t³/(eᵗ−1) over [0, 1]: 0.2248051880259382
        let a = bernoulli_series(1.0);
        let b = PI4_15 - tail(1.0);
        assert!((a - b).abs() < 1e-14, "{a} {b}");
        assert!((a / 0.224_805_188_025_938_2 - 1.0).abs() < 1e-13, "{a}");
    }
}
