/* One sample of the radiance leaving a surface point of the scene toward a viewer: the Lambertian
 * lobe by next-event estimation, plus the random-walk subsurface lobe (Cycles-like, Fresnel-free):
 * enter by cosine-weighted diffuse transmission, walk in the mesh's own Embree scene with the
 * step machine of src/walk, leave through a Lambertian exit that gathers direct light and the
 * world. For DWV_SUBSURFACE_EXIT_PRINCIPLED_V1 the exit is weighted by 1 - F_L/2 and a
 * retro-reflection lobe joins the Lambertian one (material.h). Paths go on after the walk's exit
 * and after the surface lobes up to Cycles' light-path limits (dwvb_light_paths), with Russian
 * roulette as Cycles, so that surfaces light each other (indirect light). */
#ifndef DWV_BAKE_SHADE_H
#define DWV_BAKE_SHADE_H

#include <stdint.h>

#include "bake/scene.h"
#include "geom/embree.h"
#include "light/direct.h"
#include "walk/walk.h"

/* Cycles' light-path limits (scene.cycles: Max Bounces Total, Diffuse, Glossy, Transmission,
 * Min Light Bounces), counted as Cycles' path_state_next counts them: a reflection off a diffuse
 * lobe (Lambertian, Principled diffuse, retro-reflection, a walk's exit) is one diffuse and one
 * total bounce, off the specular layer one glossy and one total bounce; a walk itself is none
 * (subsurface_bounce does not call path_state_next). A path whose next bounce would exceed a limit
 * ends there (Cycles then only looks for emission, which no dwivedi surface has). All zero: the
 * one-bounce image. `after_diffuse`: DWV_SUBSURFACE_AFTER_DIFFUSE_*, what a subsurface surface met
 * after a diffuse bounce does. */
typedef struct dwvb_light_paths {
    uint32_t max_bounces, diffuse, glossy, transmission, min_bounces;
    int after_diffuse;
    /* Cycles' Filter Glossy (scene.cycles.blur_glossy; 0: none): dwvb_blur_alpha. */
    double blur_glossy;
} dwvb_light_paths;

/* Cycles' Filter Glossy (surface_shader_prepare_closures, the same in 3.4, 4.3 and 5.x): at a
 * shading point of a path whose non-singular bounces so far had pdfs of at least min_ray_pdf
 * (+inf at the camera's hit), where b = min_ray_pdf / blur_glossy < 1, every microfacet closure's
 * alpha becomes max(alpha, 0.5 sqrt(1 - b)) (bsdf_blur). Returns that alpha (`alpha` itself
 * where no blur applies, and always for blur_glossy 0). Only alpha changes: 4.x+ compute the
 * multiscatter energy scale, the darkening and the layering weight at the closure's setup from
 * its own roughness and keep them after the blur (bsdf.h: "TODO: Recompute energy preservation
 * after blur?"), so v2's albedo tables stay the material's. */
double dwvb_blur_alpha(double alpha, double min_ray_pdf, double blur_glossy);

typedef struct dwvb_shader {
    const dwvb_scene *scene;
    dwvl_environment env;
    const dwvw_guide *guides;     /* per mesh (used where its material scatters) */
    const int *needs_closest;     /* per mesh, for its guides and channel guides alike */
    /* Per mesh: 1 where a sample runs one walk per walking colour channel, each in that channel's
     * own medium (material.h channel_medium) with channel_guides[3 m + c], instead of one walk
     * that carries the three channels by spectral MIS. NULL: none does. */
    const int *channel_walks;
    const dwvw_guide *channel_guides;
    /* Per mesh x 3, where channels walk apart: walks per sample of each channel, 1 to
     * DWVB_MAX_CHANNEL_WALKS, each weighing 1 / count (NULL: one each). Auto's pilot sets them
     * where a channel's variance is worth more walks than its cost (pilot.c). */
    const uint8_t *channel_counts;
    uint32_t max_events;
    dwvb_light_paths paths;
    /* The footprint of the ray that found the first hit (Cycles' ray differentials, sd->dP, for
     * dwvb_material.min_footprint): DWVB_FOOTPRINT_PERSPECTIVE (eye, forward, and right / up one
     * pixel apart on the plane at unit distance), DWVB_FOOTPRINT_CONSTANT (`pixel` at any
     * distance: an orthographic camera's pixel width, a UV bake texel's footprint on the surface,
     * dwvb_uv_texel_footprint), DWVB_FOOTPRINT_NONE. */
    int footprint;
    dwvu_vec3 eye, pixel_right, pixel_up, forward;
    double pixel;
} dwvb_shader;

enum { DWVB_FOOTPRINT_NONE = 0, DWVB_FOOTPRINT_PERSPECTIVE = 1, DWVB_FOOTPRINT_CONSTANT = 2 };

/* The first ray's footprint at distance t along unit `view` (Cycles 4.x compact differentials,
 * sd->dP = dP + t dD): perspective t x 0.5 (|normalize(D + dx) - D'| + |normalize(D + dy) - D'|),
 * D the direction on the unit plane, D' = view (dP = 0); constant: `pixel` (dD = 0). Along a path
 * Cycles keeps the camera's dD and takes sd->dP as the next ray's dP (shade_surface.h), so that
 * the footprint at a later hit is dP + (the path's length) dD: dwvb_shade follows that. */
double dwvb_footprint(const dwvb_shader *shader, dwvu_vec3 view, double t);

/* Cycles' light passes (Blender's bake types Diffuse, Glossy, Transmission and Combined's pass
 * filter); subsurface belongs to Diffuse, as in Cycles 3.0+. */
enum { DWVB_LOBE_DIFFUSE = 0, DWVB_LOBE_GLOSSY = 1, DWVB_LOBE_TRANSMISSION = 2, DWVB_LOBE_COUNT = 3 };

/* One sample's radiance split as Cycles splits its passes, by the lobe that scattered at the
 * camera ray's (or the texel's) hit: direct, light from the lights and the world at that
 * scattering (for a walk: at its exit); indirect, light that scattered at least once more after
 * it; color, that lobe's weight (albedo) at the hit; emission, the surface's own; environment,
 * the world seen directly (camera misses). Combined is the sum of direct, indirect, emission and
 * environment. */
typedef struct dwvb_shade_parts {
    double direct[DWVB_LOBE_COUNT][3];
    double indirect[DWVB_LOBE_COUNT][3];
    double color[DWVB_LOBE_COUNT][3];
    double emission[3];
    double environment[3];
} dwvb_shade_parts;

static inline void dwvb_shade_parts_combined(const dwvb_shade_parts *parts, double rgb[3])
{
    for (int c = 0; c < 3; ++c) {
        rgb[c] = parts->emission[c] + parts->environment[c];
        for (int l = 0; l < DWVB_LOBE_COUNT; ++l) rgb[c] += parts->direct[l][c] + parts->indirect[l][c];
    }
}

/* What samples met, summed by the caller in a fixed order. */
typedef struct dwvb_tally {
    uint64_t events, walks, warnings;
    /* Work the walks' mixtures did: per step, the components with weight > 0 times the channels
     * squared (the exponentials of the spectral MIS weight), plus the lit patches weighed. */
    uint64_t mixture_terms;
    /* Rays the walks cast (Embree's; a polytope's, dwvg_polytope, are its planes' exits and count
     * too), closest-point queries they made, their steps taken without a ray (inside a ball
     * clear of the mesh), and (checked ball mode only) those of them whose ray would have met
     * the surface. */
    uint64_t rays, point_queries, ray_free_steps, ray_free_misses;
    double truncated[3];
    /* Rays the paths after the first scattering traced (indirect light; mirrors' reflections). */
    uint64_t path_rays;
    /* Of the walks above, those of channel walks by channel: walks, events and mixture terms. */
    uint64_t channel_walks[3], channel_events[3], channel_terms[3];
    /* The mesh of the sample's first walk, plus one (0: none walked): auto's pilot counts a sample
     * whose camera ray met another mesh (a mirror, the ground) for the mesh it walked. */
    uint32_t first_walk_mesh;
} dwvb_tally;

/* Pairs of random dimensions shading uses before direct lighting starts: the entry direction. */
#define DWVB_SHADE_PAIRS 1u
/* The walk's first events drawn from the pixel's stratified sampler (walk.h, DWVW_PAIR_*), after
 * the entry's and both light samples' pairs; later events use the walk's counter-based key.
 * At equal samples, 64 spp, against 8 stratified events none: pixel variance x0.53 on the
 * report's sphere, x0.72 on the slab, x0.81 on the leaf, x0.79 on the default scene (classical);
 * the first event alone gives x0.67 to x0.85, 16 events or all of them no more than 8 within the
 * noise, while each stratified event costs two sampler pairs (docs/speed.md, "Stratified walks"). */
#define DWVB_STRATIFIED_EVENTS 8u
/* Walks per sample of one channel at most (channel_counts); walk j of a channel takes the sampler
 * pairs DWVW_PAIRS_PER_EVENT x DWVB_STRATIFIED_EVENTS x j after the first's. */
#define DWVB_MAX_CHANNEL_WALKS 3u
/* The camera vertex's path rays draw their directions from the pixel's stratified sampler, past
 * the pairs of all DWVB_MAX_CHANNEL_WALKS walks: its walks' exits' at pair 1 + c + 3 j there
 * (walk j of channel c; the one walk's 1), its surface lobes' the two after those. Over a pixel's
 * samples those directions cover the hemisphere evenly, so that the share of them that meets the
 * rest of a concave object (where its indirect light comes from) varies less than with
 * independent draws (docs/speed.md, "The bowl's variance: indirect light from its exits"). */

/* The mixture a surface point's path rays are drawn from (Cycles picks a closure by its sample
 * weight and weighs the direction by MIS over all closures), each lobe about its own normal: the
 * specular layer's about specular_n (4.x+: the shading normal kept valid for reflection), its GGX
 * visible normals reflected (Heitz 2018), pdf D_wi(h) / (4 wi.h) (Eq. 2 there and the
 * reflection's Jacobian), with probability p_s; the cosine about n, pdf cos / pi, with 1 - p_s. A
 * mirror layer (dwvb_specular_singular) is a delta instead: the mirror direction about
 * specular_n (Cycles' singular microfacet, H = N), drawn with probability p_s and in no pdf.
 * p_s is the layer's albedo toward the viewer at cos_view (its cosine to specular_n; 4.x+:
 * 1 - dwvb_specular_layer_weight; 3.x: Schlick's Fresnel of the mean F0; a mirror: its mean
 * reflectance dwvb_specular_singular_weight) against the diffuse lobes' mean weight `diffuse` (+
 * the retro-reflection's); 0 where the layer is absent; -1 where nothing scatters.
 * dwvb_surface_sample draws a direction (uniforms u0, u1 and `choice`), its lobe (DWVB_LOBE_*)
 * and whether it is the mirror's (*singular), 0 where none is drawn; dwvb_surface_pdf is the
 * density of the mixture's continuous part at any direction (its integral is 1 - p_s for a
 * mirror, 1 otherwise, less what falls below the horizons). */
double dwvb_surface_specular_probability(const dwvb_material *m, const double diffuse[3], double cos_view);
int dwvb_surface_sample(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                        double u0, double u1, double choice, dwvu_vec3 *w, int *lobe, int *singular);
double dwvb_surface_pdf(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                        dwvu_vec3 w);

/* The radiance leaving hit point `hit` along -view (view: unit direction of the ray that found
 * it, from the viewer), split into `parts` (zeroed first): the specular layer's direct light is
 * GLOSSY's; the Lambertian, Principled diffuse, retro-reflection and the walks' exits are
 * DIFFUSE's; each lobe's colour is its closures' weight (3.x) or albedo (4.x+) as Cycles' colour
 * passes. `sampler` drives entry and light sampling from pair `pair` on, then the walk's first
 * DWVB_STRATIFIED_EVENTS events; key_walk drives the rest of the walk, and (mixed) the paths that
 * go on from there (counter-based numbers). */
void dwvb_shade(const dwvb_shader *shader, const dwvg_hit *hit, dwvu_vec3 view, const dwvk_sampler *sampler,
                uint32_t pair, uint64_t key_walk, dwvb_shade_parts *parts, dwvb_tally *tally);

#endif
