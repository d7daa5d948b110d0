/* Next-event estimation: the radiance a white Lambertian surface reflects at a point, from every
 * light (one shadow-tested sample each) and the constant world (one cosine-weighted shadow ray). */
#ifndef DWV_LIGHT_DIRECT_H
#define DWV_LIGHT_DIRECT_H

#include <stdint.h>

#include "geom/embree.h"
#include "kernel/sampler.h"
#include "light.h"

typedef struct dwvl_environment {
    const dwvl_light *lights;
    uint32_t light_count;
    double world[3];          /* constant world radiance */
    int world_lit;            /* 0: the world is black and is not sampled */
    const dwvg_world *geometry;
} dwvl_environment;

/* Pairs of random dimensions one call uses: one per light and one for the world. */
static inline uint32_t dwvl_direct_pairs(const dwvl_environment *env)
{
    return env->light_count + 1u;
}

/* (1/pi) integral of L_in cos over the hemisphere of the shading normal `n` at x, estimated with
 * the uniform pairs of `sampler` starting at pair `pair`; `ng` is the unit geometric normal on
 * the same side (shadow rays leave from x + epsilon ng and never below the geometric surface). */
void dwvl_direct(const dwvl_environment *env, dwvw_vec3 x, dwvw_vec3 n, dwvw_vec3 ng, const dwvk_sampler *sampler,
                 uint32_t pair, double out[3]);

#endif
