/* Hostile meshes through the public API and through scene files: open meshes, zero-area and
 * duplicate triangles, flipped windings and inward normals, non-finite vertices, huge and tiny
 * coordinates, absurd UVs. Required of each (capi/dwivedi.h, dwv_scene_add_mesh and
 * dwv_bake_stats_t.warnings):
 *   - what the C API cannot represent (a NaN or infinite position, normal or UV) is refused with
 *     DWV_ERROR_INVALID_ARGUMENT and a message, and the scene stays usable;
 *   - everything else is accepted, and the bake (camera, and UV where the mesh has UVs) finishes,
 *     with every pixel, variance and statistic finite, and the degenerate geometry it met counted
 *     in the stats' warnings;
 *   - the bake ends: every walk is capped (max_events), which bounds its work; the seconds each
 *     case took are printed (never asserted: the machine is shared).
 * Public API only. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api_checks.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

static dwv_material_t wax(void)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.subsurface_color[0] = 0.9;
    m.subsurface_color[1] = 0.8;
    m.subsurface_color[2] = 0.7;
    m.subsurface_scale = 0.2;
    return m;
}

/* A mesh from plain arrays (owned by the caller), with optional normals and UVs. */
static dwv_mesh_t mesh_of(const test_mesh *m, const float *normals, uint32_t material_id)
{
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = m->vertex_count;
    mesh.triangle_count = m->triangle_count;
    mesh.positions = m->positions;
    mesh.indices = m->indices;
    mesh.normals = normals;
    mesh.uvs = m->uvs;
    mesh.material_id = material_id;
    return mesh;
}

/* Pixels, variances and statistics all finite; alpha in [0, 1]; returns the stats. */
static dwv_bake_stats_t check_image(const dwv_image_t *image, const char *what)
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
    CHECK(dwv_image_info(image, &info) == DWV_SUCCESS && dwv_image_stats(image, &st) == DWV_SUCCESS, "%s: info",
          what);
    size_t n = (size_t)info.width * info.height, bad = 0, bad_alpha = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c) bad += !isfinite(info.rgba[4 * i + c]);
        for (int c = 0; c < 3; ++c) bad += !isfinite(info.variance[3 * i + c]) || info.variance[3 * i + c] < 0.0f;
        bad_alpha += !(info.rgba[4 * i + 3] >= 0.0f && info.rgba[4 * i + 3] <= 1.0f);
    }
    CHECK(bad == 0, "%s: %zu non-finite or negative values among %zu pixels", what, bad, n);
    CHECK(bad_alpha == 0, "%s: %zu alphas outside [0, 1]", what, bad_alpha);
    int finite = isfinite(st.seconds) && !isnan(st.estimated_relative_error);
    for (int c = 0; c < 3; ++c) finite &= isfinite(st.mean_rgb[c]) && isfinite(st.truncated_weight[c]);
    CHECK(finite, "%s: stats mean %g %g %g truncated %g error %g", what, st.mean_rgb[0], st.mean_rgb[1],
          st.mean_rgb[2], st.truncated_weight[0], st.estimated_relative_error);
    return st;
}

/* The mean red of the last camera bake (bake_both). */
static double last_camera_mean;

/* Commits `scene` (with a white world and the camera given), bakes it from the camera and, when
 * uv_mesh is not UINT32_MAX, in that mesh's UVs; checks the images; returns the camera bake's
 * warnings plus the UV bake's. */
static uint64_t bake_both(dwv_scene_t *scene, dwv_camera_t camera, uint32_t uv_mesh, const char *what)
{
    double white[3] = {1.0, 1.0, 1.0};
    uint64_t warnings = 0;
    CHECK(dwv_scene_set_world(scene, white, 1.0) == DWV_SUCCESS, "%s: world: %s", what, dwv_last_error_message());
    CHECK(dwv_scene_set_camera(scene, &camera) == DWV_SUCCESS, "%s: camera: %s", what, dwv_last_error_message());
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "%s: commit: %s", what, dwv_last_error_message());
    for (int uv = 0; uv < (uv_mesh == UINT32_MAX ? 1 : 2); ++uv) {
        dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
        o.target = uv ? DWV_BAKE_UV : DWV_BAKE_CAMERA;
        o.uv_mesh = uv ? uv_mesh : 0u;
        o.uv_margin = 2u;
        o.width = o.height = 16u;
        o.samples = 4u;
        o.threads = 2u;
        o.max_events = 20000u; /* the bound on each walk's work */
        dwv_image_t *image = NULL;
        dwv_result_t rc = dwv_bake(scene, &o, &image);
        CHECK(rc == DWV_SUCCESS && image != NULL, "%s (%s): bake: %s", what, uv ? "uv" : "camera",
              dwv_last_error_message());
        if (!image) continue;
        char label[160];
        snprintf(label, sizeof label, "%s (%s)", what, uv ? "uv" : "camera");
        dwv_bake_stats_t st = check_image(image, label);
        printf("%-58s %6llu warnings %9llu events %7.2f s\n", label, (unsigned long long)st.warnings,
               (unsigned long long)st.events, st.seconds);
        warnings += st.warnings;
        if (!uv) last_camera_mean = st.mean_rgb[0];
        dwv_image_release(image);
    }
    return warnings;
}

static dwv_scene_t *new_scene(uint32_t *material_id)
{
    dwv_scene_t *scene = NULL;
    dwv_material_t m = wax();
    if (dwv_scene_create(&scene) != DWV_SUCCESS || dwv_scene_add_material(scene, &m, material_id) != DWV_SUCCESS) {
        fprintf(stderr, "scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static uint32_t add(dwv_scene_t *scene, const dwv_mesh_t *mesh, const char *what)
{
    uint32_t id = UINT32_MAX;
    CHECK(dwv_scene_add_mesh(scene, mesh, &id) == DWV_SUCCESS, "%s: add_mesh: %s", what, dwv_last_error_message());
    return id;
}

/* ---- open meshes ----------------------------------------------------------------------------- */

static void test_open(void)
{
    uint32_t mat;
    /* One triangle facing the camera: every walk's probe meets nothing (counted), nothing exits. */
    dwv_scene_t *scene = new_scene(&mat);
    float positions[9] = {-1.0f, -1.0f, 0.0f, 1.0f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    uint32_t indices[3] = {0, 1, 2};
    float uvs[6] = {0.1f, 0.1f, 0.9f, 0.1f, 0.5f, 0.9f};
    test_mesh single = {3u, 1u, positions, indices, uvs};
    dwv_mesh_t mesh = mesh_of(&single, NULL, mat);
    uint32_t id = add(scene, &mesh, "single triangle");
    uint64_t w = bake_both(scene, test_ortho_camera(0.0, 0.0, 5.0, 2.5), id, "open: one triangle");
    CHECK(w > 0, "open: one triangle: the probes that met nothing were not counted");
    dwv_scene_release(scene);

    /* A sphere with its top cap cut off (the camera looks into it through the hole). */
    scene = new_scene(&mat);
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24);
    uint32_t kept = 0;
    for (uint32_t t = 0; t < sphere.triangle_count; ++t) {
        const uint32_t *tri = sphere.indices + 3u * t;
        int top = sphere.positions[3u * tri[0] + 2u] > 0.7f && sphere.positions[3u * tri[1] + 2u] > 0.7f &&
                  sphere.positions[3u * tri[2] + 2u] > 0.7f;
        if (!top) memmove(sphere.indices + 3u * kept++, tri, 3u * sizeof *tri);
    }
    CHECK(kept < sphere.triangle_count, "the cap is cut");
    sphere.triangle_count = kept;
    mesh = mesh_of(&sphere, NULL, mat);
    add(scene, &mesh, "cut sphere");
    w = bake_both(scene, test_ortho_camera(0.0, 0.0, 5.0, 2.5), UINT32_MAX, "open: sphere without its cap");
    CHECK(w > 0, "open: sphere without its cap: nothing counted");
    test_mesh_free(&sphere);
    dwv_scene_release(scene);
}

/* ---- degenerate and duplicate triangles ------------------------------------------------------ */

static void test_degenerate(void)
{
    uint32_t mat;
    /* A box plus 5 zero-area triangles: a repeated corner, three equal corners, collinear corners,
     * and two far outside (collinear along the camera's view). */
    dwv_scene_t *scene = new_scene(&mat);
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    uint32_t nt = box.triangle_count + 5u, nv = box.vertex_count + 4u;
    float *positions = malloc(3u * nv * sizeof *positions);
    uint32_t *indices = malloc(3u * nt * sizeof *indices);
    float *uvs = malloc(6u * nt * sizeof *uvs);
    memcpy(positions, box.positions, 3u * box.vertex_count * sizeof *positions);
    memcpy(indices, box.indices, 3u * box.triangle_count * sizeof *indices);
    memcpy(uvs, box.uvs, 6u * box.triangle_count * sizeof *uvs);
    /* Extra vertices: the middle of the top face's diagonal, and three on the line x = y = 0. */
    const float extra[12] = {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 2.0f, 0.0f, 0.0f, 3.0f, 0.0f, 0.0f, 4.0f};
    memcpy(positions + 3u * box.vertex_count, extra, sizeof extra);
    const uint32_t bad[5][3] = {{4, 4, 5}, {7, 7, 7}, {4, 8, 7}, {9, 10, 11}, {8, 9, 10}};
    for (uint32_t t = 0; t < 5u; ++t) {
        memcpy(indices + 3u * (box.triangle_count + t), bad[t], sizeof bad[t]);
        for (int k = 0; k < 6; ++k) uvs[6u * (box.triangle_count + t) + (uint32_t)k] = 0.5f; /* zero UV area too */
    }
    test_mesh degenerate = {nv, nt, positions, indices, uvs};
    dwv_mesh_t mesh = mesh_of(&degenerate, NULL, mat);
    uint32_t id = add(scene, &mesh, "box with degenerate triangles");
    uint64_t w = bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id, "degenerate: box + 5 zero-area");
    /* The scene's count (5 per bake) is part of each bake's warnings. */
    CHECK(w >= 10u, "degenerate: %llu warnings over two bakes, expected at least 2 x 5", (unsigned long long)w);
    dwv_scene_release(scene);

    /* A mesh of zero-area triangles only: nothing to hit, the world behind; counted. */
    scene = new_scene(&mat);
    degenerate.triangle_count = 5u;
    degenerate.indices = indices + 3u * box.triangle_count;
    degenerate.uvs = uvs + 6u * box.triangle_count;
    mesh = mesh_of(&degenerate, NULL, mat);
    id = add(scene, &mesh, "only degenerate triangles");
    w = bake_both(scene, test_ortho_camera(0.0, 0.0, 8.0, 2.6), id, "degenerate: nothing but zero-area");
    CHECK(w >= 10u, "nothing but zero-area: %llu warnings", (unsigned long long)w);
    dwv_scene_release(scene);
    free(positions);
    free(indices);
    free(uvs);

    /* Every triangle twice (the same indices), and the whole box again as a second mesh in the
     * same place: walks start on one copy and meet the other at distance 0. */
    scene = new_scene(&mat);
    test_mesh twice = box;
    twice.triangle_count = 2u * box.triangle_count;
    twice.indices = malloc(3u * twice.triangle_count * sizeof *twice.indices);
    twice.uvs = malloc(6u * twice.triangle_count * sizeof *twice.uvs);
    for (int copy = 0; copy < 2; ++copy) {
        memcpy(twice.indices + 3u * box.triangle_count * (uint32_t)copy, box.indices,
               3u * box.triangle_count * sizeof *box.indices);
        memcpy(twice.uvs + 6u * box.triangle_count * (uint32_t)copy, box.uvs, 6u * box.triangle_count * sizeof *box.uvs);
    }
    mesh = mesh_of(&twice, NULL, mat);
    id = add(scene, &mesh, "duplicate triangles");
    mesh = mesh_of(&box, NULL, mat);
    add(scene, &mesh, "duplicate mesh");
    bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id, "duplicate: triangles twice, mesh twice");
    dwv_scene_release(scene);
    free(twice.indices);
    free(twice.uvs);
    test_mesh_free(&box);
}

/* ---- flipped windings and normals ------------------------------------------------------------ */

static void test_flipped(void)
{
    uint32_t mat;
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    test_mesh flipped = box;
    flipped.indices = malloc(3u * box.triangle_count * sizeof *flipped.indices);
    flipped.uvs = malloc(6u * box.triangle_count * sizeof *flipped.uvs);

    /* Inside out: every triangle clockwise seen from outside. The camera sees the backs of
     * subsurface faces: no walk is defined there (black, counted). */
    for (uint32_t t = 0; t < box.triangle_count; ++t) {
        uint32_t *i = flipped.indices + 3u * t;
        const uint32_t *j = box.indices + 3u * t;
        i[0] = j[0], i[1] = j[2], i[2] = j[1];
        const float *a = box.uvs + 6u * t;
        float *b = flipped.uvs + 6u * t;
        b[0] = a[0], b[1] = a[1], b[2] = a[4], b[3] = a[5], b[4] = a[2], b[5] = a[3];
    }
    dwv_scene_t *scene = new_scene(&mat);
    dwv_mesh_t mesh = mesh_of(&flipped, NULL, mat);
    uint32_t id = add(scene, &mesh, "inside-out box");
    uint64_t w = bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id, "flipped: inside-out box");
    CHECK(w > 0, "flipped: the backs of subsurface faces seen were not counted");
    dwv_scene_release(scene);

    /* Every other triangle flipped: half of each face inside out. */
    for (uint32_t t = 0; t < box.triangle_count; t += 2u) {
        memcpy(flipped.indices + 3u * t, box.indices + 3u * t, 3u * sizeof *box.indices);
        memcpy(flipped.uvs + 6u * t, box.uvs + 6u * t, 6u * sizeof *box.uvs);
    }
    scene = new_scene(&mat);
    mesh = mesh_of(&flipped, NULL, mat);
    id = add(scene, &mesh, "half-flipped box");
    w = bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id, "flipped: every other triangle");
    CHECK(w > 0, "flipped: half-flipped box: nothing counted");
    dwv_scene_release(scene);

    /* Right winding, but vertex normals pointing inward; then normals of length zero. */
    float normals[24];
    for (int v = 0; v < 8; ++v)
        for (int k = 0; k < 3; ++k) normals[3 * v + k] = -box.positions[3 * v + k];
    for (int variant = 0; variant < 2; ++variant) {
        if (variant) memset(normals, 0, sizeof normals);
        scene = new_scene(&mat);
        mesh = mesh_of(&box, normals, mat);
        id = add(scene, &mesh, variant ? "zero normals" : "inward normals");
        bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id,
                  variant ? "flipped: zero-length vertex normals" : "flipped: inward vertex normals");
        dwv_scene_release(scene);
    }
    free(flipped.indices);
    free(flipped.uvs);
    test_mesh_free(&box);
}

/* ---- non-finite input ------------------------------------------------------------------------ */

static void test_non_finite(void)
{
    uint32_t mat;
    dwv_scene_t *scene = new_scene(&mat);
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    float normals[24];
    for (int i = 0; i < 24; ++i) normals[i] = box.positions[i];
    static const float poison[] = {NAN, -NAN, INFINITY, -INFINITY};
    for (size_t p = 0; p < sizeof poison / sizeof poison[0]; ++p) {
        for (int field = 0; field < 3; ++field) {
            float *array = field == 0 ? box.positions : field == 1 ? normals : box.uvs;
            size_t slot = field == 2 ? 37u : 13u;
            float kept = array[slot];
            array[slot] = poison[p];
            dwv_mesh_t mesh = mesh_of(&box, normals, mat);
            uint32_t id = 12345u;
            prime_message();
            dwv_result_t rc = dwv_scene_add_mesh(scene, &mesh, &id);
            const char *name = field == 0 ? "positions" : field == 1 ? "normals" : "uvs";
            CHECK(rc == DWV_ERROR_INVALID_ARGUMENT && fresh_message_with(name) && fresh_message_with("not finite"),
                  "a %g in %s: %d '%s'", (double)poison[p], name, (int)rc, dwv_last_error_message());
            CHECK(id == 12345u, "a refused mesh got id %u", id);
            array[slot] = kept;
        }
    }
    /* The refusals left the scene as it was; now a mesh finite in object space but not in the
     * world: 1e30 x 1e10 overflows float. The transform itself is valid; the triangles touching
     * the far corner are non-finite in the world: counted, and Embree skips them. */
    test_mesh far = test_box(-1e-10, -1e-10, -1e-10, 1e-10, 1e-10, 1e-10);
    far.positions[3 * 7] = 1e30f; /* corner (x1, y1, z1) */
    dwv_mesh_t mesh = mesh_of(&far, NULL, mat);
    for (int r = 0; r < 3; ++r) mesh.transform[5 * r] = 1e10; /* a box of side 2 but for that corner */
    uint32_t id = add(scene, &mesh, "overflowing corner");
    mesh = mesh_of(&box, NULL, mat);
    for (int r = 0; r < 3; ++r) mesh.transform[4 * r + 3] = r == 0 ? 4.0 : 0.0; /* beside it */
    add(scene, &mesh, "good box");
    uint64_t w = bake_both(scene, test_ortho_camera(2.0, 0.0, 8.0, 8.0), id, "non-finite: a corner at 1e40");
    CHECK(w >= 12u, "a corner at 1e40: %llu warnings over two bakes, expected at least 2 x 6", (unsigned long long)w);
    dwv_scene_release(scene);
    test_mesh_free(&box);
    test_mesh_free(&far);
}

/* ---- huge and tiny coordinates; absurd UVs ---------------------------------------------------- */

/* A box of half-side `half` about (offset, offset, offset) of radius `radius`; its bakes must
 * count at least `warnings` (2 x 12 where Embree leaves the box out: beyond 1.844e18). */
static void scaled_box_scene(double half, double offset, double radius, uint64_t warnings, const char *what)
{
    uint32_t mat;
    dwv_scene_t *scene = NULL;
    dwv_material_t m = wax();
    for (int c = 0; c < 3; ++c) m.subsurface_radius[c] = radius;
    m.subsurface_scale = 1.0;
    CHECK(dwv_scene_create(&scene) == DWV_SUCCESS && dwv_scene_add_material(scene, &m, &mat) == DWV_SUCCESS,
          "%s: %s", what, dwv_last_error_message());
    test_mesh box = test_box(offset - half, offset - half, offset - half, offset + half, offset + half, offset + half);
    dwv_mesh_t mesh = mesh_of(&box, NULL, mat);
    uint32_t id = add(scene, &mesh, what);
    uint64_t w = bake_both(scene, test_ortho_camera(offset + 0.3 * half, offset + 0.2 * half, offset + 8.0 * half,
                                                    2.6 * half), id, what);
    CHECK(w >= warnings, "%s: %llu warnings, expected at least %llu", what, (unsigned long long)w,
          (unsigned long long)warnings);
    /* Left out: the camera sees the white world only, never a wrongly intersected box. */
    if (warnings > 0) CHECK(last_camera_mean == 1.0, "%s: camera mean %.6f, the world is 1", what, last_camera_mean);
    dwv_scene_release(scene);
    test_mesh_free(&box);
}

static void test_extreme_coordinates(void)
{
    /* Lengths only rescale: up to 2^40 the image is the same as at scale 1 (beyond about 3e12
     * Embree's float intersection overflows: such triangles are left out and counted). */
    scaled_box_scene(1.0, 0.0, 1.0, 0u, "scale 1");
    double reference = last_camera_mean;
    scaled_box_scene(1e12, 0.0, 1e12, 0u, "huge: box 1e12, radius 1e12");
    CHECK(fabs(last_camera_mean - reference) < 1e-3 * reference, "box 1e12: mean %.6f, at scale 1 %.6f",
          last_camera_mean, reference);
    scaled_box_scene(3e12, 0.0, 3e12, 24u, "huge: box 3e12 (beyond 2^40: left out)");
    scaled_box_scene(1e30, 0.0, 1e30, 24u, "huge: box 1e30, radius 1e30");
    scaled_box_scene(1e30, 0.0, 1.0, 24u, "huge: box 1e30, radius 1 (semi-infinite)");
    scaled_box_scene(1e36, 1e37, 1e36, 24u, "huge: box 1e36 at 1e37");
    scaled_box_scene(1.0, 1e7, 1.0, 0u, "huge: box 1 at 1e7 (float spacing 1)");
    scaled_box_scene(1e-30, 0.0, 1e-30, 0u, "tiny: box 1e-30");

    /* A box of 1e-6 beside one of 1e30: ray offsets follow the largest coordinate. */
    uint32_t mat;
    dwv_scene_t *scene = new_scene(&mat);
    test_mesh small = test_box(-1e-6, -1e-6, -1e-6, 1e-6, 1e-6, 1e-6);
    test_mesh big = test_box(1e29, 1e29, 1e29, 1e30, 1e30, 1e30);
    dwv_mesh_t mesh = mesh_of(&small, NULL, mat);
    uint32_t id = add(scene, &mesh, "small box");
    mesh = mesh_of(&big, NULL, mat);
    add(scene, &mesh, "big box");
    uint64_t w = bake_both(scene, test_ortho_camera(0.0, 0.0, 1e-5, 3e-6), id, "mixed: box 1e-6 beside box 1e30");
    CHECK(w >= 24u, "mixed: the box Embree leaves out was not counted (%llu)", (unsigned long long)w);
    dwv_scene_release(scene);
    test_mesh_free(&small);
    test_mesh_free(&big);

    /* UVs far outside [0, 1] and all on one point: the raster must not walk 1e30 texels. */
    for (int variant = 0; variant < 3; ++variant) {
        scene = new_scene(&mat);
        test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
        for (uint32_t i = 0; i < 6u * box.triangle_count; ++i)
            box.uvs[i] = variant == 0 ? box.uvs[i] * 1e30f : variant == 1 ? box.uvs[i] - 1e30f : 0.25f;
        mesh = mesh_of(&box, NULL, mat);
        id = add(scene, &mesh, "absurd uvs");
        bake_both(scene, test_ortho_camera(0.3, 0.2, 8.0, 2.6), id,
                  variant == 0 ? "uvs: times 1e30" : variant == 1 ? "uvs: minus 1e30" : "uvs: all one point");
        dwv_scene_release(scene);
        test_mesh_free(&box);
    }
}

/* ---- the same through scene files ------------------------------------------------------------ */

static char dir[] = "/tmp/dwivedi-hostile-meshes-XXXXXX";

static void write_text(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL, "cannot write %s", path);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

/* Loads `json` (meshes relative to the temporary folder) and bakes it from the file's camera. */
static void bake_file(const char *json, const char *what, uint64_t at_least)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    dwv_result_t rc = dwv_scene_load_json(json, strlen(json), dir, &scene, &o);
    CHECK(rc == DWV_SUCCESS, "%s: load: %s", what, dwv_last_error_message());
    if (rc != DWV_SUCCESS) return;
    o.max_events = 20000u;
    o.threads = 2u;
    dwv_image_t *image = NULL;
    rc = dwv_bake(scene, &o, &image);
    CHECK(rc == DWV_SUCCESS && image, "%s: bake: %s", what, dwv_last_error_message());
    if (image) {
        dwv_bake_stats_t st = check_image(image, what);
        printf("%-58s %6llu warnings %9llu events %7.2f s\n", what, (unsigned long long)st.warnings,
               (unsigned long long)st.events, st.seconds);
        CHECK(st.warnings >= at_least, "%s: %llu warnings, expected at least %llu", what,
              (unsigned long long)st.warnings, (unsigned long long)at_least);
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
}

static void refused_file(const char *json, const char *what, const char *keyword)
{
    dwv_scene_t *scene = (dwv_scene_t *)dir;
    prime_message();
    dwv_result_t rc = dwv_scene_load_json(json, strlen(json), dir, &scene, NULL);
    CHECK(rc != DWV_SUCCESS && scene == NULL && fresh_message_with(keyword), "%s: %d, scene %p, '%s' (wanted '%s')",
          what, (int)rc, (void *)scene, dwv_last_error_message(), keyword);
}

#define HEAD "{\"version\": 1, \"materials\": {\"m\": {\"subsurface_scale\": 0.2}}, "
#define TAIL ", \"world\": {\"color\": [1, 1, 1], \"strength\": 1}, " \
             "\"camera\": {\"kind\": \"orthographic\", \"ortho_scale\": 3, " \
             "\"transform\": {\"translate\": [0.2, 0.1, 6]}}, \"bake\": {\"width\": 16, \"height\": 16, \"samples\": 4}}"

static void test_scene_files(void)
{
    if (!mkdtemp(dir)) {
        CHECK(0, "mkdtemp");
        return;
    }
    /* An OBJ: an open box (no top), a zero-area face, a duplicated face, a flipped face. */
    write_text("hostile.obj", "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n"
                              "f 1 3 4 2\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n"
                              "f 1 1 2\nf 1 2 6\nf 2 4 8\n");
    bake_file(HEAD "\"meshes\": [{\"material\": \"m\", \"file\": \"hostile.obj\"}]" TAIL,
              "file: OBJ open, zero-area, duplicate, flipped", 1u);
    /* Inline: the same box shape with a collinear triangle and a huge one beside it. */
    bake_file(HEAD "\"meshes\": [{\"material\": \"m\", \"positions\": [-1,-1,0, 1,-1,0, 0,1,0, 2,2,0, 3,3,0],"
                   " \"indices\": [0,1,2, 2,1,0, 0,3,4, 0,0,0]},"
                   " {\"material\": \"m\", \"positions\": [1e30,0,0, 2e30,0,0, 1e30,1e30,0], \"indices\": [0,1,2]}]" TAIL,
              "file: inline one-sided, collinear, huge triangle", 2u);
    /* A transform that takes a finite vertex beyond float's range. */
    bake_file(HEAD "\"meshes\": [{\"material\": \"m\", \"positions\": [-1,-1,0, 1,-1,0, 0,1,0, 1e30,1e30,1e30],"
                   " \"indices\": [0,1,2, 0,1,3], \"transform\": {\"scale\": 1e9}}]" TAIL,
              "file: a vertex scaled to 1e39", 1u);
    /* Positions beyond float's range in the file itself, and NaN in an OBJ: refused. */
    refused_file(HEAD "\"meshes\": [{\"material\": \"m\", \"positions\": [0,0,0, 1,0,0, 0,1e39,0],"
                      " \"indices\": [0,1,2]}]" TAIL,
                 "file: a position of 1e39", "meshes[0]");
    write_text("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    refused_file(HEAD "\"meshes\": [{\"material\": \"m\", \"file\": \"inf.obj\"}]" TAIL, "file: inf in an OBJ",
                 "not finite");
    char path[256];
    snprintf(path, sizeof path, "%s/hostile.obj", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/inf.obj", dir);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    test_open();
    test_degenerate();
    test_flipped();
    test_non_finite();
    test_extreme_coordinates();
    test_scene_files();
    return check_report("test_hostile_meshes");
}
