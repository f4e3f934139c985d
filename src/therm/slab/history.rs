//! A pixel's sun/shadow history and the sunlit fraction it puts in force.

use serde::{Deserialize, Serialize};

use super::*;

/// A pixel's sun/shadow history: `sunlit[i]` is the flag sampled at
/// `start_s + i·interval_s` (seconds on the forcing clock).
///
/// **Mapping rule** (nearest sample): at time t the flag in force is sample
/// `i = floor((t − start_s)/interval_s + 0.5)`, so sample i covers
/// `[t_i − Δ/2, t_i + Δ/2)`. Times after the last sample use the last
/// sample; times before the first use the periodic extension with period
/// `len·interval_s` (24 h for the default 48 × 30 min, i.e. the same time of
/// day), which is what the spin-up before the traced window needs.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SunHistory {
    /// Time of sample 0, s from the start of the run.
    pub start_s: i64,
    /// Interval between samples, s.
    pub interval_s: i64,
    /// Sunlit flag of each sample (true: the facet sees the sun).
    pub sunlit: Vec<bool>,
}

impl SunHistory {
    /// Default sampling: 48 samples per 24 h (every 30 min).
    pub const DEFAULT_INTERVAL_S: i64 = 1800;
    /// Default number of samples (48 × 30 min = 24 h).
    pub const DEFAULT_SAMPLES: usize = 48;

    fn index_at(&self, t_s: f64) -> usize {
        let n = self.sunlit.len() as i64;
        let i = ((t_s - self.start_s as f64) / self.interval_s as f64 + 0.5).floor() as i64;
        if i >= n {
            (n - 1) as usize
        } else {
            i.rem_euclid(n) as usize
        }
    }

    /// The flag in force at `t_s` (true = sunlit).
    pub fn sunlit_at(&self, t_s: f64) -> bool {
        if self.sunlit.is_empty() {
            return true;
        }
        self.sunlit[self.index_at(t_s)]
    }

    /// The flag of sample `i` with the history's extension rules (after
    /// the last: the last; before the first: periodic).
    fn flag(&self, i: i64) -> f64 {
        let n = self.sunlit.len() as i64;
        let k = if i >= n { n - 1 } else { i.rem_euclid(n) };
        if self.sunlit[k as usize] { 1.0 } else { 0.0 }
    }

    /// The sunlit fraction at `t_s`, 0 … 1: the flags interpolated linearly
    /// between sample times. A shadow edge crosses a facet over a time, not
    /// at one instant; between two samples that disagree the linear ramp is
    /// the first-order estimate of the sunlit fraction, where the
    /// nearest-sample rule of [`SunHistory::sunlit_at`] made an hourly
    /// "staircase" of step changes (issue 11, item 7).
    pub fn sunlit_fraction_at(&self, t_s: f64) -> f64 {
        if self.sunlit.is_empty() || self.interval_s <= 0 {
            return 1.0;
        }
        let x = (t_s - self.start_s as f64) / self.interval_s as f64;
        let i0 = x.floor();
        let w = x - i0;
        let i0 = i0 as i64;
        (1.0 - w) * self.flag(i0) + w * self.flag(i0 + 1)
    }

    /// The sunlit fraction averaged over `[t0_s, t1_s]` (exactly: the
    /// fraction is piecewise linear under the ramp rule, piecewise constant
    /// under the nearest-sample rule, and each piece is integrated in
    /// closed form); `t1_s <= t0_s` gives the fraction at `t0_s`.
    ///
    /// A backward-Euler step of the march takes this as the sunlit
    /// fraction in force over the step: the absorbed direct-beam energy
    /// of the step is then the exact integral of the history's, so a step
    /// need not end where a shadow comes or goes, and the step control
    /// alone decides how finely a transition is resolved.
    pub fn mean_fraction(&self, t0_s: f64, t1_s: f64, ramp: bool) -> f64 {
        if self.sunlit.is_empty() || self.interval_s <= 0 {
            return 1.0;
        }
        if t1_s.partial_cmp(&t0_s) != Some(std::cmp::Ordering::Greater) {
            return if ramp {
                self.sunlit_fraction_at(t0_s)
            } else if self.sunlit_at(t0_s) {
                1.0
            } else {
                0.0
            };
        }
        let d = self.interval_s as f64;
        // Sample units; under the nearest-sample rule, shifted by half a
        // sample so that the constant pieces are [k, k + 1).
        let shift = if ramp { 0.0 } else { 0.5 };
        let xa = (t0_s - self.start_s as f64) / d + shift;
        let xb = (t1_s - self.start_s as f64) / d + shift;
        let mut k = xa.floor();
        let mut sum = 0.0;
        while k < xb {
            let (u, v) = (xa.max(k), xb.min(k + 1.0));
            let ki = k as i64;
            let f0 = self.flag(ki);
            if ramp {
                let f1 = self.flag(ki + 1);
                sum += (v - u) * (f0 + (0.5 * (u + v) - k) * (f1 - f0));
            } else {
                sum += (v - u) * f0;
            }
            k += 1.0;
        }
        (sum / (xb - xa)).clamp(0.0, 1.0)
    }

    /// Times in the open interval (t0, t1) where the flag changes under the
    /// nearest-sample rule (half-way between two samples that disagree).
    pub fn switch_times(&self, t0: f64, t1: f64) -> Vec<f64> {
        let mut out = Vec::new();
        if self.sunlit.len() < 2 || self.interval_s <= 0 {
            return out;
        }
        let d = self.interval_s as f64;
        let k0 = ((t0 - self.start_s as f64) / d - 0.5).floor() as i64 - 1;
        let k1 = ((t1 - self.start_s as f64) / d - 0.5).ceil() as i64 + 1;
        for k in k0..=k1 {
            // boundary between samples k and k+1
            let tb = self.start_s as f64 + (k as f64 + 0.5) * d;
            if tb > t0 && tb < t1 && self.sunlit_at(tb - 0.25 * d) != self.sunlit_at(tb + 0.25 * d)
            {
                out.push(tb);
            }
        }
        out
    }

    /// Times in the open interval (t0, t1) where the sunlit fraction has a
    /// kink: the sample times next to a change of flag (the ends of each
    /// linear ramp of [`SunHistory::sunlit_fraction_at`]).
    pub fn ramp_kinks(&self, t0: f64, t1: f64) -> Vec<f64> {
        let mut out = Vec::new();
        if self.sunlit.len() < 2 || self.interval_s <= 0 {
            return out;
        }
        let d = self.interval_s as f64;
        let k0 = ((t0 - self.start_s as f64) / d).floor() as i64 - 1;
        let k1 = ((t1 - self.start_s as f64) / d).ceil() as i64 + 1;
        for k in k0..=k1 {
            let tk = self.start_s as f64 + k as f64 * d;
            let kink = self.flag(k - 1) != self.flag(k) || self.flag(k) != self.flag(k + 1);
            if kink && tk > t0 && tk < t1 {
                out.push(tk);
            }
        }
        out
    }

    /// Packs the flags into 64-bit words (bit i of word i/64 = sample i).
    pub fn packed_bits(&self) -> Vec<u64> {
        let mut w = vec![0u64; self.sunlit.len().div_ceil(64)];
        for (i, &b) in self.sunlit.iter().enumerate() {
            if b {
                w[i / 64] |= 1 << (i % 64);
            }
        }
        w
    }

    pub(super) fn validate(&self) -> Result<(), ThermError> {
        if self.interval_s <= 0 || self.sunlit.is_empty() {
            return Err(ThermError::BadInput(format!(
                "sun/shadow history needs interval_s > 0 and at least one sample (got {} s, {} samples)",
                self.interval_s,
                self.sunlit.len()
            )));
        }
        Ok(())
    }
}

/// The sunlit fraction of an optional history averaged over `[t0_s, t1_s]`
/// (no history: 1; see [`SunHistory::mean_fraction`]).
pub fn mean_sun_fraction(shadow: Option<&SunHistory>, t0_s: f64, t1_s: f64, ramp: bool) -> f64 {
    shadow.map_or(1.0, |h| h.mean_fraction(t0_s, t1_s, ramp))
}

/// The sunlit fraction of an optional history at `t_s` (no history: 1):
/// the linear ramp between samples ([`SunHistory::sunlit_fraction_at`]) or,
/// with `ramp = false`, the nearest sample's flag (THERM's rule).
pub fn sun_fraction(shadow: Option<&SunHistory>, t_s: f64, ramp: bool) -> f64 {
    match shadow {
        None => 1.0,
        Some(h) if ramp => h.sunlit_fraction_at(t_s),
        Some(h) => {
            if h.sunlit_at(t_s) {
                1.0
            } else {
                0.0
            }
        }
    }
}
