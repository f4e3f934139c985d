//! Polygon triangulation. A face (3 or more vertices, possibly concave,
//! possibly not quite planar) is projected onto its best-fit plane, whose
//! normal is Newell's vector area N = ½ Σᵢ pᵢ × pᵢ₊₁ (Sutherland, Sproull
//! & Schumacker, "A characterization of ten hidden-surface algorithms",
//! ACM Comput. Surv. 6(1), 1974; Ericson, *Real-Time Collision Detection*,
//! 2005, §12.5.1), and split there: a convex polygon into a fan from its
//! first vertex (what every OBJ reader does, so convex faces keep their
//! triangles), any other by ear clipping (the `earcut` crate, a port of
//! Mapbox's earcut, which also handles "keyhole" polygons whose bridge
//! edges run there and back). A polygon whose edges cross, or that draws
//! the same stretch twice in one direction, has no inside to fill and is
//! refused; as a last check the triangles' area must equal the polygon's.

use glam::{DVec2, DVec3};

/// Polygons with more vertices than this skip the O(n²) edge-crossing
/// test; the area check still refuses a self-intersecting one.
const MAX_CROSSING_TEST: usize = 4096;

/// Why a polygon cannot be triangulated (vertex numbers are 1-based
/// positions in the face: edge k runs from vertex k to vertex k + 1).
#[derive(Clone, Debug, PartialEq)]
pub enum PolygonError {
    /// Two edges (each given by its two vertices) cross.
    Crossing {
        /// The first edge's vertices.
        a: [usize; 2],
        /// The second edge's vertices.
        b: [usize; 2],
    },
    /// Two edges run along the same stretch in the same direction.
    Overlap {
        /// The first edge's vertices.
        a: [usize; 2],
        /// The second edge's vertices.
        b: [usize; 2],
    },
    /// The triangles do not cover the polygon's area (it winds around or
    /// touches itself in a way ear clipping cannot resolve).
    Area {
        /// The polygon's area.
        polygon: f64,
        /// The triangles' total area.
        triangles: f64,
    },
}

impl std::fmt::Display for PolygonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let edge = |e: [usize; 2]| format!("{}→{}", e[0], e[1]);
        let fix = "expected a simple polygon: split the face into polygons whose edges \
                   neither cross nor retrace each other";
        match *self {
            PolygonError::Crossing { a, b } => write!(
                f,
                "self-intersecting polygon: its edges {} and {} cross (vertices counted from 1 \
                 in the face); {fix}",
                edge(a),
                edge(b)
            ),
            PolygonError::Overlap { a, b } => write!(
                f,
                "self-overlapping polygon: its edges {} and {} run along the same stretch in \
                 the same direction (vertices counted from 1 in the face); {fix}",
                edge(a),
                edge(b)
            ),
            PolygonError::Area { polygon, triangles } => write!(
                f,
                "self-intersecting polygon: its triangles cover {triangles:.6e} square units \
                 but the polygon encloses {polygon:.6e}; {fix}"
            ),
        }
    }
}

/// Triangles of the polygon `p` as indices into `p`, each counter-clockwise
/// about the polygon's normal (the winding of the face is kept). A polygon
/// with no area (all vertices on a line) gives its fan, whose triangles are
/// all degenerate (the scene loader skips and counts them).
pub fn triangulate(p: &[DVec3]) -> Result<Vec<[usize; 3]>, PolygonError> {
    let n = p.len();
    if n < 3 {
        return Ok(Vec::new());
    }
    if n == 3 {
        return Ok(vec![[0, 1, 2]]);
    }
    let Some(q) = project(p) else {
        return Ok(fan(n));
    };
    if n <= MAX_CROSSING_TEST {
        check_edges(&q)?;
    }
    if is_convex(&q) {
        return Ok(fan(n));
    }
    let mut idx: Vec<u32> = Vec::with_capacity(3 * (n - 2));
    earcut::Earcut::new().earcut(q.iter().map(|v| [v.x, v.y]), &[] as &[u32], &mut idx);
    let tris: Vec<[usize; 3]> = idx
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            if orient(q[a], q[b], q[c]) < 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    let polygon = shoelace(&q);
    let triangles: f64 = tris
        .iter()
        .map(|t| 0.5 * orient(q[t[0]], q[t[1]], q[t[2]]).abs())
        .sum();
    let scale2 = q.iter().map(|v| v.length_squared()).fold(0.0, f64::max);
    if (triangles - polygon).abs() > 1e-9 * n as f64 * scale2.max(f64::MIN_POSITIVE) {
        return Err(PolygonError::Area { polygon, triangles });
    }
    Ok(tris)
}

/// The fan from the first vertex: (0, 1, 2), (0, 2, 3), ...
pub fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n.saturating_sub(1)).map(|j| [0, j, j + 1]).collect()
}

/// Newell's normal of `p` (twice the vector area), computed about `p[0]`
/// so far-off coordinates keep their precision.
pub fn newell_normal(p: &[DVec3]) -> DVec3 {
    let o = p[0];
    let n = p.len();
    (0..n).fold(DVec3::ZERO, |acc, i| {
        acc + (p[i] - o).cross(p[(i + 1) % n] - o)
    })
}

/// The polygon in 2-D coordinates of its best-fit plane, counter-clockwise
/// (positive area); `None` when it has no plane (all vertices on a line).
fn project(p: &[DVec3]) -> Option<Vec<DVec2>> {
    let o = p[0];
    let d: Vec<DVec3> = p.iter().map(|v| *v - o).collect();
    let scale2 = d.iter().map(|v| v.length_squared()).fold(0.0, f64::max);
    let tiny = 1e-24 * scale2;
    let mut normal = newell_normal(p);
    if normal.length_squared() <= tiny * tiny || !normal.is_finite() {
        // No net area (e.g. a figure of eight whose halves cancel): the
        // plane through the farthest vertex and the one farthest off that
        // line, so the crossing test below can still see the polygon.
        let far = d
            .iter()
            .copied()
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?;
        normal = d
            .iter()
            .map(|v| far.cross(*v))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?;
        if normal.length_squared() <= tiny * tiny || !normal.is_finite() {
            return None;
        }
    }
    let w = normal.normalize();
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let mut q: Vec<DVec2> = d.iter().map(|x| DVec2::new(x.dot(u), x.dot(v))).collect();
    if shoelace_signed(&q) < 0.0 {
        q.iter_mut().for_each(|x| x.y = -x.y);
    }
    Some(q)
}

/// Twice the signed area of triangle (a, b, c): > 0 counter-clockwise.
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

fn shoelace_signed(q: &[DVec2]) -> f64 {
    let n = q.len();
    0.5 * (0..n).map(|i| q[i].perp_dot(q[(i + 1) % n])).sum::<f64>()
}

/// The polygon's area (its winding made positive by [`project`]).
fn shoelace(q: &[DVec2]) -> f64 {
    shoelace_signed(q).abs()
}

/// Convex: every turn is to the left or straight on (no spikes).
fn is_convex(q: &[DVec2]) -> bool {
    let n = q.len();
    (0..n).all(|i| {
        let a = q[(i + n - 1) % n];
        let (b, c) = (q[i], q[(i + 1) % n]);
        let (e1, e2) = (b - a, c - b);
        let cross = e1.perp_dot(e2);
        let tol = 1e-12 * e1.length() * e2.length();
        cross > tol || (cross >= -tol && e1.dot(e2) > 0.0)
    })
}

/// The 1-based vertex numbers of edge `i` of an `n`-gon.
fn edge_ends(i: usize, n: usize) -> [usize; 2] {
    [i + 1, (i + 1) % n + 1]
}

/// Refuses crossing edges and edges retraced in the same direction;
/// touching, and a bridge drawn there and back, are allowed.
fn check_edges(q: &[DVec2]) -> Result<(), PolygonError> {
    let n = q.len();
    for i in 0..n {
        let (a, b) = (q[i], q[(i + 1) % n]);
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            let (c, d) = (q[j], q[(j + 1) % n]);
            let (o1, o2) = (orient(a, b, c), orient(a, b, d));
            let (o3, o4) = (orient(c, d, a), orient(c, d, b));
            if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
                return Err(PolygonError::Crossing {
                    a: edge_ends(i, n),
                    b: edge_ends(j, n),
                });
            }
            if o1 == 0.0 && o2 == 0.0 && a != b && c != d {
                let dir = b - a;
                let len2 = dir.length_squared();
                let (tc, td) = ((c - a).dot(dir) / len2, (d - a).dot(dir) / len2);
                let overlap = tc.max(td).min(1.0) - tc.min(td).max(0.0);
                if overlap > 1e-12 && td > tc {
                    return Err(PolygonError::Overlap {
                        a: edge_ends(i, n),
                        b: edge_ends(j, n),
                    });
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area3(p: &[DVec3], t: &[[usize; 3]]) -> f64 {
        t.iter()
            .map(|t| 0.5 * (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).length())
            .sum()
    }

    fn pts(xy: &[[f64; 2]]) -> Vec<DVec3> {
        xy.iter().map(|v| DVec3::new(v[0], v[1], 0.0)).collect()
    }

    /// A U (30 m × 30 m with a 10 m × 20 m notch): area 700 m² by hand.
    const U: [[f64; 2]; 8] = [
        [0.0, 0.0],
        [30.0, 0.0],
        [30.0, 30.0],
        [20.0, 30.0],
        [20.0, 10.0],
        [10.0, 10.0],
        [10.0, 30.0],
        [0.0, 30.0],
    ];

    #[test]
    fn concave_u_covers_its_true_area_with_the_face_winding() {
        let p = pts(&U);
        let t = triangulate(&p).unwrap();
        assert_eq!(t.len(), 6);
        assert!((area3(&p, &t) - 700.0).abs() < 1e-9);
        for t in &t {
            let n = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
            assert!(n.z > 0.0, "triangle {t:?} flipped");
        }
        // the fan of the same U also covers the notch
        let f = fan(8);
        assert!(area3(&p, &f) > 700.0 + 1.0);
    }

    #[test]
    fn convex_polygons_keep_the_fan() {
        let p: Vec<DVec3> = (0..24)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 24.0;
                DVec3::new(a.cos(), a.sin(), 0.3 * a.cos())
            })
            .collect();
        assert_eq!(triangulate(&p).unwrap(), fan(24));
        // a collinear vertex on an edge stays convex
        let sq = pts(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
        assert_eq!(triangulate(&sq).unwrap(), fan(5));
    }

    #[test]
    fn clockwise_and_non_planar_concave_polygons() {
        // the U reversed (clockwise seen from +z): triangles keep that winding
        let mut p = pts(&U);
        p.reverse();
        let t = triangulate(&p).unwrap();
        assert!((area3(&p, &t) - 700.0).abs() < 1e-9);
        for t in &t {
            let n = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
            assert!(n.z < 0.0);
        }
        // the U tilted 30° about x and warped by ±1 cm: projected area
        // 700 m² on its best-fit plane, within the warp's effect
        let (s, c) = 30f64.to_radians().sin_cos();
        let p: Vec<DVec3> = U
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let w = if k % 2 == 0 { 0.01 } else { -0.01 };
                DVec3::new(v[0], v[1] * c - w * s, v[1] * s + w * c)
            })
            .collect();
        let t = triangulate(&p).unwrap();
        assert_eq!(t.len(), 6);
        assert!((area3(&p, &t) - 700.0).abs() < 0.01, "{}", area3(&p, &t));
    }

    #[test]
    fn self_intersections_are_refused() {
        let bowtie = pts(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(
            triangulate(&bowtie),
            Err(PolygonError::Crossing {
                a: [1, 2],
                b: [3, 4]
            })
        );
        // a square drawn twice round
        let twice = pts(&[
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
        ]);
        assert_eq!(
            triangulate(&twice),
            Err(PolygonError::Overlap {
                a: [1, 2],
                b: [5, 6]
            })
        );
        let msg = PolygonError::Crossing {
            a: [1, 2],
            b: [8, 1],
        }
        .to_string();
        assert!(msg.contains("edges 1→2 and 8→1 cross"), "{msg}");
    }

    #[test]
    fn keyhole_ring_covers_the_ring() {
        // an outer square 4 × 4 and an inner 2 × 2 hole joined by a bridge
        // drawn there and back: area 16 − 4 = 12
        let p = pts(&[
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [0.0, 0.0],
            [1.0, 1.0],
            [1.0, 3.0],
            [3.0, 3.0],
            [3.0, 1.0],
            [1.0, 1.0],
        ]);
        let t = triangulate(&p).unwrap();
        assert!((area3(&p, &t) - 12.0).abs() < 1e-9, "{}", area3(&p, &t));
    }

    #[test]
    fn collinear_polygons_give_degenerate_fans() {
        let p = pts(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]);
        assert_eq!(triangulate(&p).unwrap(), fan(4));
        assert_eq!(area3(&p, &fan(4)), 0.0);
    }
}
