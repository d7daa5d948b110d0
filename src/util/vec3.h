/* 3-vectors and orthonormal frames in double precision: the geometry, lights and walks share them. */
#ifndef DWV_UTIL_VEC3_H
#define DWV_UTIL_VEC3_H

#include <math.h>

typedef struct dwvu_vec3 { double x, y, z; } dwvu_vec3;

static inline dwvu_vec3 dwvu_v(double x, double y, double z) { dwvu_vec3 r = {x, y, z}; return r; }
static inline dwvu_vec3 dwvu_add(dwvu_vec3 a, dwvu_vec3 b) { return dwvu_v(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline dwvu_vec3 dwvu_sub(dwvu_vec3 a, dwvu_vec3 b) { return dwvu_v(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline dwvu_vec3 dwvu_scale(dwvu_vec3 a, double s) { return dwvu_v(a.x * s, a.y * s, a.z * s); }
static inline dwvu_vec3 dwvu_madd(dwvu_vec3 a, dwvu_vec3 d, double t) { return dwvu_v(a.x + d.x * t, a.y + d.y * t, a.z + d.z * t); }
static inline double dwvu_dot(dwvu_vec3 a, dwvu_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline dwvu_vec3 dwvu_cross(dwvu_vec3 a, dwvu_vec3 b)
{
    return dwvu_v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double dwvu_length(dwvu_vec3 a) { return sqrt(dwvu_dot(a, a)); }
static inline dwvu_vec3 dwvu_normalize(dwvu_vec3 a) { return dwvu_scale(a, 1.0 / dwvu_length(a)); }

/* An orthonormal frame (t, s, n) about the unit axis n: the branchless basis of Duff et al. 2017. */
typedef struct dwvu_frame { dwvu_vec3 t, s, n; } dwvu_frame;

static inline dwvu_frame dwvu_frame_about(dwvu_vec3 n)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    dwvu_frame f;
    f.t = dwvu_v(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.s = dwvu_v(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

/* The frame turned by q quarter turns about its axis: (t, s) -> (s, -t) per turn. With a frame turned
 * by q, dwvk_frame_direction (kernel/direction.h) of azimuth (c, s) is bit for bit that of the original frame with
 * (c, s) turned by q (dwvk_quarter_turns_f): the same products, negated or added in the other
 * order, both exact. */
static inline dwvu_frame dwvu_frame_turned(const dwvu_frame *f, int q)
{
    dwvu_frame r = *f;
    for (int i = 0; i < (q & 3); ++i) {
        dwvu_vec3 t = r.t;
        r.t = r.s;
        r.s = dwvu_scale(t, -1.0);
    }
    return r;
}

#endif
