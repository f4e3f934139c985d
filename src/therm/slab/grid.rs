//! The graded node-centred finite-volume mesh of one slab (module docs of
//! [`super`], "Space").

use super::*;

/// The spatial mesh of one slab.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Node depths from the exposed surface, m (`z[0] = 0`, last = L).
    pub z_m: Vec<f64>,
    /// Heat capacity of each node's control volume, J m⁻² K⁻¹.
    pub cap_j_m2k: Vec<f64>,
    /// Conductance between node i and i+1, W m⁻² K⁻¹.
    pub cond_w_m2k: Vec<f64>,
}

impl Mesh {
    /// The graded mesh described in the module docs.
    pub fn graded(mat: &SlabMaterial, s: &ThermSettings) -> Mesh {
        let l = mat.thickness_m;
        let min_cells = s.nodes.max(2) - 1;
        let max_cells = s.max_nodes.max(s.nodes).max(2) - 1;
        let d0 = (mat.diffusivity_m2_s() * s.surface_time_s).sqrt();
        let growth = s.max_growth.max(1.0 + 1e-6);
        let mut cells = min_cells;
        let mut sizes: Vec<f64>;
        if l / cells as f64 <= d0 {
            sizes = vec![l / cells as f64; cells];
        } else {
            // Geometric series d0·(r^m − 1)/(r − 1) = L; add cells until r ≤ growth.
            loop {
                let m = cells as i32;
                let total = |r: f64| d0 * (r.powi(m) - 1.0) / (r - 1.0);
                let (mut lo, mut hi) = (1.0 + 1e-12, 2.0f64);
                while total(hi) < l {
                    hi *= 2.0;
                }
                if total(lo) >= l {
                    sizes = vec![l / cells as f64; cells];
                    break;
                }
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if total(mid) < l { lo = mid } else { hi = mid }
                }
                let r = 0.5 * (lo + hi);
                if r <= growth || cells >= max_cells {
                    sizes = (0..cells).map(|i| d0 * r.powi(i as i32)).collect();
                    let sum: f64 = sizes.iter().sum();
                    for d in &mut sizes {
                        *d *= l / sum;
                    }
                    break;
                }
                cells += 1;
            }
        }
        let mut z = vec![0.0];
        for d in &sizes {
            z.push(z.last().unwrap() + d);
        }
        *z.last_mut().unwrap() = l;
        let rc = mat.density_kg_m3 * mat.specific_heat_j_kgk;
        let n = z.len();
        let mut cap = vec![0.0; n];
        for (i, d) in sizes.iter().enumerate() {
            cap[i] += 0.5 * rc * d;
            cap[i + 1] += 0.5 * rc * d;
        }
        let cond = sizes.iter().map(|d| mat.conductivity_w_mk / d).collect();
        Mesh {
            z_m: z,
            cap_j_m2k: cap,
            cond_w_m2k: cond,
        }
    }

    /// This (soil) mesh under a canopy skin: a node 0 of heat capacity
    /// `cap_j_m2k` prepended, coupled to the soil surface (now node 1)
    /// through `cond_w_m2k` (the skin conductance Λ_sk of the ECMWF land
    /// surface scheme, [`crate::therm::aero::Canopy`]). The skin stands on
    /// the soil: its depth is 0 like the soil surface's.
    pub fn with_skin(&self, cap_j_m2k: f64, cond_w_m2k: f64) -> Mesh {
        let mut z = Vec::with_capacity(self.z_m.len() + 1);
        z.push(0.0);
        z.extend_from_slice(&self.z_m);
        let mut cap = Vec::with_capacity(z.len());
        cap.push(cap_j_m2k);
        cap.extend_from_slice(&self.cap_j_m2k);
        let mut cond = Vec::with_capacity(z.len() - 1);
        cond.push(cond_w_m2k);
        cond.extend_from_slice(&self.cond_w_m2k);
        Mesh {
            z_m: z,
            cap_j_m2k: cap,
            cond_w_m2k: cond,
        }
    }

    /// Stored heat relative to 0 K, `Σ C_i·T_i`, J/m².
    pub fn stored_energy_j_m2(&self, temps_k: &[f64]) -> f64 {
        self.cap_j_m2k.iter().zip(temps_k).map(|(c, t)| c * t).sum()
    }
}
