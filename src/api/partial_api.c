/* Split bakes (capi: dwv_image_write_partial, dwv_merge_partials; docs/farm.md).
 *
 * A partial file ("DWVPART", format 2), native little-endian, written atomically:
 *   magic[8] format u32, endian u32 (0x01020304), library_version[32]
 *   u64 scene_hash, options_hash, seed, first, count, total
 *   u32 width, height, technique, features, threads, point_count
 *   u64 events, walks, warnings, rays, point_queries, ray_free_steps, ray_free_misses, mixture_terms
 *   f64 seconds, truncated_weight[3]
 *   u64 path_rays                                         (format 2 on; format 1 files are refused)
 *   point_count x {f64 seconds, f64 estimated_relative_error, u64 spp}   the chunk's own passes
 *   width x height u32 counts, then width x height x 10 i128 exact sums (dwvb_pixel_sums)
 *   u64 FNV-1a 64 of every byte before it, end[8]
 * A file of any other size, magic, end or checksum is refused. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "bake/pixel_sums.h"
#include "image_handle.h"
#include "output/atomic_file.h"
#include "partial.h"
#include "util/error.h"

_Static_assert(sizeof(dwvb_pixel_sums) == DWVB_PIXEL_SUM_FIELDS * 16u, "pixel sums have no padding");

static const char MAGIC[8] = {'D', 'W', 'V', 'P', 'A', 'R', 'T', '\0'};
static const char END[8] = {'D', 'W', 'V', 'E', 'N', 'D', '\0', '\0'};
#define FORMAT 2u
#define ENDIAN 0x01020304u
#define VERSION_BYTES 32u
#define MAX_POINTS 4096u
#define MAX_SIDE 16384u
#define MAX_PIXELS (1u << 26)
#define MAX_SAMPLES (1ull << 24)

typedef struct fnv {
    uint64_t h;
} fnv;

static void fnv_add(fnv *f, const void *data, size_t size)
{
    const unsigned char *p = data;
    uint64_t h = f->h;
    for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    f->h = h;
}

#define FNV_INIT {0xcbf29ce484222325ull}
#define ADD(f, x) fnv_add((f), &(x), sizeof(x))

/* The hash must cover everything of a scene that changes the image: a field added to one of these
 * and not hashed lets chunks of two different scenes merge. These sizes (LP64) make such an
 * addition fail to compile here until the field is added below (or said to change no image). */
_Static_assert(sizeof(dwv_material_t) == 192, "a new dwv_material_t field: hash it in dwv_scene_hash");
_Static_assert(sizeof(dwv_light_desc_t) == 248, "a new dwv_light_desc_t field: hash it in dwv_scene_hash");
_Static_assert(sizeof(dwv_camera_t) == 128, "a new dwv_camera_t field: hash it in dwv_scene_hash");
_Static_assert(sizeof(dwvb_texture) == 64, "a new dwvb_texture field: hash it in dwv_scene_hash");
_Static_assert(sizeof(dwvb_binding) == 56, "a new dwvb_binding field: hash it in dwv_scene_hash");
_Static_assert(sizeof(dwvb_mesh_layers) == 32, "a new dwvb_mesh_layers field: hash it in dwv_scene_hash");

static void add_string(fnv *f, const char *text)
{
    uint8_t present = text != NULL;
    ADD(f, present);
    if (text) fnv_add(f, text, strlen(text) + 1u);
}

/* Textures, their bindings and the meshes' extra UV layers and tangents (issue 18), hashed only
 * when a scene has any: scenes without them hash as before. */
static void add_textures(fnv *f, const dwvb_scene *s)
{
    ADD(f, s->texture_count);
    for (uint32_t i = 0; i < s->texture_count; ++i) {
        const dwvb_texture *t = &s->textures[i];
        ADD(f, t->width);
        ADD(f, t->height);
        ADD(f, t->channels);
        ADD(f, t->format);
        ADD(f, t->extension);
        ADD(f, t->interpolation);
        fnv_add(f, t->texels, (size_t)t->width * t->height * dwvb_texture_texel_bytes(t));
    }
    ADD(f, s->binding_count);
    for (uint32_t i = 0; i < s->binding_count; ++i) {
        const dwvb_binding *b = &s->bindings[i];
        ADD(f, b->material_id);
        ADD(f, b->input);
        ADD(f, b->texture_id);
        ADD(f, b->invert);
        add_string(f, b->uv_layer);
        ADD(f, b->blend);
        ADD(f, b->strength);
        ADD(f, b->distance);
        ADD(f, b->bump_shadowing);
    }
    for (uint32_t i = 0; i < s->mesh_count && s->layers; ++i) {
        const dwvb_mesh_layers *l = &s->layers[i];
        ADD(f, l->count);
        size_t corner_values = 3u * (size_t)s->meshes[i].triangle_count;
        for (uint32_t k = 0; k < l->count; ++k) {
            if (k > 0 && l->uvs) fnv_add(f, l->uvs[k], 2u * corner_values * sizeof(float));
            add_string(f, l->names ? l->names[k] : NULL);
            uint8_t tangents = l->tangents && l->tangents[k];
            ADD(f, tangents);
            if (tangents) fnv_add(f, l->tangents[k], 4u * corner_values * sizeof(float));
        }
    }
}
/* 496: spec_grids (assets18) is made at commit from the materials and bindings hashed above. */
_Static_assert(sizeof(dwvb_scene) == 496, "a new dwvb_scene field: hash it in dwv_scene_hash if it changes images");

uint64_t dwv_scene_hash(const dwvb_scene *s)
{
    fnv f = FNV_INIT;
    ADD(&f, s->material_count);
    for (uint32_t i = 0; i < s->material_count; ++i) {
        const dwv_material_t *m = &s->materials[i];
        ADD(&f, m->kind);
        fnv_add(&f, m->base_color, sizeof m->base_color);
        ADD(&f, m->subsurface_weight);
        fnv_add(&f, m->subsurface_color, sizeof m->subsurface_color);
        fnv_add(&f, m->subsurface_radius, sizeof m->subsurface_radius);
        ADD(&f, m->subsurface_scale);
        ADD(&f, m->subsurface_anisotropy);
        ADD(&f, m->subsurface_ior);
        ADD(&f, m->subsurface_exit);
        ADD(&f, m->roughness);
        /* Every field that changes the image, the later ones too: chunks of scenes that differ in
         * one of them are another scene's and must never merge. */
        ADD(&f, m->subsurface_model);
        ADD(&f, m->specular_model);
        ADD(&f, m->ior);
        ADD(&f, m->specular);
        fnv_add(&f, m->specular_tint, sizeof m->specular_tint);
        ADD(&f, m->specular_multiscatter);
        ADD(&f, m->subsurface_min_footprint);
    }
    ADD(&f, s->mesh_count);
    for (uint32_t i = 0; i < s->mesh_count; ++i) {
        const dwvg_mesh *m = &s->meshes[i];
        ADD(&f, m->vertex_count);
        ADD(&f, m->triangle_count);
        ADD(&f, m->material_id);
        fnv_add(&f, m->positions, 3u * (size_t)m->vertex_count * sizeof(float));
        fnv_add(&f, m->indices, 3u * (size_t)m->triangle_count * sizeof(uint32_t));
        uint8_t has = (uint8_t)((m->normals != NULL) | (m->uvs != NULL) << 1);
        ADD(&f, has);
        if (m->normals) fnv_add(&f, m->normals, 3u * (size_t)m->vertex_count * sizeof(float));
        if (m->uvs) fnv_add(&f, m->uvs, 6u * (size_t)m->triangle_count * sizeof(float));
        ADD(&f, s->terminator_offsets[i]);
    }
    ADD(&f, s->light_count);
    for (uint32_t i = 0; i < s->light_count; ++i) {
        const dwv_light_desc_t *l = &s->lights[i];
        ADD(&f, l->kind);
        fnv_add(&f, l->color, sizeof l->color);
        ADD(&f, l->strength);
        fnv_add(&f, l->direction, sizeof l->direction);
        ADD(&f, l->angle);
        fnv_add(&f, l->position, sizeof l->position);
        ADD(&f, l->radius);
        fnv_add(&f, l->transform, sizeof l->transform);
        ADD(&f, l->size_x);
        ADD(&f, l->size_y);
        if (l->kind == DWV_LIGHT_SPOT) { /* the fields after size_y, for spot lights only: other
                                            scenes hash as before issue 18 */
            ADD(&f, l->spot_size);
            ADD(&f, l->spot_blend);
            ADD(&f, l->spot_falloff);
        }
        /* The sphere only (the disc is how every scene before it was lit: those hash as before). */
        if (l->point_shape == DWV_POINT_SHAPE_SPHERE) ADD(&f, l->point_shape);
    }
    fnv_add(&f, s->world, sizeof s->world);
    if (s->envmap) {
        const dwvl_envmap *e = s->envmap;
        ADD(&f, e->width);
        ADD(&f, e->height);
        ADD(&f, e->interpolation);
        ADD(&f, e->strength);
        fnv_add(&f, e->rotation, sizeof e->rotation);
        fnv_add(&f, e->texels, 3u * (size_t)e->width * e->height * sizeof(float));
    }
    ADD(&f, s->have_camera);
    if (s->have_camera) {
        ADD(&f, s->camera.kind);
        fnv_add(&f, s->camera.transform, sizeof s->camera.transform);
        ADD(&f, s->camera.focal_length);
        ADD(&f, s->camera.sensor_width);
        ADD(&f, s->camera.ortho_scale);
    }
    uint32_t ball = (uint32_t)s->ball_mode;
    ADD(&f, ball);
    if (s->texture_count || s->binding_count) add_textures(&f, s);
    return f.h;
}

uint64_t dwv_options_hash(const dwv_bake_options_t *o)
{
    fnv f = FNV_INIT;
    ADD(&f, o->target);
    ADD(&f, o->width);
    ADD(&f, o->height);
    ADD(&f, o->uv_mesh);
    ADD(&f, o->uv_margin);
    ADD(&f, o->technique);
    ADD(&f, o->samples);
    ADD(&f, o->max_events);
    ADD(&f, o->channel_walks);
    if (o->transparent_background) ADD(&f, o->transparent_background); /* other bakes hash as before it */
    if (o->max_bounces) { /* one-bounce bakes hash as before indirect light */
        ADD(&f, o->max_bounces);
        ADD(&f, o->diffuse_bounces);
        ADD(&f, o->glossy_bounces);
        ADD(&f, o->transmission_bounces);
        ADD(&f, o->min_light_bounces);
        ADD(&f, o->subsurface_after_diffuse);
        if (o->blur_glossy != 0.0) ADD(&f, o->blur_glossy); /* bakes without it hash as before it */
    }
    double filter_width = o->filter_width == 0.0 ? 1.0 : o->filter_width; /* 0 is one pixel */
    if (o->pixel_filter != DWV_PIXEL_FILTER_BOX || filter_width != 1.0) { /* the box of one pixel hashes as before */
        ADD(&f, o->pixel_filter);
        ADD(&f, filter_width);
    }
    /* Only UV bakes place samples by it; RETRY hashes as before it. */
    if (o->target == DWV_BAKE_UV && o->uv_jitter != DWV_UV_JITTER_RETRY) ADD(&f, o->uv_jitter);
    return f.h;
}

/* The fixed part of the file, in file order (every field 4 or 8 bytes, no padding). */
typedef struct header {
    char magic[8];
    uint32_t format, endian;
    char version[VERSION_BYTES];
    uint64_t scene_hash, options_hash, seed, first, count, total;
    uint32_t width, height, technique, features, threads, point_count;
    uint64_t events, walks, warnings, rays, point_queries, ray_free_steps, ray_free_misses, mixture_terms;
    double seconds, truncated_weight[3];
    uint64_t path_rays;
} header;
_Static_assert(sizeof(header) == 8 + 8 + VERSION_BYTES + 6 * 8 + 6 * 4 + 8 * 8 + 4 * 8 + 8, "no padding in the header");
_Static_assert(sizeof(dwv_error_point_t) == 24, "no padding in an error point");

static int write_all(dwvo_atomic_file *file, fnv *f, const void *data, size_t size)
{
    fnv_add(f, data, size);
    return dwvo_atomic_write(file, data, size);
}

dwv_result_t dwv_image_write_partial(const dwv_image_t *image, const char *path)
{
    static const char fn[] = "dwv_image_write_partial";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(dwv_check_pointer(fn, "path", path));
    const dwvb_image *img = dwv_image_object(image);
    const dwvb_partial *part = img->partial;
    if (!part)
        return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: the image is not a chunk of a split bake (bake with sample_count > 0)", fn);
    char message[600];
    dwv_result_t r = dwvo_check_output_path(path, message, sizeof message);
    if (r != DWV_SUCCESS) return dwv_fail(r, "%s: %s", fn, message);
    header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, MAGIC, sizeof MAGIC);
    h.format = FORMAT;
    h.endian = ENDIAN;
    snprintf(h.version, sizeof h.version, "%s", dwv_version_string());
    h.scene_hash = part->scene_hash;
    h.options_hash = part->options_hash;
    h.seed = part->seed;
    h.first = part->first;
    h.count = part->count;
    h.total = part->total;
    h.width = img->width;
    h.height = img->height;
    h.technique = (uint32_t)img->stats.technique;
    h.features = img->stats.features;
    h.threads = img->stats.threads;
    h.point_count = img->stats.error_vs_time_count;
    h.events = img->stats.events;
    h.walks = img->stats.walks;
    h.warnings = img->stats.warnings;
    h.rays = img->rays;
    h.point_queries = img->point_queries;
    h.ray_free_steps = img->ray_free_steps;
    h.ray_free_misses = img->ray_free_misses;
    h.mixture_terms = img->mixture_terms;
    h.seconds = img->stats.seconds;
    for (int c = 0; c < 3; ++c) h.truncated_weight[c] = img->stats.truncated_weight[c];
    h.path_rays = img->stats.path_rays;
    size_t pixels = (size_t)img->width * img->height;
    dwvo_atomic_file file;
    r = dwvo_atomic_open(&file, path, message, sizeof message);
    if (r != DWV_SUCCESS) return dwv_fail(r, "%s: %s", fn, message);
    fnv f = FNV_INIT;
    write_all(&file, &f, &h, sizeof h);
    if (h.point_count) write_all(&file, &f, img->error_vs_time, h.point_count * sizeof *img->error_vs_time);
    write_all(&file, &f, part->counts, pixels * sizeof *part->counts);
    write_all(&file, &f, part->sums, pixels * sizeof(dwvb_pixel_sums));
    uint64_t sum = f.h;
    dwvo_atomic_write(&file, &sum, sizeof sum);
    dwvo_atomic_write(&file, END, sizeof END);
    r = dwvo_atomic_commit(&file, message, sizeof message);
    if (r != DWV_SUCCESS) return dwv_fail(r, "%s: %s", fn, message);
    return DWV_SUCCESS;
}

/* One chunk read back. */
typedef struct chunk {
    const char *path;
    header h;
    dwv_error_point_t *points;
    uint32_t *counts;
    dwvb_pixel_sums *sums;
} chunk;

static void chunk_free(chunk *c)
{
    free(c->points);
    free(c->counts);
    free(c->sums);
    c->points = NULL;
    c->counts = NULL;
    c->sums = NULL;
}

/* Reads and checks chunk `path`: its header only (header_only), or all of it with the checksum. */
static dwv_result_t read_chunk(const char *fn, const char *path, chunk *c, int header_only)
{
    memset(c, 0, sizeof *c);
    c->path = path;
    FILE *in = fopen(path, "rb");
    if (!in) return dwv_fail(DWV_ERROR_IO, "%s: cannot open chunk '%s': %s", fn, path, strerror(errno));
    dwv_result_t r = DWV_SUCCESS;
    fnv f = FNV_INIT;
    long size_long = -1;
    if (fseek(in, 0, SEEK_END) == 0) size_long = ftell(in);
    if (size_long < 0 || fseek(in, 0, SEEK_SET) != 0) {
        r = dwv_fail(DWV_ERROR_IO, "%s: cannot read chunk '%s': %s", fn, path, strerror(errno));
        goto done;
    }
    uint64_t size = (uint64_t)size_long;
    if (size < sizeof c->h || fread(&c->h, sizeof c->h, 1, in) != 1 || memcmp(c->h.magic, MAGIC, sizeof MAGIC) != 0) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: '%s' is not a dwivedi partial file (no DWVPART header)", fn, path);
        goto done;
    }
    fnv_add(&f, &c->h, sizeof c->h);
    const header *h = &c->h;
    if (h->format != FORMAT || h->endian != ENDIAN) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s' has format %u (byte order 0x%08x); this library reads format %u here",
                     fn, path, h->format, h->endian, FORMAT);
        goto done;
    }
    if (memchr(h->version, '\0', sizeof h->version) == NULL || h->width < 1u || h->height < 1u ||
        h->width > MAX_SIDE || h->height > MAX_SIDE || (uint64_t)h->width * h->height > MAX_PIXELS ||
        h->point_count > MAX_POINTS || h->total < 1u || h->total > MAX_SAMPLES || h->count < 1u ||
        h->first >= h->total || h->count > h->total - h->first) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s' has an impossible header (size, range or counts)", fn, path);
        goto done;
    }
    size_t pixels = (size_t)h->width * h->height;
    uint64_t expected = sizeof *h + (uint64_t)h->point_count * sizeof(dwv_error_point_t) +
                        (uint64_t)pixels * (sizeof(uint32_t) + sizeof(dwvb_pixel_sums)) + 16u;
    if (size != expected) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s' is %s: %llu bytes where its header says %llu", fn,
                     path, size < expected ? "truncated" : "too long", (unsigned long long)size,
                     (unsigned long long)expected);
        goto done;
    }
    if (header_only) goto done;
    c->points = malloc((h->point_count ? h->point_count : 1u) * sizeof *c->points);
    c->counts = malloc(pixels * sizeof *c->counts);
    c->sums = malloc(pixels * sizeof *c->sums);
    if (!c->points || !c->counts || !c->sums) {
        r = dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory reading chunk '%s'", fn, path);
        goto done;
    }
    uint64_t sum;
    char end[8];
    if ((h->point_count && fread(c->points, sizeof *c->points, h->point_count, in) != h->point_count) ||
        fread(c->counts, sizeof *c->counts, pixels, in) != pixels || fread(c->sums, sizeof *c->sums, pixels, in) != pixels ||
        fread(&sum, sizeof sum, 1, in) != 1 || fread(end, sizeof end, 1, in) != 1) {
        r = dwv_fail(DWV_ERROR_IO, "%s: cannot read chunk '%s' (truncated while reading)", fn, path);
        goto done;
    }
    fnv_add(&f, c->points, h->point_count * sizeof *c->points);
    fnv_add(&f, c->counts, pixels * sizeof *c->counts);
    fnv_add(&f, c->sums, pixels * sizeof *c->sums);
    if (memcmp(end, END, sizeof END) != 0 || sum != f.h) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s' is corrupt (checksum or end mark wrong)", fn, path);
        goto done;
    }
    for (size_t i = 0; i < pixels; ++i) {
        if (c->counts[i] != h->count) {
            r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s': pixel %zu has %u samples, its range %llu", fn,
                         path, i, c->counts[i], (unsigned long long)h->count);
            goto done;
        }
    }
done:
    fclose(in);
    if (r != DWV_SUCCESS) chunk_free(c);
    return r;
}

static int by_first(const void *a, const void *b)
{
    const chunk *x = a, *y = b;
    if (x->h.first != y->h.first) return x->h.first < y->h.first ? -1 : 1;
    return x->h.count < y->h.count ? -1 : x->h.count > y->h.count;
}

/* Whether two chunks come from the same bake; else fails naming `b`. */
static dwv_result_t same_bake(const char *fn, const chunk *a, const chunk *b)
{
    const char *what = NULL;
    if (strcmp(a->h.version, b->h.version) != 0) what = "another library version";
    else if (a->h.scene_hash != b->h.scene_hash) what = "another scene";
    else if (a->h.seed != b->h.seed) what = "another seed";
    else if (a->h.options_hash != b->h.options_hash || a->h.width != b->h.width || a->h.height != b->h.height ||
             a->h.total != b->h.total || a->h.technique != b->h.technique)
        what = "other options";
    if (!what) return DWV_SUCCESS;
    return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                    "%s: chunk '%s' is foreign: %s than '%s' (library %s / %s, scene %016llx / %016llx, seed %llu / %llu, "
                    "options %016llx / %016llx)",
                    fn, b->path, what, a->path, b->h.version, a->h.version, (unsigned long long)b->h.scene_hash,
                    (unsigned long long)a->h.scene_hash, (unsigned long long)b->h.seed, (unsigned long long)a->h.seed,
                    (unsigned long long)b->h.options_hash, (unsigned long long)a->h.options_hash);
}

dwv_result_t dwv_merge_partials(const char *const *paths, uint32_t count, dwv_image_t **image)
{
    static const char fn[] = "dwv_merge_partials";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    *image = NULL;
    DWV_TRY(dwv_check_pointer(fn, "paths", paths));
    if (count < 1u || count > (1u << 24))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: count = %u chunks: 1 to 2^24", fn, count);
    for (uint32_t k = 0; k < count; ++k)
        if (!paths[k]) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: paths[%u] is NULL", fn, k);
    chunk *chunks = calloc(count, sizeof *chunks);
    if (!chunks) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    dwv_result_t r = DWV_SUCCESS;
    uint32_t read = 0;
    dwvb_image *img = NULL;
    dwvb_pixel_sums *sums = NULL;
    uint32_t *counts = NULL;
    /* First the headers of all (the ranges and the bake they come from), then each chunk in turn,
     * whole and checksummed, added and freed: memory for one chunk and the sums, not for all. */
    for (; read < count; ++read) {
        if ((r = read_chunk(fn, paths[read], &chunks[read], 1)) != DWV_SUCCESS) goto done;
        if (read > 0 && (r = same_bake(fn, &chunks[0], &chunks[read])) != DWV_SUCCESS) {
            chunk_free(&chunks[read]);
            goto done;
        }
    }
    qsort(chunks, count, sizeof *chunks, by_first);
    uint64_t next = 0;
    for (uint32_t k = 0; k < count; ++k) {
        const header *h = &chunks[k].h;
        if (h->first > next) {
            r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: samples %llu to %llu are missing (no chunk before '%s', which starts at %llu)",
                         fn, (unsigned long long)next, (unsigned long long)h->first - 1u, chunks[k].path,
                         (unsigned long long)h->first);
            goto done;
        }
        if (h->first < next) {
            const chunk *prev = &chunks[k - 1u];
            int duplicate = prev->h.first == h->first && prev->h.count == h->count;
            r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: chunk '%s' (samples %llu:%llu) %s '%s' (samples %llu:%llu)", fn,
                         chunks[k].path, (unsigned long long)h->first, (unsigned long long)h->count,
                         duplicate ? "duplicates" : "overlaps", prev->path, (unsigned long long)prev->h.first,
                         (unsigned long long)prev->h.count);
            goto done;
        }
        next = h->first + h->count;
    }
    const header *h0 = &chunks[0].h;
    if (next != h0->total) {
        r = dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: samples %llu to %llu of %llu are missing (after '%s')", fn,
                     (unsigned long long)next, (unsigned long long)h0->total - 1u, (unsigned long long)h0->total,
                     chunks[count - 1u].path);
        goto done;
    }
    size_t pixels = (size_t)h0->width * h0->height;
    img = dwvb_image_new(h0->width, h0->height);
    sums = calloc(pixels, sizeof *sums);
    counts = calloc(pixels, sizeof *counts);
    if (!img || !sums || !counts) {
        r = dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory for a %u x %u merge", fn, h0->width, h0->height);
        goto done;
    }
    dwvb_sums_view view = {h0->width, h0->height, NULL, sums, counts};
    double seconds = 0.0, truncated[3] = {0.0, 0.0, 0.0};
    dwv_bake_stats_t *st = &img->stats;
    for (uint32_t k = 0; k < count; ++k) {
        chunk *c = &chunks[k];
        header expected = c->h;
        if ((r = read_chunk(fn, c->path, c, 0)) != DWV_SUCCESS) goto done;
        if (memcmp(&expected, &c->h, sizeof expected) != 0) {
            r = dwv_fail(DWV_ERROR_IO, "%s: chunk '%s' changed while it was merged", fn, c->path);
            goto done;
        }
        for (size_t i = 0; i < pixels; ++i) {
            counts[i] += c->counts[i];
            dwvb_pixel_sums *p = &sums[i];
            const dwvb_pixel_sums *q = &c->sums[i];
            for (int j = 0; j < 3; ++j) {
                p->sum[j] += q->sum[j];
                p->sum_squares[j] += q->sum_squares[j];
            }
            p->sum_alpha += q->sum_alpha;
            p->sum_luminance_squares += q->sum_luminance_squares;
            for (unsigned j = 0; j < REPLICATES; ++j) p->replicate_luminance[j] += q->replicate_luminance[j];
        }
        seconds += c->h.seconds;
        /* The series of the whole: one point per prefix of chunks in sample order, at the seconds
         * of those chunks added up. */
        dwv_error_point_t point = {seconds, dwvb_sums_estimate_error(&view), c->h.first + c->h.count};
        if (dwvb_image_add_error_point(img, point)) {
            r = dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory for the error series", fn);
            goto done;
        }
        for (int j = 0; j < 3; ++j) truncated[j] += c->h.truncated_weight[j] * (double)c->h.count * (double)pixels;
        st->events += c->h.events;
        st->walks += c->h.walks;
        st->path_rays += c->h.path_rays;
        img->rays += c->h.rays;
        img->point_queries += c->h.point_queries;
        img->ray_free_steps += c->h.ray_free_steps;
        img->ray_free_misses += c->h.ray_free_misses;
        img->mixture_terms += c->h.mixture_terms;
        st->features |= c->h.features;
        if (c->h.threads > st->threads) st->threads = c->h.threads;
        if (c->h.warnings > st->warnings) st->warnings = c->h.warnings;
        chunk_free(c);
    }
    dwvb_sums_fill_image(&view, img);
    st->technique = (dwv_technique_t)h0->technique;
    st->seconds = seconds;
    st->estimated_relative_error = img->error_vs_time[count - 1u].estimated_relative_error;
    for (int j = 0; j < 3; ++j) st->truncated_weight[j] = st->samples ? truncated[j] / (double)st->samples : 0.0;
    *image = dwv_image_handle(img);
    img = NULL;
done:
    for (uint32_t k = 0; k < read; ++k) chunk_free(&chunks[k]);
    free(chunks);
    free(sums);
    free(counts);
    if (img) dwvb_image_free(img);
    return r;
}
