/* Small 3-vector helpers for the walk (double precision). */
#ifndef DWV_WALK_VEC3_H
#define DWV_WALK_VEC3_H

#include <math.h>

#include "kernel/fastmath.h"

typedef struct dwvw_vec3 { double x, y, z; } dwvw_vec3;

static inline dwvw_vec3 dwvw_v(double x, double y, double z) { dwvw_vec3 r = {x, y, z}; return r; }
static inline dwvw_vec3 dwvw_add(dwvw_vec3 a, dwvw_vec3 b) { return dwvw_v(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline dwvw_vec3 dwvw_sub(dwvw_vec3 a, dwvw_vec3 b) { return dwvw_v(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline dwvw_vec3 dwvw_scale(dwvw_vec3 a, double s) { return dwvw_v(a.x * s, a.y * s, a.z * s); }
static inline dwvw_vec3 dwvw_madd(dwvw_vec3 a, dwvw_vec3 d, double t) { return dwvw_v(a.x + d.x * t, a.y + d.y * t, a.z + d.z * t); }
static inline double dwvw_dot(dwvw_vec3 a, dwvw_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline double dwvw_length(dwvw_vec3 a) { return sqrt(dwvw_dot(a, a)); }
static inline dwvw_vec3 dwvw_normalize(dwvw_vec3 a) { return dwvw_scale(a, 1.0 / dwvw_length(a)); }

/* An orthonormal frame (t, s, n) about the unit axis n: the branchless basis of Duff et al. 2017. */
typedef struct dwvw_frame { dwvw_vec3 t, s, n; } dwvw_frame;

static inline dwvw_frame dwvw_frame_about(dwvw_vec3 n)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    dwvw_frame f;
    f.t = dwvw_v(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.s = dwvw_v(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

/* The frame turned by q quarter turns about its axis: (t, s) -> (s, -t) per turn. With a frame turned
 * by q, dwvw_frame_direction of azimuth (c, s) is bit for bit that of the original frame with
 * (c, s) turned by q (dwvk_quarter_turns_f): the same products, negated or added in the other
 * order, both exact. */
static inline dwvw_frame dwvw_frame_turned(const dwvw_frame *f, int q)
{
    dwvw_frame r = *f;
    for (int i = 0; i < (q & 3); ++i) {
        dwvw_vec3 t = r.t;
        r.t = r.s;
        r.s = dwvw_scale(t, -1.0);
    }
    return r;
}

/* The direction with cosine mu to the frame's axis, sine sin_theta (from 1 -+ mu without
 * cancellation) and azimuth `azimuth` (a point of the unit circle, dwvk_azimuth_f). The
 * single-precision inputs leave it unit only to |l^2 - 1| <= ~1e-6; hosts and the analytic shapes
 * rely on unit directions, so it is rescaled in double by one Newton step for 1/sqrt(l^2) from 1,
 * (3 - l^2)/2, which leaves |l - 1| <= (3/8)(l^2 - 1)^2 ~ 4e-13: no square root or division. */
static inline dwvw_vec3 dwvw_frame_direction(const dwvw_frame *f, double mu, double sin_theta, dwvk_unit2_f azimuth)
{
    double c = (double)azimuth.c * sin_theta, d = (double)azimuth.s * sin_theta;
    dwvw_vec3 w = dwvw_v(f->t.x * c + f->s.x * d + f->n.x * mu, f->t.y * c + f->s.y * d + f->n.y * mu,
                         f->t.z * c + f->s.z * d + f->n.z * mu);
    return dwvw_scale(w, 1.5 - 0.5 * dwvw_dot(w, w));
}

/* The direction with cosine mu to the unit axis n and azimuth from u in [0, 1] (dwvk_azimuth_f). */
static inline dwvw_vec3 dwvw_direction_about(dwvw_vec3 n, double mu, double one_minus_mu, double one_plus_mu,
                                             double u)
{
    dwvw_frame f = dwvw_frame_about(n);
    return dwvw_frame_direction(&f, mu, sqrt(fmax(0.0, one_minus_mu * one_plus_mu)), dwvk_azimuth_f((float)u));
}

#endif
