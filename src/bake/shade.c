#include "shade.h"

#include <math.h>

#include "bake/textured.h"


/* The mixture terms of the step just sampled (see dwvb_tally): `per_component` (the channels
 * squared) for each component of weight > 0, of which a walk with a single one (the classical
 * technique at every step) has 1, plus `patches`, the lit patches weighed per step. */
static uint64_t mixture_terms(const dwvw_walk *walk, uint64_t per_component, uint64_t patches)
{
    uint64_t active = 1;
    if (walk->single_component < 0) {
        active = 0;
        for (int k = 0; k < walk->component_count; ++k) active += walk->component_q[k] > 0.0;
    }
    return active * per_component + patches;
}

/* Runs one walk from entry point x (on triangle entry_prim of mesh `mesh`) along unit `direction`
 * into the medium; on exit fills the exit hit and returns 1.
 *
 * Ray-free steps: where a lower bound L on the distance from the walk's position x to its mesh is
 * known (the mesh's clearance grid, or the closest point that the closest technique finds at every
 * event anyway), the open ball B(x, L) holds no surface of the mesh; less a margin for Embree's
 * float rounding (dwvg_clear_radius) no hit Embree would report lies in it either. A step of
 * length t < that radius stays in the ball: the walk scatters at its end without a ray, exactly as
 * after a ray that met nothing (the same walk and image, bit for bit). Walks meet only their own
 * mesh, so this holds for open meshes too. The first step (the probe, which the backward
 * technique needs in full) is always a ray (its origin is on the surface: no ball there).
 *
 * Kept balls: a mesh with neither a grid nor planes (its medium too thin against its size for the
 * grid's cells: a thick curved object of a realistic mean free path) gets its bound from a
 * closest-point query at the walk's position c, and keeps that ball: any later step from p of
 * length t with |p - c| + t below its clear radius stays inside it (the segment lies in
 * B(c, |p - c| + t)), ray-free as above. A query costs some 15-40 rays, so it is made only where a
 * large ball is possible: where the upper bound U = |p - a| + U_a on the distance to the surface
 * (a the last query's position, U_a the surface's distance from it or a bound on that; at first
 * the entry point, U_a = 0) reaches KEPT_BALL_REACH longest mean free paths, and the walk has left
 * its ball; and it looks no farther than U / 2 (below). Which steps are ray-free changes the cost
 * only: the walk and the image are the same, bit for bit (auto's pilot, which counts rays and
 * queries, may choose otherwise). */
/* A kept ball's query is made where the surface may be this many longest mean free paths away (a
 * walk leaves a ball of R free paths after some R^2 / 2 steps; a query costs 15-40 rays: at 8 the
 * subdivided head's walks, which stay near its surface, lost 2% to queries, at 16 1%, while the
 * marble and the torus gained about as much either way; docs/speed.md). */
#define KEPT_BALL_REACH 16.0

static int run_walk(const dwvb_shader *shader, uint32_t mesh, const dwvw_medium *medium, const dwvw_guide *guide,
                    uint32_t entry_prim, dwvu_vec3 x, dwvu_vec3 direction, dwvu_vec3 entry_normal, uint64_t key,
                    const dwvk_sampler *sampler, uint32_t walk_pair, dwvw_pair_cache *pairs, dwvw_walk *walk,
                    dwvg_hit *exit, dwvb_tally *tally)
{
    const dwvg_world *world = &shader->scene->geometry;
    const dwvg_mesh *m = &shader->scene->meshes[mesh];
    const dwvg_clearance *grid = &world->clearance[mesh];
    dwvw_walk_begin(walk, medium, guide, key, shader->max_events, x, direction, entry_normal);
    if (guide->q_sheet > 0.0) dwvw_walk_sheet_face(walk, dwvg_geometric_normal(m, entry_prim));
    dwvw_walk_stratify(walk, sampler, walk_pair, DWVB_STRATIFIED_EVENTS);
    if (pairs) dwvw_walk_share_pairs(walk, pairs);
    int needs_closest = shader->needs_closest[mesh];
    dwvb_ball_mode ball_mode = shader->scene->ball_mode;
    int first = 1;
    /* The first step's ray goes on past the sampled distance only as far as its answer is used:
     * to the backward technique's reach for an opposite interface (dwvw_walk_probe_reach), and on
     * an open mesh all the way, for the warning below (a closed one always has a far side:
     * dwvg_mesh_closed). A hit beyond that changes no walk (it is no exit and no opposite
     * interface), and a shorter ray is cheaper to trace. */
    int full_probe = !world->closed[mesh];
    /* Kept balls (above): where neither a grid nor planes bound the clearance, and the technique
     * does not find the closest point at every event anyway. */
    int kept_balls = !needs_closest && ball_mode != DWVB_BALL_OFF && !(grid->largest > 0.0);
    double longest_path = 0.0;
    for (int c = 0; c < medium->channels; ++c) longest_path = fmax(longest_path, 1.0 / medium->sigma_t[c]);
    double query_reach = KEPT_BALL_REACH * longest_path;
    dwvu_vec3 anchor = x;                     /* the last query's position, or the entry point */
    double anchor_reach = 0.0, kept_radius = 0.0; /* the surface's distance from it (0: none found); its ball */
    uint64_t terms_per_component = (uint64_t)walk->medium->channels * (uint64_t)walk->medium->channels;
    uint64_t patches = walk->guide->q_incident > 0.0 && walk->guide->patch_count > 1 ? (uint64_t)walk->guide->patch_count : 0u;
    while (walk->status == DWVW_RUNNING) {
        double clearance = 0.0;
        if (needs_closest) {
            dwvg_hit closest;
            ++tally->point_queries;
            if (dwvg_closest_mesh_clearance(world, mesh, walk->position, &closest, &clearance))
                dwvw_walk_set_closest(walk, dwvg_geometric_normal(m, closest.prim));
        }
        double distance = dwvw_walk_sample(walk);
        tally->mixture_terms += mixture_terms(walk, terms_per_component, patches);
        int ray_free = 0;
        /* The ball's radius is below the clearance, which the grid bounds by its largest cell
         * (planes have no such bound: +inf): a step at least that long needs neither the lookup
         * nor the radius. */
        if (!first && ball_mode != DWVB_BALL_OFF && (needs_closest || distance < grid->largest)) {
            if (!needs_closest) clearance = dwvg_clearance_above(grid, walk->position, distance);
            ray_free = distance < clearance && distance < dwvg_clear_radius(world, walk->position, clearance);
        }
        if (!first && kept_balls) {
            double away = dwvu_length(dwvu_sub(walk->position, anchor));
            ray_free = away + distance < kept_radius;
            double reach = away + anchor_reach; /* the surface is at most this far */
            if (!ray_free && reach >= query_reach && away >= kept_radius) {
                /* The query looks no farther than half the reach: a triangle nearer than that it
                 * finds (the nearest), and finding none costs little (the BVH's nodes that near);
                 * then half the reach is clear. */
                dwvg_hit closest;
                double bound = 0.0;
                ++tally->point_queries;
                anchor = walk->position;
                anchor_reach = dwvg_closest_mesh_within(world, mesh, anchor, 0.5 * reach, &closest, &bound) ? closest.t
                                                                                                          : reach;
                kept_radius = dwvg_clear_radius(world, anchor, bound);
                ray_free = distance < kept_radius;
            }
        }
        dwvg_hit hit;
        int found = 0;
        tally->ray_free_steps += (uint64_t)ray_free;
        if (!ray_free || ball_mode == DWVB_BALL_CHECKED) {
            /* The first step is the probe, as far as its reach above. A ray leaving a flat
             * triangle inward cannot meet that
             * triangle again, so a hit on the entry triangle is rounding and the ray goes on past
             * it (dwvg_intersect_mesh_leaving). */
            if (first) {
                uint32_t rays = 0;
                found = dwvg_intersect_mesh_leaving(world, mesh, walk->position, walk->direction, entry_prim,
                                                    full_probe ? INFINITY : dwvw_walk_probe_reach(walk), &hit,
                                                    &rays);
                tally->rays += rays;
            } else {
                ++tally->rays;
                found = dwvg_intersect_mesh(world, mesh, walk->position, walk->direction, 0.0, distance, &hit);
            }
            /* Checked mode: a ray-free step whose ray meets the surface would be a wrong walk. */
            if (ray_free && found) ++tally->ray_free_misses;
        }
        /* A closed mesh surrounds every point inside: a probe that meets nothing means the
         * mesh is open there, and the walk may wander off. */
        if (first && full_probe && !found) ++tally->warnings;
        first = 0;
        dwvu_vec3 normal = dwvu_v(0.0, 0.0, 0.0);
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
    if (tally->first_walk_mesh == 0u) tally->first_walk_mesh = mesh + 1u;
    return walk->status == DWVW_EXITED;
}

/* The retro-reflection lobe of Blender 3.x's Principled BSDF at a surface point. */
typedef struct retro_lobe {
    dwvu_vec3 n;       /* shading normal */
    dwvu_vec3 to_view; /* unit, toward the viewer */
    double cos_view;
    double roughness;
} retro_lobe;

static double retro_factor(const void *context, dwvu_vec3 light)
{
    const retro_lobe *lobe = context;
    return dwvb_principled_retro_factor(dwvu_dot(lobe->n, light), lobe->cos_view, dwvu_dot(light, lobe->to_view),
                                        lobe->roughness);
}

/* Blender 3.x Principled's diffuse without subsurface (both Fresnel terms and retro-reflection). */
static double principled_diffuse_factor(const void *context, dwvu_vec3 light)
{
    const retro_lobe *lobe = context;
    return dwvb_principled_diffuse_factor(dwvu_dot(lobe->n, light), lobe->cos_view, dwvu_dot(light, lobe->to_view),
                                          lobe->roughness);
}

/* The whole surface BRDF at the entry point where a specular layer is there (material.h): the
 * layered diffuse (Lambertian, or 3.x Principled's with its Fresnel terms), 3.x's retro-reflection
 * lobe and the specular layer, per channel. */
typedef struct surface_lobes {
    const dwvb_material *material;
    retro_lobe lobe;
    double diffuse[3]; /* the diffuse lobe's weight per channel (layered) */
    int bumped;        /* DWV_BUMP_SHADOWING_* where a normal map tilted lobe.n from smooth_n, else 0 */
    dwvu_vec3 smooth_n;
    dwvu_vec3 specular_n; /* the specular layer's normal (4.x+: lobe.n kept valid for reflection) */
} surface_lobes;

/* The surface's glossy (f[0]: the specular layer) and diffuse (f[1]) lobes. */
static void surface_factor(const void *context, dwvu_vec3 light, double f[2][3])
{
    const surface_lobes *s = context;
    const dwvb_material *m = s->material;
    double cos_l = dwvu_dot(s->lobe.n, light), l_dot_v = dwvu_dot(light, s->lobe.to_view);
    double diffuse = m->principled_diffuse
                         ? dwvb_principled_diffuse_factor(cos_l, s->lobe.cos_view, l_dot_v, s->lobe.roughness)
                         : 1.0;
    double retro = m->principled_v1
                       ? dwvb_principled_retro_factor(cos_l, s->lobe.cos_view, l_dot_v, s->lobe.roughness)
                       : 0.0;
    /* Cycles 3.x shadows its diffuse closures (the Lambertian, Principled diffuse and
     * retro-reflection), not the specular, where a normal map tilted them (textured.h). */
    double shadow = s->bumped ? dwvb_bump_shadowing(s->bumped, s->smooth_n, s->lobe.n, light) : 1.0;
    dwvb_specular_factor(m, s->specular_n, light, s->lobe.to_view, f[0]);
    for (int c = 0; c < 3; ++c) f[1][c] = (s->diffuse[c] * diffuse + m->retro_albedo[c] * retro) * shadow;
}

/* The exit weight of Blender 3.x's Principled BSDF; the context is the exit's shading normal. */
static double exit_factor(const void *context, dwvu_vec3 light)
{
    const dwvu_vec3 *n = context;
    return dwvb_principled_exit_factor(dwvu_dot(*n, light));
}

/* The exit's diffuse lobe where a normal map tilted its normal n from smooth_n: the 3.x
 * Principled exit weight (or 1) times the bump shadowing (textured.h). */
typedef struct bumped_exit {
    dwvu_vec3 n, smooth_n;
    int principled_v1;
    int mode; /* DWV_BUMP_SHADOWING_* */
} bumped_exit;

static double bumped_exit_factor(const void *context, dwvu_vec3 light)
{
    const bumped_exit *e = context;
    double f = e->principled_v1 ? dwvb_principled_exit_factor(dwvu_dot(e->n, light)) : 1.0;
    return f * dwvb_bump_shadowing(e->mode, e->smooth_n, e->n, light);
}

/* A walk's exit as a point a path scatters at: its shading normal (bumped where a normal map
 * tilts it) and geometric normal (outward), and its lobe (the Lambertian exit, 3.x Principled's
 * weight, the bump shadowing). */
typedef struct exit_point {
    dwvu_vec3 x, n, ng, smooth_n;
    double top;
    int principled_v1;
    int bump_mode; /* DWV_BUMP_SHADOWING_* where the normal is tilted, else 0 */
} exit_point;

/* The light a walk gathers where it left mesh `mesh` (exit: its hit), from the sampler's light
 * pairs from `pair` on: the Lambertian exit's (or Blender 3.x Principled's) direct light. The exit
 * as a scattering point goes to `point` (for a path going on from there). */
static void exit_light(const dwvb_shader *shader, uint32_t mesh_id, const dwvb_material *material, const dwvw_walk *walk,
                       const dwvg_hit *exit, const dwvk_sampler *sampler, uint32_t pair, double direct[3],
                       exit_point *point)
{
    const dwvb_scene *scene = shader->scene;
    const dwvg_mesh *mesh = &scene->meshes[mesh_id];
    dwvu_vec3 exit_ng = walk->exit_normal;
    dwvu_vec3 exit_n = dwvg_shading_normal(mesh, exit->prim, exit->u, exit->v, exit_ng);
    /* Cycles evaluates the exit's shader for its normal (SD_HAS_BSSRDF_BUMP): the normal map and
     * bump there, the rest of the material being the entry's. */
    dwvu_vec3 exit_smooth_n = exit_n;
    if (dwvb_textured_normal_bound(scene, mesh_id)) {
        /* The BSSRDF's normal there is kept valid for reflection (3.x: every closure's; 4.x+:
         * maybe_ensure_valid_specular_reflection) with the exit's incoming direction: Cycles
         * shades the exit as seen along the walk's last step, from outside. */
        exit_n = dwvb_textured_normal(scene, mesh_id, exit->prim, exit->u, exit->v, exit_n);
        if (dwvb_textured_bump_shadowing(scene, mesh_id) != DWV_BUMP_SHADOWING_NONE)
            exit_n = dwvb_valid_reflection(exit_ng, walk->direction, exit_n);
    }
    /* Cycles shades the exit as a surface point of its triangle: the same terminator offset. */
    double cutoff = scene->terminator_offsets[mesh_id];
    dwvl_terminator exit_terminator = {mesh, exit->prim, exit->u, exit->v, cutoff, exit_smooth_n};
    const dwvl_terminator *exit_smooth = mesh->normals && cutoff > 0.0 ? &exit_terminator : NULL;
    double exit_top = dwvg_world_top(&scene->geometry, mesh_id, exit->prim);
    int mode = dwvb_textured_bump_shadowing(scene, mesh_id);
    int tilted = exit_n.x != exit_smooth_n.x || exit_n.y != exit_smooth_n.y || exit_n.z != exit_smooth_n.z;
    *point = (exit_point){walk->position, exit_n, exit_ng, exit_smooth_n, exit_top, material->principled_v1,
                          mode && tilted ? mode : DWV_BUMP_SHADOWING_NONE};
    if (mode && tilted) {
        bumped_exit lobe = {exit_n, exit_smooth_n, material->principled_v1, mode};
        dwvl_direct_lobe(&shader->env, walk->position, exit_n, exit_ng, exit_smooth, exit_top, sampler, pair,
                         bumped_exit_factor, &lobe, NULL, direct);
    } else if (material->principled_v1)
        dwvl_direct_lobe(&shader->env, walk->position, exit_n, exit_ng, exit_smooth, exit_top, sampler, pair, exit_factor,
                         &exit_n, NULL, direct);
    else
        dwvl_direct(&shader->env, walk->position, exit_n, exit_ng, exit_smooth, exit_top, sampler, pair, direct);
}

double dwvb_footprint(const dwvb_shader *shader, dwvu_vec3 view, double t)
{
    if (shader->footprint == DWVB_FOOTPRINT_CONSTANT) return shader->pixel;
    if (shader->footprint != DWVB_FOOTPRINT_PERSPECTIVE) return 0.0;
    double along = dwvu_dot(view, shader->forward);
    if (!(along > 0.0)) return 0.0;
    dwvu_vec3 d = dwvu_scale(view, 1.0 / along); /* on the plane at unit distance */
    dwvu_vec3 dx = dwvu_sub(dwvu_normalize(dwvu_add(d, shader->pixel_right)), view);
    dwvu_vec3 dy = dwvu_sub(dwvu_normalize(dwvu_add(d, shader->pixel_up)), view);
    return t * 0.5 * (dwvu_length(dx) + dwvu_length(dy));
}

#define INV_PI 0.31830988618379067154

/* Whether two normals are the same (bit for bit: the one where no correction moved it). */
static int same_direction(dwvu_vec3 a, dwvu_vec3 b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

/* Where a path stands (Cycles' path state): its bounces so far by kind, whether one of them was
 * diffuse (PATH_RAY_DIFFUSE_ANCESTOR), its ray's compact differentials (Cycles' ray.dP, ray.dD:
 * the footprint at the next hit is dP + t dD; dwvb_footprint), and the smallest pdf of its
 * non-singular bounces (Cycles' min_ray_pdf: FLT_MAX at the camera, path_state_init; the min
 * with each BSDF bounce's pdf, shade_surface.h; a walk's entry leaves it, its exit's bounce is a
 * diffuse BSDF's; for Filter Glossy, dwvb_blur_alpha). */
typedef struct path_state {
    uint32_t bounce, diffuse, glossy, transmission;
    int diffuse_ancestor;
    double dP, dD;
    double min_ray_pdf;
} path_state;

double dwvb_blur_alpha(double alpha, double min_ray_pdf, double blur_glossy)
{
    if (!(blur_glossy > 0.0)) return alpha;
    double b = min_ray_pdf / blur_glossy;
    if (!(b < 1.0)) return alpha;
    return fmax(alpha, 0.5 * sqrt(1.0 - b));
}

/* A path's next segment, sampled at a scattering point: the ray (from the point's offset
 * origin), the factor f cos / pdf it multiplies the path's throughput by (times what the point
 * itself weighs, a walk's estimate for an exit), the lobe that scattered it (DWVB_LOBE_*), and
 * whether it is known to meet nothing (it rises from above the whole world: no ray needed). */
typedef struct path_ray {
    dwvu_vec3 origin, direction;
    double weight[3];
    int lobe;
    int clear;
    int exit; /* sent on from a walk's exit: 1 + the channel of a channel walk, 4 the one walk; 0 the lobes */
    /* A mirror's reflection (Cycles' LABEL_SINGULAR): no light sample can find its direction, so
     * the ray takes the whole emission it meets (lights and world, dwvl_emission_along), and it
     * is traced for that even where its bounce exceeds a limit (Cycles' kernel limits are the
     * scene's + 1: that bounce's ray is traced and only its emission is taken). */
    int singular;
    /* The density the direction was drawn with (the mixture's, dwvb_surface_pdf; a walk's exit
     * cos / pi); +inf for a mirror's (Cycles' singular pdf is a stand-in 1e6: no blur follows it). */
    double pdf;
} path_ray;

/* Cycles' path_state_next for a bounce off `lobe`: counts it, or returns 0 where it would exceed
 * a limit (Cycles' kernel limits are the scene's + 1 and end a path whose count reaches them;
 * the path then only looks for emission, which dwivedi's surfaces have not). */
static int path_state_next(path_state *s, int lobe, const dwvb_light_paths *limits)
{
    if (s->bounce + 1u > limits->max_bounces) return 0;
    if (lobe == DWVB_LOBE_DIFFUSE) {
        if (s->diffuse + 1u > limits->diffuse) return 0;
        ++s->diffuse;
        s->diffuse_ancestor = 1;
    } else if (lobe == DWVB_LOBE_GLOSSY) {
        if (s->glossy + 1u > limits->glossy) return 0;
        ++s->glossy;
    } else {
        if (s->transmission + 1u > limits->transmission) return 0;
        ++s->transmission;
    }
    ++s->bounce;
    return 1;
}

/* Whether some bounce is left to a path (the lobe it samples is checked after). */
static int path_can_go_on(const path_state *s, const dwvb_light_paths *limits)
{
    return s->bounce < limits->max_bounces && (s->diffuse < limits->diffuse || s->glossy < limits->glossy);
}

/* Cycles' path_state_continuation_probability at a path's hit after s->bounce bounces: 1 up to
 * Min Light Bounces + 1 (the kernel's min_bounce), then min(1, sqrt(max channel |throughput|))
 * (sqrt "to roughly match typical view transform": the same in 3.4, 4.3 and 5.x). */
static double continuation_probability(const path_state *s, const double throughput[3], const dwvb_light_paths *limits)
{
    if (s->bounce <= limits->min_bounces + 1u) return 1.0;
    double largest = fmax(fabs(throughput[0]), fmax(fabs(throughput[1]), fabs(throughput[2])));
    return fmin(sqrt(largest), 1.0);
}

/* A ray from surface point x along unit d leaves from x + epsilon ng; it meets nothing where it
 * starts above the world's highest point along ng (`top`, dwvg_world_top) and rises (the margin
 * of direct.c's shadow rays, which leave from the same origin). */
static void path_ray_from(const dwvb_shader *shader, dwvu_vec3 x, dwvu_vec3 ng, double top, dwvu_vec3 d, path_ray *ray)
{
    double eps = shader->scene->geometry.epsilon;
    ray->origin = dwvu_madd(x, ng, eps);
    ray->direction = d;
    ray->clear = 0;
    if (top < INFINITY && dwvu_dot(d, ng) > 0.0) {
        double coordinate = fmax(fabs(x.x), fmax(fabs(x.y), fabs(x.z))) + eps;
        ray->clear = dwvu_dot(ray->origin, ng) > top + 0.25 * eps + 0x1p-19 * coordinate;
    }
}

/* The exit's lobe sampled by its cosine (pdf cos / pi): the weight is the lobe's factor beside
 * 1/pi (1, 3.x Principled's 1 - F_L / 2, the bump shadowing). Directions below the exit's
 * geometric surface end the path. */
static int exit_path_ray(const dwvb_shader *shader, const exit_point *e, const double weight[3],
                         const dwvk_sampler *sampler, uint32_t pair, path_ray *ray)
{
    double u[2];
    dwvk_sampler_pair(sampler, pair, u);
    double mu = sqrt(u[0]);
    dwvu_vec3 w = dwvk_direction_about(e->n, mu, 1.0 - mu, 1.0 + mu, u[1]);
    if (!(dwvu_dot(w, e->ng) > 0.0)) return 0;
    double f = e->principled_v1 ? dwvb_principled_exit_factor(dwvu_dot(e->n, w)) : 1.0;
    if (e->bump_mode) f *= dwvb_bump_shadowing(e->bump_mode, e->smooth_n, e->n, w);
    path_ray_from(shader, e->x, e->ng, e->top, w, ray);
    for (int c = 0; c < 3; ++c) ray->weight[c] = weight[c] * f;
    ray->lobe = DWVB_LOBE_DIFFUSE;
    ray->singular = 0;
    ray->pdf = mu * INV_PI;
    ray->exit = 4;
    for (int c = 0; c < 3; ++c)
        if (weight[c] > 0.0 && weight[(c + 1) % 3] == 0.0 && weight[(c + 2) % 3] == 0.0) ray->exit = 1 + c;
    return 1;
}

double dwvb_surface_specular_probability(const dwvb_material *m, const double diffuse[3], double cos_view)
{
    double weight = 0.0, specular = 0.0;
    for (int c = 0; c < 3; ++c) weight += (diffuse[c] + m->retro_albedo[c]) / 3.0;
    if (m->specular && dwvb_specular_singular(m) && cos_view > 0.0) {
        /* The mirror's own reflectance (its whole albedo): its weight is then F / p_s. */
        double f[3];
        dwvb_specular_singular_weight(m, cos_view, f);
        specular = (f[0] + f[1] + f[2]) / 3.0;
    } else if (m->specular && cos_view > 0.0) {
        if (m->specular == DWV_SPECULAR_PRINCIPLED_V2) {
            specular = 1.0 - dwvb_specular_layer_weight(m, cos_view);
        } else {
            double f0 = (m->spec_f0[0] + m->spec_f0[1] + m->spec_f0[2]) / 3.0;
            specular = f0 + (1.0 - f0) * dwvb_schlick_weight(cos_view);
        }
    }
    if (!(weight + specular > 0.0)) return -1.0;
    return specular / (weight + specular);
}

/* Direction d in `frame` (z its normal). */
static dwvu_vec3 local_of(dwvu_frame frame, dwvu_vec3 d)
{
    return dwvu_v(dwvu_dot(frame.t, d), dwvu_dot(frame.s, d), dwvu_dot(frame.n, d));
}

int dwvb_surface_sample(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                        double u0, double u1, double choice, dwvu_vec3 *w, int *lobe, int *singular)
{
    *singular = 0;
    if (choice < p_specular) {
        dwvu_frame frame = dwvu_frame_about(specular_n);
        dwvu_vec3 wi = local_of(frame, to_view);
        if (!(wi.z > 0.0)) return 0;
        *lobe = DWVB_LOBE_GLOSSY;
        if (dwvb_specular_singular(m)) {
            /* Cycles' singular microfacet: H = N, the mirror direction 2 (N.V) N - V. */
            *w = dwvu_sub(dwvu_scale(specular_n, 2.0 * wi.z), to_view);
            *singular = 1;
            return 1;
        }
        dwvu_vec3 h = dwvb_ggx_sample_vndf(wi, m->spec_alpha, u0, u1);
        dwvu_vec3 wo = dwvu_sub(dwvu_scale(h, 2.0 * dwvu_dot(wi, h)), wi);
        *w = dwvu_add(dwvu_add(dwvu_scale(frame.t, wo.x), dwvu_scale(frame.s, wo.y)), dwvu_scale(frame.n, wo.z));
    } else {
        double mu = sqrt(u0);
        *w = dwvk_direction_about(n, mu, 1.0 - mu, 1.0 + mu, u1);
        *lobe = DWVB_LOBE_DIFFUSE;
    }
    return 1;
}

double dwvb_surface_pdf(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                        dwvu_vec3 w)
{
    double cos_n = dwvu_dot(n, w);
    double pdf = cos_n > 0.0 ? (1.0 - p_specular) * cos_n * INV_PI : 0.0;
    if (p_specular > 0.0 && !dwvb_specular_singular(m)) {
        dwvu_frame frame = dwvu_frame_about(specular_n);
        dwvu_vec3 wi = local_of(frame, to_view), wo = local_of(frame, w);
        dwvu_vec3 h = dwvu_normalize(dwvu_add(wi, wo));
        double wi_h = dwvu_dot(wi, h);
        if (wi.z > 0.0 && wi_h > 0.0 && h.z > 0.0) pdf += p_specular * dwvb_ggx_vndf_pdf(wi, h, m->spec_alpha) / (4.0 * wi_h);
    }
    return pdf;
}

/* A surface point's path ray from the mixture of its lobes (dwvb_surface_sample), each lobe about
 * its own normal (the specular layer's specular_n, the diffuse ones' lobe.n). A continuous
 * direction weighs the whole BRDF times each lobe's own cosine (f_s cos_s + f_d cos_n) / pi
 * (surface_factor) over the mixture's pdf; the mirror direction of a singular layer weighs its
 * reflectance over its probability (eval / pdf of Cycles' singular sample; the diffuse lobes
 * have no share in a delta). The lobe drawn names the bounce (glossy or diffuse); directions
 * below the geometric surface end the path (Cycles: LABEL_NONE). */
static int surface_path_ray(const dwvb_shader *shader, const surface_lobes *s, dwvu_vec3 x, dwvu_vec3 ng, double top,
                            const dwvk_sampler *sampler, uint32_t pair, path_ray *ray)
{
    const dwvb_material *m = s->material;
    double cos_specular = dwvu_dot(s->specular_n, s->lobe.to_view);
    double p_specular = dwvb_surface_specular_probability(m, s->diffuse, cos_specular);
    if (p_specular < 0.0) return 0;
    double u[2], v[2];
    dwvk_sampler_pair(sampler, pair, u);
    dwvk_sampler_pair(sampler, pair + 1u, v);
    dwvu_vec3 w;
    int singular;
    if (!dwvb_surface_sample(m, p_specular, s->lobe.n, s->specular_n, s->lobe.to_view, u[0], u[1], v[0], &w, &ray->lobe,
                             &singular))
        return 0;
    if (!(dwvu_dot(w, ng) > 0.0)) return 0;
    double pdf = INFINITY;
    if (singular) {
        double f[3];
        dwvb_specular_singular_weight(m, cos_specular, f);
        for (int c = 0; c < 3; ++c) ray->weight[c] = f[c] / p_specular;
    } else {
        pdf = dwvb_surface_pdf(m, p_specular, s->lobe.n, s->specular_n, s->lobe.to_view, w);
        if (!(pdf > 0.0) || !isfinite(pdf)) return 0;
        double f[2][3];
        surface_factor(s, w, f);
        double cos_n = fmax(dwvu_dot(s->lobe.n, w), 0.0), cos_s = fmax(dwvu_dot(s->specular_n, w), 0.0);
        if (!(cos_n > 0.0) && !(cos_s > 0.0)) return 0; /* below both lobes' horizons: nothing */
        /* One normal for both (no normal map, or one that needed no correction): the BRDF's sum
         * times its cosine, as before the lobes had normals of their own (the same bits). */
        for (int c = 0; c < 3; ++c)
            ray->weight[c] = cos_s == cos_n ? (f[0][c] + f[1][c]) * INV_PI * cos_n / pdf
                                            : (f[0][c] * cos_s + f[1][c] * cos_n) * INV_PI / pdf;
    }
    path_ray_from(shader, x, ng, top, w, ray);
    ray->exit = 0;
    ray->singular = singular;
    ray->pdf = pdf;
    return 1;
}

/* The surface's mixture (dwvb_surface_sample / _pdf) as the world's strategy of its direct light
 * where its lobes have normals of their own (dwvl_direct_lobes): one pair draws the three numbers,
 * the choice of lobe by u0 and u0 rescaled to [0, 1) within the branch chosen (u0 / p_s, or
 * (u0 - p_s) / (1 - p_s)), which is again uniform there. A mirror's draw is none (its delta is
 * the singular path ray's, never a light sample's); pdf is the mixture's continuous part. */
typedef struct surface_sampling {
    const surface_lobes *lobes;
    double p_specular; /* dwvb_surface_specular_probability, < 0 where nothing scatters */
} surface_sampling;

static int surface_direction(const void *context, double u0, double u1, dwvu_vec3 *w)
{
    const surface_sampling *d = context;
    const surface_lobes *s = d->lobes;
    double p = d->p_specular, choice = u0;
    if (p < 0.0) return 0;
    u0 = u0 < p ? u0 / p : (u0 - p) / (1.0 - p);
    int lobe, singular;
    if (!dwvb_surface_sample(s->material, p, s->lobe.n, s->specular_n, s->lobe.to_view, u0, u1, choice, w, &lobe,
                             &singular))
        return 0;
    return !singular;
}

static double surface_direction_pdf(const void *context, dwvu_vec3 w)
{
    const surface_sampling *d = context;
    const surface_lobes *s = d->lobes;
    if (d->p_specular < 0.0) return 0.0;
    return dwvb_surface_pdf(s->material, d->p_specular, s->lobe.n, s->specular_n, s->lobe.to_view, w);
}

/* Whether a subsurface material walks where a path meets it after a diffuse bounce. */
static int walks_after_diffuse(const dwvb_shader *shader, const dwvb_material *material)
{
    if (shader->paths.after_diffuse == DWV_SUBSURFACE_AFTER_DIFFUSE_WALK) return 1;
    if (shader->paths.after_diffuse == DWV_SUBSURFACE_AFTER_DIFFUSE_LAMBERT) return 0;
    return material->model >= DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK;
}

/* Cycles up to 4.x after a diffuse bounce (bssrdf_setup; 3.x svm_node_closure_bsdf): the walking
 * channels become diffuse of their subsurface colour, Lambertian, or (3.x Principled) the
 * Principled diffuse of the mixed colour, retro-reflection included. */
static void lambert_after_diffuse(const dwvb_material *material, dwvb_material *out)
{
    *out = *material;
    out->subsurface = 0;
    for (int c = 0; c < 3; ++c)
        if (material->walk_scale[c] > 0.0) out->diffuse_albedo[c] += material->fallback_albedo[c];
    if (material->principled_v1) {
        out->principled_v1 = 0;
        out->principled_diffuse = 1;
        for (int c = 0; c < 3; ++c) out->retro_albedo[c] = 0.0;
    }
}

/* The pairs a point's paths going on take in its `onward` sampler away from the camera (the
 * camera vertex's come from the pixel's stratified pairs, shade.h): two per ray, at fixed places
 * (the surface's first, then walk j of channel c's at 1 + c + 3 j, the one walk's at 1), so that
 * whether one ray was made never moves another's numbers. */
#define ONWARD_PAIRS 2u

/* Shades hit point `hit` seen along `view` by a path in `state` (camera: the camera ray's or the
 * texel's hit, whose walks may be channel walks and obey the footprint rule): its direct light
 * into `light` by lobe (the specular layer's GLOSSY, the rest DIFFUSE), the lobes' colours into
 * `color` where it is not NULL (Cycles' colour passes), and into `rays` the rays its lobes and walks' exits send on (at most
 * 1 + 3 DWVB_MAX_CHANNEL_WALKS; 2 away from the camera), drawn from `onward` from pair
 * `onward_pair` on: all of them where `go_on` (some bounce is left), else only a mirror's
 * reflection (traced for the emission it meets, path_ray.singular). */
static void shade_point(const dwvb_shader *shader, const dwvg_hit *hit, dwvu_vec3 view, const dwvk_sampler *sampler,
                        uint32_t pair, uint64_t key_walk, const path_state *state, int camera,
                        double light[DWVB_LOBE_COUNT][3], double color[DWVB_LOBE_COUNT][3],
                        path_ray *rays, int go_on, const dwvk_sampler *onward, uint32_t onward_pair, uint32_t *ray_count,
                        dwvb_tally *tally)
{
    const dwvb_scene *scene = shader->scene;
    const dwvg_mesh *mesh = &scene->meshes[hit->mesh];
    uint32_t material_id = mesh->material_id;
    const dwvb_material *material = &scene->shading[material_id];
    /* Textured inputs: the material as the textures make it here, once, for the surface lobes and
     * for the whole walk from here (Cycles' homogeneous medium from the entry's closure). */
    dwvb_material textured, lambert;
    if (dwvb_textured_inputs(scene, hit->mesh)) {
        dwvb_textured_material(scene, hit->mesh, hit->prim, hit->u, hit->v, &textured);
        material = &textured;
    }
    if (material->subsurface && state->diffuse_ancestor && !walks_after_diffuse(shader, material)) {
        lambert_after_diffuse(material, &lambert);
        material = &lambert;
    }
    /* Filter Glossy: the specular layer roughened after the path's bounces (none at the camera's
     * hit, whose min_ray_pdf is +inf), for its direct light and its path ray alike. */
    dwvb_material blurred;
    double blurred_alpha = dwvb_blur_alpha(material->spec_alpha, state->min_ray_pdf, shader->paths.blur_glossy);
    if (material->specular && blurred_alpha != material->spec_alpha) {
        blurred = *material;
        blurred.spec_alpha = blurred_alpha;
        material = &blurred;
    }
    *ray_count = 0u;
    for (int l = 0; l < DWVB_LOBE_COUNT; ++l) light[l][0] = light[l][1] = light[l][2] = 0.0;
    double *rgb = light[DWVB_LOBE_DIFFUSE];
    dwvu_vec3 ng = dwvg_geometric_normal(mesh, hit->prim);
    if (ng.x == 0.0 && ng.y == 0.0 && ng.z == 0.0) {
        ++tally->warnings;
        return;
    }
    int ng_flipped = 0;
    if (dwvu_dot(view, ng) > 0.0) {
        /* The back of a face. A diffuse surface is two-sided; a subsurface one is seen from inside
         * its medium (an open or inside-out mesh): no walk is defined there (a path that meets
         * one ends there: the camera's is what the warning is for). */
        if (material->subsurface) {
            if (camera) ++tally->warnings;
            return;
        }
        ng = dwvu_scale(ng, -1.0);
        ng_flipped = 1;
    }
    dwvu_vec3 x = dwvg_point(mesh, hit->prim, hit->u, hit->v);
    dwvu_vec3 n = dwvg_shading_normal(mesh, hit->prim, hit->u, hit->v, ng);
    dwvu_vec3 smooth_n = n;
    /* The normal of the specular layer and of the walk's entry (the BSSRDF's); n is the diffuse lobes'. */
    dwvu_vec3 specular_n = n;
    if (dwvb_textured_normal_bound(scene, hit->mesh)) {
        /* Cycles keeps a mapped normal's mirror reflection of the view above the surface
         * (ensure_valid_reflection): 3.x for every closure of the Principled BSDF (svm_closure.h),
         * 4.x+ for the specular ones and the BSSRDF (maybe_ensure_valid_specular_reflection), not
         * for the diffuse one. */
        int mode = dwvb_textured_bump_shadowing(scene, hit->mesh);
        n = dwvb_textured_normal(scene, hit->mesh, hit->prim, hit->u, hit->v, n);
        specular_n = mode != DWV_BUMP_SHADOWING_NONE ? dwvb_valid_reflection(ng, dwvu_scale(view, -1.0), n) : n;
        if (mode == DWV_BUMP_SHADOWING_CHIANG2019) n = specular_n;
    }
    int tilted = !same_direction(n, smooth_n);
    int bumped = tilted ? dwvb_textured_bump_shadowing(scene, hit->mesh) : DWV_BUMP_SHADOWING_NONE;
    uint32_t light_pairs = dwvl_direct_pairs(&shader->env);
    /* Cycles 4.0-4.3: channels whose radius is below a quarter of the ray's footprint are
     * Lambertian at this hit (bssrdf_setup); their walks' results are not used. The footprint: the
     * first ray's (camera or texel, dwvb_footprint), at a later hit the path's (path_state). */
    double diffuse_albedo[3], keep[3] = {1.0, 1.0, 1.0};
    int walks_left = material->subsurface;
    for (int c = 0; c < 3; ++c) diffuse_albedo[c] = material->diffuse_albedo[c];
    if (material->subsurface && material->min_footprint > 0.0 && shader->footprint) {
        double footprint = camera ? dwvb_footprint(shader, view, hit->t) : state->dP + hit->t * state->dD;
        double limit = material->min_footprint * footprint;
        walks_left = 0;
        for (int c = 0; c < 3; ++c) {
            if (material->walk_scale[c] > 0.0 && material->radius[c] < limit) {
                keep[c] = 0.0;
                diffuse_albedo[c] += material->fallback_albedo[c];
            }
            if (material->walk_scale[c] > 0.0 && keep[c] > 0.0) walks_left = 1;
        }
    }
    /* Shadow rays of smooth-shaded triangles leave from the smooth surface near the terminator,
     * as in Cycles with the mesh's geometry offset (src/light/terminator.h). */
    double cutoff = scene->terminator_offsets[hit->mesh];
    dwvl_terminator terminator = {mesh, hit->prim, hit->u, hit->v, cutoff, smooth_n};
    const dwvl_terminator *smooth = mesh->normals && cutoff > 0.0 ? &terminator : NULL;
    /* The world's top along ng is known for the outward side of the triangle only. */
    double top = ng_flipped ? INFINITY : dwvg_world_top(&scene->geometry, hit->mesh, hit->prim);
    /* The layers under a 4.x+ specular keep 1 - its albedo toward the viewer (1 otherwise). */
    double cos_view = -dwvu_dot(n, view);
    double cos_specular = -dwvu_dot(specular_n, view);
    double layer = material->specular ? dwvb_specular_layer_weight(material, cos_specular) : 1.0;
    /* The colour passes (Cycles' surface_shader_diffuse / _glossy): the diffuse closures' weights,
     * the Lambertian's, the retro-reflection's (3.x: a diffuse BSDF of the BSSRDF's whole weight,
     * beside the BSSRDF) and the walking channels' BSSRDF (w x subsurface colour, a channel that
     * turned Lambertian by the footprint rule counted once, in diffuse_albedo); the specular
     * layer's weight (3.x) or albedo (4.x+). */
    if (color) {
        for (int c = 0; c < 3; ++c) {
            double bssrdf = material->subsurface && material->walk_scale[c] > 0.0 && keep[c] > 0.0
                                ? material->fallback_albedo[c]
                                : 0.0;
            color[DWVB_LOBE_DIFFUSE][c] = layer * (diffuse_albedo[c] + bssrdf) + material->retro_albedo[c];
        }
        if (material->specular) dwvb_specular_color(material, cos_specular, color[DWVB_LOBE_GLOSSY]);
    }
    surface_lobes lobes = {material, {n, dwvu_scale(view, -1.0), cos_view, material->roughness}, {0.0, 0.0, 0.0},
                           bumped, smooth_n, specular_n};
    for (int c = 0; c < 3; ++c) lobes.diffuse[c] = layer * diffuse_albedo[c];
    if (material->specular || bumped) {
        /* (A tilted normal's shadowing goes through the general lobe too.) */
        double surface[2][3];
        if (material->specular && !same_direction(specular_n, n)) {
            /* Each lobe about its own normal (4.x+: the specular's kept valid for reflection), as
             * the path rays below are drawn. */
            surface_sampling sampling = {&lobes, dwvb_surface_specular_probability(material, lobes.diffuse, cos_specular)};
            dwvl_lobes own = {surface_factor, &lobes, {specular_n, n}, surface_direction, surface_direction_pdf, &sampling};
            dwvl_direct_lobes(&shader->env, x, ng, smooth, top, sampler, pair + DWVB_SHADE_PAIRS, &own, surface);
        } else {
            dwvl_direct_split(&shader->env, x, n, ng, smooth, top, sampler, pair + DWVB_SHADE_PAIRS, surface_factor,
                              &lobes, surface);
        }
        for (int c = 0; c < 3; ++c) {
            light[DWVB_LOBE_GLOSSY][c] = surface[0][c];
            rgb[c] = surface[1][c];
        }
    } else if (material->principled_v1) {
        /* The Lambertian lobe and the retro-reflection lobe from the same light samples. */
        retro_lobe lobe = {n, dwvu_scale(view, -1.0), -dwvu_dot(n, view), material->roughness};
        double direct[3], retro[3];
        dwvl_direct_lobe(&shader->env, x, n, ng, smooth, top, sampler, pair + DWVB_SHADE_PAIRS, retro_factor, &lobe, direct, retro);
        for (int c = 0; c < 3; ++c) rgb[c] += material->diffuse_albedo[c] * direct[c] + material->retro_albedo[c] * retro[c];
    } else if (material->principled_diffuse) {
        retro_lobe lobe = {n, dwvu_scale(view, -1.0), -dwvu_dot(n, view), material->roughness};
        double diffuse[3];
        dwvl_direct_lobe(&shader->env, x, n, ng, smooth, top, sampler, pair + DWVB_SHADE_PAIRS, principled_diffuse_factor, &lobe,
                         NULL, diffuse);
        for (int c = 0; c < 3; ++c) rgb[c] += material->diffuse_albedo[c] * diffuse[c];
    } else if (diffuse_albedo[0] > 0.0 || diffuse_albedo[1] > 0.0 || diffuse_albedo[2] > 0.0) {
        double direct[3];
        dwvl_direct(&shader->env, x, n, ng, smooth, top, sampler, pair + DWVB_SHADE_PAIRS, direct);
        for (int c = 0; c < 3; ++c) rgb[c] += layer * diffuse_albedo[c] * direct[c];
    }
    /* The camera vertex's path rays from the pixel's stratified pairs past its walks' (shade.h,
     * beside DWVB_MAX_CHANNEL_WALKS): its exits' at 1 + c + 3 j, its surface's the two after those;
     * away from the camera from the vertex's `onward` pairs (ONWARD_PAIRS). */
    uint32_t camera_rays = pair + DWVB_SHADE_PAIRS + 2u * light_pairs +
                           DWVW_PAIRS_PER_EVENT * DWVB_STRATIFIED_EVENTS * DWVB_MAX_CHANNEL_WALKS;
    const dwvk_sampler *ray_sampler = camera ? sampler : onward;
    uint32_t surface_pair = camera ? camera_rays + 1u + 3u * DWVB_MAX_CHANNEL_WALKS : onward_pair;
    /* The surface's lobes send a path on (the same BRDF as their direct light above); past the
     * limits only a mirror's reflection is kept (its other draws end there, which keeps the
     * estimate of the emission it finds unbiased). */
    if ((go_on || dwvb_specular_singular(material)) &&
        surface_path_ray(shader, &lobes, x, ng, top, ray_sampler, surface_pair, &rays[*ray_count]) &&
        (go_on || rays[*ray_count].singular))
        ++*ray_count;
    if (!walks_left) return;
    /* Entry: cosine-weighted about minus the BSSRDF's normal (specular_n), rejected (no
     * contribution, as Cycles) where it would not go below the geometric surface. The pdf cos/pi
     * cancels the diffuse transmission f = 1/pi. */
    double u[2];
    dwvk_sampler_pair(sampler, pair, u);
    dwvu_vec3 inward;
    if (material->entry == DWVB_ENTRY_DIFFUSE) {
        double mu = sqrt(u[0]);
        inward = dwvk_direction_about(dwvu_scale(specular_n, -1.0), mu, 1.0 - mu, 1.0 + mu, u[1]);
    } else {
        /* Cycles 4.x+: GGX refraction (Skin: half of it), a direction distribution of unit weight
         * (subsurface_entry_bounce); none where the viewer is below the shading normal. */
        dwvu_frame frame = dwvu_frame_about(specular_n);
        dwvu_vec3 to_view = dwvu_scale(view, -1.0);
        dwvu_vec3 wi = dwvu_v(dwvu_dot(frame.t, to_view), dwvu_dot(frame.s, to_view), dwvu_dot(frame.n, to_view));
        dwvu_vec3 wo;
        if (!dwvb_entry_sample(material, wi, u[0], u[1], &wo)) return;
        inward = dwvu_add(dwvu_add(dwvu_scale(frame.t, wo.x), dwvu_scale(frame.s, wo.y)), dwvu_scale(frame.n, wo.z));
    }
    if (!(dwvu_dot(inward, ng) < 0.0)) return;
    /* The walk's first events take the pairs after the exit's lights (walk.h, DWVW_PAIR_*). */
    uint32_t walk_pair = pair + DWVB_SHADE_PAIRS + 2u * light_pairs;
    uint32_t exit_pair = pair + DWVB_SHADE_PAIRS + light_pairs;
    dwvw_walk walk;
    dwvg_hit exit = {0};
    exit_point point;
    double direct[3];
    if (camera && shader->channel_walks && shader->channel_walks[hit->mesh]) {
        /* Channel walks: each channel's estimate is its own walk's (its own extinction, albedo and
         * Dwivedi distribution), so no channel's weight carries another's sampling pdf. They
         * share the entry and the pixel's stratified numbers (each channel is stratified over the
         * pixel's samples), made once for the three (`pairs`); their counter-based numbers differ. */
        dwvw_pair_cache pairs[DWVB_MAX_CHANNEL_WALKS]; /* bits are written before they are read */
        for (uint32_t j = 0; j < DWVB_MAX_CHANNEL_WALKS; ++j) {
            pairs[j].first_pair = walk_pair + j * DWVW_PAIRS_PER_EVENT * DWVB_STRATIFIED_EVENTS;
            pairs[j].have = pairs[j].stratified = 0u;
        }
        for (int c = 0; c < 3; ++c) {
            if (!(material->walk_scale[c] > 0.0) || !(keep[c] > 0.0)) continue;
            /* A channel of `count` walks averages them; walk j draws its own stratified pairs
             * (shared with the other channels' walk j) and counter-based numbers. */
            uint32_t count = shader->channel_counts ? shader->channel_counts[3u * hit->mesh + (uint32_t)c] : 1u;
            uint64_t walks = tally->walks, events = tally->events, terms = tally->mixture_terms;
            for (uint32_t j = 0; j < count; ++j) {
                int exited = run_walk(shader, hit->mesh, &material->channel_medium[c],
                                      &shader->channel_guides[3u * hit->mesh + (uint32_t)c], hit->prim, x, inward, n,
                                      dwvk_mix64(key_walk + (uint64_t)c + 3u * (uint64_t)j), sampler,
                                      pairs[j].first_pair, &pairs[j], &walk, &exit, tally);
                double share = layer * material->walk_scale[c] / (double)count;
                if (walk.status == DWVW_TRUNCATED) tally->truncated[c] += walk.weight[0] * share;
                if (!exited) continue;
                exit_light(shader, hit->mesh, material, &walk, &exit, sampler, exit_pair, direct, &point);
                rgb[c] += walk.weight[0] * share * direct[c];
                /* This channel's walk sends a path on in its channel alone. */
                double weight[3] = {0.0, 0.0, 0.0};
                weight[c] = walk.weight[0] * share;
                uint32_t exit_pairs = camera ? camera_rays + 1u + (uint32_t)c + 3u * j
                                             : onward_pair + ONWARD_PAIRS * (1u + (uint32_t)c + 3u * j);
                if (go_on && exit_path_ray(shader, &point, weight, ray_sampler, exit_pairs, &rays[*ray_count]))
                    ++*ray_count;
            }
            tally->channel_walks[c] += tally->walks - walks;
            tally->channel_events[c] += tally->events - events;
            tally->channel_terms[c] += tally->mixture_terms - terms;
        }
        return;
    }
    int exited = run_walk(shader, hit->mesh, &material->medium, &shader->guides[hit->mesh], hit->prim, x, inward, n,
                          key_walk, sampler, walk_pair, NULL, &walk, &exit, tally);
    int grey = material->medium.channels == 1;
    if (camera && walk.status == DWVW_TRUNCATED)
        for (int c = 0; c < 3; ++c) tally->truncated[c] += walk.weight[grey ? 0 : c] * material->walk_scale[c];
    if (!exited) return;
    exit_light(shader, hit->mesh, material, &walk, &exit, sampler, exit_pair, direct, &point);
    double weight[3];
    for (int c = 0; c < 3; ++c) {
        weight[c] = keep[c] * layer * walk.weight[grey ? 0 : c] * material->walk_scale[c];
        rgb[c] += weight[c] * direct[c];
    }
    uint32_t exit_pairs = camera ? camera_rays + 1u : onward_pair + ONWARD_PAIRS;
    if (go_on && exit_path_ray(shader, &point, weight, ray_sampler, exit_pairs, &rays[*ray_count])) ++*ray_count;
}

/* Salts of the counter-based keys of the paths after the camera vertex: the vertex's sampler,
 * its walk, the camera vertex's onward rays (any constants; dwvk_mix64 decorrelates them). */
#define PATH_VERTEX_SALT 0x5851f42d4c957f2dull
#define PATH_WALK_SALT 0x14057b7ef767814full
#define PATH_ONWARD_SALT 0xda942042e4dd58b5ull
/* The pairs of an indirect vertex's sampler: 0 Russian roulette and the choice of ray, from 1 on
 * the shading (dwvb_shade's layout), its rays from ONWARD_PAIR on (far past both). */
#define ONWARD_PAIR (1u << 20)
/* The camera vertex's choices among its walks' exits, one per channel (past their rays' pairs in
 * `onward`). */
#define ONWARD_CHOICE_PAIR (ONWARD_PAIRS * (1u + 3u * DWVB_MAX_CHANNEL_WALKS))

/* One of rays[0..count) chosen with probability in proportion to its mean weight by uniform u,
 * its weight divided by that probability (one-sample estimation of their sum); returns 0 where
 * none has weight. */
static int choose_ray(const path_ray *rays, uint32_t count, double u, path_ray *chosen)
{
    double total = 0.0;
    for (uint32_t j = 0; j < count; ++j) total += rays[j].weight[0] + rays[j].weight[1] + rays[j].weight[2];
    if (!(total > 0.0)) return 0;
    double target = u * total, sum = 0.0;
    uint32_t pick = count - 1u;
    for (uint32_t j = 0; j < count; ++j) {
        sum += rays[j].weight[0] + rays[j].weight[1] + rays[j].weight[2];
        if (target < sum) {
            pick = j;
            break;
        }
    }
    double p = (rays[pick].weight[0] + rays[pick].weight[1] + rays[pick].weight[2]) / total;
    if (!(p > 0.0)) return 0;
    *chosen = rays[pick];
    for (int c = 0; c < 3; ++c) chosen->weight[c] /= p;
    return 1;
}

/* Follows a path from its first ray on (the camera vertex in `state`), iteratively: at each hit
 * Russian roulette (Cycles' continuation probability, dividing the throughput by it), the hit's
 * direct light (next-event estimation for lights and world, which covers them wholly: no light is
 * geometry, and a ray that leaves the world adds nothing), then one of the rays its lobes and its
 * walk's exit send on, chosen in proportion to their mean weights (the chosen one divided by its
 * probability). A mirror's ray (path_ray.singular) adds the emission it meets before its hit
 * (before RR, which Cycles applies at surfaces only), and goes no further where its bounce
 * exceeds a limit. `key`: the path's counter-based numbers. Light the first ray's emission brings
 * goes to `first_light` (Cycles' direct light of the vertex that sent it), the rest to `out`. */
static void follow_path(const dwvb_shader *shader, const path_ray *first, path_state state, uint64_t key,
                        double first_light[3], double out[3], dwvb_tally *tally)
{
    double throughput[3] = {1.0, 1.0, 1.0};
    out[0] = out[1] = out[2] = 0.0;
    first_light[0] = first_light[1] = first_light[2] = 0.0;
    path_ray ray = *first;
    for (uint64_t vertex = 1;; ++vertex) {
        int shaded = path_state_next(&state, ray.lobe, &shader->paths);
        if (!shaded && !ray.singular) return;
        if (!ray.singular) state.min_ray_pdf = fmin(state.min_ray_pdf, ray.pdf);
        int alive = 0;
        for (int c = 0; c < 3; ++c) {
            throughput[c] *= ray.weight[c];
            alive |= throughput[c] > 0.0;
        }
        if (!alive) return;
        dwvg_hit hit;
        tally->path_rays += (uint64_t)!ray.clear;
        int found = !ray.clear && dwvg_intersect(&shader->scene->geometry, ray.origin, ray.direction, 0.0, INFINITY, &hit);
        if (ray.singular) {
            double emission[3];
            dwvl_emission_along(&shader->env, ray.origin, ray.direction, found ? hit.t : INFINITY, emission);
            double *to = vertex == 1u ? first_light : out;
            for (int c = 0; c < 3; ++c) to[c] += throughput[c] * emission[c];
        }
        if (!found || !shaded) return;
        uint64_t vertex_key = dwvk_mix64(key ^ (PATH_VERTEX_SALT + vertex));
        dwvk_sampler sampler = {vertex_key, 0u, 0};
        double u[2];
        dwvk_sampler_pair(&sampler, 0u, u);
        double p = continuation_probability(&state, throughput, &shader->paths);
        if (p < 1.0) {
            if (!(u[0] < p)) return;
            for (int c = 0; c < 3; ++c) throughput[c] /= p;
        }
        double direct[DWVB_LOBE_COUNT][3];
        path_ray rays[2];
        uint32_t count = 0u;
        int onward = path_can_go_on(&state, &shader->paths);
        shade_point(shader, &hit, ray.direction, &sampler, 1u, dwvk_mix64(vertex_key ^ PATH_WALK_SALT), &state, 0, direct, NULL,
                    rays, onward, &sampler, ONWARD_PAIR, &count, tally);
        for (int c = 0; c < 3; ++c)
            out[c] += throughput[c] * (direct[DWVB_LOBE_DIFFUSE][c] + direct[DWVB_LOBE_GLOSSY][c]);
        if (count == 0u || !choose_ray(rays, count, u[1], &ray)) return;
        /* The next ray's differentials: dP the footprint here, dD kept, 0 after a walk
         * (shade_surface.h, subsurface.h). */
        state.dP += hit.t * state.dD;
        if (ray.exit) state.dD = 0.0;
    }
}

void dwvb_shade(const dwvb_shader *shader, const dwvg_hit *hit, dwvu_vec3 view, const dwvk_sampler *sampler,
                uint32_t pair, uint64_t key_walk, dwvb_shade_parts *parts, dwvb_tally *tally)
{
    *parts = (dwvb_shade_parts){0};
    path_state state = {0u, 0u, 0u, 0u, 0, 0.0, 0.0, INFINITY};
    path_ray rays[1u + 3u * DWVB_MAX_CHANNEL_WALKS];
    uint32_t count = 0u;
    /* No ray goes on where the limits leave no bounce: the one-bounce image, bit for bit. */
    int onward = path_can_go_on(&state, &shader->paths);
    dwvk_sampler onward_sampler = {dwvk_mix64(key_walk ^ PATH_ONWARD_SALT), 0u, 0};
    shade_point(shader, hit, view, sampler, pair, key_walk, &state, 1, parts->direct, parts->color,
                rays, onward, &onward_sampler, 0u, &count, tally);
    /* The surface lobes' ray is a path of its own, and so is, per channel of channel walks (or
     * for the one walk), one of its walks' exits' rays, chosen by their weights where the pilot
     * gave a channel several walks: tracing all of those cost the report's bowl twice its time
     * per sample, while one exit for the three channels' walks tripled the torus's variance. Each
     * path's light is indirect light of the lobe that sent it. */
    path_ray paths[5];
    uint32_t path_count = 0u;
    for (uint32_t j = 0; j < count; ++j)
        if (!rays[j].exit) paths[path_count++] = rays[j];
    for (int group = 1; group <= 4; ++group) {
        path_ray exits[DWVB_MAX_CHANNEL_WALKS];
        uint32_t exit_count = 0u;
        for (uint32_t j = 0; j < count; ++j)
            if (rays[j].exit == group && exit_count < DWVB_MAX_CHANNEL_WALKS) exits[exit_count++] = rays[j];
        double u[2];
        dwvk_sampler_pair(&onward_sampler, ONWARD_CHOICE_PAIR + (uint32_t)group, u);
        if (exit_count == 1u) paths[path_count++] = exits[0];
        else if (exit_count && choose_ray(exits, exit_count, u[0], &paths[path_count])) ++path_count;
    }
    /* The paths' first rays' differentials: dP the footprint at this hit, dD the camera ray's
     * (0 after a walk and for a constant footprint). */
    state.dP = dwvb_footprint(shader, view, hit->t);
    double spread = shader->footprint == DWVB_FOOTPRINT_PERSPECTIVE ? dwvb_footprint(shader, view, 1.0) : 0.0;
    for (uint32_t j = 0; j < path_count; ++j) {
        double reflected[3], gathered[3];
        state.dD = paths[j].exit ? 0.0 : spread;
        follow_path(shader, &paths[j], state, dwvk_mix64(key_walk ^ (PATH_ONWARD_SALT + 1u + j)), reflected, gathered,
                    tally);
        for (int c = 0; c < 3; ++c) {
            parts->direct[paths[j].lobe][c] += reflected[c];
            parts->indirect[paths[j].lobe][c] += gathered[c];
        }
    }
}
