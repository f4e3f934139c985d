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
    /// The graded mesh described in the module docs. A layered slab
    /// ([`SlabMaterial::layers`]) has a node on every interface, each layer
    /// meshed as a slab of its own (its first cell the smaller of its own
    /// `sqrt(κ_j·t_res)` and the cell above it grown by `max_growth`, at
    /// least two cells and its share of [`ThermSettings::nodes`]), so that
    /// every cell lies in one layer: the conductance between two nodes is
    /// `k_j/Δz` of the layer between them (the series resistance
    /// `Σ Δz/k` of what lies between the nodes, which is that one cell),
    /// and an interface node's control volume holds half a cell of each
    /// layer (`(ρc_j·Δz_j + ρc_{j+1}·Δz_{j+1})/2`). Flux is continuous
    /// across the interface and the steady profile is exact
    /// (piecewise linear, kinked at the interfaces).
    pub fn graded(mat: &SlabMaterial, s: &ThermSettings) -> Mesh {
        if !mat.layers.is_empty() {
            return Self::layered(mat, s);
        }
        let l = mat.thickness_m;
        let min_cells = s.nodes.max(2) - 1;
        let max_cells = s.max_nodes.max(s.nodes).max(2) - 1;
        let d0 = (mat.diffusivity_m2_s() * s.surface_time_s).sqrt();
        let sizes = cell_sizes(l, d0, min_cells, max_cells, s.max_growth);
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

    /// [`Mesh::graded`] of a layered slab.
    fn layered(mat: &SlabMaterial, s: &ThermSettings) -> Mesh {
        let layers = mat.layer_list();
        let total: f64 = layers.iter().map(|l| l.thickness_m).sum();
        let min_total = s.nodes.max(2) - 1;
        let mut max_left = s.max_nodes.max(s.nodes).max(2) - 1;
        let growth = s.max_growth.max(1.0 + 1e-6);
        let (mut z, mut cap, mut cond) = (vec![0.0], vec![0.0], Vec::new());
        let mut top_m = 0.0;
        let mut last_cell: Option<f64> = None;
        for (j, layer) in layers.iter().enumerate() {
            let own = (layer.diffusivity_m2_s() * s.surface_time_s).sqrt();
            let d0 = last_cell.map_or(own, |d| own.min(d * growth));
            let share = (min_total as f64 * layer.thickness_m / total).ceil() as usize;
            let layers_below = layers.len() - j - 1;
            let max_cells = max_left.saturating_sub(2 * layers_below).max(2);
            let min_cells = share.max(2).min(max_cells);
            let sizes = cell_sizes(layer.thickness_m, d0, min_cells, max_cells, s.max_growth);
            max_left = max_left.saturating_sub(sizes.len());
            let rc = layer.heat_capacity_j_m3k();
            let mut depth = top_m;
            for d in &sizes {
                *cap.last_mut().unwrap() += 0.5 * rc * d;
                cap.push(0.5 * rc * d);
                cond.push(layer.conductivity_w_mk / d);
                depth += d;
                z.push(depth);
            }
            top_m += layer.thickness_m;
            // the interface (and the back face) exactly where the layers put it
            *z.last_mut().unwrap() = top_m;
            last_cell = sizes.last().copied();
        }
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

/// The cell sizes of a slab of thickness `l`: `min_cells` equal cells when
/// they are no larger than `d0`, else a geometric series from `d0` with the
/// fewest cells (at least `min_cells`, at most `max_cells`) whose ratio is
/// at most `max_growth`, scaled to sum to `l`.
fn cell_sizes(l: f64, d0: f64, min_cells: usize, max_cells: usize, max_growth: f64) -> Vec<f64> {
    let growth = max_growth.max(1.0 + 1e-6);
    let mut cells = min_cells;
    if l / cells as f64 <= d0 {
        return vec![l / cells as f64; cells];
    }
    // Geometric series d0·(r^m − 1)/(r − 1) = L; add cells until r ≤ growth.
    loop {
        let m = cells as i32;
        let total = |r: f64| d0 * (r.powi(m) - 1.0) / (r - 1.0);
        let (mut lo, mut hi) = (1.0 + 1e-12, 2.0f64);
        while total(hi) < l {
            hi *= 2.0;
        }
        if total(lo) >= l {
            return vec![l / cells as f64; cells];
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if total(mid) < l { lo = mid } else { hi = mid }
        }
        let r = 0.5 * (lo + hi);
        if r <= growth || cells >= max_cells {
            let mut sizes: Vec<f64> = (0..cells).map(|i| d0 * r.powi(i as i32)).collect();
            let sum: f64 = sizes.iter().sum();
            for d in &mut sizes {
                *d *= l / sum;
            }
            return sizes;
        }
        cells += 1;
    }
}
