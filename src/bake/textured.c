#include "textured.h"

#include <math.h>
#include <stdlib.h>

#include "geom/embree.h"

static dwvu_vec3 cross3(dwvu_vec3 a, dwvu_vec3 b)
{
    return dwvu_v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static const dwvb_material_textures *textures_of(const dwvb_scene *scene, uint32_t mesh_id)
{
    if (!scene->material_textures) return NULL;
    const dwvb_material_textures *t = &scene->material_textures[scene->meshes[mesh_id].material_id];
    return t->count ? t : NULL;
}

int dwvb_textured_inputs(const dwvb_scene *scene, uint32_t mesh_id)
{
    const dwvb_material_textures *t = textures_of(scene, mesh_id);
    return t && t->inputs;
}

int dwvb_textured_normal_bound(const dwvb_scene *scene, uint32_t mesh_id)
{
    const dwvb_material_textures *t = textures_of(scene, mesh_id);
    return t && (t->normal_map >= 0 || t->bump >= 0);
}

int dwvb_textured_bump_shadowing(const dwvb_scene *scene, uint32_t mesh_id)
{
    const dwvb_material_textures *t = textures_of(scene, mesh_id);
    return t && (t->normal_map >= 0 || t->bump >= 0) ? t->bump_shadowing : DWV_BUMP_SHADOWING_NONE;
}

double dwvb_bump_shadowing(int mode, dwvu_vec3 n_s, dwvu_vec3 n, dwvu_vec3 light)
{
    double cos_si = dwvu_dot(n_s, light), cos_sn = dwvu_dot(n_s, n), cos_ni = dwvu_dot(n, light);
    if (mode == DWV_BUMP_SHADOWING_CONTY2019) {
        if (cos_si * cos_sn * cos_ni < 0.0) return 0.0;
        double cos_i = fabs(cos_si), cos_d = fabs(cos_sn);
        if (cos_d >= 1.0 || cos_i >= 1.0) return 1.0;
        if (cos_i < 1e-6) return 0.0;
        double alpha2 = fmin(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 1.0);
        double tan2_i = 1.0 / (cos_i * cos_i) - 1.0;
        return 2.0 / (1.0 + sqrt(1.0 + alpha2 * tan2_i));
    }
    if (mode == DWV_BUMP_SHADOWING_NONE) return 1.0;
    double denominator = cos_ni * cos_sn;
    double g = denominator != 0.0 ? cos_si / denominator : 0.0;
    if (g >= 1.0) return 1.0;
    if (!(g >= 0.0)) return 0.0;
    return g * (1.0 + g * (1.0 - g));
}

dwvu_vec3 dwvb_valid_reflection(dwvu_vec3 ng, dwvu_vec3 to_view, dwvu_vec3 n)
{
    double iz = dwvu_dot(to_view, ng);
    double t = fmin(0.9 * iz, 0.01);
    dwvu_vec3 r = dwvu_sub(dwvu_scale(n, 2.0 * dwvu_dot(n, to_view)), to_view);
    if (dwvu_dot(r, ng) >= t) return n;
    dwvu_vec3 across = dwvu_madd(n, ng, -dwvu_dot(n, ng));
    double length = dwvu_length(across);
    if (!(length > 0.0)) return ng;
    dwvu_vec3 x_axis = dwvu_scale(across, 1.0 / length);
    double ix = dwvu_dot(to_view, x_axis), ix2 = ix * ix;
    double a = ix2 + iz * iz;
    if (!(a > 0.0)) return ng;
    double root = sqrt(fmax(ix2 * (a - t * t), 0.0)), c = a + iz * t;
    double w[2] = {(c + root) / (2.0 * a), (c - root) / (2.0 * a)};
    double reflection[2];
    int valid[2];
    double xs[2], zs[2];
    for (int k = 0; k < 2; ++k) {
        valid[k] = w[k] > 1e-5 && w[k] <= 1.0 + 1e-5;
        zs[k] = sqrt(fmin(fmax(w[k], 0.0), 1.0));
        xs[k] = sqrt(fmax(1.0 - w[k], 0.0));
        /* R' . ng for the candidate: 2 (n' . I) z - Iz (squaring admitted roots below the surface). */
        reflection[k] = 2.0 * (xs[k] * ix + zs[k] * iz) * zs[k] - iz;
    }
    int pick;
    if (valid[0] && valid[1]) {
        int above0 = reflection[0] >= 1e-5, above1 = reflection[1] >= 1e-5;
        if (above0 && above1) pick = reflection[0] < reflection[1] ? 0 : 1;
        else pick = reflection[0] > reflection[1] ? 0 : 1;
    } else if (valid[0] || valid[1]) {
        pick = valid[0] ? 0 : 1;
    } else {
        return ng;
    }
    return dwvu_add(dwvu_scale(x_axis, xs[pick]), dwvu_scale(ng, zs[pick]));
}

/* The corner UVs of triangle `prim` in UV layer `layer` of the mesh (NULL if it has none). */
static const float *layer_uvs(const dwvb_scene *scene, uint32_t mesh_id, uint32_t layer, uint32_t prim)
{
    const float *uvs = layer == 0u ? scene->meshes[mesh_id].uvs : scene->layers[mesh_id].uvs[layer];
    return uvs ? uvs + 6u * (size_t)prim : NULL;
}

/* Barycentric interpolation of corner values (Embree's u weighs corner 1, v corner 2). */
static double corner_mix(const float *c, int stride, int k, double u, double v)
{
    return (1.0 - u - v) * c[k] + u * c[stride + k] + v * c[2 * stride + k];
}

/* The UV layer of the material's k-th binding on mesh `mesh_id`. */
static uint32_t binding_layer(const dwvb_scene *scene, uint32_t mesh_id, uint32_t k)
{
    return scene->binding_layers[mesh_id][k];
}

/* Mixes `value` (clamped to [lo, hi]) into `*field` by the binding's blend. */
static void apply(double *field, double value, double lo, double hi, double blend)
{
    value = fmin(fmax(value, lo), hi);
    *field = (1.0 - blend) * *field + blend * value;
}

/* Applies one binding's texture value (decoded, per channel) to the material's input. */
static void apply_binding(const dwvb_binding *b, const dwvb_texture *t, const double value[4], dwv_material_t *m)
{
    double s = dwvb_texture_scalar(t, value), w = b->blend;
    /* The specular's upper end: below 12.5 for the 3.x layer (its IOR is infinite there). */
    double specular_hi = m->specular_model == DWV_SPECULAR_PRINCIPLED_V1 ? 12.49 : 1e6;
    switch (b->input) {
    case DWV_INPUT_BASE_COLOR:
        for (int c = 0; c < 3; ++c) apply(&m->base_color[c], value[c], 0.0, 1.0, w);
        break;
    case DWV_INPUT_SUBSURFACE_COLOR:
        for (int c = 0; c < 3; ++c) apply(&m->subsurface_color[c], value[c], 0.0, 1.0, w);
        break;
    case DWV_INPUT_SUBSURFACE_RADIUS:
        for (int c = 0; c < 3; ++c) apply(&m->subsurface_radius[c], value[c], 0.0, 1e30, w);
        break;
    case DWV_INPUT_SPECULAR_TINT:
        for (int c = 0; c < 3; ++c) apply(&m->specular_tint[c], value[c], 0.0, 1.0, w);
        break;
    case DWV_INPUT_SUBSURFACE_WEIGHT: apply(&m->subsurface_weight, s, 0.0, 1.0, w); break;
    case DWV_INPUT_SUBSURFACE_SCALE: apply(&m->subsurface_scale, s, 0.0, 1e30, w); break;
    case DWV_INPUT_SUBSURFACE_ANISOTROPY: apply(&m->subsurface_anisotropy, s, -0.999, 0.999, w); break;
    case DWV_INPUT_ROUGHNESS: apply(&m->roughness, s, 0.0, 1.0, w); break;
    case DWV_INPUT_SPECULAR: apply(&m->specular, s, 0.0, specular_hi, w); break;
    default: break; /* the normal: dwvb_textured_normal */
    }
}

void dwvb_textured_material(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                            dwvb_material *out)
{
    uint32_t material_id = scene->meshes[mesh_id].material_id;
    const dwvb_material_textures *t = &scene->material_textures[material_id];
    dwv_material_t m = scene->materials[material_id];
    for (uint32_t k = 0; k < t->count; ++k) {
        const dwvb_binding *b = &scene->bindings[scene->binding_order[t->first + k]];
        if (b->input == DWV_INPUT_NORMAL_MAP || b->input == DWV_INPUT_BUMP) continue;
        const float *uv = layer_uvs(scene, mesh_id, binding_layer(scene, mesh_id, k), prim);
        double value[4];
        const dwvb_texture *texture = &scene->textures[b->texture_id];
        dwvb_texture_lookup(texture, corner_mix(uv, 2, 0, u, v), corner_mix(uv, 2, 1, u, v), value);
        apply_binding(b, texture, value, &m);
    }
    dwvb_material_init_like(out, &m, &scene->shading[material_id]);
}

void dwvb_textured_representative(const dwvb_scene *scene, uint32_t material_id, dwv_material_t *out)
{
    const dwvb_material_textures *t = &scene->material_textures[material_id];
    *out = scene->materials[material_id];
    for (uint32_t k = 0; k < t->count; ++k) {
        const dwvb_binding *b = &scene->bindings[scene->binding_order[t->first + k]];
        const dwvb_texture *texture = &scene->textures[b->texture_id];
        apply_binding(b, texture, texture->max, out);
    }
}

/* The index (in binding_order's run of the material) of binding `index`. */
static uint32_t run_position(const dwvb_material_textures *t, const dwvb_scene *scene, int32_t index)
{
    for (uint32_t k = 0; k < t->count; ++k)
        if (scene->binding_order[t->first + k] == (uint32_t)index) return k;
    return 0u;
}

/* The interpolated vertex normal at (u, v), not normalised (Cycles'
 * triangle_smooth_normal_unnormalized), where n (the unit shading normal) is that normal's
 * direction; n itself where the mesh has no vertex normals or n is the geometric normal in its
 * place (dwvg_shading_normal: a vertex normal on the far side). */
static dwvu_vec3 interpolated_normal(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvu_vec3 n)
{
    if (!mesh->normals) return n;
    const uint32_t *index = mesh->indices + 3u * (size_t)prim;
    float corners[9];
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) corners[3 * k + c] = mesh->normals[3u * (size_t)index[k] + (size_t)c];
    dwvu_vec3 r = dwvu_v(corner_mix(corners, 3, 0, u, v), corner_mix(corners, 3, 1, u, v), corner_mix(corners, 3, 2, u, v));
    return dwvu_dot(r, n) > 0.0 ? r : n;
}

/* Cycles' svm_node_normal_map, tangent space, with (x, y, z) = 2 rgb - 1, T the interpolated
 * tangent and N the interpolated vertex normal, both not normalised ("get _unnormalized_
 * interpolated normal and tangent"), B = sign (N x T), n the unit smooth normal (sd->N):
 * - Blender 3.x (bump_shadowing DWV_BUMP_SHADOWING_CHIANG2019, and NONE):
 *   M = normalize(x T + y B + z N), then normalize(n + strength (M - n)) where strength != 1;
 * - Blender 4.0+ (CHIANG2019_MAPPED, CONTY2019; Cycles d71e0f45d, "Normal Map node strength
 *   interpolation artifacts", in 4.0 to 5.2): the strength in tangent space,
 *   normalize(strength x T + strength y B + mix(1, z, min(strength, 1)) N).
 * n where the result vanishes. */
static dwvu_vec3 normal_map(const dwvb_scene *scene, uint32_t mesh_id, uint32_t layer, const dwvb_binding *b,
                            uint32_t prim, double u, double v, dwvu_vec3 n)
{
    const float *uv = layer_uvs(scene, mesh_id, layer, prim);
    const float *tangents = scene->layers[mesh_id].tangents[layer] + 12u * (size_t)prim;
    double rgb[4];
    dwvb_texture_lookup(&scene->textures[b->texture_id], corner_mix(uv, 2, 0, u, v), corner_mix(uv, 2, 1, u, v), rgb);
    dwvu_vec3 tangent = dwvu_v(corner_mix(tangents, 4, 0, u, v), corner_mix(tangents, 4, 1, u, v),
                               corner_mix(tangents, 4, 2, u, v));
    double sign = corner_mix(tangents, 4, 3, u, v);
    dwvu_vec3 normal = interpolated_normal(&scene->meshes[mesh_id], prim, u, v, n);
    dwvu_vec3 bitangent = dwvu_scale(cross3(normal, tangent), sign);
    double x = 2.0 * rgb[0] - 1.0, y = 2.0 * rgb[1] - 1.0, z = 2.0 * rgb[2] - 1.0;
    int tangent_strength = b->bump_shadowing == DWV_BUMP_SHADOWING_CHIANG2019_MAPPED ||
                           b->bump_shadowing == DWV_BUMP_SHADOWING_CONTY2019;
    if (tangent_strength) {
        x *= b->strength;
        y *= b->strength;
        z = 1.0 + (z - 1.0) * fmin(b->strength, 1.0);
    }
    dwvu_vec3 mapped = dwvu_add(dwvu_add(dwvu_scale(tangent, x), dwvu_scale(bitangent, y)), dwvu_scale(normal, z));
    double length = dwvu_length(mapped);
    if (!(length > 0.0) || !isfinite(length)) return n;
    mapped = dwvu_scale(mapped, 1.0 / length);
    if (!tangent_strength && b->strength != 1.0) {
        mapped = dwvu_madd(n, dwvu_sub(mapped, n), b->strength);
        length = dwvu_length(mapped);
        if (!(length > 0.0)) return n;
        mapped = dwvu_scale(mapped, 1.0 / length);
    }
    return mapped;
}

/* The surface gradient (world space) of a function with values f[0..2] at the corners of the
 * triangle p0, p1, p2: (df1 (e2 x N) + df2 (N x e1)) / |N|^2, e_k = p_k - p0, N = e1 x e2 (so
 * that grad . e_k = df_k). */
static dwvu_vec3 surface_gradient(dwvu_vec3 e1, dwvu_vec3 e2, double df1, double df2)
{
    dwvu_vec3 N = cross3(e1, e2);
    double n2 = dwvu_dot(N, N);
    if (!(n2 > 0.0)) return dwvu_v(0.0, 0.0, 0.0);
    return dwvu_scale(dwvu_add(dwvu_scale(cross3(e2, N), df1), dwvu_scale(cross3(N, e1), df2)), 1.0 / n2);
}

/* Cycles' svm_node_set_bump in the limit of small differentials: the height differences along
 * dP/dx and dP/dy make |det| (n - distance grad h), grad h the height's surface gradient; then
 * normalize(strength N' + (1 - strength) n). The gradient in UV is the interpolated texture's,
 * by central differences a thousandth of a texel apart. */
static dwvu_vec3 bump(const dwvb_scene *scene, uint32_t mesh_id, uint32_t layer, const dwvb_binding *b, uint32_t prim,
                      double u, double v, dwvu_vec3 n)
{
    const dwvg_mesh *mesh = &scene->meshes[mesh_id];
    const dwvb_texture *texture = &scene->textures[b->texture_id];
    const float *uv = layer_uvs(scene, mesh_id, layer, prim);
    double s = corner_mix(uv, 2, 0, u, v), t = corner_mix(uv, 2, 1, u, v);
    double hs = 1e-3 / texture->width, ht = 1e-3 / texture->height, value[4];
    dwvb_texture_lookup(texture, s + hs, t, value);
    double h_sp = dwvb_texture_scalar(texture, value);
    dwvb_texture_lookup(texture, s - hs, t, value);
    double h_sm = dwvb_texture_scalar(texture, value);
    dwvb_texture_lookup(texture, s, t + ht, value);
    double h_tp = dwvb_texture_scalar(texture, value);
    dwvb_texture_lookup(texture, s, t - ht, value);
    double h_tm = dwvb_texture_scalar(texture, value);
    double dh_ds = (h_sp - h_sm) / (2.0 * hs), dh_dt = (h_tp - h_tm) / (2.0 * ht);
    dwvu_vec3 p0 = dwvg_point(mesh, prim, 0.0, 0.0), p1 = dwvg_point(mesh, prim, 1.0, 0.0),
              p2 = dwvg_point(mesh, prim, 0.0, 1.0);
    dwvu_vec3 e1 = dwvu_sub(p1, p0), e2 = dwvu_sub(p2, p0);
    dwvu_vec3 grad_s = surface_gradient(e1, e2, uv[2] - uv[0], uv[4] - uv[0]);
    dwvu_vec3 grad_t = surface_gradient(e1, e2, uv[3] - uv[1], uv[5] - uv[1]);
    dwvu_vec3 grad = dwvu_add(dwvu_scale(grad_s, dh_ds), dwvu_scale(grad_t, dh_dt));
    double distance = b->invert ? -b->distance : b->distance;
    dwvu_vec3 bumped = dwvu_madd(n, grad, -distance);
    double length = dwvu_length(bumped);
    if (!(length > 0.0) || !isfinite(length)) return n;
    bumped = dwvu_scale(bumped, 1.0 / length);
    dwvu_vec3 mixed = dwvu_add(dwvu_scale(bumped, b->strength), dwvu_scale(n, 1.0 - b->strength));
    length = dwvu_length(mixed);
    return length > 0.0 ? dwvu_scale(mixed, 1.0 / length) : n;
}

dwvu_vec3 dwvb_textured_normal(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                               dwvu_vec3 n)
{
    const dwvb_material_textures *t = textures_of(scene, mesh_id);
    if (!t) return n;
    if (t->normal_map >= 0) {
        uint32_t layer = binding_layer(scene, mesh_id, run_position(t, scene, t->normal_map));
        n = normal_map(scene, mesh_id, layer, &scene->bindings[t->normal_map], prim, u, v, n);
    }
    if (t->bump >= 0) {
        uint32_t layer = binding_layer(scene, mesh_id, run_position(t, scene, t->bump));
        n = bump(scene, mesh_id, layer, &scene->bindings[t->bump], prim, u, v, n);
    }
    return n;
}

/* One corner of the tangent generation: the vertex, its UV and its triangle's orientation in UV
 * (the corners MikkTSpace welds share all three). */
typedef struct tangent_corner {
    uint32_t vertex;
    float s, t;
    int32_t flip;
    uint32_t corner;
} tangent_corner;

static int corner_order(const void *pa, const void *pb)
{
    const tangent_corner *a = pa, *b = pb;
    if (a->vertex != b->vertex) return a->vertex < b->vertex ? -1 : 1;
    if (a->s != b->s) return a->s < b->s ? -1 : 1;
    if (a->t != b->t) return a->t < b->t ? -1 : 1;
    if (a->flip != b->flip) return a->flip < b->flip ? -1 : 1;
    return a->corner < b->corner ? -1 : a->corner > b->corner;
}

float *dwvb_make_tangents(const dwvg_mesh *mesh, const float *uvs)
{
    size_t nt = mesh->triangle_count, corners = 3u * nt;
    float *out = calloc(4u * corners, sizeof *out);
    double *tri = malloc(6u * nt * sizeof *tri); /* per triangle: dP/ds and dP/dt */
    tangent_corner *order = malloc(corners * sizeof *order);
    if (!out || !tri || !order) {
        free(out);
        free(tri);
        free(order);
        return NULL;
    }
    for (size_t f = 0; f < nt; ++f) {
        dwvu_vec3 p0 = dwvg_point(mesh, (uint32_t)f, 0.0, 0.0), p1 = dwvg_point(mesh, (uint32_t)f, 1.0, 0.0),
                  p2 = dwvg_point(mesh, (uint32_t)f, 0.0, 1.0);
        const float *uv = uvs + 6u * f;
        double ds1 = uv[2] - uv[0], dt1 = uv[3] - uv[1], ds2 = uv[4] - uv[0], dt2 = uv[5] - uv[1];
        double det = ds1 * dt2 - ds2 * dt1;
        dwvu_vec3 e1 = dwvu_sub(p1, p0), e2 = dwvu_sub(p2, p0), ts = dwvu_v(0, 0, 0), tt = dwvu_v(0, 0, 0);
        if (det != 0.0 && isfinite(det)) {
            /* [e1 e2] = [dP/ds dP/dt] [[ds1 ds2] [dt1 dt2]], inverted. */
            ts = dwvu_scale(dwvu_sub(dwvu_scale(e1, dt2), dwvu_scale(e2, dt1)), 1.0 / det);
            tt = dwvu_scale(dwvu_sub(dwvu_scale(e2, ds1), dwvu_scale(e1, ds2)), 1.0 / det);
        }
        tri[6 * f] = ts.x, tri[6 * f + 1] = ts.y, tri[6 * f + 2] = ts.z;
        tri[6 * f + 3] = tt.x, tri[6 * f + 4] = tt.y, tri[6 * f + 5] = tt.z;
        for (int k = 0; k < 3; ++k) {
            tangent_corner c = {mesh->indices[3 * f + (size_t)k], uv[2 * k], uv[2 * k + 1], det < 0.0, (uint32_t)(3 * f + (size_t)k)};
            order[3 * f + (size_t)k] = c;
        }
    }
    qsort(order, corners, sizeof *order, corner_order);
    for (size_t first = 0; first < corners;) {
        size_t last = first;
        while (last + 1 < corners && order[last + 1].vertex == order[first].vertex && order[last + 1].s == order[first].s &&
               order[last + 1].t == order[first].t && order[last + 1].flip == order[first].flip)
            ++last;
        /* The welded corners' tangents, each weighed by its corner's angle (as MikkTSpace). */
        dwvu_vec3 ts = dwvu_v(0, 0, 0), tt = dwvu_v(0, 0, 0);
        for (size_t i = first; i <= last; ++i) {
            uint32_t f = order[i].corner / 3u, k = order[i].corner % 3u;
            /* The corner and the two after it (barycentric (u, v) of corners 0, 1, 2). */
            static const double corner_u[3] = {0.0, 1.0, 0.0}, corner_v[3] = {0.0, 0.0, 1.0};
            uint32_t ka = (k + 1u) % 3u, kb = (k + 2u) % 3u;
            dwvu_vec3 p = dwvg_point(mesh, f, corner_u[k], corner_v[k]);
            dwvu_vec3 da = dwvu_sub(dwvg_point(mesh, f, corner_u[ka], corner_v[ka]), p);
            dwvu_vec3 db = dwvu_sub(dwvg_point(mesh, f, corner_u[kb], corner_v[kb]), p);
            double la = dwvu_length(da), lb = dwvu_length(db);
            double angle = la > 0.0 && lb > 0.0 ? acos(fmin(fmax(dwvu_dot(da, db) / (la * lb), -1.0), 1.0)) : 0.0;
            ts = dwvu_madd(ts, dwvu_v(tri[6 * f], tri[6 * f + 1], tri[6 * f + 2]), angle);
            tt = dwvu_madd(tt, dwvu_v(tri[6 * f + 3], tri[6 * f + 4], tri[6 * f + 5]), angle);
        }
        for (size_t i = first; i <= last; ++i) {
            uint32_t f = order[i].corner / 3u, k = order[i].corner % 3u;
            dwvu_vec3 ng = dwvg_geometric_normal(mesh, f);
            dwvu_vec3 n = dwvg_shading_normal(mesh, f, k == 1u, k == 2u, ng);
            /* Gram-Schmidt against the corner's normal; the sign says whether dP/dt is n x T. */
            dwvu_vec3 t = dwvu_madd(ts, n, -dwvu_dot(ts, n));
            double length = dwvu_length(t);
            if (!(length > 0.0) || !isfinite(length)) {
                dwvu_frame frame = dwvu_frame_about(n);
                t = frame.t;
            } else {
                t = dwvu_scale(t, 1.0 / length);
            }
            float *o = out + 4u * order[i].corner;
            o[0] = (float)t.x, o[1] = (float)t.y, o[2] = (float)t.z;
            o[3] = dwvu_dot(cross3(n, t), tt) < 0.0 ? -1.0f : 1.0f;
        }
        first = last + 1;
    }
    free(tri);
    free(order);
    return out;
}
