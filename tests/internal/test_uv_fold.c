/* Cycles up to 3.4's placement of a UV bake's samples in their texel (dwv_uv_jitter_t MIRROR;
 * src/bake/uv_raster.c dwvb_uv_fold, src/bake/bake.c texel_sample), against this test's own
 * computation of the rule from its formula (capi/dwivedi.h): Blender's barycentrics (u, v) of
 * corners 0 and 1 and its half-texel differentials (bake_differentials' formula, from the UVs), the
 * moved point folded by reflecting it at the ends of [0, 1] and then of [0, 1 - u'] until inside.
 * - mirror repeat at known values; folded points of random triangles (slivers too) and random
 *   uniforms lie in the closed triangle, and equal this test's fold to 1e-12;
 * - a UV bake's diffuse colour pass of a quad whose base colour is a texture linear in UV (so a
 *   texel's value is the signal at the mean of its samples' points): 1 sample (sample 0) is the
 *   signal at the texel centre; 256 samples match (1/N) f(centre) + (N-1)/N E[f(fold)], E on a
 *   128 x 128 midpoint grid, within 2e-4 on every texel (the texels whose box crosses a triangle's
 *   edge move by 5e-3 between rules), and the retry rule's model misses that bake by more than 10
 *   times the bound (the harness catches a wrong rule); the default rule's bake, 1024 samples,
 *   matches its own model (the box cut to the triangle: kept tries, after 10 the centre) within
 *   1e-3 (its retries are unstratified) and misses the folding model by more than 4 times that;
 * - bad values refused; an older options struct bakes the default rule's bits; 1 and 2 threads
 *   give the same bits; the scene file's bake.uv_jitter read and a bad name refused; a UV bake's
 *   rule changes the partial files' options hash, a camera bake's does not. Runs in 0.5 s. */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/partial.h"
#include "bake/uv_raster.h"
#include "check.h"
#include <dwivedi.h>

#define SIZE 20u          /* the bake's texels per side */
#define SAMPLES 256u
#define GRID 128u         /* the model's uniforms per axis */
#define TOLERANCE 2e-4    /* a texel's colour against its model (measured: 9e-5) */
/* The default rule's retries take unstratified numbers: its texels near an edge carry Monte Carlo
 * noise, sigma ~ 2e-4 at 1024 samples (measured worst of 139 texels: 5.3e-4 at 256). */
#define RETRY_SAMPLES 1024u
#define RETRY_TOLERANCE 1e-3

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double uniform(void) /* xorshift64*, top 53 bits */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * 0x1p-53;
}

/* x reflected at 0 and m until it lies in [0, m] (the fold as a mirror); [0, 0] holds 0. */
static double reflect_into(double x, double m)
{
    if (!(m > 0.0)) return 0.0;
    while (x < 0.0 || x > m) x = x < 0.0 ? -x : 2.0 * m - x;
    return x;
}

/* A texel's frame as Blender hands it to Cycles: corner UVs in texels p[3][2]; the centre c. */
typedef struct blender_texel {
    double u, v;                       /* barycentrics of corners 0 and 1 at the centre */
    double du_dx, du_dy, dv_dx, dv_dy; /* bake_differentials: 0.5 / A times the edge terms */
} blender_texel;

static blender_texel blender_frame(double p[3][2], const double c[2])
{
    blender_texel t;
    double a = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    /* c = p2 + u (p0 - p2) + v (p1 - p2), by Cramer's rule */
    double x0 = p[0][0] - p[2][0], y0 = p[0][1] - p[2][1], x1 = p[1][0] - p[2][0], y1 = p[1][1] - p[2][1];
    double cx = c[0] - p[2][0], cy = c[1] - p[2][1], det = x0 * y1 - x1 * y0;
    t.u = (cx * y1 - x1 * cy) / det;
    t.v = (x0 * cy - cx * y0) / det;
    double half = 0.5 / a;
    t.du_dx = (p[1][1] - p[2][1]) * half;
    t.dv_dx = (p[2][1] - p[0][1]) * half;
    t.du_dy = (p[2][0] - p[1][0]) * half;
    t.dv_dy = (p[0][0] - p[2][0]) * half;
    return t;
}

/* The rule's point for uniforms (rx, ry): Blender's (u', v'), folded or (inside = 0 if not
 * strictly inside) as moved. */
static void moved(const blender_texel *t, double rx, double ry, int fold, double *u, double *v, int *inside)
{
    *u = t->u + t->du_dx * (rx - 0.5) + t->du_dy * (ry - 0.5);
    *v = t->v + t->dv_dx * (rx - 0.5) + t->dv_dy * (ry - 0.5);
    *inside = *u > 0.0 && *v > 0.0 && *u + *v < 1.0;
    if (fold) {
        *u = reflect_into(*u, 1.0);
        *v = reflect_into(*v, 1.0 - *u);
    }
}

static void test_mirror_repeat(void)
{
    const double cases[][3] = {{0.3, 1.0, 0.3}, {1.2, 1.0, 0.8},  {-0.2, 1.0, 0.2}, {2.3, 1.0, 0.3},
                               {-1.3, 1.0, 0.7}, {0.6, 0.5, 0.4}, {-0.1, 0.5, 0.1}, {0.4, 0.0, 0.0}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        double got = dwvb_uv_mirror_repeat(cases[i][0], cases[i][1]);
        CHECK(fabs(got - cases[i][2]) < 1e-15, "mirror_repeat(%g, %g) = %.17g, not %g", cases[i][0], cases[i][1], got,
              cases[i][2]);
    }
}

/* Random triangles (a tenth of them slivers) and centres, some outside the triangle by up to a
 * texel (an island's edge texels) and random uniforms: the folded point in the closed triangle and
 * at this test's fold of Blender's coordinates. */
static void test_fold_inside(void)
{
    int outside = 0, off = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 2000; ++trial) {
        uint32_t w = 4u + (uint32_t)(uniform() * 60.0), h = 4u + (uint32_t)(uniform() * 60.0);
        float uv[6];
        for (int k = 0; k < 6; ++k) uv[k] = (float)uniform();
        if (trial % 10 == 0) { /* a sliver: corner 2 near the edge from 0 to 1 */
            uv[4] = (float)(0.5 * (uv[0] + uv[2]) + 1e-3 * uniform());
            uv[5] = (float)(0.5 * (uv[1] + uv[3]) + 1e-3 * uniform());
        }
        dwvb_uv_steps step;
        dwvb_uv_texel_steps(uv, w, h, &step);
        double p[3][2];
        for (int k = 0; k < 3; ++k) {
            p[k][0] = uv[2 * k] * (double)w;
            p[k][1] = uv[2 * k + 1] * (double)h;
        }
        double area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        if (!(fabs(area) > (double)FLT_EPSILON)) continue;
        double b1 = uniform(), b2 = (1.0 - b1) * uniform();
        if (trial % 3 == 0) { /* beyond the edge from corner 1 to 2 by up to a texel's steps */
            b1 += 2.0 * fabs(step.d[0][0]) * uniform();
            b2 += 2.0 * fabs(step.d[1][1]) * uniform();
        }
        double c[2] = {p[0][0] + b1 * (p[1][0] - p[0][0]) + b2 * (p[2][0] - p[0][0]),
                       p[0][1] + b1 * (p[1][1] - p[0][1]) + b2 * (p[2][1] - p[0][1])};
        blender_texel t = blender_frame(p, c);
        t.u = 1.0 - b1 - b2; /* as given, not solved back from c (slivers' solve loses digits) */
        t.v = b1;
        for (int k = 0; k < 8; ++k) {
            double r0 = uniform(), r1 = uniform(), j1, j2, u, v;
            int inside;
            dwvb_uv_fold(&step, b1, b2, r0, r1, &j1, &j2);
            if (!(j1 >= 0.0 && j2 >= 0.0 && j1 + j2 <= 1.0)) ++outside;
            moved(&t, r0, r1, 1, &u, &v, &inside);
            /* rounding grows with the steps (the moved point's size): relative to 1 + their sum */
            double scale = 1.0 + fabs(t.du_dx) + fabs(t.du_dy) + fabs(t.dv_dx) + fabs(t.dv_dy);
            double d = fmax(fabs(j1 - v), fabs(j2 - (1.0 - u - v))) / scale;
            if (!(d < 1e-10)) ++off; /* measured: 1e-11 on slivers, whose steps are far apart */
            worst = fmax(worst, d);
        }
    }
    CHECK(outside == 0, "%d folded points outside their triangle", outside);
    printf("folded points: worst off this test's fold %.3g (relative to 1 + the steps)\n", worst);
    CHECK(off == 0, "%d folded points off this test's fold (worst %.3g)", off, worst);
}

/* The quad: corners at UVs (a generic shape, no texel centre on its diagonal), positions x = u,
 * y = v, z = 0, facing +z; triangles (0, 1, 2) and (0, 2, 3). */
static const double quad_uv[4][2] = {{0.22, 0.2}, {0.8, 0.24}, {0.78, 0.81}, {0.2, 0.77}};
static const uint32_t quad_triangles[2][3] = {{0, 1, 2}, {0, 2, 3}};

/* The base colour's texture: 4 x 4 texels of R = i / 3, G = j / 3 (column i, row j from the
 * bottom), linear interpolation: between the outer texels' centres (UV 1/8 to 7/8, where the quad
 * lies) R = (4 u - 1/2) / 3, G = (4 v - 1/2) / 3, linear. */
static void signal(double u, double v, double out[2])
{
    out[0] = (4.0 * u - 0.5) / 3.0;
    out[1] = (4.0 * v - 0.5) / 3.0;
}

static dwv_scene_t *quad_scene(void)
{
    float positions[12], uvs[12], texels[4 * 4 * 3];
    uint32_t indices[6];
    for (int k = 0; k < 4; ++k) {
        positions[3 * k] = (float)quad_uv[k][0];
        positions[3 * k + 1] = (float)quad_uv[k][1];
        positions[3 * k + 2] = 0.0f;
    }
    for (int t = 0; t < 2; ++t)
        for (int k = 0; k < 3; ++k) {
            indices[3 * t + k] = quad_triangles[t][k];
            uvs[6 * t + 2 * k] = (float)quad_uv[quad_triangles[t][k]][0];
            uvs[6 * t + 2 * k + 1] = (float)quad_uv[quad_triangles[t][k]][1];
        }
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            texels[3 * (4 * j + i)] = (float)i / 3.0f;
            texels[3 * (4 * j + i) + 1] = (float)j / 3.0f;
            texels[3 * (4 * j + i) + 2] = 0.5f;
        }
    dwv_scene_t *scene = NULL;
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    dwv_texture_desc_t texture = DWV_TEXTURE_DESC_INIT;
    texture.width = texture.height = 4u;
    texture.channels = 3u;
    texture.extension = DWV_EXTENSION_EXTEND;
    texture.texels = texels;
    dwv_texture_binding_t binding = DWV_TEXTURE_BINDING_INIT;
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4u;
    mesh.triangle_count = 2u;
    mesh.positions = positions;
    mesh.indices = indices;
    mesh.uvs = uvs;
    double world[3] = {0.5, 0.5, 0.5};
    uint32_t material_id, mesh_id;
    if (dwv_scene_create(&scene) || dwv_scene_add_material(scene, &m, &material_id) ||
        dwv_scene_add_texture(scene, &texture, &binding.texture_id) ||
        dwv_scene_bind_texture(scene, material_id, &binding) || (mesh.material_id = material_id, 0) ||
        dwv_scene_add_mesh(scene, &mesh, &mesh_id) || dwv_scene_set_world(scene, world, 1.0) ||
        dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static dwv_bake_options_t fold_options(dwv_uv_jitter_t rule, uint64_t samples, uint32_t threads)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.target = DWV_BAKE_UV;
    o.width = o.height = SIZE;
    o.uv_margin = 0u;
    o.samples = samples;
    o.threads = threads;
    o.seed = 5u;
    o.max_bounces = 0u;
    o.passes = DWV_PASS_BIT(DWV_PASS_DIFFUSE_COLOR);
    o.uv_jitter = rule;
    return o;
}

/* The diffuse colour pass of a bake (NULL, and a failed check, if it failed). */
static dwv_image_t *colour_pass(dwv_scene_t *scene, const dwv_bake_options_t *o, dwv_image_t **combined)
{
    dwv_image_t *image = NULL, *pass = NULL;
    dwv_result_t r = dwv_bake(scene, o, &image);
    CHECK(r == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    if (r != DWV_SUCCESS) return NULL;
    r = dwv_image_pass(image, DWV_PASS_DIFFUSE_COLOR, &pass);
    CHECK(r == DWV_SUCCESS, "pass: %s", dwv_last_error_message());
    if (combined) *combined = image;
    else dwv_image_release(image);
    return pass;
}

/* The model of texel (x, row)'s colour: 0 if no triangle holds its centre. samples = 1: the
 * centre; else by `fold`: (1/N) f(centre) + (N-1)/N E[f(folded)], or the box's points inside the
 * triangle, and the centre with the probability that 10 tries all fall outside. */
static int texel_model(uint32_t x, uint32_t row, int fold, uint64_t samples, double out[2])
{
    double c[2] = {x + 0.5, SIZE - (row + 0.5)}; /* texels, y up */
    for (int t = 0; t < 2; ++t) {
        double p[3][2];
        for (int k = 0; k < 3; ++k) {
            p[k][0] = quad_uv[quad_triangles[t][k]][0] * SIZE;
            p[k][1] = quad_uv[quad_triangles[t][k]][1] * SIZE;
        }
        blender_texel frame = blender_frame(p, c);
        if (!(frame.u > 0.0 && frame.v > 0.0 && frame.u + frame.v < 1.0)) continue;
        double centre[2], sum[2] = {0.0, 0.0};
        signal(c[0] / SIZE, c[1] / SIZE, centre);
        uint32_t kept = 0;
        for (uint32_t i = 0; i < GRID; ++i)
            for (uint32_t j = 0; j < GRID; ++j) {
                double u, v, f[2];
                int inside;
                moved(&frame, (i + 0.5) / GRID, (j + 0.5) / GRID, fold, &u, &v, &inside);
                if (!fold && !inside) continue;
                ++kept;
                double w = 1.0 - u - v;
                signal((u * p[0][0] + v * p[1][0] + w * p[2][0]) / SIZE, (u * p[0][1] + v * p[1][1] + w * p[2][1]) / SIZE,
                       f);
                sum[0] += f[0];
                sum[1] += f[1];
            }
        for (int ch = 0; ch < 2; ++ch) {
            double mean = sum[ch] / kept;
            if (fold) {
                out[ch] = (centre[ch] + (double)(samples - 1u) * mean) / (double)samples;
            } else {
                double all_out = pow(1.0 - (double)kept / (GRID * GRID), 10.0);
                out[ch] = (1.0 - all_out) * mean + all_out * centre[ch];
            }
        }
        return 1;
    }
    return 0;
}

/* The largest difference of a bake's covered texels from the model (R and G), and how many there
 * were; the largest move of a texel's model between the rules in *rules_apart. */
static double worst_off(dwv_image_t *pass, int fold, uint64_t samples, uint32_t *covered, double *rules_apart)
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(pass, &info);
    double worst = 0.0;
    *covered = 0u;
    if (rules_apart) *rules_apart = 0.0;
    for (uint32_t row = 0; row < SIZE; ++row)
        for (uint32_t x = 0; x < SIZE; ++x) {
            double model[2], other[2];
            if (!texel_model(x, row, fold, samples, model)) continue;
            ++*covered;
            const float *rgba = info.rgba + 4u * (row * SIZE + x);
            for (int ch = 0; ch < 2; ++ch) worst = fmax(worst, fabs(rgba[ch] - model[ch]));
            if (rules_apart && texel_model(x, row, !fold, samples, other))
                for (int ch = 0; ch < 2; ++ch) *rules_apart = fmax(*rules_apart, fabs(model[ch] - other[ch]));
        }
    return worst;
}

static void test_bake_distribution(dwv_scene_t *scene)
{
    uint32_t covered = 0;
    dwv_bake_options_t o = fold_options(DWV_UV_JITTER_MIRROR, 1u, 2u);
    dwv_image_t *pass = colour_pass(scene, &o, NULL);
    if (pass) {
        double worst = worst_off(pass, 1, 1u, &covered, NULL);
        printf("sample 0 alone: %u texels, worst off the centre's signal %.3g\n", covered, worst);
        CHECK(covered > 100u && worst < 1e-6, "sample 0 alone: %u texels, %.3g off the centre's signal", covered, worst);
        dwv_image_release(pass);
    }
    o = fold_options(DWV_UV_JITTER_MIRROR, SAMPLES, 2u);
    pass = colour_pass(scene, &o, NULL);
    if (pass) {
        double apart = 0.0, worst = worst_off(pass, 1, SAMPLES, &covered, &apart);
        double against_retry = worst_off(pass, 0, SAMPLES, &covered, NULL);
        printf("mirror, %u spp: worst off its model %.3g, off the retry model %.3g (models up to %.3g apart)\n",
               SAMPLES, worst, against_retry, apart);
        CHECK(worst < TOLERANCE, "mirror: a texel %.3g off the folding rule's model", worst);
        CHECK(apart > 10.0 * TOLERANCE && against_retry > 10.0 * TOLERANCE,
              "the rules' models only %.3g apart, the bake %.3g off the retry model: the test cannot tell them", apart,
              against_retry);
        dwv_image_release(pass);
    }
    o = fold_options(DWV_UV_JITTER_RETRY, RETRY_SAMPLES, 2u);
    pass = colour_pass(scene, &o, NULL);
    if (pass) {
        double worst = worst_off(pass, 0, RETRY_SAMPLES, &covered, NULL);
        double against_fold = worst_off(pass, 1, RETRY_SAMPLES, &covered, NULL);
        printf("retry, %u spp: worst off its model %.3g, off the folding model %.3g\n", RETRY_SAMPLES, worst,
               against_fold);
        CHECK(worst < RETRY_TOLERANCE, "retry: a texel %.3g off its model", worst);
        CHECK(against_fold > 4.0 * RETRY_TOLERANCE, "retry: only %.3g off the folding model", against_fold);
        dwv_image_release(pass);
    }
}

static int same_bits(dwv_image_t *a, dwv_image_t *b)
{
    dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
    dwv_image_info(a, &ia);
    dwv_image_info(b, &ib);
    return ia.width == ib.width && ia.height == ib.height &&
           memcmp(ia.rgba, ib.rgba, 4u * ia.width * ia.height * sizeof(float)) == 0;
}

static void test_options(dwv_scene_t *scene)
{
    struct {
        int32_t rule;
        uint32_t reserved4;
        const char *named;
    } bad[] = {{2, 0u, "uv_jitter"}, {-1, 0u, "uv_jitter"}, {DWV_UV_JITTER_MIRROR, 1u, "reserved4"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        dwv_bake_options_t o = fold_options(bad[i].rule, 4u, 1u);
        o.reserved4 = bad[i].reserved4;
        dwv_image_t *image = NULL;
        dwv_result_t r = dwv_bake(scene, &o, &image);
        CHECK(r == DWV_ERROR_INVALID_ARGUMENT && image == NULL && strstr(dwv_last_error_message(), bad[i].named),
              "case %zu: result %d, message '%s'", i, (int)r, dwv_last_error_message());
        if (image) dwv_image_release(image);
    }
    /* An older header's struct: uv_jitter lies past its end (the combined images compared). */
    dwv_bake_options_t older = fold_options(DWV_UV_JITTER_MIRROR, 16u, 1u), retry = fold_options(DWV_UV_JITTER_RETRY, 16u, 1u);
    older.struct_size = (uint32_t)offsetof(dwv_bake_options_t, uv_jitter);
    dwv_image_t *a = NULL, *b = NULL, *c = NULL, *pa = colour_pass(scene, &older, &a), *pb = colour_pass(scene, &retry, &b);
    if (a && b) CHECK(same_bits(a, b) && same_bits(pa, pb), "an older options struct does not bake the retry rule");
    /* Mirror on 1 and 2 threads: the same bits; and not the retry rule's. */
    dwv_bake_options_t one = fold_options(DWV_UV_JITTER_MIRROR, 16u, 1u), two = fold_options(DWV_UV_JITTER_MIRROR, 16u, 2u);
    dwv_image_t *d = NULL, *pc = colour_pass(scene, &one, &c), *pd = colour_pass(scene, &two, &d);
    if (c && d) CHECK(same_bits(c, d) && same_bits(pc, pd), "mirror: 1 and 2 threads differ");
    if (pb && pc) CHECK(!same_bits(pb, pc), "mirror and retry bake the same colours");
    dwv_image_t *all[] = {a, b, c, d, pa, pb, pc, pd};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; ++i)
        if (all[i]) dwv_image_release(all[i]);
}

/* The scene file's bake.uv_jitter, and the partial files' options hash: a UV bake's rule changes
 * it (its partials must not merge with the other rule's), RETRY and camera bakes hash as before. */
static void test_scene_key_and_hash(void)
{
#define SCENE_HEAD                                                                                       \
    "{\"version\": 1, \"materials\": {\"m\": {\"kind\": \"diffuse\", \"subsurface_weight\": 0}},"            \
    " \"meshes\": [{\"name\": \"tri\", \"material\": \"m\", \"positions\": [0,0,0, 1,0,0, 0,1,0],"              \
    " \"indices\": [0,1,2], \"uvs\": [0,0, 1,0, 0,1]}], "
    static const char good[] = SCENE_HEAD "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"tri\", \"uv_jitter\": \"mirror\"}}";
    static const char bad[] = SCENE_HEAD "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"tri\", \"uv_jitter\": \"clamp\"}}";
#undef SCENE_HEAD
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    dwv_result_t r = dwv_scene_load_json(good, sizeof good - 1u, NULL, &scene, &o);
    CHECK(r == DWV_SUCCESS && o.uv_jitter == DWV_UV_JITTER_MIRROR, "scene file uv_jitter mirror: %d, %d, '%s'", (int)r,
          (int)o.uv_jitter, dwv_last_error_message());
    dwv_scene_release(scene);
    scene = NULL;
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    r = dwv_scene_load_json(bad, sizeof bad - 1u, NULL, &scene, &o);
    CHECK(r != DWV_SUCCESS && !scene && strstr(dwv_last_error_message(), "bake.uv_jitter"),
          "scene file uv_jitter clamp: %d, '%s'", (int)r, dwv_last_error_message());
    dwv_scene_release(scene);

    dwv_bake_options_t retry = fold_options(DWV_UV_JITTER_RETRY, 16u, 1u), mirror = fold_options(DWV_UV_JITTER_MIRROR, 16u, 1u);
    CHECK(dwv_options_hash(&retry) != dwv_options_hash(&mirror), "a UV bake's rule does not change the options hash");
    retry.target = mirror.target = DWV_BAKE_CAMERA;
    CHECK(dwv_options_hash(&retry) == dwv_options_hash(&mirror), "the rule changes a camera bake's options hash");
}

int main(void)
{
    test_mirror_repeat();
    test_fold_inside();
    dwv_scene_t *scene = quad_scene();
    test_bake_distribution(scene);
    test_options(scene);
    dwv_scene_release(scene);
    test_scene_key_and_hash();
    return check_report("test_uv_fold");
}
