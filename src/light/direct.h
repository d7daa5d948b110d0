/* Next-event estimation: the radiance a white Lambertian surface reflects at a point, from every
 * light (one shadow-tested sample each) and the world: a constant world by one cosine-weighted
 * shadow ray; an environment map by that ray and one drawn from the map's own distribution,
 * weighted by multiple importance sampling (balance heuristic, Veach 1997 Eq. 9.10). */
#ifndef DWV_LIGHT_DIRECT_H
#define DWV_LIGHT_DIRECT_H

#include <stdint.h>

#include "geom/embree.h"
#include "kernel/sampler.h"
#include "envmap.h"
#include "light.h"
#include "terminator.h"

typedef struct dwvl_environment {
    const dwvl_light *lights;
    uint32_t light_count;
    double world[3];          /* constant world radiance (unused with an envmap) */
    int world_lit;            /* 0: the world is black and is not sampled */
    const dwvg_world *geometry;
    const dwvl_envmap *envmap; /* NULL: the world is the constant `world` */
} dwvl_environment;

/* Pairs of random dimensions one call uses: one per light and one for the world (the cosine
 * ray), and one more for an environment map's own sample. */
static inline uint32_t dwvl_direct_pairs(const dwvl_environment *env)
{
    return env->light_count + 1u + (env->envmap ? 1u : 0u);
}

/* (1/pi) integral of L_in cos over the hemisphere of the shading normal `n` at x, estimated with
 * the uniform pairs of `sampler` starting at pair `pair`; `ng` is the unit geometric normal on
 * the same side (shadow rays leave from x + epsilon ng). `top`: the largest ng.y over the points
 * y of the world (dwvg_world_top for the outward normal of x's triangle), +inf if not known; a
 * shadow ray from above it (by a margin for Embree's rounding) along a direction that rises along
 * ng is not cast: it cannot meet anything (a convex world's every outward shadow ray).
 * `terminator` (NULL: a flat-shaded point) moves each shadow ray's origin by its share of the
 * smooth surface's lift (terminator.h), as Cycles does for smooth-shaded triangles; a light at a
 * finite distance is then aimed at from the moved origin. With a terminator whose cutoff is
 * above 0, light that n faces but the flat triangle does not (ng.light <= 0) is also tested, from
 * the smooth surface, as Cycles does; without one it is taken as shadowed. The side a shadow ray
 * leaves from and its share of the lift follow the terminator's smooth normal (Cycles' sd->N in
 * shadow_ray_offset), not n: where a normal map turned n toward a light that the smooth normal
 * faces away from, the ray leaves from under the triangle (a closed mesh's far side shadows it). */
void dwvl_direct(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                 const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair, double out[3]);

/* A BRDF's factor beside the Lambertian 1/pi for light arriving along unit `light` (toward the
 * light): the BRDF is (1/pi) factor(context, light). */
typedef double (*dwvl_lobe_factor)(const void *context, dwvu_vec3 light);

/* dwvl_direct with the same light samples (the same pairs of `sampler`) also weighted by
 * `factor`: lambert gets what dwvl_direct gives (NULL: not wanted), lobe the same integral with
 * (1/pi) factor(light) cos as the BRDF term. */
void dwvl_direct_lobe(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                      const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair,
                      dwvl_lobe_factor factor, const void *context, double lambert[3], double lobe[3]);

/* Two BRDFs per colour channel beside the Lambertian 1/pi for light along unit `light` (a
 * surface's glossy and diffuse layers, which bake passes keep apart): the BRDF of channel c of
 * lobe k is (1/pi) f[k][c]. */
typedef void (*dwvl_split_factor)(const void *context, dwvu_vec3 light, double f[2][3]);

/* dwvl_direct_lobe with two per-channel BRDFs: out[k][c] is the integral of L_in,c (1/pi)
 * f[k][c] cos, both lobes from the same light samples (pairs) as dwvl_direct, so their sum is
 * the estimate of the summed BRDF with no extra random numbers. */
void dwvl_direct_split(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                       const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair,
                       dwvl_split_factor factor, const void *context, double out[2][3]);

/* Two per-channel lobes with normals of their own (a Blender 4.x+ specular layer about its normal
 * kept valid for reflection beside the diffuse lobes about the mapped normal): as Cycles evaluates
 * each closure about its own N, lobe k takes light only from above its own horizon and with its
 * own cosine, normal[k] . L: out[k][c] is the integral of L_in,c (1/pi) f[k][c] (normal[k] . L)+.
 * A light's sample counts where it is above either horizon (a sun below both draws none). The
 * world's second strategy is the surface's own sampling (the one its path rays are drawn by, in
 * place of the cosine about one normal, which would miss the lobe whose horizon is the other):
 * `sample` draws a direction of the BRDF's continuous part from two uniforms (0: none), `pdf` is
 * that draw's density; an environment map is weighted against it by the balance heuristic. */
typedef struct dwvl_lobes {
    dwvl_split_factor factor;
    const void *context;
    dwvu_vec3 normal[2];
    int (*sample)(const void *sampling, double u0, double u1, dwvu_vec3 *w);
    double (*pdf)(const void *sampling, dwvu_vec3 w);
    const void *sampling;
} dwvl_lobes;

/* dwvl_direct_split with each lobe about its own normal (dwvl_lobes), from the same pairs; n (the
 * Lambertian `plain` sum's normal) is the diffuse lobes' (normal[1]). */
void dwvl_direct_lobes(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 ng, const dwvl_terminator *terminator,
                       double top, const dwvk_sampler *sampler, uint32_t pair, const dwvl_lobes *lobes,
                       double out[2][3]);

/* The emission a path ray from `origin` along unit d finds before its first surface at distance
 * t_max (+inf: it leaves the world): every light it passes (dwvl_light_along; Cycles' rays go on
 * through lights) and, where it leaves, the world's radiance along d. Without MIS: for rays that
 * no light sample could have found (singular reflections), which take the whole of it. */
void dwvl_emission_along(const dwvl_environment *env, dwvu_vec3 origin, dwvu_vec3 d, double t_max, double rgb[3]);

#endif
