//! Standing objects on the terrain: `z = "terrain"` on an `[[object]]` or
//! one of its `[[object.instance]]`s moves each placed instance up or down
//! so that its anchor lies on the meshed terrain under it (optionally
//! tilted to the terrain's slope first).
//!
//! The ground is the terrain *mesh* the tracer sees (every `[[terrain]]`,
//! the highest where they overlap), not the DEM's bilinear surface, so an
//! object stands on the triangles it is rendered on. With M the instance's
//! transform (up axis, scale, rotate, translate of instance and object) and
//! P = M·p its placed vertices:
//!
//! - `anchor = "base"` (default): the anchor is the base centre
//!   a = (centre of P's x-y bounding box, min z of P). The object is moved
//!   so that its lowest point lies `offset` above the lowest point of the
//!   terrain under its footprint (P's x-y bounding box; exact for the
//!   piecewise-linear mesh: each terrain triangle is clipped to the box
//!   and the plane evaluated at the clipped polygon's corners). So no side
//!   of the base floats on a slope; the uphill side is sunk into it.
//! - `anchor = "origin"`: the anchor is the model's origin a = M·0; it is
//!   moved to `offset` above the terrain under a's (x, y).
//! - `align = "slope"`: first turn the object about a by the shortest
//!   rotation that takes +z to the terrain's normal (`origin`: of the
//!   triangle under a; `base`: the area-weighted mean normal over the
//!   footprint), then move a to `offset` above the terrain under a.
//!
//! `offset` is the z of `translate_m` (object's plus instance's): with
//! `z = "terrain"` it is the anchor's height above the ground, not a
//! coordinate. Every point of the footprint must have terrain under it (a
//! hole, or a footprint past a terrain's edge, is an error naming the
//! object, the point and the terrains' cover).

use glam::{DAffine3, DQuat, DVec3};

use crate::scene::error::SceneError;
use crate::scene::mesh::Mesh;
use crate::scene::spec::{Align, Anchor, ObjectSpec};
use crate::scene::tomlsrc::{Seg, TomlSource};

/// The terrain triangles of a scene, binned on an x-y grid for vertical
/// look-ups, in the tracer's local frame (double precision). It borrows
/// the terrain meshes and keeps 4 bytes per triangle and bin it meets.
pub struct Ground<'a> {
    meshes: &'a [Mesh],
    /// Triangle k of all meshes together lies in the mesh m with
    /// `first[m] <= k < first[m + 1]`.
    first: Vec<usize>,
    origin: DVec3,
    lo: [f64; 2],
    hi: [f64; 2],
    cell_m: f64,
    n: [usize; 2],
    /// CSR: the triangles of bin b are `items[start[b]..start[b + 1]]`
    /// (those facing up: seen from above, counter-clockwise).
    start: Vec<u32>,
    items: Vec<u32>,
}

/// The terrain under a footprint: its lowest point and mean normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Under {
    /// The lowest terrain point under the footprint, local frame, m.
    pub min_z_m: f64,
    /// Area-weighted mean of the unit normals (upward), normalised.
    pub normal: DVec3,
}

impl<'a> Ground<'a> {
    /// The ground of the terrain meshes (world coordinates) in the frame
    /// whose origin is `origin_m`.
    pub fn new(meshes: &'a [Mesh], origin_m: [f64; 3]) -> Ground<'a> {
        let mut first = vec![0];
        for m in meshes {
            first.push(first.last().unwrap() + m.triangles.len());
        }
        let mut g = Ground {
            meshes,
            first,
            origin: DVec3::from(origin_m),
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
            cell_m: 1.0,
            n: [1, 1],
            start: Vec::new(),
            items: Vec::new(),
        };
        let total = *g.first.last().unwrap();
        let up = |g: &Ground, k: usize| xy_cross(&g.tri(k)) > 0.0;
        let mut count = 0usize;
        for k in 0..total {
            if up(&g, k) {
                count += 1;
                for p in g.tri(k) {
                    g.lo = [g.lo[0].min(p.x), g.lo[1].min(p.y)];
                    g.hi = [g.hi[0].max(p.x), g.hi[1].max(p.y)];
                }
            }
        }
        if count == 0 {
            g.start = vec![0, 0];
            return g;
        }
        // About two triangles a bin, at most 2^12 bins a side.
        let bins = (count / 2).max(1) as f64;
        let (w, h) = ((g.hi[0] - g.lo[0]).max(1e-9), (g.hi[1] - g.lo[1]).max(1e-9));
        let cell_m = (w * h / bins).sqrt().max(1e-6);
        g.n = [
            ((w / cell_m).ceil() as usize).clamp(1, 1 << 12),
            ((h / cell_m).ceil() as usize).clamp(1, 1 << 12),
        ];
        g.cell_m = (w / g.n[0] as f64).max(h / g.n[1] as f64);
        let nb = g.n[0] * g.n[1];
        g.start = vec![0; nb + 1];
        for pass in 0..2 {
            let mut fill = g.start.clone();
            for k in 0..total {
                if !up(&g, k) {
                    continue;
                }
                let t = g.tri(k);
                let (a, b) = g.bin_range(
                    [
                        t[0].x.min(t[1].x).min(t[2].x),
                        t[0].y.min(t[1].y).min(t[2].y),
                    ],
                    [
                        t[0].x.max(t[1].x).max(t[2].x),
                        t[0].y.max(t[1].y).max(t[2].y),
                    ],
                );
                for j in a[1]..=b[1] {
                    for i in a[0]..=b[0] {
                        let bin = j * g.n[0] + i;
                        if pass == 0 {
                            g.start[bin + 1] += 1;
                        } else {
                            g.items[fill[bin] as usize] = k as u32;
                            fill[bin] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for b in 0..nb {
                    g.start[b + 1] += g.start[b];
                }
                g.items = vec![0; g.start[nb] as usize];
            }
        }
        g
    }

    /// Triangle k (of all meshes together), local frame.
    fn tri(&self, k: usize) -> [DVec3; 3] {
        let m = self.first.partition_point(|&f| f <= k) - 1;
        let mesh = &self.meshes[m];
        mesh.triangles[k - self.first[m]]
            .map(|i| DVec3::from(mesh.positions[i as usize]) - self.origin)
    }

    /// The inclusive bin range covering the box `lo`..`hi`.
    fn bin_range(&self, lo: [f64; 2], hi: [f64; 2]) -> ([usize; 2], [usize; 2]) {
        let f = |v: f64, k: usize| {
            (((v - self.lo[k]) / self.cell_m).floor().max(0.0) as usize).min(self.n[k] - 1)
        };
        ([f(lo[0], 0), f(lo[1], 1)], [f(hi[0], 0), f(hi[1], 1)])
    }

    /// The distinct triangles whose bins meet the box `lo`..`hi`.
    fn candidates(&self, lo: [f64; 2], hi: [f64; 2]) -> Vec<u32> {
        if self.items.is_empty()
            || hi[0] < self.lo[0]
            || hi[1] < self.lo[1]
            || lo[0] > self.hi[0]
            || lo[1] > self.hi[1]
        {
            return Vec::new();
        }
        let (a, b) = self.bin_range(lo, hi);
        let mut out = Vec::new();
        for j in a[1]..=b[1] {
            for i in a[0]..=b[0] {
                let bin = j * self.n[0] + i;
                let r = self.start[bin] as usize..self.start[bin + 1] as usize;
                out.extend_from_slice(&self.items[r]);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The terrain's height and unit normal at (x, y): the highest
    /// triangle whose x-y projection holds the point; `None` off the
    /// terrain or over a hole.
    pub fn at(&self, x: f64, y: f64) -> Option<(f64, DVec3)> {
        let mut best: Option<(f64, DVec3)> = None;
        for k in self.candidates([x, y], [x, y]) {
            let t = &self.tri(k as usize);
            let d = xy_cross(t);
            let w1 = ((t[2].x - t[0].x) * (y - t[0].y) - (t[2].y - t[0].y) * (x - t[0].x)) / -d;
            let w2 = ((t[1].x - t[0].x) * (y - t[0].y) - (t[1].y - t[0].y) * (x - t[0].x)) / d;
            let w0 = 1.0 - w1 - w2;
            let eps = -1e-12;
            if w0 >= eps && w1 >= eps && w2 >= eps {
                let z = w0 * t[0].z + w1 * t[1].z + w2 * t[2].z;
                if best.is_none_or(|(b, _)| z > b) {
                    best = Some((z, normal(t)));
                }
            }
        }
        best
    }

    /// The terrain under the box `lo`..`hi` (x-y, m): its lowest point
    /// (exact on the piecewise-linear mesh) and mean normal; `Err` with a
    /// point of the box that has no terrain under it.
    pub fn under(&self, lo: [f64; 2], hi: [f64; 2]) -> Result<Under, [f64; 2]> {
        let c = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        for p in [c, lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]] {
            if self.at(p[0], p[1]).is_none() {
                return Err(p);
            }
        }
        let mut min_z = f64::INFINITY;
        let mut area = 0.0;
        let mut nsum = DVec3::ZERO;
        for k in self.candidates(lo, hi) {
            let t = &self.tri(k as usize);
            let poly = clip(t, lo, hi);
            if poly.is_empty() {
                continue;
            }
            for p in &poly {
                min_z = min_z.min(p.z);
            }
            let a = polygon_area(&poly);
            area += a;
            nsum += normal(t) * a;
        }
        let box_area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        if box_area > 1e-12 && area < box_area * (1.0 - 1e-6) {
            // A hole inside the box: find a point of it for the message.
            let steps = 16;
            for j in 0..=steps {
                for i in 0..=steps {
                    let p = [
                        lo[0] + (hi[0] - lo[0]) * i as f64 / steps as f64,
                        lo[1] + (hi[1] - lo[1]) * j as f64 / steps as f64,
                    ];
                    if self.at(p[0], p[1]).is_none() {
                        return Err(p);
                    }
                }
            }
            return Err(c);
        }
        let normal = if nsum.length() > 0.0 {
            nsum.normalize()
        } else {
            self.at(c[0], c[1]).map_or(DVec3::Z, |(_, n)| n)
        };
        Ok(Under {
            min_z_m: min_z,
            normal,
        })
    }

    /// The x-y box the terrains cover, for messages.
    pub fn cover(&self) -> ([f64; 2], [f64; 2]) {
        (self.lo, self.hi)
    }
}

/// Twice the signed x-y area of a triangle (> 0: counter-clockwise seen
/// from above).
fn xy_cross(t: &[DVec3; 3]) -> f64 {
    (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x)
}

/// A triangle's unit normal, pointing up.
fn normal(t: &[DVec3; 3]) -> DVec3 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(DVec3::Z);
    if n.z < 0.0 { -n } else { n }
}

/// The part of triangle `t` above the box `lo`..`hi` (Sutherland-Hodgman
/// in x-y; z interpolated along the edges, so the corners lie on the
/// triangle's plane).
fn clip(t: &[DVec3; 3], lo: [f64; 2], hi: [f64; 2]) -> Vec<DVec3> {
    let mut poly: Vec<DVec3> = t.to_vec();
    // (axis, bound, keep where coordinate >= bound (true) or <= bound)
    for (axis, bound, above) in [
        (0, lo[0], true),
        (0, hi[0], false),
        (1, lo[1], true),
        (1, hi[1], false),
    ] {
        if poly.is_empty() {
            break;
        }
        let inside = |p: &DVec3| {
            let v = if axis == 0 { p.x } else { p.y };
            if above { v >= bound } else { v <= bound }
        };
        let mut out = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (ip, iq) = (inside(&p), inside(&q));
            if ip {
                out.push(p);
            }
            if ip != iq {
                let (vp, vq) = if axis == 0 { (p.x, q.x) } else { (p.y, q.y) };
                let s = (bound - vp) / (vq - vp);
                out.push(p + (q - p) * s);
            }
        }
        poly = out;
    }
    poly
}

/// The x-y area of a polygon (shoelace), m².
fn polygon_area(p: &[DVec3]) -> f64 {
    let mut s = 0.0;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        s += a.x * b.y - b.x * a.y;
    }
    (s / 2.0).abs()
}

/// How one instance stands: from its own keys, else its object's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stand {
    /// The point that stands on the ground.
    pub anchor: Anchor,
    /// Upright, or tilted to the slope.
    pub align: Align,
    /// Height of the anchor above the terrain, m (the z of `translate_m`,
    /// object's plus instance's).
    pub offset_m: f64,
}

/// The instances' stands of object `oi` (`None`: placed by its transform
/// alone, `z` unset), and the key (`z`) that asks for each; an `anchor` or
/// `align` without `z = "terrain"` is an error at its key.
#[allow(clippy::type_complexity)]
pub fn stands(
    src: &TomlSource,
    oi: usize,
    o: &ObjectSpec,
) -> Result<Vec<Option<(Stand, Vec<Seg>)>>, SceneError> {
    let obj_at = vec![Seg::Key("object".into()), Seg::Index(oi)];
    let key_at = |base: &[Seg], k: &str| {
        let mut p = base.to_vec();
        p.push(Seg::Key(k.into()));
        p
    };
    let one = |inst: Option<(usize, &crate::scene::spec::Transform)>| {
        let inst_at = inst.map(|(k, _)| {
            let mut p = obj_at.clone();
            p.extend([Seg::Key("instance".into()), Seg::Index(k)]);
            p
        });
        let i = inst.map(|(_, t)| t);
        let (z, z_at) = match i.and_then(|t| t.z) {
            Some(z) => (Some(z), inst_at.clone().unwrap_or(obj_at.clone())),
            None => (o.z, obj_at.clone()),
        };
        let anchor = i.and_then(|t| t.anchor).or(o.anchor);
        let align = i.and_then(|t| t.align).or(o.align);
        if z.is_none() {
            for (k, set, on_inst) in [
                (
                    "anchor",
                    anchor.is_some(),
                    i.is_some_and(|t| t.anchor.is_some()),
                ),
                (
                    "align",
                    align.is_some(),
                    i.is_some_and(|t| t.align.is_some()),
                ),
            ] {
                if set {
                    let base = if on_inst {
                        inst_at.clone().unwrap_or(obj_at.clone())
                    } else {
                        obj_at.clone()
                    };
                    return Err(src.invalid(
                        &key_at(&base, k),
                        format!(
                            "`{k}` says how an object stands on the terrain, but `z = \"terrain\"` \
                             is not set for it: add `z = \"terrain\"` (or remove `{k}`)"
                        ),
                    ));
                }
            }
            return Ok(None);
        }
        Ok(Some((
            Stand {
                anchor: anchor.unwrap_or_default(),
                align: align.unwrap_or_default(),
                offset_m: o.translate_m[2] + i.map_or(0.0, |t| t.translate_m[2]),
            },
            key_at(&z_at, "z"),
        )))
    };
    if o.instances.is_empty() {
        Ok(vec![one(None)?])
    } else {
        o.instances
            .iter()
            .enumerate()
            .map(|(k, t)| one(Some((k, t))))
            .collect()
    }
}

/// Where an instance could not stand: the point (local frame, m) with no
/// terrain under it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoGround {
    /// The point with no terrain under it (x, y), local frame, m.
    pub at_m: [f64; 2],
    /// What the point is, for the message (e.g. "its footprint").
    pub what: &'static str,
}

/// The transform `xf` (mesh → local frame) of an instance of `mesh`, moved
/// (and with `Align::Slope` turned) to stand on `ground` as `stand` says.
/// A transform that places a vertex at a non-finite position is returned
/// unchanged (the loader refuses it with its own message).
pub fn stand(
    mesh: &Mesh,
    xf: DAffine3,
    stand: &Stand,
    ground: &Ground,
) -> Result<DAffine3, NoGround> {
    let placed = |xf: &DAffine3| -> Option<(DVec3, DVec3)> {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for t in &mesh.triangles {
            for &i in t {
                let p = xf.transform_point3(DVec3::from(mesh.positions[i as usize]));
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    };
    let Some((lo, hi)) = placed(&xf) else {
        return Ok(xf);
    };
    let anchor = match stand.anchor {
        Anchor::Base => DVec3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, lo.z),
        Anchor::Origin => xf.translation,
    };
    let under_box = |lo: DVec3, hi: DVec3| {
        ground
            .under([lo.x, lo.y], [hi.x, hi.y])
            .map_err(|p| NoGround {
                at_m: p,
                what: "its footprint",
            })
    };
    let at_anchor = |a: DVec3| {
        ground.at(a.x, a.y).ok_or(NoGround {
            at_m: [a.x, a.y],
            what: match stand.anchor {
                Anchor::Base => "its base centre",
                Anchor::Origin => "its origin",
            },
        })
    };
    let (xf, ground_z, anchor_z) = match (stand.align, stand.anchor) {
        (Align::Upright, Anchor::Base) => {
            let u = under_box(lo, hi)?;
            (xf, u.min_z_m, lo.z)
        }
        (Align::Upright, Anchor::Origin) => {
            let (z, _) = at_anchor(anchor)?;
            (xf, z, anchor.z)
        }
        (Align::Slope, a) => {
            let n = match a {
                Anchor::Base => under_box(lo, hi)?.normal,
                Anchor::Origin => at_anchor(anchor)?.1,
            };
            let turn = DAffine3::from_translation(anchor)
                * DAffine3::from_quat(DQuat::from_rotation_arc(DVec3::Z, n))
                * DAffine3::from_translation(-anchor);
            let xf = turn * xf;
            if let Some((lo, hi)) = placed(&xf) {
                under_box(lo, hi)?;
            }
            let (z, _) = at_anchor(anchor)?;
            (xf, z, anchor.z)
        }
    };
    let dz = ground_z + stand.offset_m - anchor_z;
    Ok(DAffine3::from_translation(DVec3::new(0.0, 0.0, dz)) * xf)
}
