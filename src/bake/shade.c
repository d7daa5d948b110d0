#include "shade.h"

#include <math.h>


/* The mixture terms of the step just sampled (see dwvb_tally). */
static uint64_t mixture_terms(const dwvw_walk *walk)
{
    uint64_t active = 0;
    for (int k = 0; k < walk->component_count; ++k) active += walk->component_q[k] > 0.0;
    uint64_t channels = (uint64_t)walk->medium->channels;
    uint64_t patches = walk->guide->q_incident > 0.0 && walk->guide->patch_count > 1 ? (uint64_t)walk->guide->patch_count : 0u;
    return active * channels * channels + patches;
}

/* Runs one walk from entry point x (on triangle entry_prim of mesh `mesh`) along unit `direction`
 * into the medium; on exit fills the exit hit and returns 1. */
static int run_walk(const dwvb_shader *shader, uint32_t mesh, const dwvb_material *material, uint32_t entry_prim, dwvw_vec3 x, dwvw_vec3 direction, dwvw_vec3 entry_normal, uint64_t key,
                    dwvw_walk *walk, dwvg_hit *exit, dwvb_tally *tally)
{
    const dwvg_world *world = &shader->scene->geometry;
    const dwvg_mesh *m = &shader->scene->meshes[mesh];
    dwvw_walk_begin(walk, &material->medium, &shader->guides[mesh], key, shader->max_events, x, direction,
                    entry_normal);
    int needs_closest = shader->needs_closest[mesh];
    int first = 1;
    while (walk->status == DWVW_RUNNING) {
        if (needs_closest) {
            dwvg_hit closest;
            if (dwvg_closest_mesh(world, mesh, walk->position, &closest))
                dwvw_walk_set_closest(walk, dwvg_geometric_normal(m, closest.prim));
        }
        double distance = dwvw_walk_sample(walk);
        tally->mixture_terms += mixture_terms(walk);
        /* The first step is the probe: its full distance to the surface locates an opposite
         * interface. A ray leaving a flat triangle inward cannot meet that triangle again, so a
         * hit on the entry triangle is rounding and the ray goes on past it. */
        double tnear = 0.0, tfar = first ? INFINITY : distance;
        dwvg_hit hit;
        int found;
        for (;;) {
            found = dwvg_intersect_mesh(world, mesh, walk->position, walk->direction, tnear, tfar, &hit);
            if (!(found && first && hit.prim == entry_prim)) break;
            tnear = nextafterf((float)hit.t, INFINITY);
        }
        /* A closed mesh surrounds every point inside: a probe that meets nothing means the
         * mesh is open there (or the ray slipped through), and the walk may wander off. */
        if (first && !found) ++tally->warnings;
        first = 0;
        dwvw_vec3 normal = dwvw_v(0.0, 0.0, 0.0);
        if (found) {
            normal = dwvg_geometric_normal(m, hit.prim);
            if (normal.x == 0.0 && normal.y == 0.0 && normal.z == 0.0) {
                ++tally->warnings;
                return 0;
            }
            *exit = hit;
        }
        dwvw_walk_complete(walk, found ? hit.t : INFINITY, normal);
    }
    tally->events += walk->events;
    ++tally->walks;
    if (walk->status == DWVW_TRUNCATED) {
        int channels = material->medium.channels;
        for (int c = 0; c < 3; ++c) tally->truncated[c] += walk->weight[channels == 1 ? 0 : c] * material->walk_scale[c];
    }
    return walk->status == DWVW_EXITED;
}

/* The exit weight of Blender 3.x's Principled BSDF; the context is the exit's shading normal. */
static double exit_factor(const void *context, dwvw_vec3 light);

/* What an exit at point y of triangle `prim` (barycentrics u, v; outward geometric normal ng)
 * of mesh `mesh` gathers per unit walk weight: the direct light through a Lambertian exit, or
 * Principled v1's exit weight 1 - F_L/2; the light pairs of `sampler` from `pair` on. */
static void gather_exit(const dwvb_shader *shader, const dwvg_mesh *mesh, const dwvb_material *material,
                        uint32_t prim, double u, double v, dwvw_vec3 y, dwvw_vec3 ng, const dwvk_sampler *sampler,
                        uint32_t pair, double direct[3])
{
    dwvw_vec3 n = dwvg_shading_normal(mesh, prim, u, v, ng);
    if (material->principled_v1)
        dwvl_direct_lobe(&shader->env, y, n, ng, sampler, pair, exit_factor, &n, NULL, direct);
    else
        dwvl_direct(&shader->env, y, n, ng, sampler, pair, direct);
}

/* Whether any light might reach a surface point with outward geometric normal ng: dwvl_direct
 * takes only directions above the geometric surface, so a sun of angular radius h lights no point
 * whose normal is more than 90 degrees + h from it, and a sphere light none whose tangent plane
 * it lies below. Area lights and a lit world are taken as reaching everywhere. */
static int may_be_lit(const dwvl_environment *env, dwvw_vec3 y, dwvw_vec3 ng)
{
    if (env->world_lit) return 1;
    for (uint32_t i = 0; i < env->light_count; ++i) {
        const dwvl_light *light = &env->lights[i];
        if (light->kind == DWV_LIGHT_SUN) {
            double omc = light->one_minus_cos_half;
            if (dwvw_dot(ng, light->direction) > -sqrt(omc * (2.0 - omc))) return 1;
        } else if (light->kind == DWV_LIGHT_POINT) {
            if (dwvw_dot(ng, dwvw_sub(light->position, y)) > -light->radius) return 1;
        } else {
            return 1;
        }
    }
    return 0;
}

/* Adds the expected exit of the pending step of `walk` (direction sampled, ray cast: the surface
 * at hit, y) to rgb: factor x walk_scale x C(y), gathered only where light may reach y, and with
 * Russian roulette (uniform u) where the largest channel's factor is below the threshold. */
static void score_exit(const dwvb_shader *shader, const dwvg_mesh *m, const dwvb_material *material,
                       const dwvw_walk *walk, const dwvg_hit *hit, dwvw_vec3 normal, double u,
                       const dwvk_sampler *sampler, uint32_t light_pair, double rgb[3], dwvb_tally *tally)
{
    const int grey = material->medium.channels == 1;
    dwvw_vec3 y = dwvw_madd(walk->position, walk->direction, hit->t);
    double factor[DWVW_MAX_CHANNELS];
    dwvw_walk_exit_factor(walk, hit->t, factor);
    double largest = 0.0;
    for (int c = 0; c < material->medium.channels; ++c) largest = fmax(largest, factor[c]);
    if (!(largest > 0.0) || !may_be_lit(&shader->env, y, normal)) return;
    if (largest < DWVB_EXIT_ROULETTE_THRESHOLD) {
        double keep = largest / DWVB_EXIT_ROULETTE_THRESHOLD;
        if (!(u < keep)) return;
        for (int c = 0; c < material->medium.channels; ++c) factor[c] /= keep;
    }
    double direct[3];
    gather_exit(shader, m, material, hit->prim, hit->u, hit->v, y, normal, sampler, light_pair, direct);
    ++tally->gathers;
    for (int c = 0; c < 3; ++c) rgb[c] += factor[grey ? 0 : c] * material->walk_scale[c] * direct[c];
}

/* The ray along walk->direction to the surface, up to tfar; at the first step a hit on the entry
 * triangle is rounding and the ray goes on past it (as run_walk's probe). 0 where it meets
 * nothing, -1 on a degenerate triangle, else 1 with the hit and its outward geometric normal. */
static int surface_along(const dwvb_shader *shader, uint32_t mesh, const dwvw_walk *walk, int first,
                         uint32_t entry_prim, double tfar, dwvg_hit *hit, dwvw_vec3 *normal)
{
    const dwvg_world *world = &shader->scene->geometry;
    double tnear = 0.0;
    int found;
    for (;;) {
        found = dwvg_intersect_mesh(world, mesh, walk->position, walk->direction, tnear, tfar, hit);
        if (!(found && first && hit->prim == entry_prim)) break;
        tnear = nextafterf((float)hit->t, INFINITY);
    }
    *normal = dwvw_v(0.0, 0.0, 0.0);
    if (!found) return 0;
    *normal = dwvg_geometric_normal(&shader->scene->meshes[mesh], hit->prim);
    return normal->x == 0.0 && normal->y == 0.0 && normal->z == 0.0 ? -1 : 1;
}

/* The walk of run_walk (the same steps and numbers), its exit scored in expectation at the first
 * `expected_events` events (dwvw_walk_exit_factor): at such an event the ray along the sampled
 * direction runs on to the reach (DWVB_EXIT_REACH mean free paths of the thinnest channel) or
 * the sampled flight if longer; where it meets the surface within the reach, the exit point y
 * adds factor x walk_scale x C(y) to rgb (score_exit) and the flight is drawn again inside
 * (dwvw_walk_stay_inside, the weight cut by the chance of leaving), so no walk leaves there.
 * Elsewhere (later events, or a surface beyond the reach: a choice made from the direction alone,
 * which keeps the expectation) the step is run_walk's and a flight that reaches the surface leaves
 * and gathers as in dwvb_shade. An expected exit's light C(y) uses the exit's light pairs
 * (`light_pair` on) like a sampled exit: each term keeps its expectation; the terms of one walk
 * share those numbers. */
static void run_walk_expected_exit(const dwvb_shader *shader, uint32_t mesh, const dwvb_material *material,
                                   uint32_t entry_prim, dwvw_vec3 x, dwvw_vec3 direction, dwvw_vec3 entry_normal,
                                   uint64_t key, uint32_t expected_events, const dwvk_sampler *sampler,
                                   uint32_t light_pair, double rgb[3], dwvb_tally *tally)
{
    const dwvg_world *world = &shader->scene->geometry;
    const dwvb_scene *scene = shader->scene;
    const dwvg_mesh *m = &scene->meshes[mesh];
    const dwvw_medium *medium = &material->medium;
    const int grey = medium->channels == 1;
    dwvw_walk walk;
    dwvw_walk_begin(&walk, medium, &shader->guides[mesh], key, shader->max_events, x, direction, entry_normal);
    int needs_closest = shader->needs_closest[mesh];
    double sigma_min = medium->sigma_t[0];
    for (int c = 1; c < medium->channels; ++c) sigma_min = fmin(sigma_min, medium->sigma_t[c]);
    const double reach = DWVB_EXIT_REACH / sigma_min;
    int first = 1;
    while (walk.status == DWVW_RUNNING) {
        if (needs_closest) {
            dwvg_hit closest;
            if (dwvg_closest_mesh(world, mesh, walk.position, &closest))
                dwvw_walk_set_closest(&walk, dwvg_geometric_normal(m, closest.prim));
        }
        const uint32_t roulette_dim = dwvw_event_dim(walk.events) + DWVW_DIM_EXIT_ROULETTE;
        double distance = dwvw_walk_sample(&walk);
        tally->mixture_terms += mixture_terms(&walk);
        int forced = walk.events < expected_events;
        /* The first step's ray is run_walk's probe, uncut; a forced step's runs to the reach. */
        double tfar = first ? INFINITY : forced ? fmax(distance, reach) : distance;
        dwvg_hit hit;
        dwvw_vec3 normal;
        int found = surface_along(shader, mesh, &walk, first, entry_prim, tfar, &hit, &normal);
        if (first && !found) ++tally->warnings;
        first = 0;
        if (found < 0) {
            ++tally->warnings;
            break;
        }
        if (found && forced && hit.t <= reach) {
            score_exit(shader, m, material, &walk, &hit, normal, dwvk_rng_uniform_d(walk.key, roulette_dim), sampler,
                       light_pair, rgb, tally);
            dwvw_walk_stay_inside(&walk, hit.t);
        }
        dwvw_walk_complete(&walk, found ? hit.t : INFINITY, normal);
        if (walk.status == DWVW_EXITED) {
            double direct[3];
            gather_exit(shader, m, material, hit.prim, hit.u, hit.v, walk.position, normal, sampler, light_pair, direct);
            for (int c = 0; c < 3; ++c) rgb[c] += walk.weight[grey ? 0 : c] * material->walk_scale[c] * direct[c];
        }
    }
    tally->events += walk.events;
    ++tally->walks;
    if (walk.status == DWVW_TRUNCATED)
        for (int c = 0; c < 3; ++c) tally->truncated[c] += walk.weight[grey ? 0 : c] * material->walk_scale[c];
}

/* The retro-reflection lobe of Blender 3.x's Principled BSDF at a surface point. */
typedef struct retro_lobe {
    dwvw_vec3 n;       /* shading normal */
    dwvw_vec3 to_view; /* unit, toward the viewer */
    double cos_view;
    double roughness;
} retro_lobe;

static double retro_factor(const void *context, dwvw_vec3 light)
{
    const retro_lobe *lobe = context;
    return dwvb_principled_retro_factor(dwvw_dot(lobe->n, light), lobe->cos_view, dwvw_dot(light, lobe->to_view),
                                        lobe->roughness);
}

static double exit_factor(const void *context, dwvw_vec3 light)
{
    const dwvw_vec3 *n = context;
    return dwvb_principled_exit_factor(dwvw_dot(*n, light));
}

void dwvb_shade(const dwvb_shader *shader, const dwvg_hit *hit, dwvw_vec3 view, const dwvk_sampler *sampler,
                uint32_t pair, uint64_t key_walk, double rgb[3], dwvb_tally *tally)
{
    const dwvb_scene *scene = shader->scene;
    const dwvg_mesh *mesh = &scene->meshes[hit->mesh];
    uint32_t material_id = mesh->material_id;
    const dwvb_material *material = &scene->shading[material_id];
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    dwvw_vec3 ng = dwvg_geometric_normal(mesh, hit->prim);
    if (ng.x == 0.0 && ng.y == 0.0 && ng.z == 0.0) {
        ++tally->warnings;
        return;
    }
    if (dwvw_dot(view, ng) > 0.0) {
        /* The back of a face. A diffuse surface is two-sided; a subsurface one is seen from inside
         * its medium (an open or inside-out mesh): no walk is defined there. */
        if (material->subsurface) {
            ++tally->warnings;
            return;
        }
        ng = dwvw_scale(ng, -1.0);
    }
    dwvw_vec3 x = dwvg_point(mesh, hit->prim, hit->u, hit->v);
    dwvw_vec3 n = dwvg_shading_normal(mesh, hit->prim, hit->u, hit->v, ng);
    uint32_t light_pairs = dwvl_direct_pairs(&shader->env);
    if (material->principled_v1) {
        /* The Lambertian lobe and the retro-reflection lobe from the same light samples. */
        retro_lobe lobe = {n, dwvw_scale(view, -1.0), -dwvw_dot(n, view), material->roughness};
        double direct[3], retro[3];
        dwvl_direct_lobe(&shader->env, x, n, ng, sampler, pair + DWVB_SHADE_PAIRS, retro_factor, &lobe, direct, retro);
        for (int c = 0; c < 3; ++c) rgb[c] += material->diffuse_albedo[c] * direct[c] + material->retro_albedo[c] * retro[c];
    } else if (material->diffuse_albedo[0] > 0.0 || material->diffuse_albedo[1] > 0.0 ||
               material->diffuse_albedo[2] > 0.0) {
        double direct[3];
        dwvl_direct(&shader->env, x, n, ng, sampler, pair + DWVB_SHADE_PAIRS, direct);
        for (int c = 0; c < 3; ++c) rgb[c] += material->diffuse_albedo[c] * direct[c];
    }
    if (!material->subsurface) return;
    /* Entry: cosine-weighted about -n, rejected (no contribution, as Cycles) where it would not
     * go below the geometric surface. The pdf cos/pi cancels the diffuse transmission f = 1/pi. */
    double u[2];
    dwvk_sampler_pair(sampler, pair, u);
    double mu = sqrt(u[0]);
    dwvw_vec3 inward = dwvw_direction_about(dwvw_scale(n, -1.0), mu, 1.0 - mu, 1.0 + mu, u[1]);
    if (!(dwvw_dot(inward, ng) < 0.0)) return;
    if (shader->expected_exit && shader->expected_exit[hit->mesh] > 0u) {
        run_walk_expected_exit(shader, hit->mesh, material, hit->prim, x, inward, n, key_walk,
                               shader->expected_exit[hit->mesh], sampler, pair + DWVB_SHADE_PAIRS + light_pairs, rgb,
                               tally);
        return;
    }
    dwvw_walk walk;
    dwvg_hit exit = {0};
    if (!run_walk(shader, hit->mesh, material, hit->prim, x, inward, n, key_walk, &walk, &exit,
                  tally))
        return;
    double direct[3];
    gather_exit(shader, mesh, material, exit.prim, exit.u, exit.v, walk.position, walk.exit_normal, sampler,
                pair + DWVB_SHADE_PAIRS + light_pairs, direct);
    int grey = material->medium.channels == 1;
    for (int c = 0; c < 3; ++c) rgb[c] += walk.weight[grey ? 0 : c] * material->walk_scale[c] * direct[c];
}
