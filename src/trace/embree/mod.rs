//! Safe layer over Embree (3 or 4, through the C shim): a device and a
//! committed triangle scene (ROBUST flag), shared read-only across threads,
//! with 16-wide packet queries (SoA [`ffi::RTCRayHit16`]) and single-ray
//! queries.

pub mod ffi;

use std::ffi::CStr;
use std::sync::Arc;

use glam::Vec3;

use super::geometry::{Geometry, GeometryError};
use super::ray::{Hit, Ray, in_ray_range};
use super::tracer::{Backend, QueryMode, Tracer};

const INVALID_ID: u32 = u32::MAX; // RTC_INVALID_GEOMETRY_ID

/// Major version of the Embree library irsig was built against (3 or 4).
pub fn embree_major() -> i32 {
    // SAFETY: a pure C function without arguments or side effects.
    unsafe { ffi::irsig_embree_major() }
}

/// Sets flush-to-zero and denormals-are-zero for the calling thread, as
/// Embree recommends. Call it from every worker thread (rayon
/// `start_handler`) so that all threads compute alike.
pub fn set_thread_ftz_daz() {
    // SAFETY: only writes this thread's MXCSR control bits.
    unsafe { ffi::irsig_set_ftz_daz() }
}

/// An Embree device (owns the library state).
struct Device(ffi::RTCDevice);

// SAFETY: Embree devices are thread-safe handles (Embree API docs: all
// rtc* calls are thread-safe except concurrent modification of one object);
// irsig only creates and releases it from the owning struct.
unsafe impl Send for Device {}
unsafe impl Sync for Device {}

impl Device {
    fn new() -> Result<Self, GeometryError> {
        // SAFETY: a NULL-terminated empty config string; a NULL return is handled.
        let d = unsafe { ffi::rtcNewDevice(c"".as_ptr()) };
        if d.is_null() {
            return Err(GeometryError::Embree(
                "rtcNewDevice failed (unsupported CPU or library?)".into(),
            ));
        }
        Ok(Device(d))
    }

    fn check(&self, what: &str) -> Result<(), GeometryError> {
        // SAFETY: self.0 is a live device.
        let code = unsafe { ffi::rtcGetDeviceError(self.0) };
        if code == ffi::RTC_ERROR_NONE {
            Ok(())
        } else {
            Err(GeometryError::Embree(format!(
                "{what} failed with RTCError {code}"
            )))
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device is live and released exactly once; the scene that
        // uses it is dropped first (field order in EmbreeTracer).
        unsafe { ffi::rtcReleaseDevice(self.0) }
    }
}

/// A committed Embree scene with one triangle geometry.
struct CommittedScene(ffi::RTCScene);

// SAFETY: after rtcCommitScene the scene is only read; Embree documents
// rtcIntersect*/rtcOccluded* as safe to call concurrently on a committed scene.
unsafe impl Send for CommittedScene {}
unsafe impl Sync for CommittedScene {}

impl Drop for CommittedScene {
    fn drop(&mut self) {
        // SAFETY: live scene, released exactly once.
        unsafe { ffi::rtcReleaseScene(self.0) }
    }
}

/// The Embree backend of [`Tracer`].
pub struct EmbreeTracer {
    // Field order matters: the scene is dropped before the device.
    scene: CommittedScene,
    _device: Device,
    geometry: Arc<Geometry>,
    mode: QueryMode,
}

impl EmbreeTracer {
    /// Builds and commits the scene (ROBUST + high build quality).
    pub fn new(geometry: Arc<Geometry>, mode: QueryMode) -> Result<Self, GeometryError> {
        let device = Device::new()?;
        // SAFETY: the device is live; every pointer Embree returns is checked
        // for NULL before use, and the buffers are written within the item
        // counts we asked for (Embree allocates them, with its own padding).
        let scene = unsafe {
            let scene = ffi::rtcNewScene(device.0);
            if scene.is_null() {
                device.check("rtcNewScene")?;
                return Err(GeometryError::Embree("rtcNewScene returned NULL".into()));
            }
            let scene = CommittedScene(scene);
            ffi::rtcSetSceneFlags(scene.0, ffi::RTC_SCENE_FLAG_ROBUST);
            ffi::rtcSetSceneBuildQuality(scene.0, ffi::RTC_BUILD_QUALITY_HIGH);
            if !geometry.traced.is_empty() {
                let g = ffi::rtcNewGeometry(device.0, ffi::RTC_GEOMETRY_TYPE_TRIANGLE);
                if g.is_null() {
                    device.check("rtcNewGeometry")?;
                    return Err(GeometryError::Embree("rtcNewGeometry returned NULL".into()));
                }
                let nv = geometry.positions.len();
                let vb = ffi::rtcSetNewGeometryBuffer(
                    g,
                    ffi::RTC_BUFFER_TYPE_VERTEX,
                    0,
                    ffi::RTC_FORMAT_FLOAT3,
                    12,
                    nv,
                ) as *mut f32;
                let nt = geometry.traced.len();
                let ib = ffi::rtcSetNewGeometryBuffer(
                    g,
                    ffi::RTC_BUFFER_TYPE_INDEX,
                    0,
                    ffi::RTC_FORMAT_UINT3,
                    12,
                    nt,
                ) as *mut u32;
                if vb.is_null() || ib.is_null() {
                    ffi::rtcReleaseGeometry(g);
                    device.check("rtcSetNewGeometryBuffer")?;
                    return Err(GeometryError::Embree(
                        "geometry buffer allocation failed".into(),
                    ));
                }
                let vs = std::slice::from_raw_parts_mut(vb, nv * 3);
                for (i, p) in geometry.positions.iter().enumerate() {
                    vs[3 * i..3 * i + 3].copy_from_slice(&p.to_array());
                }
                let is = std::slice::from_raw_parts_mut(ib, nt * 3);
                for (i, &t) in geometry.traced.iter().enumerate() {
                    is[3 * i..3 * i + 3].copy_from_slice(&geometry.triangles[t as usize]);
                }
                ffi::rtcCommitGeometry(g);
                ffi::rtcAttachGeometry(scene.0, g);
                ffi::rtcReleaseGeometry(g);
            }
            ffi::rtcCommitScene(scene.0);
            device.check("rtcCommitScene")?;
            scene
        };
        Ok(EmbreeTracer {
            scene,
            _device: device,
            geometry,
            mode,
        })
    }

    /// The query mode (packets or single rays).
    pub fn mode(&self) -> QueryMode {
        self.mode
    }

    /// Embree's build/version string, e.g. "3.13.5".
    pub fn version_string() -> String {
        CStr::from_bytes_with_nul(ffi::RTC_VERSION_STRING)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|_| format!("{}", embree_major()))
    }

    fn hit_of(&self, geom_id: u32, prim_id: u32, t: f32, u: f32, v: f32) -> Option<Hit> {
        (geom_id != INVALID_ID).then(|| Hit {
            t,
            prim: self.geometry.traced[prim_id as usize],
            u,
            v,
        })
    }

    fn intersect_single(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let mut rh = ffi::RTCRayHit::default();
        fill_ray1(&mut rh.ray, ray);
        rh.hit.geomID = INVALID_ID;
        rh.hit.instID[0] = INVALID_ID;
        // SAFETY: the scene is committed and live; rh is a fully initialised
        // RTCRayHit (16-byte aligned by its generated repr).
        unsafe { ffi::irsig_intersect1(self.scene.0, 0, &mut rh) };
        self.hit_of(
            rh.hit.geomID,
            rh.hit.primID,
            rh.ray.tfar,
            rh.hit.u,
            rh.hit.v,
        )
    }

    fn occluded_single(&self, ray: &Ray) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let mut r = ffi::RTCRay::default();
        fill_ray1(&mut r, ray);
        // SAFETY: as in intersect_single.
        unsafe { ffi::irsig_occluded1(self.scene.0, 0, &mut r) };
        r.tfar == f32::NEG_INFINITY
    }

    fn intersect_packet(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        let mut rh = ffi::RTCRayHit16::default();
        let mut valid = Valid16([0; 16]);
        for (lane, ray) in rays.iter().enumerate() {
            if ray.is_valid() {
                valid.0[lane] = -1;
                fill_lane(&mut rh.ray, lane, ray);
            }
            rh.hit.geomID[lane] = INVALID_ID;
            rh.hit.instID[0][lane] = INVALID_ID;
        }
        // SAFETY: committed scene; `valid` has 16 lanes, 64-byte aligned as
        // Embree requires, and `rh` is the 64-byte-aligned RTCRayHit16
        // generated from the installed header;
        // inactive lanes are masked off by `valid`.
        unsafe { ffi::irsig_intersect16(valid.0.as_ptr(), self.scene.0, 1, &mut rh) };
        for (lane, h) in hits.iter_mut().enumerate() {
            *h = if valid.0[lane] != 0 {
                self.hit_of(
                    rh.hit.geomID[lane],
                    rh.hit.primID[lane],
                    rh.ray.tfar[lane],
                    rh.hit.u[lane],
                    rh.hit.v[lane],
                )
            } else {
                None
            };
        }
    }

    fn occluded_packet(&self, rays: &[Ray], blocked: &mut [bool]) {
        let mut r = ffi::RTCRay16::default();
        let mut valid = Valid16([0; 16]);
        for (lane, ray) in rays.iter().enumerate() {
            if ray.is_valid() {
                valid.0[lane] = -1;
                fill_lane(&mut r, lane, ray);
            }
        }
        // SAFETY: as in intersect_packet.
        unsafe { ffi::irsig_occluded16(valid.0.as_ptr(), self.scene.0, 1, &mut r) };
        for (lane, b) in blocked.iter_mut().enumerate() {
            *b = valid.0[lane] != 0 && r.tfar[lane] == f32::NEG_INFINITY;
        }
    }
}

fn fill_ray1(r: &mut ffi::RTCRay, ray: &Ray) {
    r.org_x = ray.org.x;
    r.org_y = ray.org.y;
    r.org_z = ray.org.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = ray.tnear.max(0.0);
    r.tfar = ray.tfar;
    r.time = 0.0;
    r.mask = u32::MAX;
    r.id = 0;
    r.flags = 0;
}

fn fill_lane(r: &mut ffi::RTCRay16, lane: usize, ray: &Ray) {
    r.org_x[lane] = ray.org.x;
    r.org_y[lane] = ray.org.y;
    r.org_z[lane] = ray.org.z;
    r.dir_x[lane] = ray.dir.x;
    r.dir_y[lane] = ray.dir.y;
    r.dir_z[lane] = ray.dir.z;
    r.tnear[lane] = ray.tnear.max(0.0);
    r.tfar[lane] = ray.tfar;
    r.time[lane] = 0.0;
    r.mask[lane] = u32::MAX;
    r.id[lane] = lane as u32;
    r.flags[lane] = 0;
}

/// The valid mask of a 16-wide query: Embree requires it aligned like the
/// packet (64 bytes for 16-wide; rtcIntersect16 docs).
#[repr(C, align(64))]
struct Valid16([i32; 16]);

/// Below this many rays in a group of 16, single-ray calls are cheaper.
const MIN_PACKET_FILL: usize = 4;

impl Tracer for EmbreeTracer {
    fn backend(&self) -> Backend {
        Backend::Embree
    }

    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        for (rs, hs) in rays.chunks(16).zip(hits.chunks_mut(16)) {
            if self.mode == QueryMode::Single || rs.len() < MIN_PACKET_FILL {
                for (r, h) in rs.iter().zip(hs.iter_mut()) {
                    *h = self.intersect_single(r);
                }
            } else {
                self.intersect_packet(rs, hs);
            }
        }
    }

    fn occluded(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "one slot per ray");
        for (rs, bs) in rays.chunks(16).zip(blocked.chunks_mut(16)) {
            if self.mode == QueryMode::Single || rs.len() < MIN_PACKET_FILL {
                for (r, b) in rs.iter().zip(bs.iter_mut()) {
                    *b = self.occluded_single(r);
                }
            } else {
                self.occluded_packet(rs, bs);
            }
        }
    }

    fn occluded_fan(&self, origins: &[Vec3], dirs: &[Vec3], active: &[u16], blocked: &mut [u16]) {
        assert!(origins.len() <= 16, "at most 16 origins");
        assert!(dirs.len() == active.len() && dirs.len() == blocked.len());
        // One packet for all directions: the origins, mask and id lanes
        // are written once (tnear, time and flags stay the default zeros);
        // per direction only the direction lanes and tfar (which Embree
        // sets to −∞ on a hit and changes nothing else: rtcOccluded16 docs)
        // are written. A lane's answer does not depend on its position in
        // the packet or on the other lanes.
        let mut r = ffi::RTCRay16::default();
        let mut in_range = 0u16;
        for (lane, o) in origins.iter().enumerate() {
            // A lane whose origin Embree cannot take keeps zeros: Embree's
            // AVX2 packet kernels (Debian's build keeps its assertions)
            // abort on a non-finite origin even in a masked-off lane (seen
            // on an AVX-512-less AMD EPYC; tests/trace.rs).
            if in_ray_range(*o) {
                r.org_x[lane] = o.x;
                r.org_y[lane] = o.y;
                r.org_z[lane] = o.z;
                in_range |= 1 << lane;
            }
            r.mask[lane] = u32::MAX;
            r.id[lane] = lane as u32;
        }
        for ((dir, &act), out) in dirs.iter().zip(active).zip(blocked.iter_mut()) {
            *out = 0;
            let fill = act.count_ones() as usize;
            if fill == 0 {
                continue;
            }
            if self.mode == QueryMode::Single || fill < MIN_PACKET_FILL {
                for (lane, o) in origins.iter().enumerate() {
                    if act >> lane & 1 == 1 && self.occluded_single(&Ray::new(*o, *dir)) {
                        *out |= 1 << lane;
                    }
                }
                continue;
            }
            // `Ray::is_valid` of Ray::new(o, dir): the direction's part
            // once, the origin's (`in_ray_range`) per lane.
            let live = if Ray::new(Vec3::ZERO, *dir).is_valid() {
                act & in_range
            } else {
                0
            };
            if live == 0 {
                // Nothing to trace (and an invalid direction must not
                // reach Embree's lanes, above).
                continue;
            }
            let mut valid = Valid16([0; 16]);
            for lane in 0..16 {
                valid.0[lane] = -((live >> lane & 1) as i32);
                r.dir_x[lane] = dir.x;
                r.dir_y[lane] = dir.y;
                r.dir_z[lane] = dir.z;
                r.tfar[lane] = f32::INFINITY;
            }
            // SAFETY: as in intersect_packet.
            unsafe { ffi::irsig_occluded16(valid.0.as_ptr(), self.scene.0, 1, &mut r) };
            for lane in 0..16 {
                if valid.0[lane] != 0 && r.tfar[lane] == f32::NEG_INFINITY {
                    *out |= 1 << lane;
                }
            }
        }
    }
}
