/* The built-in default scene: where the choice of walk technique shows.
 *
 * Left, a thin back-lit leaf: a cupped shell 3 mm thick at its middle, about 3 to 5 mean free
 * paths (Cycles' random walk takes mean free path = radius x scale / (4 pi): the fixed-radius
 * remap of Cycles' bssrdf_setup_radius), lit by a sun from behind. Its light enters through the
 * back and must come out of the front, the face the camera sees. Classical walks and Dwivedi
 * sampling toward the entry normal (Krivanek and d'Eon 2014) both push walks back toward the
 * side they came in, so the transmitted light is rare and noisy; guiding toward the closest
 * surface point or toward the lit patches (Meng et al. 2016) or toward the opposite interface
 * (Cycles' backward guide, d'Eon and Krivanek 2020) is what finds it.
 *
 * Right, a thick front-lit wax block, 7 to 36 mean free paths across with a high albedo, lit by
 * an area light in front: light comes back out near where it entered after long walks. This is
 * the case entry-normal Dwivedi sampling was made for (it shortens the walks), and where a
 * technique tuned for thin shapes must not lose.
 *
 * Both share a grey diffuse ground (shadows, and a plain diffuse surface shaded directly) and a
 * dim bluish world, so that the leaf's front is dark except for what comes through it.
 * The resolution and samples are the CLI's default bake: a few tens of seconds on two cores. */
#include "scenefile/default_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"
#include "scenefile/transform.h"

#define PI 3.14159265358979323846

/* Default bake: 16:9; 128 samples: about 28 s of CPU (14 s on two cores) for this engine at
 * commit f7aebb7, measured on the shared build machine (64 samples: 14.3 s of CPU). */
#define DEFAULT_WIDTH 480u
#define DEFAULT_HEIGHT 270u
#define DEFAULT_SAMPLES 128u

static int allocate(dwvs_mesh_data *mesh, uint32_t vertices, uint32_t triangles)
{
    memset(mesh, 0, sizeof *mesh);
    mesh->vertex_count = vertices;
    mesh->triangle_count = triangles;
    mesh->positions = calloc((size_t)vertices * 3u, sizeof(float));
    mesh->normals = calloc((size_t)vertices * 3u, sizeof(float));
    mesh->indices = calloc((size_t)triangles * 3u, sizeof(uint32_t));
    mesh->uvs = calloc((size_t)triangles * 6u, sizeof(float));
    if (!mesh->positions || !mesh->normals || !mesh->indices || !mesh->uvs) {
        dwvs_mesh_data_free(mesh);
        return -1;
    }
    return 0;
}

/* Smooth vertex normals: the area-weighted mean of the faces around each vertex (the cross
 * product's length is twice the area, so summing unnormalised face normals weights by area). */
static void smooth_normals(dwvs_mesh_data *mesh)
{
    size_t nv = mesh->vertex_count;
    double *sum = calloc(nv * 3u, sizeof *sum);
    if (!sum) return; /* cannot happen after allocate() in practice; normals then stay as given */
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        const uint32_t *tri = mesh->indices + 3u * t;
        const float *a = mesh->positions + 3u * tri[0], *b = mesh->positions + 3u * tri[1],
                    *c = mesh->positions + 3u * tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j) sum[3u * tri[k] + j] += n[j];
    }
    for (size_t v = 0; v < nv; ++v) {
        double *n = sum + 3u * v;
        double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (length > 0.0)
            for (int j = 0; j < 3; ++j) mesh->normals[3u * v + j] = (float)(n[j] / length);
    }
    free(sum);
}

/* ---- the leaf ---------------------------------------------------------------------------------
 * A flat ellipsoid (half-axes: half width a, half height b, half thickness c) in the leaf's own
 * frame (u across, v up, w toward the viewer), so the two faces meet at a smoothly rounded rim
 * and the thickness 2 c sqrt(1 - r^2) tapers toward it; then bent about a vertical axis at
 * distance R in front, which cups it toward the viewer and keeps its thickness: the point at
 * lateral u and depth w goes to ((R - w) sin(u/R), R (1 - cos(u/R)) + w cos(u/R)). Meshed as a
 * latitude-longitude sphere whose poles are the middles of the two faces.
 * Stored with x = u, y = -w (the front faces -y), z = v. UVs: front in the left half of the
 * texture, back (mirrored, as seen from behind) in the right half. */
#define LEAF_RINGS 48u    /* latitude steps from the front pole to the back pole (even) */
#define LEAF_SEGMENTS 96u /* longitude steps around */

int dwvs_default_leaf(dwvs_mesh_data *mesh)
{
    const double a = DWVS_LEAF_HALF_WIDTH, b = DWVS_LEAF_HALF_HEIGHT, c = 0.5 * DWVS_LEAF_THICKNESS;
    const double R = DWVS_LEAF_BEND_RADIUS;
    const uint32_t rings = LEAF_RINGS, segments = LEAF_SEGMENTS;
    uint32_t vertices = 2u + (rings - 1u) * segments;
    uint32_t triangles = 2u * segments + 2u * segments * (rings - 2u);
    if (allocate(mesh, vertices, triangles)) return -1;

    /* Vertex (ring i in 1..rings-1, segment j), poles 0 (front) and vertices - 1 (back). */
    double *flat = malloc((size_t)vertices * 2u * sizeof *flat); /* (u/a, v/b) for UVs */
    if (!flat) {
        dwvs_mesh_data_free(mesh);
        return -1;
    }
    for (uint32_t k = 0; k < vertices; ++k) {
        double theta, phi;
        if (k == 0) theta = 0.0, phi = 0.0;
        else if (k == vertices - 1u) theta = PI, phi = 0.0;
        else {
            theta = PI * (double)(1u + (k - 1u) / segments) / rings;
            phi = 2.0 * PI * (double)((k - 1u) % segments) / segments;
        }
        double su = sin(theta) * cos(phi), sv = sin(theta) * sin(phi);
        double u = a * su, v = b * sv, w = c * cos(theta);
        double beta = u / R;
        double bent_u = (R - w) * sin(beta), bent_w = R * (1.0 - cos(beta)) + w * cos(beta);
        float *p = mesh->positions + 3u * k;
        p[0] = (float)bent_u;
        p[1] = (float)(-bent_w);
        p[2] = (float)v;
        flat[2u * k] = su;
        flat[2u * k + 1u] = sv;
    }

    uint32_t t = 0;
#define RING_VERTEX(i, j) (1u + ((i) - 1u) * segments + ((j) % segments))
    /* Orientation: on the ellipsoid dP/dtheta x dP/dphi points outward, and both the bend and
     * (u, v, w) -> (u, -w, v) keep handedness (positive Jacobians), so a triangle winds outward
     * when its corners go (theta, phi), (theta + dtheta, phi), (theta + dtheta, phi + dphi). */
    for (uint32_t j = 0; j < segments; ++j) {
        uint32_t *tri = mesh->indices + 3u * t++;
        tri[0] = 0u, tri[1] = RING_VERTEX(1u, j), tri[2] = RING_VERTEX(1u, j + 1u);
    }
    for (uint32_t i = 1; i + 1u < rings; ++i)
        for (uint32_t j = 0; j < segments; ++j) {
            uint32_t q00 = RING_VERTEX(i, j), q01 = RING_VERTEX(i, j + 1u), q10 = RING_VERTEX(i + 1u, j),
                     q11 = RING_VERTEX(i + 1u, j + 1u);
            uint32_t *tri = mesh->indices + 3u * t;
            tri[0] = q00, tri[1] = q10, tri[2] = q11;
            tri[3] = q00, tri[4] = q11, tri[5] = q01;
            t += 2u;
        }
    for (uint32_t j = 0; j < segments; ++j) {
        uint32_t *tri = mesh->indices + 3u * t++;
        tri[0] = vertices - 1u, tri[1] = RING_VERTEX(rings - 1u, j + 1u), tri[2] = RING_VERTEX(rings - 1u, j);
    }
#undef RING_VERTEX

    /* Per-corner UVs: a triangle belongs to the front if its rings are in the front half. */
    for (uint32_t k = 0; k < triangles; ++k) {
        const uint32_t *tri = mesh->indices + 3u * k;
        int front = k < segments || (k < segments + 2u * segments * (rings - 2u) &&
                                     (k - segments) / (2u * segments) + 1u < rings / 2u);
        for (int corner = 0; corner < 3; ++corner) {
            const double *f = flat + 2u * tri[corner];
            float *uv = mesh->uvs + 6u * k + 2u * corner;
            uv[0] = (float)(front ? 0.25 + 0.24 * f[0] : 0.75 - 0.24 * f[0]);
            uv[1] = (float)(0.5 + 0.49 * f[1]);
        }
    }
    free(flat);
    smooth_normals(mesh);
    return 0;
}

/* ---- the wax block ----------------------------------------------------------------------------
 * A rounded box, the superellipsoid |x/A|^4 + |y/B|^4 + |z/C|^4 = 1: a cube's six faces, each an
 * N x N grid, pushed onto it along rays from the centre. Grid points on shared cube edges are
 * computed from identical numbers, so they land on identical positions and are welded into one
 * vertex: the mesh is closed. Normals are the implicit surface's gradient (x^3/A^4, ...).
 * UVs: the six faces in a 3 x 2 grid of cells. */
#define BLOCK_GRID 24u

typedef struct keyed {
    float p[3];
    uint32_t index;
} keyed;

static int compare_points(const float *a, const float *b)
{
    for (int k = 0; k < 3; ++k)
        if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int compare_positions(const void *x, const void *y)
{
    const keyed *a = x, *b = y;
    int c = compare_points(a->p, b->p);
    return c ? c : (a->index < b->index ? -1 : (a->index > b->index));
}

int dwvs_default_block(dwvs_mesh_data *mesh)
{
    const double half[3] = {DWVS_BLOCK_HALF_SIZE_X, DWVS_BLOCK_HALF_SIZE_Y, DWVS_BLOCK_HALF_SIZE_Z};
    const uint32_t n = BLOCK_GRID, side = n + 1u;
    const uint32_t raw = 6u * side * side, triangles = 12u * n * n;
    keyed *points = malloc((size_t)raw * sizeof *points);
    uint32_t *remap = malloc((size_t)raw * sizeof *remap);
    dwvs_mesh_data grid;
    if (!points || !remap || allocate(&grid, raw, triangles)) {
        free(points);
        free(remap);
        return -1;
    }
    for (uint32_t face = 0; face < 6u; ++face) {
        uint32_t axis = face % 3u;
        double sign = face < 3u ? 1.0 : -1.0;
        /* Tangent axes with e_b x e_c = sign e_axis, so (i, j) increasing winds outward. */
        uint32_t b = (axis + 1u) % 3u, c = (axis + 2u) % 3u;
        if (sign < 0.0) {
            uint32_t swap = b;
            b = c;
            c = swap;
        }
        for (uint32_t i = 0; i <= n; ++i)
            for (uint32_t j = 0; j <= n; ++j) {
                double q[3];
                q[axis] = sign;
                q[b] = -1.0 + 2.0 * (double)i / n;
                q[c] = -1.0 + 2.0 * (double)j / n;
                double norm = pow(pow(q[0], 4) + pow(q[1], 4) + pow(q[2], 4), 0.25);
                uint32_t k = face * side * side + i * side + j;
                for (int d = 0; d < 3; ++d) {
                    double s = q[d] / norm; /* on the unit superellipsoid */
                    grid.positions[3u * k + d] = (float)(half[d] * s);
                }
            }
        for (uint32_t i = 0; i < n; ++i)
            for (uint32_t j = 0; j < n; ++j) {
                uint32_t base = face * side * side, q00 = base + i * side + j, q10 = q00 + side, q01 = q00 + 1u,
                         q11 = q10 + 1u;
                uint32_t t = 2u * (face * n * n + i * n + j);
                uint32_t *tri = grid.indices + 3u * t;
                tri[0] = q00, tri[1] = q10, tri[2] = q11;
                tri[3] = q00, tri[4] = q11, tri[5] = q01;
                /* cell (face % 3, face / 3) of a 3 x 2 layout, with a gap around each face */
                double u0 = (face % 3u) / 3.0 + 0.01, v0 = (face / 3u) / 2.0 + 0.01;
                double du = 1.0 / 3.0 - 0.02, dv = 0.5 - 0.02;
                const uint32_t corners[6][2] = {{i, j}, {i + 1u, j}, {i + 1u, j + 1u},
                                                {i, j}, {i + 1u, j + 1u}, {i, j + 1u}};
                for (int k = 0; k < 6; ++k) {
                    grid.uvs[6u * t + 2u * k] = (float)(u0 + du * corners[k][0] / n);
                    grid.uvs[6u * t + 2u * k + 1u] = (float)(v0 + dv * corners[k][1] / n);
                }
            }
    }
    /* Weld equal positions: sort, then number the distinct ones. */
    for (uint32_t k = 0; k < raw; ++k) {
        memcpy(points[k].p, grid.positions + 3u * k, sizeof points[k].p);
        points[k].index = k;
    }
    qsort(points, raw, sizeof *points, compare_positions);
    uint32_t distinct = 0;
    for (uint32_t k = 0; k < raw; ++k) {
        if (k == 0 || compare_points(points[k].p, points[k - 1u].p)) ++distinct;
        remap[points[k].index] = distinct - 1u;
    }
    if (allocate(mesh, distinct, triangles)) {
        free(points);
        free(remap);
        dwvs_mesh_data_free(&grid);
        return -1;
    }
    for (uint32_t k = 0; k < raw; ++k) memcpy(mesh->positions + 3u * remap[k], grid.positions + 3u * k, 3u * sizeof(float));
    for (uint32_t k = 0; k < 3u * triangles; ++k) mesh->indices[k] = remap[grid.indices[k]];
    memcpy(mesh->uvs, grid.uvs, (size_t)triangles * 6u * sizeof(float));
    for (uint32_t v = 0; v < distinct; ++v) {
        const float *p = mesh->positions + 3u * v;
        double g[3], length = 0.0;
        for (int d = 0; d < 3; ++d) {
            double s = p[d] / half[d];
            g[d] = s * s * s / half[d];
            length += g[d] * g[d];
        }
        length = sqrt(length);
        for (int d = 0; d < 3; ++d) mesh->normals[3u * v + d] = (float)(g[d] / length);
    }
    free(points);
    free(remap);
    dwvs_mesh_data_free(&grid);
    return 0;
}

/* ---- the scene ------------------------------------------------------------------------------ */

static dwv_result_t add_mesh(dwv_scene_t *scene, const dwvs_mesh_data *data, uint32_t material,
                             const double transform[12], const char *what)
{
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = data->vertex_count;
    mesh.triangle_count = data->triangle_count;
    mesh.material_id = material;
    mesh.positions = data->positions;
    mesh.indices = data->indices;
    mesh.normals = data->normals;
    mesh.uvs = data->uvs;
    memcpy(mesh.transform, transform, sizeof mesh.transform);
    uint32_t id;
    dwv_result_t r = dwv_scene_add_mesh(scene, &mesh, &id);
    if (r != DWV_SUCCESS) {
        char message[400];
        snprintf(message, sizeof message, "%s", dwv_last_error_message());
        return dwv_fail(r, "%s: %s", what, message);
    }
    return DWV_SUCCESS;
}

static dwv_result_t build(dwv_scene_t *scene)
{
    /* Materials in Cycles' terms (Principled BSDF, Random Walk (Fixed Radius)). */
    dwv_material_t leaf = DWV_MATERIAL_INIT;
    leaf.base_color[0] = 0.3, leaf.base_color[1] = 0.7, leaf.base_color[2] = 0.2;
    leaf.subsurface_color[0] = 0.3, leaf.subsurface_color[1] = 0.7, leaf.subsurface_color[2] = 0.2;
    /* radius x scale = (12, 12, 7.2) mm: mean free paths (0.95, 0.95, 0.57) mm, so the 3 mm leaf is
     * 3.1 to 5.2 of them thick: thin enough that green light comes through. */
    leaf.subsurface_radius[0] = 1.0, leaf.subsurface_radius[1] = 1.0, leaf.subsurface_radius[2] = 0.6;
    leaf.subsurface_scale = 0.012;
    leaf.subsurface_anisotropy = 0.0;
    dwv_material_t wax = DWV_MATERIAL_INIT;
    wax.base_color[0] = 0.95, wax.base_color[1] = 0.75, wax.base_color[2] = 0.5;
    wax.subsurface_color[0] = 0.95, wax.subsurface_color[1] = 0.75, wax.subsurface_color[2] = 0.5;
    /* radius x scale = (100, 50, 25) mm: mean free paths (8, 4, 2) mm against a 6 to 7 cm block:
     * red light wanders far (the glowing edges of wax), blue stays near where it entered. */
    wax.subsurface_radius[0] = 1.0, wax.subsurface_radius[1] = 0.5, wax.subsurface_radius[2] = 0.25;
    wax.subsurface_scale = 0.1;
    dwv_material_t ground = DWV_MATERIAL_INIT;
    ground.kind = DWV_MATERIAL_DIFFUSE;
    ground.base_color[0] = ground.base_color[1] = ground.base_color[2] = 0.5;
    ground.subsurface_weight = 0.0;
    uint32_t leaf_id, wax_id, ground_id;
    DWV_TRY(dwv_scene_add_material(scene, &leaf, &leaf_id));
    DWV_TRY(dwv_scene_add_material(scene, &wax, &wax_id));
    DWV_TRY(dwv_scene_add_material(scene, &ground, &ground_id));

    /* Meshes: the leaf left of centre, tilted back 12 degrees (its back toward the sun) and
     * turned a little toward the block; the block right of centre, turned 25 degrees so that two
     * of its faces and a rounded edge face the camera; a ground under both that reaches past the top of the frame. */
    dwvs_mesh_data data;
    double m[12];
    if (dwvs_default_leaf(&data)) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "no memory for the leaf");
    dwvs_transform_trs((const double[3]){-0.058, 0.0, 0.078}, (const double[3]){-12.0, 0.0, -12.0},
                        (const double[3]){1.0, 1.0, 1.0}, m);
    dwv_result_t r = add_mesh(scene, &data, leaf_id, m, "leaf");
    dwvs_mesh_data_free(&data);
    DWV_TRY(r);
    if (dwvs_default_block(&data)) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "no memory for the block");
    dwvs_transform_trs((const double[3]){0.062, 0.012, DWVS_BLOCK_HALF_SIZE_Z + 0.0005},
                        (const double[3]){0.0, 0.0, 25.0}, (const double[3]){1.0, 1.0, 1.0}, m);
    r = add_mesh(scene, &data, wax_id, m, "wax block");
    dwvs_mesh_data_free(&data);
    DWV_TRY(r);
    static const float ground_positions[12] = {-4.0f, -1.0f, 0.0f, 4.0f, -1.0f, 0.0f,
                                               4.0f,  8.0f,  0.0f, -4.0f, 8.0f, 0.0f};
    static const uint32_t ground_indices[6] = {0u, 1u, 2u, 0u, 2u, 3u};
    dwv_mesh_t plane = DWV_MESH_INIT;
    plane.vertex_count = 4u;
    plane.triangle_count = 2u;
    plane.material_id = ground_id;
    plane.positions = ground_positions;
    plane.indices = ground_indices;
    uint32_t plane_id;
    DWV_TRY(dwv_scene_add_mesh(scene, &plane, &plane_id));

    /* Lights: a warm sun from behind and above the leaf (so its light comes through the leaf
     * toward the camera), and a small, weak square area light close in front of the block and to
     * its right, aimed at it: it lights the block's faces the camera sees, and meets the leaf's
     * front only at a grazing angle and from twice as far (a quarter of the irradiance), so what
     * the leaf's front shows is mostly light that came through it. */
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.kind = DWV_LIGHT_SUN;
    sun.color[0] = 1.0, sun.color[1] = 0.95, sun.color[2] = 0.85;
    sun.strength = 4.0;
    sun.direction[0] = 0.3, sun.direction[1] = -1.0, sun.direction[2] = -0.6;
    sun.angle = 2.0 * PI / 180.0;
    DWV_TRY(dwv_scene_add_light(scene, &sun));
    dwv_light_desc_t area = DWV_LIGHT_DESC_INIT;
    area.kind = DWV_LIGHT_AREA_RECTANGLE;
    area.strength = 0.4;
    area.size_x = area.size_y = 0.12;
    if (dwvs_transform_look_at((const double[3]){0.17, -0.09, 0.13}, (const double[3]){0.062, 0.012, 0.034},
                                (const double[3]){0.0, 0.0, 1.0}, area.transform))
        return dwv_fail(DWV_ERROR_INTERNAL, "the area light's frame is degenerate");
    DWV_TRY(dwv_scene_add_light(scene, &area));

    DWV_TRY(dwv_scene_set_world(scene, (const double[3]){0.6, 0.7, 1.0}, 0.05));

    /* Camera: 50 mm lens on a 36 mm sensor, 42 cm in front and a little above, framing both. */
    dwv_camera_t camera = DWV_CAMERA_INIT;
    if (dwvs_transform_look_at((const double[3]){0.0, -0.42, 0.16}, (const double[3]){0.0, 0.0, 0.062},
                                (const double[3]){0.0, 0.0, 1.0}, camera.transform))
        return dwv_fail(DWV_ERROR_INTERNAL, "the camera's frame is degenerate");
    DWV_TRY(dwv_scene_set_camera(scene, &camera));
    return dwv_scene_commit(scene);
}

dwv_result_t dwvs_default_scene(dwv_scene_t **scene, dwv_bake_options_t *options)
{
    *scene = NULL;
    dwv_scene_t *made;
    DWV_TRY(dwv_scene_create(&made));
    dwv_result_t r = build(made);
    if (r != DWV_SUCCESS) {
        dwv_scene_release(made);
        return r;
    }
    if (options) {
        options->target = DWV_BAKE_CAMERA;
        options->width = DEFAULT_WIDTH;
        options->height = DEFAULT_HEIGHT;
        options->samples = DEFAULT_SAMPLES;
    }
    *scene = made;
    return DWV_SUCCESS;
}
