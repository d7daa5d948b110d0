/* The scene file's bake settings, checked against the ranges of dwv_bake_options_t. */
#include "scenefile/scene_json_internal.h"

#include <stdio.h>
#include <string.h>

#include "util/error.h"

/* The ranges of dwv_bake_options_t as capi/dwivedi.h states them: checked here because the bake
 * only checks them when it starts, and a file should fail where the value is written. */
#define MAX_SIDE 16384u
#define MAX_PIXELS (1u << 26)
#define MAX_SAMPLES (1u << 24)
#define MAX_THREADS 1024u
#define MAX_BOUNCES 1024u
#define MAX_MARGIN 64u

static dwv_result_t read_seed(const cJSON *item, uint64_t *seed)
{
    static const char path[] = "bake.seed";
    if (cJSON_IsString(item)) { /* all 64 bits, which a JSON number (a double) cannot carry */
        const char *s = item->valuestring;
        uint64_t v = 0;
        if (!s[0]) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "the string is empty");
        for (; *s; ++s) {
            char name[SHOWN_SIZE];
            if (*s < '0' || *s > '9')
                return dwvs_fail_at(DWV_ERROR_FORMAT, path, "'%s' is not a decimal number",
                                    dwvs_shown(item->valuestring, name));
            unsigned d = (unsigned)(*s - '0');
            if (v > (UINT64_MAX - d) / 10u)
                return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, path, "'%s' is larger than 2^64 - 1",
                                    dwvs_shown(item->valuestring, name));
            v = 10u * v + d;
        }
        *seed = v;
        return DWV_SUCCESS;
    }
    return dwvs_read_integer(item, path, 0.0, 9007199254740992.0, seed);
}

dwv_result_t dwvs_read_bake(dwvs_parser *ps, const cJSON *item)
{
    static const char *const keys[] = {"target",  "width",       "height",  "samples",   "technique",
                                       "channel_walks", "time_limit", "target_error", "seed", "threads",
                                       "max_events", "tile_size", "uv_mesh",     "uv_margin",
                                       "transparent_background", "passes", "max_bounces", "diffuse_bounces",
                                       "glossy_bounces", "transmission_bounces", "min_light_bounces",
                                       "subsurface_after_diffuse", "blur_glossy", "pixel_filter", "filter_width",
                                       "uv_jitter"};
    static const char *const after_diffuse[] = {"by_model", "lambert", "walk"};
    static const char *const targets[] = {"camera", "uv"};
    static const char *const uv_jitters[] = {"retry", "mirror"}; /* DWV_UV_JITTER_* */
    DWV_TRY(dwvs_check_keys(item, "bake", keys, sizeof keys / sizeof keys[0]));
    dwv_bake_options_t *o = &ps->options;
    const cJSON *target = dwvs_member(item, "target");
    if (target) {
        size_t t = 0;
        DWV_TRY(dwvs_read_choice(target, "bake.target", targets, 2, &t));
        o->target = t == 0 ? DWV_BAKE_CAMERA : DWV_BAKE_UV;
    }
    DWV_TRY(dwvs_opt_u32(item, "bake", "width", 1u, MAX_SIDE, &o->width));
    DWV_TRY(dwvs_opt_u32(item, "bake", "height", 1u, MAX_SIDE, &o->height));
    if ((uint64_t)o->width * o->height > MAX_PIXELS)
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, "bake", "%u x %u is more than %u pixels", o->width, o->height,
                            MAX_PIXELS);
    const cJSON *samples = dwvs_member(item, "samples");
    if (samples) DWV_TRY(dwvs_read_integer(samples, "bake.samples", 1.0, (double)MAX_SAMPLES, &o->samples));
    const cJSON *technique = dwvs_member(item, "technique");
    if (technique) {
        const char *name = NULL;
        DWV_TRY(dwvs_read_string(technique, "bake.technique", &name));
        dwv_result_t r = dwv_technique_from_name(name, &o->technique);
        if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, "bake.technique");
    }
    const cJSON *channel_walks = dwvs_member(item, "channel_walks");
    if (channel_walks) {
        const char *name = NULL;
        DWV_TRY(dwvs_read_string(channel_walks, "bake.channel_walks", &name));
        dwv_result_t r = dwv_channel_walks_from_name(name, &o->channel_walks);
        if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, "bake.channel_walks");
    }
    DWV_TRY(dwvs_opt_number(item, "bake", "time_limit", &o->time_limit));
    if (o->time_limit < 0.0)
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.time_limit", "%.17g is negative (0 means no limit)",
                            o->time_limit);
    DWV_TRY(dwvs_opt_number(item, "bake", "target_error", &o->target_error));
    if (o->target_error < 0.0)
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.target_error", "%.17g is negative (0 means none)",
                            o->target_error);
    const cJSON *seed = dwvs_member(item, "seed");
    if (seed) DWV_TRY(read_seed(seed, &o->seed));
    DWV_TRY(dwvs_opt_u32(item, "bake", "threads", 0u, MAX_THREADS, &o->threads));
    DWV_TRY(dwvs_opt_u32(item, "bake", "max_events", 0u, UINT32_MAX, &o->max_events));
    DWV_TRY(dwvs_opt_u32(item, "bake", "tile_size", 0u, MAX_SIDE, &o->tile_size));
    const cJSON *transparent = dwvs_member(item, "transparent_background");
    if (transparent) {
        if (!cJSON_IsBool(transparent))
            return dwvs_fail_at(DWV_ERROR_FORMAT, "bake.transparent_background", "must be true or false");
        o->transparent_background = cJSON_IsTrue(transparent) ? 1 : 0;
    }
    const cJSON *passes = dwvs_member(item, "passes");
    if (passes) {
        /* Blender's pass names (dwv_pass_from_name), each at most once. */
        if (!cJSON_IsArray(passes))
            return dwvs_fail_at(DWV_ERROR_FORMAT, "bake.passes", "must be an array of pass names such as [\"DiffDir\"]");
        uint32_t mask = 0u;
        int index = 0;
        for (const cJSON *entry = passes->child; entry; entry = entry->next, ++index) {
            char path[48];
            snprintf(path, sizeof path, "bake.passes[%d]", index);
            const char *name = NULL;
            DWV_TRY(dwvs_read_string(entry, path, &name));
            dwv_pass_t pass;
            dwv_result_t r = dwv_pass_from_name(name, &pass);
            if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, path);
            if (mask & DWV_PASS_BIT(pass)) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "'%s' is listed twice", name);
            mask |= DWV_PASS_BIT(pass);
        }
        o->passes = mask;
    }

    /* Cycles' Light Paths (capi's dwv_bake_options_t: 0 to 1024 each). */
    DWV_TRY(dwvs_opt_u32(item, "bake", "max_bounces", 0u, MAX_BOUNCES, &o->max_bounces));
    DWV_TRY(dwvs_opt_u32(item, "bake", "diffuse_bounces", 0u, MAX_BOUNCES, &o->diffuse_bounces));
    DWV_TRY(dwvs_opt_u32(item, "bake", "glossy_bounces", 0u, MAX_BOUNCES, &o->glossy_bounces));
    DWV_TRY(dwvs_opt_u32(item, "bake", "transmission_bounces", 0u, MAX_BOUNCES, &o->transmission_bounces));
    DWV_TRY(dwvs_opt_u32(item, "bake", "min_light_bounces", 0u, MAX_BOUNCES, &o->min_light_bounces));
    const cJSON *after = dwvs_member(item, "subsurface_after_diffuse");
    if (after) {
        size_t a = 0;
        DWV_TRY(dwvs_read_choice(after, "bake.subsurface_after_diffuse", after_diffuse, 3, &a));
        o->subsurface_after_diffuse = (dwv_subsurface_after_diffuse_t)a;
    }
    /* Cycles' Filter Glossy (scene.cycles.blur_glossy): finite, >= 0. */
    DWV_TRY(dwvs_opt_number(item, "bake", "blur_glossy", &o->blur_glossy));
    if (!(o->blur_glossy >= 0.0))
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.blur_glossy", "%.17g is negative (0 means no blur)",
                            o->blur_glossy);
    /* Cycles' pixel filter (scene.cycles.pixel_filter_type, filter_width): a name and pixels, 0
     * (one pixel) or 0.01 to 10. */
    const cJSON *pixel_filter = dwvs_member(item, "pixel_filter");
    if (pixel_filter) {
        const char *name = NULL;
        DWV_TRY(dwvs_read_string(pixel_filter, "bake.pixel_filter", &name));
        dwv_result_t r = dwv_pixel_filter_from_name(name, &o->pixel_filter);
        if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, "bake.pixel_filter");
    }
    DWV_TRY(dwvs_opt_number(item, "bake", "filter_width", &o->filter_width));
    if (!(o->filter_width == 0.0 || (o->filter_width >= 0.01 && o->filter_width <= 10.0)))
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.filter_width",
                            "%.17g pixels is neither 0 (one pixel) nor in [0.01, 10] (Blender's range)", o->filter_width);
    /* Where UV samples sit in their texel: Cycles 3.5+'s tries, or up to 3.4's fold (accepted on
     * camera bakes too, which place their samples by the pixel filter). */
    const cJSON *uv_jitter = dwvs_member(item, "uv_jitter");
    if (uv_jitter) {
        size_t j = 0;
        DWV_TRY(dwvs_read_choice(uv_jitter, "bake.uv_jitter", uv_jitters, 2, &j));
        o->uv_jitter = (dwv_uv_jitter_t)j;
    }

    const cJSON *uv_mesh = dwvs_member(item, "uv_mesh"), *uv_margin = dwvs_member(item, "uv_margin");
    if (o->target != DWV_BAKE_UV) {
        if (uv_mesh || uv_margin)
            return dwvs_fail_at(DWV_ERROR_FORMAT, "bake", "'uv_mesh' and 'uv_margin' need \"target\": \"uv\"");
        if (!ps->has_camera) return dwvs_fail_at(DWV_ERROR_FORMAT, "bake", "a camera bake needs a 'camera'");
        return DWV_SUCCESS;
    }
    DWV_TRY(dwvs_opt_u32(item, "bake", "uv_margin", 0u, MAX_MARGIN, &o->uv_margin));
    if (!uv_mesh) return dwvs_fail_at(DWV_ERROR_FORMAT, "bake", "a UV bake needs 'uv_mesh' (a mesh's name)");
    const char *name = NULL;
    char shown_name[SHOWN_SIZE];
    DWV_TRY(dwvs_read_string(uv_mesh, "bake.uv_mesh", &name));
    for (size_t i = 0; i < ps->mesh_count; ++i)
        if (ps->meshes[i].name && strcmp(ps->meshes[i].name, name) == 0) {
            if (!ps->meshes[i].has_uvs)
                return dwvs_fail_at(DWV_ERROR_INVALID_ARGUMENT, "bake.uv_mesh", "the mesh '%s' has no UVs",
                                    dwvs_shown(name, shown_name));
            o->uv_mesh = ps->meshes[i].id;
            return DWV_SUCCESS;
        }
    return dwvs_fail_at(DWV_ERROR_UNKNOWN_NAME, "bake.uv_mesh", "no mesh is named '%s'", dwvs_shown(name, shown_name));
}
