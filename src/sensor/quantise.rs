//! Quantisation: digital number DN = clamp(round(gain·(L − offset)), 0,
//! 2^bits − 1), the radiometric quantisation the paper applies to its images.

use serde::{Deserialize, Serialize};

/// Quantiser settings: `gain` in DN per unit of the input (e.g. per
/// W m⁻² sr⁻¹ µm⁻¹), `offset` in input units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quantiser {
    /// Bits per DN (the largest DN is 2^bits − 1).
    pub bits: u32,
    /// DN per unit of the input.
    pub gain: f64,
    /// Input value subtracted before the gain, input units.
    pub offset: f64,
}

impl Quantiser {
    /// Largest DN.
    pub fn max_dn(&self) -> f64 {
        (2f64).powi(self.bits.clamp(1, 32) as i32) - 1.0
    }

    /// DN of one value (non-finite input → 0).
    pub fn dn(&self, value: f64) -> f64 {
        if !value.is_finite() {
            return 0.0;
        }
        (self.gain * (value - self.offset))
            .round()
            .clamp(0.0, self.max_dn())
    }

    /// The input value a DN stands for (centre of its bin).
    pub fn value(&self, dn: f64) -> f64 {
        dn / self.gain + self.offset
    }

    /// A quantiser that maps [lo, hi] onto the full DN range.
    pub fn spanning(bits: u32, lo: f64, hi: f64) -> Self {
        let q = Quantiser {
            bits,
            gain: 1.0,
            offset: lo,
        };
        Quantiser {
            gain: q.max_dn() / (hi - lo),
            ..q
        }
    }
}
