#include "embree.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static dwvu_vec3 vertex(const dwvg_mesh *mesh, uint32_t index)
{
    const float *p = mesh->positions + 3u * (size_t)index;
    return dwvu_v(p[0], p[1], p[2]);
}

static void corners(const dwvg_mesh *mesh, uint32_t prim, dwvu_vec3 *a, dwvu_vec3 *b, dwvu_vec3 *c)
{
    const uint32_t *i = mesh->indices + 3u * (size_t)prim;
    *a = vertex(mesh, i[0]);
    *b = vertex(mesh, i[1]);
    *c = vertex(mesh, i[2]);
}

/* Embree takes ray origins and directions up to its FLT_LARGE, 1.844e18, in magnitude, and
 * asserts on (or ignores) rays beyond: such rays (a walk wandering off an open mesh, a camera far
 * out) meet nothing here without asking Embree. Triangles are kept far inside that range by
 * dwvg_mesh_init (DWVG_LARGEST_COORDINATE). */
#define EMBREE_LARGEST 1.844e18f

static int in_embree_range(float x, float y, float z)
{
    return fabsf(x) <= EMBREE_LARGEST && fabsf(y) <= EMBREE_LARGEST && fabsf(z) <= EMBREE_LARGEST;
}

static dwvu_vec3 cross(dwvu_vec3 a, dwvu_vec3 b)
{
    return dwvu_v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

dwvu_vec3 dwvg_geometric_normal(const dwvg_mesh *mesh, uint32_t prim)
{
    dwvu_vec3 a, b, c;
    corners(mesh, prim, &a, &b, &c);
    dwvu_vec3 n = cross(dwvu_sub(b, a), dwvu_sub(c, a));
    double length = dwvu_length(n);
    return length > 0.0 && isfinite(length) ? dwvu_scale(n, 1.0 / length) : dwvu_v(0.0, 0.0, 0.0);
}

double dwvg_triangle_area(const dwvg_mesh *mesh, uint32_t prim)
{
    dwvu_vec3 a, b, c;
    corners(mesh, prim, &a, &b, &c);
    double area = 0.5 * dwvu_length(cross(dwvu_sub(b, a), dwvu_sub(c, a)));
    return isfinite(area) ? area : 0.0;
}

dwvu_vec3 dwvg_point(const dwvg_mesh *mesh, uint32_t prim, double u, double v)
{
    dwvu_vec3 a, b, c;
    corners(mesh, prim, &a, &b, &c);
    return dwvu_add(a, dwvu_add(dwvu_scale(dwvu_sub(b, a), u), dwvu_scale(dwvu_sub(c, a), v)));
}

dwvu_vec3 dwvg_shading_normal(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvu_vec3 geometric)
{
    if (!mesh->normals) return geometric;
    const uint32_t *i = mesh->indices + 3u * (size_t)prim;
    const float *n0 = mesh->normals + 3u * (size_t)i[0], *n1 = mesh->normals + 3u * (size_t)i[1],
                *n2 = mesh->normals + 3u * (size_t)i[2];
    double w = 1.0 - u - v;
    dwvu_vec3 n = dwvu_v(w * n0[0] + u * n1[0] + v * n2[0], w * n0[1] + u * n1[1] + v * n2[1],
                         w * n0[2] + u * n1[2] + v * n2[2]);
    double length = dwvu_length(n);
    if (!(length > 1e-6)) return geometric;
    n = dwvu_scale(n, 1.0 / length);
    /* A shading normal on the far side of the surface would light the wrong hemisphere. */
    return dwvu_dot(n, geometric) > 0.0 ? n : geometric;
}

static void embree_error(void *user, enum RTCError code, const char *text)
{
    (void)text;
    dwvg_world *world = user;
    int expected = 0;
    atomic_compare_exchange_strong(&world->embree_error, &expected, (int)code);
}

static bool embree_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;
    dwvg_world *world = user;
    atomic_fetch_add(&world->embree_bytes, (long long)bytes);
    return true;
}

static int failed(dwvg_world *world, char *message, size_t size, const char *what)
{
    int code = atomic_load(&world->embree_error);
    if (code) snprintf(message, size, "Embree failed while %s (error %d)", what, code);
    else snprintf(message, size, "out of memory while %s", what);
    dwvg_world_free(world);
    return -1;
}

/* Sorts the n keys of `keys`, each below 2^bits, by LSD radix sort, 16 bits a pass (scratch: n
 * keys; counts: 65536); returns the array that holds them sorted (keys or scratch). The
 * closed-mesh test sorts three keys per triangle: a million triangles took qsort 0.4-0.8 s. */
static uint64_t *sort_keys(uint64_t *keys, uint64_t *scratch, size_t n, int bits, size_t *counts)
{
    for (int shift = 0; shift < bits; shift += 16) {
        memset(counts, 0, 65536 * sizeof *counts);
        for (size_t e = 0; e < n; ++e) ++counts[(keys[e] >> shift) & 0xffffu];
        size_t start = 0;
        for (size_t d = 0; d < 65536; ++d) {
            size_t count = counts[d];
            counts[d] = start;
            start += count;
        }
        for (size_t e = 0; e < n; ++e) scratch[counts[(keys[e] >> shift) & 0xffffu]++] = keys[e];
        uint64_t *swap = keys;
        keys = scratch;
        scratch = swap;
    }
    return keys;
}

int dwvg_mesh_closed(const dwvg_mesh *mesh)
{
    size_t edges = 3u * (size_t)mesh->triangle_count;
    if (edges == 0) return 0;
    uint64_t *directed = malloc(3 * edges * sizeof *directed);
    size_t *counts = malloc(65536 * sizeof *counts);
    if (!directed || !counts) {
        free(directed);
        free(counts);
        return -1;
    }
    /* An edge (from, to) as the key from * 2^b + to, b the bits of the vertex numbers: the fewer
     * the bits, the fewer the radix passes. */
    int b = 1;
    while (b < 32 && (uint64_t)mesh->vertex_count > (uint64_t)1 << b) ++b;
    uint64_t *reversed = directed + edges, *scratch = directed + 2 * edges;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        const uint32_t *i = mesh->indices + 3u * (size_t)t;
        for (int k = 0; k < 3; ++k) {
            uint64_t from = i[k], to = i[(k + 1) % 3];
            directed[3u * (size_t)t + (size_t)k] = from << b | to;
            reversed[3u * (size_t)t + (size_t)k] = to << b | from;
        }
    }
    uint64_t *sorted = sort_keys(directed, scratch, edges, 2 * b, counts);
    if (sorted == scratch) memcpy(directed, scratch, edges * sizeof *directed);
    sorted = sort_keys(reversed, scratch, edges, 2 * b, counts);
    if (sorted == scratch) memcpy(reversed, scratch, edges * sizeof *reversed);
    /* Closed: no directed edge twice, none from a vertex to itself, and each one's reverse present
     * (then, with the first, its undirected edge has exactly two triangles, one each way). With no
     * edge twice, the reverses are as many distinct edges, so "each reverse present" is "the
     * sorted reverses are the sorted edges". */
    int closed = 1;
    for (size_t e = 0; e < edges && closed; ++e) {
        uint64_t edge = directed[e];
        closed = (e + 1 == edges || directed[e + 1] != edge) && (edge >> b) != (edge & (((uint64_t)1 << b) - 1)) &&
                 reversed[e] == edge;
    }
    free(directed);
    free(counts);
    for (uint32_t t = 0; t < mesh->triangle_count && closed; ++t) closed = dwvg_triangle_area(mesh, t) > 0.0;
    return closed;
}

/* *p for a closed mesh without vertex normals whose triangles lie in at most
 * DWVG_POLYTOPE_PLANES planes (equal geometric normals and offsets, bit for bit), with every
 * vertex on or below each plane (to 2^-40 of the largest coordinate): convex. Else p->plane_count
 * stays 0. */
static void find_polytope(const dwvg_world *world, const dwvg_mesh *mesh, int closed, dwvg_polytope *p)
{
    memset(p, 0, sizeof *p);
    if (!closed || mesh->normals || mesh->triangle_count > DWVG_POLYTOPE_TRIANGLES) return;
    uint32_t plane_of[DWVG_POLYTOPE_TRIANGLES], count = 0;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        dwvu_vec3 n = dwvg_geometric_normal(mesh, t), a = vertex(mesh, mesh->indices[3u * (size_t)t]);
        if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return;
        double offset = dwvu_dot(n, a);
        uint32_t i = 0;
        while (i < count && !(p->planes[i][0] == n.x && p->planes[i][1] == n.y && p->planes[i][2] == n.z &&
                              p->planes[i][3] == offset))
            ++i;
        if (i == count) {
            if (count == DWVG_POLYTOPE_PLANES) return;
            p->planes[count][0] = n.x;
            p->planes[count][1] = n.y;
            p->planes[count][2] = n.z;
            p->planes[count][3] = offset;
            ++count;
        }
        plane_of[t] = i;
    }
    double tolerance = 0x1p-23 * world->epsilon;
    for (uint32_t i = 0; i < count; ++i)
        for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
            dwvu_vec3 n = dwvu_v(p->planes[i][0], p->planes[i][1], p->planes[i][2]);
            if (!(dwvu_dot(n, vertex(mesh, v)) - p->planes[i][3] <= tolerance)) return;
        }
    uint32_t k = 0;
    for (uint32_t i = 0; i < count; ++i) {
        p->first[i] = k;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t)
            if (plane_of[t] == i) p->triangles[k++] = t;
    }
    p->first[count] = k;
    p->plane_count = count;
}

/* world->tops (embree.h), where the world is small enough: 0, or -1 out of memory. */
static int make_tops(dwvg_world *world)
{
    double vertices = 0.0, triangles = 0.0;
    for (uint32_t m = 0; m < world->mesh_count; ++m) {
        vertices += world->meshes[m].vertex_count;
        triangles += world->meshes[m].triangle_count;
    }
    if (vertices * triangles > DWVG_TOPS_WORK) return 0;
    world->tops = calloc(world->mesh_count, sizeof *world->tops);
    if (!world->tops) return -1;
    for (uint32_t m = 0; m < world->mesh_count; ++m) {
        const dwvg_mesh *mesh = &world->meshes[m];
        world->tops[m] = malloc((mesh->triangle_count ? mesh->triangle_count : 1u) * sizeof **world->tops);
        if (!world->tops[m]) return -1;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            dwvu_vec3 n = dwvg_geometric_normal(mesh, t);
            double top = -INFINITY;
            for (uint32_t o = 0; o < world->mesh_count && top < INFINITY; ++o)
                for (uint32_t v = 0; v < world->meshes[o].vertex_count; ++v) {
                    /* A non-finite vertex (Embree skips its triangles) counts as unbounded. */
                    double h = dwvu_dot(n, vertex(&world->meshes[o], v));
                    top = h > top ? h : isnan(h) ? INFINITY : top;
                }
            world->tops[m][t] = n.x == 0.0 && n.y == 0.0 && n.z == 0.0 ? INFINITY : top;
        }
    }
    return 0;
}

int dwvg_world_build(dwvg_world *world, const dwvg_mesh *meshes, uint32_t count, char *message, size_t size)
{
    memset(world, 0, sizeof *world);
    atomic_init(&world->embree_bytes, 0);
    atomic_init(&world->embree_error, 0);
    world->meshes = meshes;
    double largest = 0.0;
    for (uint32_t m = 0; m < count; ++m) {
        const dwvg_mesh *mesh = &meshes[m];
        world->triangles += mesh->triangle_count;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t)
            if (!(dwvg_triangle_area(mesh, t) > 0.0)) ++world->warnings;
        for (size_t i = 0; i < 3u * (size_t)mesh->vertex_count; ++i)
            if (isfinite(mesh->positions[i])) largest = fmax(largest, fabs((double)mesh->positions[i]));
    }
    world->epsilon = 0x1p-17 * fmax(largest, 1e-30);

    RTCDevice device = rtcNewDevice(NULL);
    if (!device) {
        snprintf(message, size, "Embree could not create a device (error %d)", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    world->device = device;
    world->leaving_filter = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) != 0;
    rtcSetDeviceErrorFunction(device, embree_error, world);
    rtcSetDeviceMemoryMonitorFunction(device, embree_memory, world);
    world->mesh_scenes = calloc(count ? count : 1u, sizeof *world->mesh_scenes);
    world->clearance = calloc(count ? count : 1u, sizeof *world->clearance);
    world->closed = calloc(count ? count : 1u, sizeof *world->closed);
    world->polytopes = calloc(count ? count : 1u, sizeof *world->polytopes);
    if (!world->mesh_scenes || !world->clearance || !world->closed || !world->polytopes)
        return failed(world, message, size, "listing the meshes");
    world->mesh_count = count;
    RTCScene top = rtcNewScene(device);
    if (!top) return failed(world, message, size, "creating the top-level scene");
    world->top = top;
    /* Robust traversal: a walk must not slip out of a closed mesh through an edge between two
     * triangles. */
    rtcSetSceneFlags(top, RTC_SCENE_FLAG_ROBUST);
    for (uint32_t m = 0; m < count; ++m) {
        const dwvg_mesh *mesh = &meshes[m];
        RTCScene scene = rtcNewScene(device);
        if (!scene) return failed(world, message, size, "creating a mesh scene");
        world->mesh_scenes[m] = scene;
        /* The context filter lets a walk's probe pass over the triangle it starts on in one ray
         * (dwvg_intersect_mesh_leaving); other rays set none, and Embree then calls nothing. */
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST |
                                    (world->leaving_filter ? RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION : 0));
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!geometry) return failed(world, message, size, "creating a triangle geometry");
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh->positions, 0,
                                   3u * sizeof(float), mesh->vertex_count);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                                   3u * sizeof(uint32_t), mesh->triangle_count);
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(scene, geometry, 0);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene);
        if (atomic_load(&world->embree_error)) return failed(world, message, size, "building a mesh's BVH");

        RTCGeometry instance = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        if (!instance) return failed(world, message, size, "creating an instance");
        rtcSetGeometryInstancedScene(instance, scene);
        static const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, identity);
        rtcCommitGeometry(instance);
        rtcAttachGeometryByID(top, instance, m);
        rtcReleaseGeometry(instance);
    }
    rtcCommitScene(top);
    if (atomic_load(&world->embree_error)) return failed(world, message, size, "building the top-level BVH");
    if (make_tops(world) < 0) return failed(world, message, size, "finding the triangles' tops");
    for (uint32_t m = 0; m < count; ++m)
    {
        if ((world->closed[m] = dwvg_mesh_closed(&meshes[m])) < 0) return failed(world, message, size, "finding closed meshes");
        find_polytope(world, &meshes[m], world->closed[m], &world->polytopes[m]);
    }
    return 0;
}

void dwvg_world_free(dwvg_world *world)
{
    if (world->mesh_scenes)
        for (uint32_t m = 0; m < world->mesh_count; ++m)
            if (world->mesh_scenes[m]) rtcReleaseScene(world->mesh_scenes[m]);
    free(world->mesh_scenes);
    if (world->clearance)
        for (uint32_t m = 0; m < world->mesh_count; ++m) dwvg_clearance_free(&world->clearance[m]);
    free(world->clearance);
    world->clearance = NULL;
    if (world->tops)
        for (uint32_t m = 0; m < world->mesh_count; ++m) free(world->tops[m]);
    free(world->tops);
    world->tops = NULL;
    free(world->closed);
    world->closed = NULL;
    free(world->polytopes);
    world->polytopes = NULL;
    if (world->top) rtcReleaseScene(world->top);
    if (world->device) rtcReleaseDevice(world->device);
    world->mesh_scenes = NULL;
    world->top = world->device = NULL;
    world->mesh_count = 0;
}

/* Fills an Embree ray; 0 if Embree could not trace it (see EMBREE_LARGEST, or a NaN bound). */
static int make_ray(struct RTCRayHit *rh, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar)
{
    rh->ray.org_x = (float)o.x;
    rh->ray.org_y = (float)o.y;
    rh->ray.org_z = (float)o.z;
    rh->ray.dir_x = (float)d.x;
    rh->ray.dir_y = (float)d.y;
    rh->ray.dir_z = (float)d.z;
    rh->ray.tnear = (float)tnear;
    rh->ray.tfar = tfar < (double)FLT_MAX ? (float)tfar : INFINITY;
    rh->ray.time = 0.0f;
    rh->ray.mask = 0xffffffffu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return in_embree_range(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z) &&
           in_embree_range(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z) && !isnan(tnear) && !isnan(tfar);
}

/* Inline: it is every walk ray's way to Embree, and GCC left it out of line once the polytopes
 * grew this file (some 170 instructions more per sphere walk). */
static inline int trace(RTCScene scene, int instanced, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar, dwvg_hit *hit)
{
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    struct RTCRayHit rh;
    if (!make_ray(&rh, o, d, tnear, tfar)) return 0;
    rtcIntersect1(scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    hit->mesh = instanced ? rh.hit.instID[0] : 0u;
    hit->prim = rh.hit.primID;
    hit->t = rh.ray.tfar;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return 1;
}

static void polytope_hit(const dwvg_world *world, uint32_t mesh, uint32_t plane, dwvu_vec3 o, dwvu_vec3 d, double t,
                         dwvg_hit *hit);
static int polytope_first(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar,
                          dwvg_hit *hit);

/* A world of one mesh traces that mesh's scene: the top-level scene would only add an instance
 * (the identity transform, which leaves a ray's floats as they are) around the same BVH. */
int dwvg_intersect(const dwvg_world *world, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar, dwvg_hit *hit)
{
    if (world->mesh_count == 0) return 0;
    if (world->mesh_count == 1 && world->polytopes[0].plane_count) return polytope_first(world, 0u, o, d, tnear, tfar, hit);
    if (world->mesh_count == 1) return trace(world->mesh_scenes[0], 0, o, d, tnear, tfar, hit);
    return trace(world->top, 1, o, d, tnear, tfar, hit);
}

static int polytope_intersect(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, double tnear,
                              double tfar, dwvg_hit *hit)
{
    const dwvg_polytope *p = &world->polytopes[mesh];
    double best = INFINITY;
    uint32_t plane = DWVG_POLYTOPE_PLANES;
    for (uint32_t i = 0; i < p->plane_count; ++i) {
        const double *q = p->planes[i];
        double rate = q[0] * d.x + q[1] * d.y + q[2] * d.z;
        if (!(rate > 0.0)) continue;
        double t = (q[3] - (q[0] * o.x + q[1] * o.y + q[2] * o.z)) / rate;
        if (t < best) {
            best = t;
            plane = i;
        }
    }
    if (plane == DWVG_POLYTOPE_PLANES) return 0; /* no plane ahead (d not finite) */
    double t = best > 0.0 ? best : 0.0;
    if (!(t >= tnear && t <= tfar)) return 0;
    polytope_hit(world, mesh, plane, o, d, t, hit);
    return 1;
}

/* The hit at distance t along d from o on plane `plane` of polytope `mesh`: the triangle of that
 * plane holding the point, the one whose least barycentric is largest. */
static void polytope_hit(const dwvg_world *world, uint32_t mesh, uint32_t plane, dwvu_vec3 o, dwvu_vec3 d, double t,
                         dwvg_hit *hit)
{
    const dwvg_polytope *p = &world->polytopes[mesh];
    const dwvg_mesh *m = &world->meshes[mesh];
    dwvu_vec3 x = dwvu_madd(o, d, t);
    double chosen = -INFINITY;
    for (uint32_t k = p->first[plane]; k < p->first[plane + 1]; ++k) {
        uint32_t prim = p->triangles[k];
        dwvu_vec3 a, b, c;
        corners(m, prim, &a, &b, &c);
        dwvu_vec3 e1 = dwvu_sub(b, a), e2 = dwvu_sub(c, a), w = dwvu_sub(x, a);
        double d11 = dwvu_dot(e1, e1), d12 = dwvu_dot(e1, e2), d22 = dwvu_dot(e2, e2);
        double w1 = dwvu_dot(w, e1), w2 = dwvu_dot(w, e2), det = d11 * d22 - d12 * d12;
        double u = (d22 * w1 - d12 * w2) / det, v = (d11 * w2 - d12 * w1) / det;
        double least = fmin(1.0 - u - v, fmin(u, v));
        if (least > chosen) {
            chosen = least;
            hit->prim = prim;
            hit->u = u;
            hit->v = v;
        }
    }
    hit->mesh = mesh;
    hit->t = t;
}

/* A ray from anywhere against a polytope: the first crossing of its surface within [tnear, tfar].
 * The line is inside between t_in, the last of the planes it enters (n.d < 0), and t_out, the
 * first it leaves (n.d > 0); it misses where t_in > t_out or it runs outside a plane it is
 * parallel to. The crossing is t_in where that is at tnear or beyond, else t_out (from inside). */
static int polytope_first(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar,
                          dwvg_hit *hit)
{
    const dwvg_polytope *p = &world->polytopes[mesh];
    double t_in = -INFINITY, t_out = INFINITY;
    uint32_t in = DWVG_POLYTOPE_PLANES, out = DWVG_POLYTOPE_PLANES;
    for (uint32_t i = 0; i < p->plane_count; ++i) {
        const double *q = p->planes[i];
        double rate = q[0] * d.x + q[1] * d.y + q[2] * d.z, gap = q[3] - (q[0] * o.x + q[1] * o.y + q[2] * o.z);
        if (rate > 0.0) {
            double t = gap / rate;
            if (t < t_out) {
                t_out = t;
                out = i;
            }
        } else if (rate < 0.0) {
            double t = gap / rate;
            if (t > t_in) {
                t_in = t;
                in = i;
            }
        } else if (!(gap >= 0.0)) {
            return 0; /* parallel outside, or not finite */
        }
    }
    if (!(t_in <= t_out)) return 0;
    uint32_t plane = t_in >= tnear ? in : out;
    double t = t_in >= tnear ? t_in : t_out;
    if (plane == DWVG_POLYTOPE_PLANES || !(t >= tnear && t <= tfar)) return 0;
    polytope_hit(world, mesh, plane, o, d, t, hit);
    return 1;
}

int dwvg_intersect_mesh(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, double tnear,
                        double tfar, dwvg_hit *hit)
{
    if (world->polytopes[mesh].plane_count) return polytope_intersect(world, mesh, o, d, tnear, tfar, hit);
    if (!trace(world->mesh_scenes[mesh], 0, o, d, tnear, tfar, hit)) return 0;
    hit->mesh = mesh;
    return 1;
}

/* An intersect context that rejects the hits on one triangle and keeps where it met them. Embree
 * hands the filter the context's address, so the context comes first. */
typedef struct leaving_context {
    struct RTCIntersectContext context;
    uint32_t prim;
    float t; /* the distance Embree found on triangle prim; +inf if none */
} leaving_context;

static void leaving_filter(const struct RTCFilterFunctionNArguments *args)
{
    /* Ray and hit 0 of Embree's structure-of-arrays layout (rtcore_ray.h's RTCHitN_primID and
     * RTCRayN_tfar, C++ only): rtcIntersect1 hands one (N = 1). */
    leaving_context *leaving = (leaving_context *)args->context;
    unsigned int n = args->N;
    if (((const unsigned int *)args->hit)[5u * n] != leaving->prim) return;
    leaving->t = ((const float *)args->ray)[8u * n];
    args->valid[0] = 0;
}

/* The loop that dwvg_intersect_mesh_leaving stands for: one ray after another, each from just
 * past the last hit on `prim`. */
static int leaving_by_rays(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, uint32_t prim, double tfar,
                           dwvg_hit *hit, uint32_t *rays)
{
    double tnear = 0.0;
    for (;;) {
        ++*rays;
        int found = dwvg_intersect_mesh(world, mesh, o, d, tnear, tfar, hit);
        if (!(found && hit->prim == prim)) return found;
        tnear = nextafterf((float)hit->t, INFINITY);
    }
}

int dwvg_intersect_mesh_leaving(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, uint32_t prim,
                                double tfar, dwvg_hit *hit, uint32_t *rays)
{
    /* A polytope's exit is never the plane o starts on, which the ray leaves downward. */
    if (world->polytopes[mesh].plane_count) {
        ++*rays;
        return polytope_intersect(world, mesh, o, d, 0.0, tfar, hit);
    }
    if (!world->leaving_filter) return leaving_by_rays(world, mesh, o, d, prim, tfar, hit, rays);
    leaving_context leaving;
    rtcInitIntersectContext(&leaving.context);
    leaving.context.filter = leaving_filter;
    leaving.prim = prim;
    leaving.t = INFINITY;
    struct RTCRayHit rh;
    ++*rays;
    if (!make_ray(&rh, o, d, 0.0, tfar)) return 0;
    rtcIntersect1(world->mesh_scenes[mesh], &leaving.context, &rh);
    int found = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    /* Another triangle met at the very distance of prim: which of the two the first of the rays
     * would have returned is up to Embree's traversal order, so they are cast. */
    if (found && rh.ray.tfar == leaving.t) return leaving_by_rays(world, mesh, o, d, prim, tfar, hit, rays);
    if (!found) return 0;
    hit->mesh = mesh;
    hit->prim = rh.hit.primID;
    hit->t = rh.ray.tfar;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return 1;
}

int dwvg_occluded(const dwvg_world *world, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar)
{
    if (world->mesh_count == 0 || !(tfar > tnear)) return 0;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    struct RTCRayHit rh;
    if (!make_ray(&rh, o, d, tnear, tfar)) return 0;
    rtcOccluded1(world->mesh_count == 1 ? world->mesh_scenes[0] : world->top, &context, &rh.ray);
    return rh.ray.tfar < 0.0f; /* Embree marks an occluded ray with tfar = -inf */
}

typedef struct closest_query {
    const dwvg_mesh *mesh;
    dwvu_vec3 p;
    dwvg_hit best;
    int found;
    int bounded;       /* the query began with a finite radius: nothing beyond it is taken */
    double degenerate; /* the distance to the nearest zero-area triangle seen */
} closest_query;

static bool closest_callback(struct RTCPointQueryFunctionArguments *args)
{
    closest_query *q = args->userPtr;
    uint32_t prim = args->primID;
    dwvu_vec3 a, b, c;
    corners(q->mesh, prim, &a, &b, &c);
    if (!(dwvg_triangle_area(q->mesh, prim) > 0.0)) {
        q->degenerate = fmin(q->degenerate, dwvg_triangle_distance(q->p, a, b, c));
        return false;
    }
    double u, v;
    dwvg_closest_on_triangle(q->p, a, b, c, &u, &v);
    dwvu_vec3 x = dwvg_point(q->mesh, prim, u, v);
    double distance = dwvu_length(dwvu_sub(x, q->p));
    /* A triangle beyond the radius is no answer once one is found, nor ever in a bounded query:
     * taking it would widen the radius after nodes within the old one were passed over, and a
     * nearer triangle in a node culled before could be missed. */
    if (!(distance < args->query->radius) && (q->found || q->bounded)) return false;
    q->best.prim = prim;
    q->best.u = u;
    q->best.v = v;
    q->best.t = distance;
    q->found = 1;
    args->query->radius = (float)distance;
    return true;
}

int dwvg_closest_mesh_clearance(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, dwvg_hit *hit, double *clearance)
{
    return dwvg_closest_mesh_within(world, mesh, p, INFINITY, hit, clearance);
}

int dwvg_closest_mesh_within(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, double within, dwvg_hit *hit,
                             double *clearance)
{
    *clearance = 0.0;
    struct RTCPointQuery query;
    if (!in_embree_range((float)p.x, (float)p.y, (float)p.z)) return 0;
    query.x = (float)p.x;
    query.y = (float)p.y;
    query.z = (float)p.z;
    query.time = 0.0f;
    /* Embree calls back for every triangle whose bounds meet the query's sphere, so a finite radius
     * spares the nodes farther away. It is rounded up past the double one, and past the float
     * centre's own rounding (at most 2^-24 of its largest coordinate). */
    int bounded = within < INFINITY;
    double largest = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
    query.radius = bounded ? (float)(within * 1.0001 + largest * 0x1p-22) : INFINITY;
    struct RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    closest_query q = {.mesh = &world->meshes[mesh], .p = p, .found = 0, .bounded = bounded, .degenerate = INFINITY};
    rtcPointQuery(world->mesh_scenes[mesh], &query, &context, closest_callback, &q);
    if (!q.found) {
        /* Nothing within `within`: that far is clear (but for a zero-area triangle seen nearer). */
        if (bounded) *clearance = fmin(within, q.degenerate);
        return 0;
    }
    *hit = q.best;
    hit->mesh = mesh;
    *clearance = fmin(q.best.t, q.degenerate);
    return 1;
}

int dwvg_closest_mesh(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, dwvg_hit *hit)
{
    double clearance;
    return dwvg_closest_mesh_clearance(world, mesh, p, hit, &clearance);
}

int dwvg_world_build_clearance(dwvg_world *world, uint32_t mesh, double cell_size, double largest_cell)
{
    return dwvg_clearance_build(&world->clearance[mesh], &world->meshes[mesh], cell_size, largest_cell) < 0 ? -1 : 0;
}
