#include "direct.h"

#include "kernel/direction.h"

#include <math.h>


#define INV_PI 0.31830988618379067154

/* The origins of one shading point's shadow rays: x + epsilon ng, or x - epsilon ng for a ray that
 * leaves from the other side (shadow_side), moved by a ray's share of the smooth surface's lift
 * on its side (terminator.h), which is computed once per side, for the first ray that takes some. */
typedef struct shadow_origins {
    const dwvl_terminator *terminator; /* NULL: a flat-shaded point */
    dwvu_vec3 ng, flat, under, lift[2];
    int have_lift[2];
    double clear; /* ng.origin above this, rising along ng: the ray meets nothing (clear_of) */
} shadow_origins;

/* Whether a shadow ray from `origin` along unit d is known to meet nothing: it starts above the
 * world's highest point along ng (the `top` of dwvl_direct) and rises. The margin above the top is
 * 2^-19 of (the world's largest coordinate + the origin's), a sixteenth of the float ulps of
 * that sum: Embree traces the ray rounded to float (the origin within half an ulp, the direction
 * within 2^-24, which lowers it by at most 2^-23 of the world's diameter before it is past the
 * world) with a watertight test that errs by a few ulps. The flat origin is 2^-17 of the largest
 * coordinate above its plane (the epsilon), which is the top of a convex world: it clears. */
static int clear_of(const shadow_origins *o, dwvu_vec3 origin, dwvu_vec3 d)
{
    return dwvu_dot(d, o->ng) > 0.0 && dwvu_dot(origin, o->ng) > o->clear;
}

/* The side a shadow ray along unit `light` leaves from, as Cycles' shadow_ray_offset (3.x to 5.x,
 * light/sample.h) decides it by the smooth normal sd->N, not by any normal a normal map or bump
 * gave the lobes: 0, ng's, where the smooth normal faces the light; 1, the other, where it does
 * not (Cycles' "transmit": Ng and the lift turned inward, the smooth surface below the flat
 * triangle). A lobe whose mapped normal faces a light that the smooth normal does not is thus
 * shadowed by the mesh behind (a closed mesh's own far side), as in Cycles. */
static int shadow_side(const shadow_origins *o, dwvu_vec3 light)
{
    return o->terminator && dwvu_dot(o->terminator->n, light) < 0.0;
}

/* The share of the lift a shadow ray along unit `light` takes from side `side` (its cosines to the
 * smooth and the geometric normal both turned to that side). */
static double lift_amount(const shadow_origins *o, dwvu_vec3 light, int side)
{
    const dwvl_terminator *t = o->terminator;
    if (!t) return 0.0;
    double cos_n = dwvu_dot(t->n, light), cos_g = dwvu_dot(o->ng, light);
    return side ? dwvl_terminator_amount(-cos_n, -cos_g, t->cutoff) : dwvl_terminator_amount(cos_n, cos_g, t->cutoff);
}

/* The origin of the shadow ray along unit `light`; *amount gets the share of the lift it took. */
static dwvu_vec3 shadow_origin(shadow_origins *o, dwvu_vec3 light, double *amount)
{
    int side = shadow_side(o, light);
    *amount = lift_amount(o, light, side);
    dwvu_vec3 start = side ? o->under : o->flat;
    if (!(*amount > 0.0)) return start;
    if (!o->have_lift[side]) {
        const dwvl_terminator *t = o->terminator;
        o->lift[side] = dwvl_terminator_lift_at(t->mesh, t->prim, t->u, t->v, side ? dwvu_scale(o->ng, -1.0) : o->ng);
        o->have_lift[side] = 1;
    }
    return dwvu_madd(start, o->lift[side], *amount);
}

/* Whether a light the shading normal faces gets a shadow ray. The lift never goes below the flat
 * triangle on its side. Light above the flat triangle (ng.light > 0) always does: the ray cannot
 * meet its own triangle, so the epsilon does what Cycles' skipping of the triangle itself (its
 * self-intersection test when Ng.L > 0 on the ray's side) does. Light below it (ng.light <= 0,
 * the shading normal's terminator lies beyond the flat one's) does only from a smooth surface,
 * as in Cycles: from above (the smooth normal facing the light) the ray takes the whole lift
 * (dwvl_terminator_amount is 1 there) and, Cycles not skipping its own triangle then, is
 * shadowed where it passes through that triangle; from below (shadow_side 1) it leaves from
 * under the triangle. A flat point (no terminator, or cutoff 0) is unlit there: its ray would
 * enter the mesh at once. */
static int shadow_ray_allowed(const shadow_origins *o, dwvu_vec3 light)
{
    return dwvu_dot(o->ng, light) > 0.0 || (o->terminator && o->terminator->cutoff > 0.0);
}

/* Whether the world is seen from the shading point along unit w (a shadow ray to infinity). */
static int world_visible(const dwvl_environment *env, shadow_origins *origins, dwvu_vec3 w)
{
    if (!shadow_ray_allowed(origins, w)) return 0;
    if (!env->geometry) return 1;
    double amount;
    dwvu_vec3 origin = shadow_origin(origins, w, &amount);
    return clear_of(origins, origin, w) || !dwvg_occluded(env->geometry, origin, w, 0.0, INFINITY);
}

/* A lobe's factor: scalar (`factor`, the same in every channel, into f[0]), or two per-channel
 * ones (`split`); f[1] is 0 for a scalar one, and both are 0 for none (Lambertian only). */
typedef struct lobe_factors {
    dwvl_lobe_factor factor;
    dwvl_split_factor split;
    const void *context;
    const dwvl_lobes *own; /* lobes about normals of their own (its factor then); NULL: all about n */
} lobe_factors;

static void lobe_weights(const lobe_factors *lobes, dwvu_vec3 light, double f[2][3])
{
    for (int k = 0; k < 2; ++k) f[k][0] = f[k][1] = f[k][2] = 0.0;
    if (lobes->own) lobes->own->factor(lobes->own->context, light, f);
    else if (lobes->split) lobes->split(lobes->context, light, f);
    else if (lobes->factor) f[0][0] = f[0][1] = f[0][2] = lobes->factor(lobes->context, light);
}

/* Lobe k's cosine to unit `light` (about its own normal where it has one, else n's cos_n), 0
 * below its horizon; returns 0 where the light is below every lobe's horizon. */
static int lobe_cosines(const lobe_factors *lobes, double cos_n, dwvu_vec3 light, double cosine[2])
{
    if (!lobes->own) {
        cosine[0] = cosine[1] = cos_n;
        return cos_n > 0.0;
    }
    for (int k = 0; k < 2; ++k) cosine[k] = fmax(dwvu_dot(lobes->own->normal[k], light), 0.0);
    return cosine[0] > 0.0 || cosine[1] > 0.0;
}

/* The world's light from lobes about normals of their own (lobes->own): the surface's sampling
 * (pdf p_b, pair `pair`) and, with an environment map, the map's (p_e, pair `pair` + 1), each
 * weighted by the balance heuristic p / (p_b + p_e) (p_e = 0 without a map: the one strategy);
 * each adds L f_k (cos_k / pi) / (p_b + p_e) where it is above lobe k's horizon and unshadowed
 * (cos_k its own normal's; envmap_light's expression with p_b for p_c). The Lambertian about n
 * (plain) from the same samples likewise. */
static void own_world_light(const dwvl_environment *env, shadow_origins *origins, dwvu_vec3 n,
                            const dwvk_sampler *sampler, uint32_t pair, const lobe_factors *lobes, double plain[3],
                            double weighted[2][3])
{
    const dwvl_lobes *own = lobes->own;
    int strategies = env->envmap ? 2 : 1;
    for (int strategy = 0; strategy < strategies; ++strategy) {
        double u[2];
        dwvk_sampler_pair(sampler, pair + (uint32_t)strategy, u);
        dwvu_vec3 w;
        double p_e = 0.0;
        if (strategy == 0) {
            if (!own->sample(own->sampling, u[0], u[1], &w)) continue;
            if (env->envmap) p_e = dwvl_envmap_pdf(env->envmap, w);
        } else {
            dwvl_envmap_sample(env->envmap, u[0], u[1], &w, &p_e);
            if (!(p_e > 0.0)) continue;
        }
        double cos_n = dwvu_dot(n, w), cosine[2];
        if (!lobe_cosines(lobes, cos_n, w, cosine)) continue;
        double p_b = own->pdf(own->sampling, w);
        if (!(p_b + p_e > 0.0) || !isfinite(p_b + p_e)) continue;
        double radiance[3] = {env->world[0], env->world[1], env->world[2]};
        if (env->envmap) dwvl_envmap_radiance(env->envmap, w, radiance);
        if (!(radiance[0] > 0.0 || radiance[1] > 0.0 || radiance[2] > 0.0)) continue;
        if (!world_visible(env, origins, w)) continue;
        double f[2][3];
        lobe_weights(lobes, w, f);
        double lambert = fmax(cos_n, 0.0) * INV_PI / (p_b + p_e);
        for (int c = 0; c < 3; ++c) {
            plain[c] += radiance[c] * lambert;
            for (int k = 0; k < 2; ++k) weighted[k][c] += radiance[c] * (cosine[k] * INV_PI / (p_b + p_e)) * f[k][c];
        }
    }
}

/* An environment map's share of direct_core: two strategies, the cosine-weighted direction about
 * n (pdf p_c = cos / pi, pair `pair`) and the map's own (pdf p_e, pair `pair` + 1), each weighted
 * by the balance heuristic p_s / (p_c + p_e). With L the map's radiance and f the lobe's factor,
 * the estimator of (1/pi) integral L f cos is, per strategy,
 *   cosine:  L f (cos/pi) / p_c x p_c / (p_c + p_e) = L f (cos/pi) / (p_c + p_e),
 *   map:     L f (cos/pi) / p_e x p_e / (p_c + p_e) = the same expression at its direction,
 * so both add L f (cos/pi) / (p_c + p_e) where the direction is above n and unshadowed. */
static void envmap_light(const dwvl_environment *env, shadow_origins *origins, dwvu_vec3 n, const dwvk_sampler *sampler,
                         uint32_t pair, const lobe_factors *lobes, double plain[3], double weighted[2][3])
{
    for (int strategy = 0; strategy < 2; ++strategy) {
        double u[2];
        dwvk_sampler_pair(sampler, pair + (uint32_t)strategy, u);
        dwvu_vec3 w;
        double p_e, cos_n;
        if (strategy == 0) {
            cos_n = sqrt(u[0]);
            w = dwvk_direction_about(n, cos_n, 1.0 - cos_n, 1.0 + cos_n, u[1]);
            p_e = dwvl_envmap_pdf(env->envmap, w);
        } else {
            dwvl_envmap_sample(env->envmap, u[0], u[1], &w, &p_e);
            if (!(p_e > 0.0)) continue;
            cos_n = dwvu_dot(n, w);
        }
        if (!(cos_n > 0.0)) continue;
        double p_c = cos_n * INV_PI;
        if (!(p_c + p_e > 0.0) || !isfinite(p_e)) continue;
        double radiance[3];
        dwvl_envmap_radiance(env->envmap, w, radiance);
        if (!(radiance[0] > 0.0 || radiance[1] > 0.0 || radiance[2] > 0.0)) continue;
        if (!world_visible(env, origins, w)) continue;
        double scale = p_c / (p_c + p_e);
        double f[2][3];
        lobe_weights(lobes, w, f);
        for (int c = 0; c < 3; ++c) {
            plain[c] += radiance[c] * scale;
            for (int k = 0; k < 2; ++k) weighted[k][c] += radiance[c] * scale * f[k][c];
        }
    }
}

/* The estimator of dwvl_direct_lobe and dwvl_direct_split: a scalar factor (the same in every
 * channel) or two per-channel ones (split, when not NULL). */
static void direct_core(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                        const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair,
                        const lobe_factors *lobes, double lambert[3], double lobe[2][3])
{
    double plain[3] = {0.0, 0.0, 0.0}, weighted[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    double eps = env->geometry ? env->geometry->epsilon : 0.0;
    shadow_origins origins = {terminator, ng, dwvu_madd(x, ng, eps), dwvu_madd(x, ng, -eps),
                              {dwvu_v(0.0, 0.0, 0.0), dwvu_v(0.0, 0.0, 0.0)}, {0, 0}, INFINITY};
    if (top < INFINITY) {
        /* eps is 2^-17 of the largest coordinate: the margin is 2^-19 of it and of the origin's. */
        double coordinate = fmax(fabs(x.x), fmax(fabs(x.y), fabs(x.z))) + eps;
        origins.clear = top + 0.25 * eps + 0x1p-19 * coordinate;
    }
    for (uint32_t i = 0; i < env->light_count; ++i) {
        /* A sun below the shading normal's horizon (every lobe's) gives nothing: its pair is not
         * drawn (each light has its own pair, which nothing else uses). */
        if (lobes->own ? dwvl_light_below(&env->lights[i], lobes->own->normal[0]) &&
                             dwvl_light_below(&env->lights[i], lobes->own->normal[1])
                       : dwvl_light_below(&env->lights[i], n))
            continue;
        dwvl_sample s;
        double u[2];
        dwvk_sampler_pair(sampler, pair + i, u);
        dwvl_light_sample(&env->lights[i], x, u[0], u[1], &s);
        double cos_n = dwvu_dot(n, s.direction), cosine[2];
        if (!lobe_cosines(lobes, cos_n, s.direction, cosine)) continue;
        if (!shadow_ray_allowed(&origins, s.direction)) continue;
        if (!(s.value[0] > 0.0 || s.value[1] > 0.0 || s.value[2] > 0.0)) continue;
        if (env->geometry) {
            double amount;
            dwvu_vec3 origin = shadow_origin(&origins, s.direction, &amount);
            dwvu_vec3 toward = s.direction;
            double distance = s.distance;
            if (amount > 0.0 && isfinite(distance)) {
                /* The sampled light point, seen from the moved origin (as Cycles aims it). */
                dwvu_vec3 to_light = dwvu_sub(dwvu_madd(x, s.direction, s.distance), origin);
                distance = dwvu_length(to_light);
                toward = dwvu_scale(to_light, 1.0 / distance);
            }
            /* The segment stops short of the light by the offset, so that an area light lying on
             * a surface does not shadow itself. */
            if (!clear_of(&origins, origin, toward) && dwvg_occluded(env->geometry, origin, toward, 0.0, distance - 2.0 * eps))
                continue;
        }
        double f[2][3];
        lobe_weights(lobes, s.direction, f);
        for (int c = 0; c < 3; ++c) {
            plain[c] += s.value[c] * fmax(cos_n, 0.0) * INV_PI;
            for (int k = 0; k < 2; ++k) weighted[k][c] += s.value[c] * cosine[k] * INV_PI * f[k][c];
        }
    }
    if (env->world_lit && lobes->own) {
        own_world_light(env, &origins, n, sampler, pair + env->light_count, lobes, plain, weighted);
    } else if (env->world_lit && env->envmap) {
        envmap_light(env, &origins, n, sampler, pair + env->light_count, lobes, plain, weighted);
    } else if (env->world_lit) {
        /* Cosine-weighted direction about n (pdf cos / pi): the estimate is L_world x visibility
         * (x the factor for the lobe). */
        double u[2];
        dwvk_sampler_pair(sampler, pair + env->light_count, u);
        double mu = sqrt(u[0]);
        dwvu_vec3 w = dwvk_direction_about(n, mu, 1.0 - mu, 1.0 + mu, u[1]);
        int blocked = !shadow_ray_allowed(&origins, w);
        if (!blocked && env->geometry) {
            double amount;
            dwvu_vec3 origin = shadow_origin(&origins, w, &amount);
            blocked = !clear_of(&origins, origin, w) && dwvg_occluded(env->geometry, origin, w, 0.0, INFINITY);
        }
        if (!blocked) {
            double f[2][3];
            lobe_weights(lobes, w, f);
            for (int c = 0; c < 3; ++c) {
                plain[c] += env->world[c];
                for (int k = 0; k < 2; ++k) weighted[k][c] += env->world[c] * f[k][c];
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        if (lambert) lambert[c] = plain[c];
        if (lobe)
            for (int k = 0; k < 2; ++k) lobe[k][c] = weighted[k][c];
    }
}

void dwvl_direct_lobe(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                      const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair,
                      dwvl_lobe_factor factor, const void *context, double lambert[3], double lobe[3])
{
    lobe_factors lobes = {factor, NULL, context, NULL};
    double weighted[2][3];
    direct_core(env, x, n, ng, terminator, top, sampler, pair, &lobes, lambert, weighted);
    if (lobe)
        for (int c = 0; c < 3; ++c) lobe[c] = weighted[0][c];
}

void dwvl_direct_split(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                       const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair,
                       dwvl_split_factor factor, const void *context, double out[2][3])
{
    lobe_factors lobes = {NULL, factor, context, NULL};
    direct_core(env, x, n, ng, terminator, top, sampler, pair, &lobes, NULL, out);
}

void dwvl_direct_lobes(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 ng, const dwvl_terminator *terminator,
                       double top, const dwvk_sampler *sampler, uint32_t pair, const dwvl_lobes *own,
                       double out[2][3])
{
    lobe_factors lobes = {NULL, NULL, NULL, own};
    direct_core(env, x, own->normal[1], ng, terminator, top, sampler, pair, &lobes, NULL, out);
}

void dwvl_direct(const dwvl_environment *env, dwvu_vec3 x, dwvu_vec3 n, dwvu_vec3 ng,
                 const dwvl_terminator *terminator, double top, const dwvk_sampler *sampler, uint32_t pair, double out[3])
{
    dwvl_direct_lobe(env, x, n, ng, terminator, top, sampler, pair, NULL, NULL, out, NULL);
}

void dwvl_emission_along(const dwvl_environment *env, dwvu_vec3 origin, dwvu_vec3 d, double t_max, double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    for (uint32_t i = 0; i < env->light_count; ++i) {
        double met[3];
        if (dwvl_light_along(&env->lights[i], origin, d, t_max, met))
            for (int c = 0; c < 3; ++c) rgb[c] += met[c];
    }
    if (!env->world_lit || t_max < INFINITY) return;
    double world[3] = {env->world[0], env->world[1], env->world[2]};
    if (env->envmap) dwvl_envmap_radiance(env->envmap, d, world);
    for (int c = 0; c < 3; ++c) rgb[c] += world[c];
}
