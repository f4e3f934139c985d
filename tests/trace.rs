//! Ray-tracing core: Embree vs obvhs agreement on generated meshes, packet vs
//! single-ray identity, robust secondary origins at km scale, bad geometry.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use irsig::bench::crosscheck::{self, RayKind, RaySet, Report, Tolerances};
use irsig::sensor::camera::Camera;
use irsig::trace::bvh::BvhTracer;
use irsig::trace::embree::EmbreeTracer;
use irsig::trace::meshgen::{self, MeshBuilder, SplitMix};
use irsig::trace::offset::offset_origin;
use irsig::trace::{Geometry, Hit, QueryMode, Ray, Tracer};

fn geometry(m: MeshBuilder) -> Arc<Geometry> {
    let (p, t) = m.finish();
    Arc::new(Geometry::new(p, t).expect("valid generated geometry"))
}

fn tracers(g: &Arc<Geometry>) -> (EmbreeTracer, BvhTracer) {
    (
        EmbreeTracer::new(g.clone(), QueryMode::Packet16).unwrap(),
        BvhTracer::new(g.clone()),
    )
}

fn sun_dirs() -> Vec<Vec3> {
    [(120.0f32, 25.0f32), (180.0, 60.0), (250.0, 12.0)]
        .iter()
        .map(|&(az, el)| {
            let (az, el) = (az.to_radians(), el.to_radians());
            Vec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
        })
        .collect()
}

/// Asserts equal answers, listing the first differences.
fn assert_same<T: PartialEq + std::fmt::Debug>(a: &[T], b: &[T], rays: &[Ray]) {
    assert_same_except(a, b, rays, |_, _| false)
}

/// Asserts equal answers except where `allowed(a_i, b_i)`.
fn assert_same_except<T: PartialEq + std::fmt::Debug>(
    a: &[T],
    b: &[T],
    rays: &[Ray],
    allowed: impl Fn(&T, &T) -> bool,
) {
    let diff: Vec<_> = (0..a.len())
        .filter(|&i| a[i] != b[i] && !allowed(&a[i], &b[i]))
        .collect();
    let show: Vec<_> = diff
        .iter()
        .take(5)
        .map(|&i| (i, &rays[i], &a[i], &b[i]))
        .collect();
    assert!(
        diff.is_empty(),
        "{} of {} differ, e.g. {show:#?}",
        diff.len(),
        a.len()
    );
}

fn assert_clean(r: &Report) {
    assert_eq!(
        r.unexplained(),
        0,
        "unexplained differences:\n{}",
        r.to_text()
    );
}

#[test]
fn backends_agree_on_mixed_scene_camera_rays() {
    let g = geometry(meshgen::mixed_scene());
    let (e, b) = tracers(&g);
    let cam = Camera::look_at(DVec3::new(-30.0, -40.0, 45.0), DVec3::ZERO, 40.0, 160, 120);
    let r = crosscheck::run(&g, &e, &b, &cam, &sun_dirs(), Tolerances::default());
    assert_clean(&r);
    // The test must exercise every ray kind, and most hits must be identical.
    assert_eq!(r.primary.compared, 160 * 120);
    assert!(
        r.specular.compared > 8_000 && r.solar.compared > 8_000,
        "{}",
        r.to_text()
    );
    assert!(
        r.primary.identical as f64 > 0.99 * r.primary.compared as f64,
        "{}",
        r.to_text()
    );
    assert_eq!(r.skipped_degenerate, 2);
}

#[test]
fn backends_agree_on_benchmark_scene() {
    let g = geometry(meshgen::bench_scene());
    assert_eq!(g.triangles.len(), 5000);
    let (e, b) = tracers(&g);
    let cam = Camera::look_at(DVec3::new(0.0, -150.0, 250.0), DVec3::ZERO, 55.0, 128, 128);
    assert_clean(&crosscheck::run(
        &g,
        &e,
        &b,
        &cam,
        &sun_dirs(),
        Tolerances::default(),
    ));
}

/// Rays aimed exactly at shared edges and vertices of a grid, rays parallel
/// to the faces (in the plane and just above it), rays starting on the
/// surface: both backends agree up to explained differences.
#[test]
fn backends_agree_on_edges_parallel_and_surface_rays() {
    let g = geometry({
        let mut m = MeshBuilder::new();
        m.grid(Vec3::new(0.0, 0.0, 0.0), (8.0, 8.0), (8, 8), |_, _| 0.0);
        m.cuboid(Vec3::new(2.0, 2.0, 0.0), Vec3::new(3.0, 3.0, 1.0));
        m
    });
    let (e, b) = tracers(&g);
    let mut set = RaySet::default();
    // Down onto every vertex (shared by up to six triangles) and mid-edge.
    for j in 0..=16 {
        for i in 0..=16 {
            let p = Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 0.0);
            set.push(
                RayKind::Primary,
                None,
                Ray::new(p + Vec3::new(0.0, 0.0, 10.0), -Vec3::Z),
            );
            set.push(
                RayKind::Primary,
                None,
                Ray::new(p + Vec3::new(0.3, 0.2, 10.0), Vec3::new(-0.03, -0.02, -1.0)),
            );
        }
    }
    // Parallel to the ground plane, in it and just above; along the diagonals.
    for k in 0..40 {
        let y = k as f32 * 0.2;
        set.push(
            RayKind::Primary,
            None,
            Ray::new(Vec3::new(-1.0, y, 0.0), Vec3::X),
        );
        set.push(
            RayKind::Primary,
            None,
            Ray::new(Vec3::new(-1.0, y, 1e-4), Vec3::X),
        );
        set.push(
            RayKind::Primary,
            None,
            Ray::new(Vec3::new(-1.0, y - 1.0, 0.5), Vec3::new(1.0, 1.0, 0.0)),
        );
        // Grazing the box's top edge.
        set.push(
            RayKind::Primary,
            None,
            Ray::new(Vec3::new(-1.0, 2.0 + k as f32 * 0.025, 1.0), Vec3::X),
        );
    }
    // Starting exactly on the surface, going up, down and sideways.
    let mut rng = SplitMix(3);
    for _ in 0..400 {
        let p = Vec3::new(rng.unit() * 8.0, rng.unit() * 8.0, 0.0);
        let d = Vec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
        set.push(RayKind::Solar, None, Ray::new(p, d));
    }
    let mut r = Report::default();
    crosscheck::compare(&g, &e, &b, &set, Tolerances::default(), 10, &mut r);
    assert_clean(&r);
    assert!(r.primary.compared > 700);
}

#[test]
fn backends_agree_on_slivers_and_coplanar_overlaps() {
    let g = geometry({
        let mut m = MeshBuilder::new();
        m.slivers(Vec3::ZERO, 5.0, 1e-4, 64);
        m.slivers(Vec3::new(0.0, 0.0, 1.0), 5.0, 1e-2, 64);
        let z = 2.0;
        m.triangle(
            Vec3::new(-3.0, -3.0, z),
            Vec3::new(3.0, -3.0, z),
            Vec3::new(3.0, 3.0, z),
        );
        m.triangle(
            Vec3::new(-2.0, -3.0, z),
            Vec3::new(4.0, -3.0, z),
            Vec3::new(4.0, 3.0, z),
        );
        m
    });
    let (e, b) = tracers(&g);
    let cam = Camera::look_at(DVec3::new(0.5, 0.3, 20.0), DVec3::ZERO, 40.0, 200, 200);
    let r = crosscheck::run(&g, &e, &b, &cam, &sun_dirs(), Tolerances::default());
    assert_clean(&r);
}

#[test]
fn empty_scene_and_degenerate_only_scene_never_hit() {
    for m in [MeshBuilder::new(), {
        let mut m = MeshBuilder::new();
        m.degenerate(Vec3::ZERO);
        m
    }] {
        let g = geometry(m);
        assert!(g.traced.is_empty());
        let (e, b) = tracers(&g);
        let rays: Vec<Ray> = (0..37)
            .map(|i| Ray::new(Vec3::new(i as f32, 0.5, 3.0), -Vec3::Z))
            .collect();
        for t in [&e as &dyn Tracer, &b] {
            let mut h = vec![None; rays.len()];
            t.intersect(&rays, &mut h);
            assert!(h.iter().all(Option::is_none));
            let mut o = vec![true; rays.len()];
            t.occluded(&rays, &mut o);
            assert!(o.iter().all(|x| !x));
        }
    }
}

/// Packets and single rays must give bit-identical answers, except that on
/// exactly coplanar overlapping facets (z-fighting, a modelling error) the
/// triangle reported at the tied `t` may differ: Embree's packet and
/// single-ray traversals visit them in different orders. The tie must then
/// be exact: same `t` bits, coplanar triangles.
#[test]
fn embree_packets_equal_single_rays() {
    let g = geometry(meshgen::mixed_scene());
    let packet = EmbreeTracer::new(g.clone(), QueryMode::Packet16).unwrap();
    let single = EmbreeTracer::new(g.clone(), QueryMode::Single).unwrap();
    let cam = Camera::look_at(DVec3::new(-30.0, -40.0, 45.0), DVec3::ZERO, 40.0, 96, 96);
    let mut set = RaySet::default();
    for (x, y) in cam.tile_order() {
        set.push(
            RayKind::Primary,
            Some((x, y)),
            cam.ray(x as f64 + 0.5, y as f64 + 0.5),
        );
    }
    let mut hp = vec![None; set.rays.len()];
    let mut hs = vec![None; set.rays.len()];
    packet.intersect(&set.rays, &mut hp);
    single.intersect(&set.rays, &mut hs);
    let exact_coplanar_tie = |a: &Option<Hit>, b: &Option<Hit>| match (a, b) {
        (Some(a), Some(b)) => {
            let (na, nb) = (g.normals[a.prim as usize], g.normals[b.prim as usize]);
            let pa = g.vertices(a.prim)[0];
            let pb = g.vertices(b.prim)[0];
            a.t.to_bits() == b.t.to_bits() && na.dot(nb) > 0.999_999 && na.dot(pb - pa).abs() < 1e-6
        }
        _ => false,
    };
    assert_same_except(&hp, &hs, &set.rays, exact_coplanar_tie);
    let sec = crosscheck::secondary_rays(&g, &set, &hp, &sun_dirs());
    let mut sp = vec![None; sec.rays.len()];
    let mut ss = vec![None; sec.rays.len()];
    packet.intersect(&sec.rays, &mut sp);
    single.intersect(&sec.rays, &mut ss);
    assert_same_except(&sp, &ss, &sec.rays, exact_coplanar_tie);
    let mut op = vec![false; sec.rays.len()];
    let mut os = vec![false; sec.rays.len()];
    packet.occluded(&sec.rays, &mut op);
    single.occluded(&sec.rays, &mut os);
    assert_same(&op, &os, &sec.rays);
    assert!(hp.iter().filter(|h| h.is_some()).count() > hp.len() / 3);
}

/// The solar-history query (`occluded_fan`: up to 16 origins, one packet
/// traced toward several sun directions, lanes chosen by a mask) answers
/// exactly as `occluded` on `Ray::new(origin, dir)` for every active lane
/// and never blocks an inactive one, for Embree packets, Embree single rays
/// and the obvhs backend (the trait's default), with groups shorter than 16,
/// masks below the packet threshold (fewer than 4 lanes), empty masks, and
/// invalid origins (NaN, beyond Embree's range) and an invalid direction that
/// must never be blocked.
#[test]
fn occluded_fan_equals_occluded_of_the_same_rays() {
    let g = geometry(meshgen::mixed_scene());
    let tracers: Vec<Box<dyn Tracer>> = vec![
        Box::new(EmbreeTracer::new(g.clone(), QueryMode::Packet16).unwrap()),
        Box::new(EmbreeTracer::new(g.clone(), QueryMode::Single).unwrap()),
        Box::new(BvhTracer::new(g.clone())),
    ];
    let mut rng = SplitMix(7);
    let mut origins: Vec<Vec3> = (0..203)
        .map(|_| {
            Vec3::new(
                rng.unit() * 60.0 - 30.0,
                rng.unit() * 60.0 - 30.0,
                rng.unit() * 6.0 + 0.05,
            )
        })
        .collect();
    origins[17] = Vec3::new(f32::NAN, 0.0, 1.0);
    origins[18] = Vec3::new(0.0, 1e30, 1.0);
    // Each sun twice (other masks) and an invalid (zero) direction.
    let mut dirs = sun_dirs();
    dirs.extend(sun_dirs());
    dirs.push(Vec3::ZERO);
    let (mut blocked_seen, mut open_seen) = (0, 0);
    for t in &tracers {
        for start in (0..origins.len()).step_by(16) {
            let os = &origins[start..(start + 16).min(origins.len())];
            let full = if os.len() == 16 {
                u16::MAX
            } else {
                (1u16 << os.len()) - 1
            };
            // Per direction: all lanes, a random half, at most 3 lanes, none.
            let active: Vec<u16> = (0..dirs.len())
                .map(|k| {
                    let r = (rng.unit() * 65536.0) as u16;
                    full & [u16::MAX, r, r & 0x0111, 0][k % 4]
                })
                .collect();
            let mut got = vec![0xffffu16; dirs.len()];
            t.occluded_fan(os, &dirs, &active, &mut got);
            for (k, dir) in dirs.iter().enumerate() {
                let rays: Vec<Ray> = os.iter().map(|o| Ray::new(*o, *dir)).collect();
                let mut want = vec![false; os.len()];
                t.occluded(&rays, &mut want);
                let got_k: Vec<bool> = (0..os.len()).map(|i| got[k] >> i & 1 == 1).collect();
                let want_k: Vec<bool> = (0..os.len())
                    .map(|i| active[k] >> i & 1 == 1 && want[i])
                    .collect();
                assert_same(&got_k, &want_k, &rays);
                assert_eq!(got[k] & !active[k], 0, "an inactive lane is never blocked");
                if start == 16 {
                    assert!(got[k] & 0b110 == 0, "invalid origins are never blocked");
                }
                blocked_seen += got[k].count_ones();
                open_seen += (active[k] & !got[k]).count_ones();
            }
        }
    }
    // Both answers occur, so the comparison can fail.
    assert!(
        blocked_seen > 50 && open_seen > 50,
        "{blocked_seen} blocked, {open_seen} open"
    );
}

/// A 10 km × 10 km undulating ground at 1 km altitude, seen from 3 km above:
/// shadow rays to a 60°-high sun and mirror rays from every hit, with the
/// robust origin offset, never hit the surface they start on. (The slopes
/// are below 3°, so nothing can truly shadow or be hit.) Without the offset
/// the same rays do self-intersect, so the test can fail.
#[test]
fn secondary_rays_do_not_self_intersect_at_km_scale() {
    let g = geometry(meshgen::terrain(10_000.0, 100, 1000.0));
    let e = EmbreeTracer::new(g.clone(), QueryMode::Packet16).unwrap();
    let b = BvhTracer::new(g.clone());
    let cam = Camera::look_at(
        DVec3::new(300.0, -1500.0, 5000.0),
        DVec3::new(0.0, 0.0, 1000.0),
        60.0,
        128,
        128,
    );
    let rays: Vec<Ray> = cam
        .tile_order()
        .iter()
        .map(|&(x, y)| cam.ray(x as f64 + 0.5, y as f64 + 0.5))
        .collect();
    let mut hits = vec![None; rays.len()];
    e.intersect(&rays, &mut hits);
    let sun = Vec3::new(0.3, -0.4, 0.866).normalize();
    let (mut robust, mut naive) = (Vec::new(), Vec::new());
    for (r, h) in rays.iter().zip(&hits) {
        let h: Hit = h.expect("every pixel sees the ground");
        let p = g.point(h.prim, h.u, h.v);
        let n = g.normals[h.prim as usize];
        let refl = r.dir - 2.0 * r.dir.dot(n) * n;
        robust.push(Ray::new(offset_origin(p, n), sun));
        robust.push(Ray::new(offset_origin(p, n), refl));
        naive.push(Ray::new(p, sun));
        naive.push(Ray::new(p, refl));
    }
    for t in [&e as &dyn Tracer, &b] {
        let mut o = vec![false; robust.len()];
        t.occluded(&robust, &mut o);
        assert_eq!(
            o.iter().filter(|x| **x).count(),
            0,
            "{} self-intersections",
            t.backend()
        );
    }
    let mut o = vec![false; naive.len()];
    e.occluded(&naive, &mut o);
    assert!(
        o.iter().any(|x| *x),
        "the naive origins should self-intersect somewhere at this scale"
    );
}

#[test]
fn bad_geometry_is_an_error_or_a_counted_skip() {
    let nan = Geometry::new(
        vec![Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y],
        vec![[0, 1, 2]],
    );
    assert_eq!(
        nan.unwrap_err().to_string(),
        "vertex 1 is not finite: (NaN, 0, 0); every coordinate must be a finite number"
    );
    let oob = Geometry::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 3]]).unwrap_err();
    assert_eq!(
        oob.to_string(),
        "triangle 0 refers to vertex 3, but there are only 3 vertices"
    );
    let g = Geometry::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, 2.0 * Vec3::X],
        vec![[0, 1, 2], [0, 1, 3], [1, 1, 1]],
    )
    .unwrap();
    assert_eq!(g.skipped(), 2);
    assert_eq!(g.traced, vec![0]);
}

/// The classifier itself: a real disagreement is reported as unexplained.
#[test]
fn classifier_flags_real_disagreements() {
    use irsig::bench::crosscheck::{Verdict, classify};
    let g = geometry(meshgen::mixed_scene());
    let ray = Ray::new(Vec3::new(0.0, 0.0, 50.0), -Vec3::Z);
    let tol = Tolerances::default();
    let centre = Hit {
        t: 44.0,
        prim: 10,
        u: 0.3,
        v: 0.3,
    };
    // A hit in the middle of a facet that the other backend misses.
    assert_eq!(
        classify(&g, &ray, Some(centre), None, tol),
        Verdict::Unexplained
    );
    // Same facet, t off by 1 m.
    assert_eq!(
        classify(&g, &ray, Some(centre), Some(Hit { t: 45.0, ..centre }), tol),
        Verdict::Unexplained
    );
    // Different facets far apart in t, the nearer one well inside its facet.
    assert_eq!(
        classify(
            &g,
            &ray,
            Some(centre),
            Some(Hit {
                t: 50.0,
                prim: 11,
                ..centre
            }),
            tol
        ),
        Verdict::Unexplained
    );
    // Explained cases.
    let edge = Hit { u: 0.0, ..centre };
    assert_eq!(
        classify(&g, &ray, Some(edge), None, tol),
        Verdict::EdgeGraze
    );
    assert_eq!(
        classify(
            &g,
            &ray,
            Some(centre),
            Some(Hit { prim: 11, ..centre }),
            tol
        ),
        Verdict::Tie
    );
    assert_eq!(
        classify(&g, &ray, Some(centre), Some(centre), tol),
        Verdict::Identical
    );
}
