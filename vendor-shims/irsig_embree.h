/* irsig_embree.h -- one version-neutral API over Embree 3 and Embree 4.
 *
 * bindgen runs over this header. It pulls the RTC types (RTCRayHit16, ...)
 * from the *installed* rtcore.h so that the Rust structs always match the
 * library we link, and declares the few calls whose signature differs
 * between Embree 3 and 4 (intersect/occluded: context vs arguments) or
 * that are header-inline in Embree (rtcInit*), implemented in irsig_embree.c.
 */
#ifndef IRSIG_EMBREE_H
#define IRSIG_EMBREE_H

#if defined(IRSIG_EMBREE4)
#include <embree4/rtcore.h>
#else
#include <embree3/rtcore.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Major version of the Embree headers the shim was compiled against (3 or 4). */
int irsig_embree_major(void);

/* Set FTZ and DAZ in this thread's MXCSR (Embree's recommendation). */
void irsig_set_ftz_daz(void);

/* coherent != 0 selects the COHERENT query flag (Embree 3 context flag,
 * Embree 4 ray-query flag). */
void irsig_intersect1(RTCScene scene, int coherent, struct RTCRayHit* rayhit);
void irsig_occluded1(RTCScene scene, int coherent, struct RTCRay* ray);
void irsig_intersect8(const int* valid, RTCScene scene, int coherent, struct RTCRayHit8* rayhit);
void irsig_occluded8(const int* valid, RTCScene scene, int coherent, struct RTCRay8* ray);
void irsig_intersect16(const int* valid, RTCScene scene, int coherent, struct RTCRayHit16* rayhit);
void irsig_occluded16(const int* valid, RTCScene scene, int coherent, struct RTCRay16* ray);

#ifdef __cplusplus
}
#endif
#endif
