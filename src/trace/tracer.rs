//! The [`Tracer`] trait every backend implements, and the choice of
//! backend and query mode.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::ray::{Hit, Ray};

/// Which backend traces the rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// Embree (system library through the C shim), 16-wide packets.
    Embree,
    /// obvhs BVH (pure Rust), single rays.
    Bvh,
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Backend::Embree => "embree",
            Backend::Bvh => "bvh",
        })
    }
}

/// How a backend issues queries. Packets are used for groups of rays that
/// callers order by 4x4 pixel tile; `Single` forces one ray per call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum QueryMode {
    #[default]
    /// Groups of 16 rays per Embree call (`rtcIntersect16`/`rtcOccluded16`).
    Packet16,
    /// One ray per call.
    Single,
}

/// Ray queries over a committed, read-only scene. Implementations are
/// shared across rayon threads.
pub trait Tracer: Send + Sync {
    /// Which backend answers the queries.
    fn backend(&self) -> Backend;
    /// Closest hit of each ray (`hits.len() == rays.len()`). Rays are taken
    /// in groups of 16 in order: for coherent packets, order rays by tile.
    /// Invalid rays (non-finite or zero direction) never hit.
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]);
    /// Whether anything blocks each ray within `[tnear, tfar]`.
    fn occluded(&self, rays: &[Ray], blocked: &mut [bool]);
    /// Shadow queries from up to 16 origins toward several directions (the
    /// solar history of a group of points: one sun direction at a time).
    /// For each `k`, the origins whose lane bit is set in `active[k]` are
    /// queried toward `dirs[k]`, and `blocked[k]` gets the lanes whose ray
    /// is blocked: lane `i` of `blocked[k]` is [`Self::occluded`] of
    /// `Ray::new(origins[i], dirs[k])` where `active[k]` has it, else 0.
    /// Backends may fill a packet's origins once for all directions (no
    /// [`Ray`] per query).
    fn occluded_fan(&self, origins: &[Vec3], dirs: &[Vec3], active: &[u16], blocked: &mut [u16]) {
        assert!(origins.len() <= 16, "at most 16 origins");
        assert!(dirs.len() == active.len() && dirs.len() == blocked.len());
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); 16];
        let (mut lanes, mut hit) = ([0usize; 16], [false; 16]);
        for ((dir, &act), out) in dirs.iter().zip(active).zip(blocked.iter_mut()) {
            let mut m = 0;
            for (lane, o) in origins.iter().enumerate() {
                if act >> lane & 1 == 1 {
                    rays[m] = Ray::new(*o, *dir);
                    lanes[m] = lane;
                    m += 1;
                }
            }
            self.occluded(&rays[..m], &mut hit[..m]);
            *out = (lanes[..m].iter().zip(&hit[..m]))
                .filter(|(_, b)| **b)
                .fold(0, |acc, (lane, _)| acc | 1 << lane);
        }
    }
}
