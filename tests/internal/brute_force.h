/* References for the internal tests, written apart from the library's code: a SplitMix64
 * generator of uniforms (deterministic test points and directions), and the distance from a
 * point to a mesh triangle by brute force. */
#ifndef DWV_TESTS_BRUTE_FORCE_H
#define DWV_TESTS_BRUTE_FORCE_H

#include <math.h>
#include <stdint.h>

#include "geom/embree.h"

/* The next uniform on [0, 1) of a SplitMix64 stream (Steele, Lea and Flood 2014). */
static inline double brute_uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

/* The point of segment ab nearest to p (a itself for a zero-length segment). */
static inline dwvu_vec3 brute_segment_nearest(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b)
{
    dwvu_vec3 ab = dwvu_sub(b, a);
    double length2 = dwvu_dot(ab, ab);
    double t = length2 > 0.0 ? dwvu_dot(dwvu_sub(p, a), ab) / length2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return dwvu_madd(a, ab, t);
}

/* Distance from p to triangle `prim` of `mesh`: the face's plane where the projection falls
 * inside the triangle, else the nearest of its three edges; a zero-area triangle by its edges.
 * *nearest (if not NULL) gets the nearest point. */
static inline double brute_triangle_distance(const dwvg_mesh *mesh, uint32_t prim, dwvu_vec3 p, dwvu_vec3 *nearest)
{
    dwvu_vec3 v[3];
    for (int k = 0; k < 3; ++k) {
        const float *q = mesh->positions + 3u * mesh->indices[3u * prim + (uint32_t)k];
        v[k] = dwvu_v(q[0], q[1], q[2]);
    }
    dwvu_vec3 n = dwvg_geometric_normal(mesh, prim);
    if (n.x != 0.0 || n.y != 0.0 || n.z != 0.0) {
        double h = dwvu_dot(dwvu_sub(p, v[0]), n);
        dwvu_vec3 x = dwvu_madd(p, n, -h);
        int inside = 1;
        for (int k = 0; k < 3; ++k) {
            dwvu_vec3 e = dwvu_sub(v[(k + 1) % 3], v[k]), w = dwvu_sub(x, v[k]);
            dwvu_vec3 c = dwvu_v(e.y * w.z - e.z * w.y, e.z * w.x - e.x * w.z, e.x * w.y - e.y * w.x);
            if (dwvu_dot(c, n) < 0.0) inside = 0;
        }
        if (inside) {
            if (nearest) *nearest = x;
            return fabs(h);
        }
    }
    double best = INFINITY;
    for (int k = 0; k < 3; ++k) {
        dwvu_vec3 x = brute_segment_nearest(p, v[k], v[(k + 1) % 3]);
        double d = dwvu_length(dwvu_sub(p, x));
        if (d < best) {
            best = d;
            if (nearest) *nearest = x;
        }
    }
    return best;
}

#endif
