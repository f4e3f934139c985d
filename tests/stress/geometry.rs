//! Geometry extremes: a scene translated 50 km from the origin, 10 km
//! terrain, slivers down to aspect 1e-6, stacks of coplanar overlapping
//! facets; rays aimed at facets, grazing, axis-aligned and invalid. Both
//! backends (Embree, obvhs) must give finite hits with t ≥ 0 and
//! barycentrics in [0, 1] (within 1e-4) that lie on the ray, and robust
//! secondary origins must be finite, on the normal's side of the facet and
//! never re-hit their own facet.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use irsig::bench::crosscheck::{self, RayKind, RaySet, Report, Tolerances};
use irsig::trace::meshgen::{self, MeshBuilder, SplitMix};
use irsig::trace::offset::offset_origin;
use irsig::trace::{self, Backend, Geometry, Hit, Ray, Tracer};

fn translated(mut m: MeshBuilder, by: Vec3) -> MeshBuilder {
    m.positions.iter_mut().for_each(|p| *p += by);
    m
}

/// Slivers (aspect 1e-2 to 1e-6, some of them zero-area in f32) and
/// stacks of coplanar overlapping facets around `c`.
fn slivers_and_coplanar(c: Vec3) -> MeshBuilder {
    let mut m = MeshBuilder::new();
    m.grid(
        c + Vec3::new(-30.0, -30.0, 0.0),
        (60.0, 60.0),
        (6, 6),
        |_, _| 0.0,
    );
    for (k, aspect) in [1e-2f32, 1e-4, 1e-6].iter().enumerate() {
        m.slivers(
            c + Vec3::new(-15.0 + 15.0 * k as f32, 10.0, 1.0),
            6.0,
            *aspect,
            32,
        );
        // vertical slivers too
        let b = c + Vec3::new(-15.0 + 15.0 * k as f32, -10.0, 0.0);
        m.triangle(
            b,
            b + Vec3::new(6.0 * aspect, 0.0, 0.0),
            b + Vec3::new(0.0, 0.0, 8.0),
        );
    }
    // the same facet five times, and shifted overlapping copies, at z = 2
    let z = c + Vec3::new(0.0, -20.0, 2.0);
    for k in 0..5 {
        m.triangle(
            z,
            z + Vec3::new(8.0, 0.0, 0.0),
            z + Vec3::new(8.0, 8.0, 0.0),
        );
        let s = z + Vec3::new(1.5 * k as f32, 0.7 * k as f32, 0.0);
        m.triangle(
            s,
            s + Vec3::new(8.0, 0.0, 0.0),
            s + Vec3::new(0.0, 8.0, 0.0),
        );
    }
    // coplanar overlapping vertical walls
    let w = c + Vec3::new(20.0, -25.0, 0.0);
    m.cuboid(w, w + Vec3::new(4.0, 4.0, 6.0));
    m.cuboid(w + Vec3::new(0.0, 1.0, 0.0), w + Vec3::new(4.0, 5.0, 6.0));
    m.degenerate(c + Vec3::new(5.0, 5.0, 1.0));
    m
}

fn scenes() -> Vec<(&'static str, MeshBuilder)> {
    let far = Vec3::new(50_000.0, -50_000.0, 1_000.0);
    let mut terrain_10km = meshgen::terrain(10_000.0, 48, 1_000.0);
    terrain_10km.cuboid(
        Vec3::new(100.0, 100.0, 990.0),
        Vec3::new(130.0, 160.0, 1_030.0),
    );
    vec![
        ("mixed scene at origin", meshgen::mixed_scene()),
        (
            "mixed scene 50 km out",
            translated(meshgen::mixed_scene(), far),
        ),
        ("10 km terrain", terrain_10km),
        (
            "10 km terrain 50 km out",
            translated(meshgen::terrain(10_000.0, 32, 0.0), far),
        ),
        (
            "slivers/coplanar at origin",
            slivers_and_coplanar(Vec3::ZERO),
        ),
        ("slivers/coplanar 50 km out", slivers_and_coplanar(far)),
    ]
}

fn unit_dir(rng: &mut SplitMix) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.unit() * 2.0 - 1.0,
            rng.unit() * 2.0 - 1.0,
            rng.unit() * 2.0 - 1.0,
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

/// A seeded mix of rays: aimed at random points of random facets from
/// 1 m to 3 km away (unit and non-unit directions), grazing the scene at
/// 0.01°-0.5° elevation, along the coordinate axes, random.
fn rays(g: &Geometry, seed: u64, n: usize) -> Vec<Ray> {
    let mut rng = SplitMix(seed);
    let (lo, hi) = g.bounds();
    let center = (lo + hi) * 0.5;
    let ext = (hi - lo).max_element().max(1.0);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let prim = g.traced[(rng.next_u64() % g.traced.len() as u64) as usize];
        let (mut u, mut v) = (rng.unit(), rng.unit());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let target = g.point(prim, u, v);
        match out.len() % 5 {
            0 | 1 => {
                let dist = 10f32.powf(rng.unit() * 3.5);
                let org = target + unit_dir(&mut rng) * dist;
                let dir = if out.len() % 5 == 0 {
                    target - org
                } else {
                    (target - org).normalize()
                };
                out.push(Ray::new(org, dir));
            }
            2 => {
                let el = (0.01 + rng.unit() * 0.49).to_radians();
                let az = rng.unit() * std::f32::consts::TAU;
                let back = Vec3::new(az.cos() * el.cos(), az.sin() * el.cos(), el.sin());
                let org = target + back * (ext * 0.5);
                out.push(Ray::new(org, -back));
            }
            3 => {
                let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
                let d = axes[(rng.next_u64() % 6) as usize];
                out.push(Ray::new(target - d * (1.0 + rng.unit() * 100.0), d));
            }
            _ => {
                let org = center + (Vec3::new(rng.unit(), rng.unit(), rng.unit()) - 0.5) * ext;
                out.push(Ray::new(org, unit_dir(&mut rng)));
            }
        }
    }
    out
}

fn check_hit(g: &Geometry, ray: &Ray, h: &Hit, ctx: &dyn Fn() -> String) {
    assert!(
        h.t.is_finite() && h.t >= ray.tnear.max(0.0) && h.t <= ray.tfar,
        "{}: t = {}",
        ctx(),
        h.t
    );
    let tol = 1e-4;
    assert!(
        h.u.is_finite() && h.v.is_finite() && h.u >= -tol && h.v >= -tol && h.u + h.v <= 1.0 + tol,
        "{}: barycentrics ({}, {})",
        ctx(),
        h.u,
        h.v
    );
    assert!((h.prim as usize) < g.triangles.len(), "{}", ctx());
    assert!(
        g.normals[h.prim as usize] != Vec3::ZERO,
        "{}: hit on a skipped (zero-area) triangle {}",
        ctx(),
        h.prim
    );
    // t is accurate: org + t·dir lies on the facet's plane (f32 precision
    // at the scene's scale, divided by the incidence cosine)
    let n = g.normals[h.prim as usize];
    let on_ray = ray.org.as_dvec3() + ray.dir.as_dvec3() * h.t as f64;
    let scale = (g.max_abs_coord as f64)
        .max(ray.org.abs().max_element() as f64)
        .max(1.0);
    let reach = scale + (ray.dir.length() * h.t) as f64;
    let cos = (n.dot(ray.dir.normalize()) as f64).abs().max(1e-3);
    let off_plane = plane_distance(g, h.prim, n, on_ray.as_vec3()).abs();
    assert!(
        off_plane <= 1e-5 * reach,
        "{}: org + t dir is {off_plane} m off the facet's plane",
        ctx()
    );
    // the barycentric point is the same point where barycentrics are well
    // conditioned (smallest altitude ≥ 1 % of the longest edge; a sliver's
    // barycentrics carry its width's relative error)
    let p = g.point(h.prim, h.u, h.v);
    assert!(p.is_finite(), "{}", ctx());
    let [a, b, c] = g.vertices(h.prim);
    let edges = [(b - a).length(), (c - b).length(), (a - c).length()];
    let longest = edges.iter().cloned().fold(0.0f32, f32::max) as f64;
    let twice_area = (b - a).cross(c - a).length() as f64;
    if twice_area / longest >= 0.01 * longest {
        let miss = (p.as_dvec3() - on_ray).length();
        let allowed = 2e-4 * longest + 1e-5 * reach / cos;
        assert!(
            miss <= allowed,
            "{}: hit point {miss} m off the ray (allowed {allowed})",
            ctx()
        );
    }
}

/// Signed distance (f64) of `p` from the plane of facet `prim` along its
/// normal `n`.
fn plane_distance(g: &Geometry, prim: u32, n: Vec3, p: Vec3) -> f64 {
    let [a, _, _] = g.vertices(prim);
    (p.as_dvec3() - a.as_dvec3()).dot(n.as_dvec3())
}

fn tracers(g: &Arc<Geometry>) -> Vec<(Backend, Box<dyn Tracer>)> {
    [Backend::Embree, Backend::Bvh]
        .into_iter()
        .map(|b| (b, trace::build(b, g).unwrap()))
        .collect()
}

/// Primary and secondary rays in every extreme scene, with both backends.
#[test]
fn tracers_finite_hits_and_robust_secondary_origins() {
    for (name, mesh) in scenes() {
        let (pos, tris) = mesh.finish();
        let g = Arc::new(Geometry::new(pos, tris).unwrap());
        let rs = rays(&g, 0x5EED ^ g.triangles.len() as u64, 3000);
        let mut rng = SplitMix(99);
        for (backend, tracer) in tracers(&g) {
            let mut hits = vec![None; rs.len()];
            tracer.intersect(&rs, &mut hits);
            let mut blocked = vec![false; rs.len()];
            tracer.occluded(&rs, &mut blocked);
            let n_hits = hits.iter().flatten().count();
            assert!(
                n_hits * 10 >= rs.len() * 6,
                "{name} {backend}: only {n_hits} of {} aimed rays hit",
                rs.len()
            );
            // secondary rays from every hit
            let mut sec = Vec::new();
            let mut from = Vec::new();
            for (i, (ray, h)) in rs.iter().zip(&hits).enumerate() {
                let Some(h) = h else { continue };
                check_hit(&g, ray, h, &|| format!("{name} {backend}: ray {i} {ray:?}"));
                let n = g.normals[h.prim as usize];
                let d = ray.dir.normalize();
                let nf = if n.dot(d) > 0.0 { -n } else { n };
                let p = g.point(h.prim, h.u, h.v);
                let o = offset_origin(p, nf);
                let ctx = || format!("{name} {backend}: ray {i}, prim {}, p {p}, n {nf}", h.prim);
                assert!(o.is_finite(), "{}: offset origin {o}", ctx());
                let dist = plane_distance(&g, h.prim, nf, o);
                assert!(
                    dist > 0.0,
                    "{}: offset origin {o} is {dist} m behind the facet",
                    ctx()
                );
                assert!(
                    (o - p).abs().max_element() <= 1e-4 * p.abs().max_element() + 1e-4,
                    "{}: offset moved too far: {o}",
                    ctx()
                );
                // mirror bounce and a random ray into the hemisphere of nf
                let refl = d - 2.0 * d.dot(nf) * nf;
                let mut r = unit_dir(&mut rng);
                if r.dot(nf) < 0.0 {
                    r = -r;
                }
                for dir in [refl, r] {
                    if dir.dot(nf) > 1e-3 {
                        sec.push(Ray::new(o, dir));
                        from.push(h.prim);
                    }
                }
            }
            let mut sh = vec![None; sec.len()];
            tracer.intersect(&sec, &mut sh);
            let mut sb = vec![false; sec.len()];
            tracer.occluded(&sec, &mut sb);
            for (i, (ray, h)) in sec.iter().zip(&sh).enumerate() {
                let Some(h) = h else { continue };
                let ctx = || format!("{name} {backend}: secondary {i} {ray:?} from {}", from[i]);
                check_hit(&g, ray, h, &ctx);
                assert_ne!(
                    h.prim,
                    from[i],
                    "{}: self-intersection at t = {}",
                    ctx(),
                    h.t
                );
            }
        }
    }
}

/// The backend cross-check over the same rays in the far-from-origin and
/// sliver/coplanar scenes: every difference between Embree and obvhs is
/// explained (coplanar tie, edge graze, grazing t, surface start).
#[test]
fn backends_agree_far_from_origin() {
    for (name, mesh) in scenes() {
        let (pos, tris) = mesh.finish();
        let g = Arc::new(Geometry::new(pos, tris).unwrap());
        let t = tracers(&g);
        let mut set = RaySet::default();
        for r in rays(&g, 7 + g.triangles.len() as u64, 2000) {
            set.push(RayKind::Primary, None, r);
        }
        let mut report = Report::default();
        let hits = crosscheck::compare(
            &g,
            t[0].1.as_ref(),
            t[1].1.as_ref(),
            &set,
            Tolerances::default(),
            5,
            &mut report,
        );
        let sun: Vec<Vec3> = [(0.3f32, 0.2f32), (-0.5, 0.7), (0.01, -0.02)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 1.0).normalize())
            .collect();
        let sec = crosscheck::secondary_rays(&g, &set, &hits, &sun);
        crosscheck::compare(
            &g,
            t[0].1.as_ref(),
            t[1].1.as_ref(),
            &sec,
            Tolerances::default(),
            5,
            &mut report,
        );
        assert_eq!(report.unexplained(), 0, "{name}:\n{}", report.to_text());
    }
}

/// Invalid rays (NaN/infinite origin or direction, zero direction, empty
/// or inverted intervals, components beyond Embree's 1.844e18) never hit
/// and never panic, in packets mixed with valid rays. Regression: a finite
/// origin above Embree's `FLT_LARGE` used to abort the process inside
/// Embree (`Assertion all(valid, ray.valid()) failed`).
#[test]
fn invalid_rays_never_hit() {
    let (pos, tris) = meshgen::mixed_scene().finish();
    let g = Arc::new(Geometry::new(pos, tris).unwrap());
    let down = Vec3::new(0.1, 0.2, -1.0);
    let above = Vec3::new(1.0, 1.0, 50.0);
    let nan = Vec3::splat(f32::NAN);
    let inf = Vec3::new(f32::INFINITY, 0.0, 0.0);
    let mut rays = vec![
        Ray::new(nan, down),
        Ray::new(above, nan),
        Ray::new(inf, down),
        Ray::new(above, inf),
        Ray::new(above, Vec3::ZERO),
        Ray {
            tnear: 10.0,
            tfar: 5.0,
            ..Ray::new(above, down)
        },
        Ray {
            tnear: 0.0,
            tfar: -1.0,
            ..Ray::new(above, down)
        },
        Ray {
            tnear: f32::NAN,
            ..Ray::new(above, down)
        },
        Ray {
            tfar: f32::NAN,
            ..Ray::new(above, down)
        },
        Ray::new(Vec3::splat(f32::MAX), down),
        Ray::new(Vec3::new(1e19, 0.0, 0.0), down),
        Ray::new(above, Vec3::new(0.0, 0.0, -1e19)),
    ];
    let n_bad = rays.len();
    rays.extend((0..22).map(|_| Ray::new(above, down)));
    for (backend, tracer) in tracers(&g) {
        let mut hits = vec![None; rays.len()];
        tracer.intersect(&rays, &mut hits);
        let mut blocked = vec![false; rays.len()];
        tracer.occluded(&rays, &mut blocked);
        for i in 0..n_bad {
            assert!(
                hits[i].is_none() && !blocked[i],
                "{backend}: bad ray {i} {:?} hit",
                rays[i]
            );
        }
        for i in n_bad..rays.len() {
            let h = hits[i].unwrap_or_else(|| panic!("{backend}: valid ray {i} missed"));
            check_hit(&g, &rays[i], &h, &|| format!("{backend} ray {i}"));
            assert!(blocked[i]);
        }
    }
}

/// `offset_origin` over coordinates from 0 to 10,000 km (both signs,
/// the near-origin switch at 1/32 m, subnormals) and normals along the
/// axes, diagonal, and with tiny components: the origin is finite, strictly
/// on the normal's side of the original point, and moved by at most
/// 1e-4 relative (+ 20 µm near the origin).
#[test]
fn offset_origin_extremes() {
    let mags = [
        0.0f32,
        1e-40,
        1e-30,
        1e-6,
        1.0 / 32.0 - 1e-9,
        1.0 / 32.0,
        1.0 / 32.0 + 1e-9,
        0.5,
        1.0,
        1e3,
        5e4,
        1e6,
        1e7,
    ];
    let mut coords: Vec<f32> = mags.iter().flat_map(|&m| [m, -m]).collect();
    coords.dedup();
    let mut normals = vec![
        Vec3::X,
        -Vec3::X,
        Vec3::Y,
        -Vec3::Y,
        Vec3::Z,
        -Vec3::Z,
        Vec3::ONE.normalize(),
        -Vec3::ONE.normalize(),
        Vec3::new(1.0, 1e-5, 0.0).normalize(),
        Vec3::new(-1e-3, 1.0, -1e-7).normalize(),
        Vec3::new(0.003, -0.003, 1.0).normalize(),
    ];
    let mut rng = SplitMix(3);
    normals.extend((0..20).map(|_| unit_dir(&mut rng)));
    for &x in &coords {
        for &y in &[0.0f32, -1e6, 3.5] {
            for &z in &[x, 1.0, -2e3] {
                let p = Vec3::new(x, y, z);
                for &n in &normals {
                    let o = offset_origin(p, n);
                    let ctx = format!("p {p:?} n {n:?} -> {o:?}");
                    assert!(o.is_finite(), "{ctx}");
                    let d: DVec3 = o.as_dvec3() - p.as_dvec3();
                    assert!(d.dot(n.as_dvec3()) > 0.0, "{ctx}: not on the normal's side");
                    for k in 0..3 {
                        // each coordinate moves with the sign of its normal component
                        assert!(d[k] * n[k] as f64 >= 0.0, "{ctx}: axis {k} moved against n");
                        assert!(
                            d[k].abs() <= 1e-4 * p[k].abs() as f64 + 2e-5,
                            "{ctx}: axis {k} moved {}",
                            d[k]
                        );
                    }
                }
            }
        }
    }
}
