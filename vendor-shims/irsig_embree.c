/* irsig_embree.c -- see irsig_embree.h. */
#include "irsig_embree.h"
#include <xmmintrin.h>
#include <pmmintrin.h>

int irsig_embree_major(void) { return RTC_VERSION_MAJOR; }

void irsig_set_ftz_daz(void)
{
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

#if RTC_VERSION_MAJOR >= 4
/* Embree 4: rtcIntersectN(valid, scene, rayhit, &args) */
static void init_i(struct RTCIntersectArguments* a, int coherent)
{
  rtcInitIntersectArguments(a);
  a->flags = coherent ? RTC_RAY_QUERY_FLAG_COHERENT : RTC_RAY_QUERY_FLAG_INCOHERENT;
}
static void init_o(struct RTCOccludedArguments* a, int coherent)
{
  rtcInitOccludedArguments(a);
  a->flags = coherent ? RTC_RAY_QUERY_FLAG_COHERENT : RTC_RAY_QUERY_FLAG_INCOHERENT;
}
void irsig_intersect1(RTCScene s, int c, struct RTCRayHit* r)
{ struct RTCIntersectArguments a; init_i(&a, c); rtcIntersect1(s, r, &a); }
void irsig_occluded1(RTCScene s, int c, struct RTCRay* r)
{ struct RTCOccludedArguments a; init_o(&a, c); rtcOccluded1(s, r, &a); }
void irsig_intersect8(const int* v, RTCScene s, int c, struct RTCRayHit8* r)
{ struct RTCIntersectArguments a; init_i(&a, c); rtcIntersect8(v, s, r, &a); }
void irsig_occluded8(const int* v, RTCScene s, int c, struct RTCRay8* r)
{ struct RTCOccludedArguments a; init_o(&a, c); rtcOccluded8(v, s, r, &a); }
void irsig_intersect16(const int* v, RTCScene s, int c, struct RTCRayHit16* r)
{ struct RTCIntersectArguments a; init_i(&a, c); rtcIntersect16(v, s, r, &a); }
void irsig_occluded16(const int* v, RTCScene s, int c, struct RTCRay16* r)
{ struct RTCOccludedArguments a; init_o(&a, c); rtcOccluded16(v, s, r, &a); }
#else
/* Embree 3: rtcIntersectN(valid, scene, &context, rayhit) */
static void init_c(struct RTCIntersectContext* ctx, int coherent)
{
  rtcInitIntersectContext(ctx);
  ctx->flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
}
void irsig_intersect1(RTCScene s, int c, struct RTCRayHit* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcIntersect1(s, &x, r); }
void irsig_occluded1(RTCScene s, int c, struct RTCRay* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcOccluded1(s, &x, r); }
void irsig_intersect8(const int* v, RTCScene s, int c, struct RTCRayHit8* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcIntersect8(v, s, &x, r); }
void irsig_occluded8(const int* v, RTCScene s, int c, struct RTCRay8* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcOccluded8(v, s, &x, r); }
void irsig_intersect16(const int* v, RTCScene s, int c, struct RTCRayHit16* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcIntersect16(v, s, &x, r); }
void irsig_occluded16(const int* v, RTCScene s, int c, struct RTCRay16* r)
{ struct RTCIntersectContext x; init_c(&x, c); rtcOccluded16(v, s, &x, r); }
#endif
