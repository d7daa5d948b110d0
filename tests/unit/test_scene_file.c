/* Scene files through the public API: every example scene loads with the bake settings it
 * states; the default scene loads; bad text and bad mesh files give a non-success code and a
 * message that says where (the JSON path or the line and column), never a crash, and leave the
 * caller's options untouched. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

#define EXAMPLES DWV_TEST_DATA_DIR "/../../examples/scenes"

static char temp_dir[256];

static void write_file(const char *name, const void *data, size_t size)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", temp_dir, name);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL, "cannot write %s", path);
    if (!f) return;
    CHECK(fwrite(data, 1, size, f) == size, "short write to %s", path);
    fclose(f);
}

static char *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)n + 1u);
    if (text && fread(text, 1, (size_t)n, f) != (size_t)n) {
        free(text);
        text = NULL;
    }
    fclose(f);
    if (text) text[n] = '\0';
    *size = (size_t)n;
    return text;
}

static int same_options(const dwv_bake_options_t *a, const dwv_bake_options_t *b)
{
    return a->struct_size == b->struct_size && a->target == b->target && a->width == b->width &&
           a->height == b->height && a->uv_mesh == b->uv_mesh && a->uv_margin == b->uv_margin &&
           a->technique == b->technique && a->samples == b->samples && a->time_limit == b->time_limit &&
           a->target_error == b->target_error && a->threads == b->threads && a->max_events == b->max_events &&
           a->seed == b->seed && a->tile_size == b->tile_size && a->channel_walks == b->channel_walks &&
           a->progress == b->progress && a->max_bounces == b->max_bounces &&
           a->diffuse_bounces == b->diffuse_bounces && a->glossy_bounces == b->glossy_bounces &&
           a->transmission_bounces == b->transmission_bounces && a->min_light_bounces == b->min_light_bounces &&
           a->subsurface_after_diffuse == b->subsurface_after_diffuse && a->progress_user == b->progress_user &&
           a->sample_first == b->sample_first && a->sample_count == b->sample_count &&
           a->transparent_background == b->transparent_background && a->passes == b->passes &&
           a->blur_glossy == b->blur_glossy && a->pixel_filter == b->pixel_filter &&
           a->filter_width == b->filter_width;
}

/* Loads JSON text (with meshes relative to the temp folder) and expects failure with `code`, a
 * fresh message containing every keyword given, no scene, and the options as they came in. */
static void expect_failure_sized(const char *what, const char *json, size_t size, dwv_result_t code,
                                 const char *keyword1, const char *keyword2)
{
    dwv_scene_t *scene = (dwv_scene_t *)&scene; /* not NULL: the call must clear it */
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT, untouched = DWV_BAKE_OPTIONS_INIT;
    prime_message();
    dwv_result_t r = dwv_scene_load_json(json, size, temp_dir, &scene, &options);
    const char *message = dwv_last_error_message();
    CHECK(r != DWV_SUCCESS, "%s: loaded", what);
    CHECK(code == 0 || r == code, "%s: code %d (%s), wanted %d", what, (int)r, message, (int)code);
    CHECK(scene == NULL, "%s: *scene not cleared", what);
    CHECK(same_options(&options, &untouched), "%s: options changed on failure", what);
    CHECK(strlen(message) < 512, "%s: message of %zu bytes", what, strlen(message));
    if (keyword1) CHECK(fresh_message_with(keyword1), "%s: message \"%s\" lacks \"%s\"", what, message, keyword1);
    if (keyword2) CHECK(fresh_message_with(keyword2), "%s: message \"%s\" lacks \"%s\"", what, message, keyword2);
    if (r == DWV_SUCCESS) dwv_scene_release(scene);
}

static void expect_failure(const char *what, const char *json, dwv_result_t code, const char *keyword1,
                           const char *keyword2)
{
    expect_failure_sized(what, json, strlen(json), code, keyword1, keyword2);
}

static dwv_result_t load_text(const char *json, dwv_bake_options_t *options)
{
    dwv_scene_t *scene = NULL;
    dwv_result_t r = dwv_scene_load_json(json, strlen(json), temp_dir, &scene, options);
    CHECK((r == DWV_SUCCESS) == (scene != NULL), "scene handle and result disagree");
    dwv_scene_release(scene);
    return r;
}

/* A valid scene to start from: one material, one inline tetrahedron, a camera. */
#define MATERIAL "\"materials\": {\"m\": {\"subsurface_radius\": [1, 1, 1], \"subsurface_scale\": 0.1}}"
#define TETRA "\"positions\": [0,0,0, 1,0,0, 0,1,0, 0,0,1], \"indices\": [0,2,1, 0,1,3, 0,3,2, 1,2,3]"
#define CAMERA "\"camera\": {\"transform\": {\"look_at\": {\"eye\": [0, -3, 0], \"target\": [0, 0, 0]}}}"

static void test_examples(void)
{
    int count = 0;
    DIR *dir = opendir(EXAMPLES);
    CHECK(dir != NULL, "cannot list %s", EXAMPLES);
    if (!dir) return;
    for (struct dirent *e; (e = readdir(dir));) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 5, ".json") != 0) continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", EXAMPLES, e->d_name);
        dwv_scene_t *scene = NULL;
        dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
        dwv_result_t r = dwv_scene_load(path, &scene, &options);
        CHECK(r == DWV_SUCCESS && scene, "%s: %s", e->d_name, dwv_last_error_message());
        /* Committed: it refuses changes. */
        double black[3] = {0, 0, 0};
        CHECK(scene && dwv_scene_set_world(scene, black, 0.0) == DWV_ERROR_INVALID_STATE, "%s: not committed",
              e->d_name);
        dwv_scene_release(scene);
        ++count;
    }
    closedir(dir);
    CHECK(count >= 3, "only %d example scenes", count);

    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    dwv_scene_t *scene = NULL;
    CHECK(dwv_scene_load(EXAMPLES "/backlit_slab.json", &scene, &options) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    CHECK(options.width == 256u && options.height == 256u && options.samples == 64u && options.seed == 1u &&
              options.technique == DWV_TECHNIQUE_AUTO && options.target == DWV_BAKE_CAMERA,
          "backlit_slab options %u x %u, %llu samples", options.width, options.height,
          (unsigned long long)options.samples);
    CHECK(options.struct_size == sizeof options, "struct_size changed");
    dwv_scene_release(scene);

    dwv_bake_options_t uv = DWV_BAKE_OPTIONS_INIT;
    CHECK(dwv_scene_load(EXAMPLES "/uv_tile.json", &scene, &uv) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(uv.target == DWV_BAKE_UV && uv.uv_mesh == 0u && uv.uv_margin == 8u && uv.target_error == 0.02 &&
              uv.seed == UINT64_MAX && uv.samples == 32u,
          "uv_tile options: target %d mesh %u margin %u seed %llu", (int)uv.target, uv.uv_mesh, uv.uv_margin,
          (unsigned long long)uv.seed);
    dwv_scene_release(scene);

    dwv_bake_options_t poe = DWV_BAKE_OPTIONS_INIT;
    CHECK(dwv_scene_load(EXAMPLES "/frontlit_sphere.json", &scene, &poe) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    CHECK(poe.technique == DWV_TECHNIQUE_POE && poe.time_limit == 60.0 && poe.width == 320u, "frontlit options");
    dwv_scene_release(scene);

    /* options may be NULL */
    CHECK(dwv_scene_load(EXAMPLES "/backlit_slab.json", &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    dwv_scene_release(scene);
}

static void test_default_scene(void)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    CHECK(dwv_scene_create_default(&scene, &options) == DWV_SUCCESS && scene, "%s", dwv_last_error_message());
    CHECK(options.width == 480u && options.height == 270u && options.samples == 128u, "default options %u x %u",
          options.width, options.height);
    double black[3] = {0, 0, 0};
    CHECK(scene && dwv_scene_set_world(scene, black, 0.0) == DWV_ERROR_INVALID_STATE, "default scene not committed");
    dwv_scene_release(scene);
    CHECK(dwv_scene_create_default(&scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    dwv_scene_release(scene);
}

static void test_arguments(void)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t small = DWV_BAKE_OPTIONS_INIT;
    small.struct_size = 8u;
    prime_message();
    CHECK(dwv_scene_load(NULL, &scene, NULL) == DWV_ERROR_NULL_POINTER && fresh_message_with("path"), "NULL path");
    prime_message();
    CHECK(dwv_scene_load(EXAMPLES "/backlit_slab.json", NULL, NULL) == DWV_ERROR_NULL_POINTER, "NULL scene");
    prime_message();
    CHECK(dwv_scene_load(EXAMPLES "/backlit_slab.json", &scene, &small) == DWV_ERROR_STRUCT_SIZE &&
              fresh_message_with("struct_size"),
          "small options: %s", dwv_last_error_message());
    prime_message();
    CHECK(dwv_scene_create_default(&scene, &small) == DWV_ERROR_STRUCT_SIZE, "default, small options");
    prime_message();
    CHECK(dwv_scene_load_json(NULL, 3, NULL, &scene, NULL) == DWV_ERROR_NULL_POINTER, "NULL json");
    prime_message();
    CHECK(dwv_scene_load(EXAMPLES "/no-such-scene.json", &scene, NULL) == DWV_ERROR_IO &&
              fresh_message_with("no-such-scene.json"),
          "missing scene: %s", dwv_last_error_message());
    prime_message();
    CHECK(dwv_scene_load(EXAMPLES, &scene, NULL) == DWV_ERROR_IO && fresh_message_with("folder"),
          "a folder: %s", dwv_last_error_message());
    prime_message();
    CHECK(dwv_scene_load("", &scene, NULL) == DWV_ERROR_IO, "empty path");
    CHECK(scene == NULL, "scene set on failure");
    /* A base_dir of NULL means "."; an inline scene needs none. */
    const char *json = "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA "}]}";
    CHECK(dwv_scene_load_json(json, strlen(json), NULL, &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    dwv_scene_release(scene);
}

static void test_syntax(void)
{
    expect_failure_sized("empty", "", 0, DWV_ERROR_FORMAT, "empty", NULL);
    expect_failure("white space", "  \n\t ", DWV_ERROR_FORMAT, "line 2", NULL);
    expect_failure("not an object", "[1, 2]", DWV_ERROR_FORMAT, "expected an object", NULL);
    expect_failure("NaN", "{\"version\": NaN}", DWV_ERROR_FORMAT, "line 1, column", NULL);
    expect_failure("trailing", "{\"version\": 1, \"meshes\": []} x", DWV_ERROR_FORMAT, "after the end", NULL);
    expect_failure("trailing comma", "{\"version\": 1,}", DWV_ERROR_FORMAT, "not valid JSON", NULL);
    expect_failure_sized("NUL byte", "{\"version\": 1}\0", 15, DWV_ERROR_FORMAT, "NUL", NULL);
    expect_failure("escaped NUL", "{\"version\": 1, \"description\": \"a\\u0000b\", \"meshes\": []}", DWV_ERROR_FORMAT,
                   "\\u0000", NULL);
    expect_failure("lone surrogate", "{\"version\": 1, \"description\": \"\\udc00\", \"meshes\": []}",
                   DWV_ERROR_FORMAT, "not valid JSON", NULL);

    /* Binary garbage: random bytes from a fixed LCG, several lengths. */
    uint64_t state = 12345u;
    for (int trial = 0; trial < 64; ++trial) {
        size_t n = 1u + (size_t)trial * 37u;
        unsigned char *bytes = malloc(n);
        for (size_t i = 0; i < n; ++i) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            bytes[i] = (unsigned char)(state >> 56);
        }
        expect_failure_sized("garbage", (const char *)bytes, n, 0, "line", NULL);
        free(bytes);
    }

    /* Every prefix of a valid scene is refused (a truncated file), with a position. */
    size_t size = 0;
    char *text = read_file(EXAMPLES "/frontlit_sphere.json", &size);
    CHECK(text != NULL, "cannot read the example");
    if (text) {
        /* (the mesh file is relative: give the example's folder) */
        for (size_t cut = 1; cut + 1 < size; cut += 13) {
            dwv_scene_t *scene = NULL;
            dwv_result_t r = dwv_scene_load_json(text, cut, EXAMPLES, &scene, NULL);
            CHECK(r == DWV_ERROR_FORMAT && scene == NULL, "prefix of %zu bytes: %d %s", cut, (int)r,
                  dwv_last_error_message());
        }
        dwv_scene_t *scene = NULL;
        CHECK(dwv_scene_load_json(text, size / 2, EXAMPLES, &scene, NULL) == DWV_ERROR_FORMAT &&
                  strstr(dwv_last_error_message(), "ends inside"),
              "half the file: %s", dwv_last_error_message());
        CHECK(dwv_scene_load_json(text, size, EXAMPLES, &scene, NULL) == DWV_SUCCESS, "the whole file: %s",
              dwv_last_error_message());
        dwv_scene_release(scene);
        free(text);
    }

    /* Deep nesting: 10^5 brackets of each kind, refused before cJSON recurses. */
    size_t deep = 100000u;
    char *nest = malloc(deep * 5u + 64u);
    memset(nest, '[', deep);
    expect_failure_sized("10^5 '['", nest, deep, DWV_ERROR_FORMAT, "nested deeper", NULL);
    size_t k = 0;
    k += (size_t)sprintf(nest, "{\"version\": 1, \"meshes\": ");
    for (size_t i = 0; i < deep; ++i) k += (size_t)sprintf(nest + k, "{\"a\":");
    expect_failure_sized("10^5 objects", nest, k, DWV_ERROR_FORMAT, "nested deeper", NULL);
    free(nest);

    /* Invalid UTF-8: a stray byte, an overlong '/', a UTF-16 surrogate, a cut sequence, > U+10FFFF. */
    const char *bad_utf8[] = {"\xff", "\xc0\xaf", "\xed\xa0\x80", "\xe2\x82", "\xf4\x90\x80\x80"};
    for (size_t i = 0; i < sizeof bad_utf8 / sizeof bad_utf8[0]; ++i) {
        char json[256];
        snprintf(json, sizeof json, "{\"version\": 1, \"description\": \"ab%scd\", \"meshes\": []}", bad_utf8[i]);
        expect_failure("invalid UTF-8", json, DWV_ERROR_FORMAT, "UTF-8", "column 34");
    }
    /* Valid UTF-8 passes (a name in Greek and an emoji). */
    const char *greek = "{\"version\": 1, \"materials\": {\"\xce\xba\xce\xb7\xcf\x81\xcf\x8c\xcf\x82 \xf0\x9f\x95\xaf\": "
                        "{}}, \"meshes\": [{\"material\": \"\xce\xba\xce\xb7\xcf\x81\xcf\x8c\xcf\x82 \xf0\x9f\x95\xaf\", " TETRA "}]}";
    CHECK(load_text(greek, NULL) == DWV_SUCCESS, "UTF-8 names: %s", dwv_last_error_message());
    /* A byte-order mark is skipped. */
    CHECK(load_text("\xef\xbb\xbf{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA "}]}",
                    NULL) == DWV_SUCCESS,
          "BOM: %s", dwv_last_error_message());
}

/* The scene's "bake" object as JSON text around `members`. */
#define BAKE_WITH(members) "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {" members "}}"

/* bake.pixel_filter and bake.filter_width: each filter's name (dwv_pixel_filter_name) read, the
 * caller's kept when absent; a value that is no name or no width refused naming its key. */
static void test_pixel_filter(void)
{
    for (dwv_pixel_filter_t f = DWV_PIXEL_FILTER_BOX; dwv_pixel_filter_name(f); ++f) {
        char json[256];
        snprintf(json, sizeof json, BAKE_WITH("\"pixel_filter\": \"%s\", \"filter_width\": 2.5"),
                 dwv_pixel_filter_name(f));
        dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
        o.pixel_filter = f == DWV_PIXEL_FILTER_BOX ? DWV_PIXEL_FILTER_GAUSSIAN : DWV_PIXEL_FILTER_BOX;
        CHECK(load_text(json, &o) == DWV_SUCCESS && o.pixel_filter == f && o.filter_width == 2.5,
              "%s: read %d %g (%s)", dwv_pixel_filter_name(f), (int)o.pixel_filter, o.filter_width,
              dwv_last_error_message());
        CHECK(load_text(BAKE_WITH("\"samples\": 4"), &o) == DWV_SUCCESS && o.pixel_filter == f && o.filter_width == 2.5,
              "%s not kept when absent: %d %g", dwv_pixel_filter_name(f), (int)o.pixel_filter, o.filter_width);
    }
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    CHECK(load_text(BAKE_WITH("\"filter_width\": 0"), &o) == DWV_SUCCESS && o.filter_width == 0.0,
          "filter_width 0 (one pixel): %s", dwv_last_error_message());
    CHECK(load_text(BAKE_WITH("\"filter_width\": 0.01"), &o) == DWV_SUCCESS &&
              load_text(BAKE_WITH("\"filter_width\": 10"), &o) == DWV_SUCCESS && o.filter_width == 10.0,
          "filter_width 0.01 and 10, Blender's ends: %s", dwv_last_error_message());

    expect_failure("pixel filter mitchell", BAKE_WITH("\"pixel_filter\": \"mitchell\""), DWV_ERROR_UNKNOWN_NAME,
                   "bake.pixel_filter: dwv_pixel_filter_from_name: unknown pixel filter 'mitchell'",
                   "(box, gaussian or blackman_harris)");
    expect_failure("pixel filter in Blender's capitals", BAKE_WITH("\"pixel_filter\": \"BLACKMAN_HARRIS\""),
                   DWV_ERROR_UNKNOWN_NAME, "bake.pixel_filter: ", "'BLACKMAN_HARRIS'");
    expect_failure("pixel filter as a number", BAKE_WITH("\"pixel_filter\": 2"), DWV_ERROR_FORMAT,
                   "bake.pixel_filter", "expected a string, found a number");
    expect_failure("pixel filter null", BAKE_WITH("\"pixel_filter\": null"), DWV_ERROR_FORMAT, "bake.pixel_filter",
                   "expected a string, found null");
    expect_failure("empty pixel filter", BAKE_WITH("\"pixel_filter\": \"\""), DWV_ERROR_FORMAT, "bake.pixel_filter",
                   "empty");
    static const struct {
        const char *what, *json;
        dwv_result_t code;
        const char *said;
    } widths[] = {
        {"filter width below 0.01", BAKE_WITH("\"filter_width\": 0.005"), DWV_ERROR_OUT_OF_RANGE, "0.005"},
        {"negative filter width", BAKE_WITH("\"filter_width\": -1"), DWV_ERROR_OUT_OF_RANGE, "-1 pixels"},
        {"filter width 11", BAKE_WITH("\"filter_width\": 11"), DWV_ERROR_OUT_OF_RANGE, "[0.01, 10]"},
        {"filter width as a string", BAKE_WITH("\"filter_width\": \"1.5\""), DWV_ERROR_FORMAT,
         "expected a number, found a string"},
        {"filter width null", BAKE_WITH("\"filter_width\": null"), DWV_ERROR_FORMAT, "expected a number, found null"},
        {"filter width 1e400", BAKE_WITH("\"filter_width\": 1e400"), DWV_ERROR_FORMAT, "too large"},
        {"filter width -1e400", BAKE_WITH("\"filter_width\": -1e400"), DWV_ERROR_FORMAT, "too large"},
    };
    for (size_t i = 0; i < sizeof widths / sizeof widths[0]; ++i)
        expect_failure(widths[i].what, widths[i].json, widths[i].code, "bake.filter_width", widths[i].said);
}

static void test_schema(void)
{
    expect_failure("no version", "{\"meshes\": []}", DWV_ERROR_FORMAT, "version", NULL);
    expect_failure("version 2", "{\"version\": 2, \"meshes\": []}", DWV_ERROR_FORMAT, "version", "newer");
    expect_failure("version 1.5", "{\"version\": 1.5, \"meshes\": []}", DWV_ERROR_FORMAT, "whole number", NULL);
    expect_failure("no meshes", "{\"version\": 1}", DWV_ERROR_FORMAT, "meshes", NULL);
    expect_failure("unknown top-level key", "{\"version\": 1, \"meshs\": []}", DWV_ERROR_FORMAT,
                   "unknown key 'meshs'", NULL);
    expect_failure("duplicate key", "{\"version\": 1, \"version\": 1, \"meshes\": []}", DWV_ERROR_FORMAT,
                   "appears twice", NULL);
    expect_failure("meshes a string", "{\"version\": 1, \"meshes\": \"x\"}", DWV_ERROR_FORMAT,
                   "meshes: expected an array", NULL);
    expect_failure("colour a string",
                   "{\"version\": 1, \"materials\": {\"m\": {\"base_color\": \"red\"}}, \"meshes\": []}",
                   DWV_ERROR_FORMAT, "materials.m.base_color: expected an array of 3 numbers", NULL);
    expect_failure("colour of 2",
                   "{\"version\": 1, \"materials\": {\"m\": {\"base_color\": [1, 1]}}, \"meshes\": []}",
                   DWV_ERROR_FORMAT, "materials.m.base_color", "another length");
    expect_failure("colour with a string",
                   "{\"version\": 1, \"materials\": {\"m\": {\"base_color\": [1, \"1\", 1]}}, \"meshes\": []}",
                   DWV_ERROR_FORMAT, "materials.m.base_color[1]: expected a number", NULL);
    expect_failure("typo in a material",
                   "{\"version\": 1, \"materials\": {\"m\": {\"subsurface_colour\": [1, 1, 1]}}, \"meshes\": []}",
                   DWV_ERROR_FORMAT, "materials.m: unknown key 'subsurface_colour'", NULL);
    expect_failure("material kind",
                   "{\"version\": 1, \"materials\": {\"m\": {\"kind\": \"glass\"}}, \"meshes\": []}",
                   DWV_ERROR_UNKNOWN_NAME, "materials.m.kind", "'glass'");
    /* The capi checks ranges; the message keeps its code and gets the JSON path. */
    expect_failure("ior out of range",
                   "{\"version\": 1, \"materials\": {\"m\": {\"subsurface_ior\": 9}}, \"meshes\": []}",
                   DWV_ERROR_OUT_OF_RANGE, "materials.m: dwv_scene_add_material", "subsurface_ior");
    expect_failure("subsurface exit",
                   "{\"version\": 1, \"materials\": {\"m\": {\"subsurface_exit\": \"fresnel\"}}, \"meshes\": []}",
                   DWV_ERROR_UNKNOWN_NAME, "materials.m.subsurface_exit", "'fresnel'");
    expect_failure("roughness out of range",
                   "{\"version\": 1, \"materials\": {\"m\": {\"roughness\": 2}}, \"meshes\": []}",
                   DWV_ERROR_OUT_OF_RANGE, "materials.m: dwv_scene_add_material", "roughness");
    CHECK(load_text("{\"version\": 1, \"materials\": {\"m\": {\"subsurface_exit\": \"principled_v1\", "
                    "\"roughness\": 0.25}}, \"meshes\": []}",
                    NULL) == DWV_SUCCESS,
          "a Blender 3.x Principled material: %s", dwv_last_error_message());
    expect_failure("unknown material",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA "}, "
                   "{\"material\": \"m\", " TETRA "}, {\"material\": \"wax\", " TETRA "}]}",
                   DWV_ERROR_UNKNOWN_NAME, "meshes[2].material: unknown material 'wax'", NULL);
    expect_failure("typo in a mesh",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"matrial\": \"m\", " TETRA "}]}", DWV_ERROR_FORMAT,
                   "meshes[0]: unknown key 'matrial'", NULL);
    expect_failure("mesh without material", "{\"version\": 1, " MATERIAL ", \"meshes\": [{" TETRA "}]}",
                   DWV_ERROR_FORMAT, "meshes[0]", "material");
    expect_failure("negative geometry offset",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"shadow_terminator_geometry_offset\": -1}]}",
                   DWV_ERROR_OUT_OF_RANGE, "meshes[0]", "shadow_terminator_geometry_offset");
    expect_failure("geometry offset a string",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"shadow_terminator_geometry_offset\": \"0.1\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].shadow_terminator_geometry_offset", "number");
    CHECK(load_text("{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                    ", \"shadow_terminator_geometry_offset\": 0}]}",
                    NULL) == DWV_SUCCESS,
          "a mesh with geometry offset 0: %s", dwv_last_error_message());
    expect_failure("file and inline",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"a.obj\", " TETRA "}]}",
                   DWV_ERROR_FORMAT, "meshes[0]", "either");
    expect_failure("positions not in threes",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"positions\": [0, 0, 0, 1], "
                   "\"indices\": [0, 0, 0]}]}",
                   DWV_ERROR_FORMAT, "meshes[0].positions", "multiple of 3");
    expect_failure("index out of range",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", "
                   "\"positions\": [0,0,0, 1,0,0, 0,1,0], \"indices\": [0, 1, 3]}]}",
                   DWV_ERROR_OUT_OF_RANGE, "meshes[0]: dwv_scene_add_mesh", "indices[2]");
    expect_failure("negative index",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", "
                   "\"positions\": [0,0,0, 1,0,0, 0,1,0], \"indices\": [0, 1, -2]}]}",
                   DWV_ERROR_OUT_OF_RANGE, "meshes[0].indices[2]", NULL);
    expect_failure("uvs of the wrong count",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", "
                   "\"positions\": [0,0,0, 1,0,0, 0,1,0], \"indices\": [0, 1, 2], \"uvs\": [0, 0, 1, 0]}]}",
                   DWV_ERROR_FORMAT, "meshes[0].uvs", "corner");
    expect_failure("duplicate mesh names",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"name\": \"a\", \"material\": \"m\", " TETRA "}, "
                   "{\"name\": \"a\", \"material\": \"m\", " TETRA "}]}",
                   DWV_ERROR_FORMAT, "'a'", "two meshes");
    expect_failure("duplicate material names",
                   "{\"version\": 1, \"materials\": {\"m\": {}, \"m\": {}}, \"meshes\": []}", DWV_ERROR_FORMAT,
                   "materials", "'m' appears twice");

    /* Transforms */
    expect_failure("two transform forms",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"transform\": {\"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0], \"scale\": 2}}]}",
                   DWV_ERROR_FORMAT, "meshes[0].transform", "one of");
    expect_failure("matrix of 9",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"transform\": {\"matrix\": [1,0,0, 0,1,0, 0,0,1]}}]}",
                   DWV_ERROR_FORMAT, "meshes[0].transform.matrix", "12 or 16");
    expect_failure("projective matrix",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"transform\": {\"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]}}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "meshes[0].transform.matrix", "0 0 0 1");
    expect_failure("singular scale",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                   ", \"transform\": {\"scale\": [1, 0, 1]}}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "meshes[0]: dwv_scene_add_mesh", "singular");
    CHECK(load_text("{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA
                    ", \"transform\": {\"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}, "
                    "{\"material\": \"m\", " TETRA ", \"transform\": {\"translate\": [1, 2, 3], \"rotate\": [10, 20, 30], "
                    "\"scale\": [1, 2, 3]}}]}",
                    NULL) == DWV_SUCCESS,
          "matrix and TRS transforms: %s", dwv_last_error_message());

    /* Lights */
    expect_failure("light kind", "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"laser\"}]}",
                   DWV_ERROR_UNKNOWN_NAME, "lights[0].kind", "'laser'");
    expect_failure("light without kind", "{\"version\": 1, \"meshes\": [], \"lights\": [{\"strength\": 1}]}",
                   DWV_ERROR_FORMAT, "lights[0]", "kind");
    expect_failure("position on a sun",
                   "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"sun\", \"position\": [0, 0, 1]}]}",
                   DWV_ERROR_FORMAT, "lights[0]: unknown key 'position'", NULL);
    expect_failure("zero sun direction",
                   "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"sun\", \"direction\": [0, 0, 0]}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "lights[0]: dwv_scene_add_light", "direction");
    expect_failure("negative strength",
                   "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"point\", \"strength\": -1}]}",
                   DWV_ERROR_OUT_OF_RANGE, "lights[0]: dwv_scene_add_light", "strength");
    expect_failure("area light shape",
                   "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"area\", \"shape\": \"star\"}]}",
                   DWV_ERROR_UNKNOWN_NAME, "lights[0].shape", NULL);
    expect_failure("area light degenerate look_at",
                   "{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"area\", \"transform\": {\"look_at\": "
                   "{\"eye\": [0, 0, 1], \"target\": [0, 0, 1]}}}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "lights[0].transform.look_at", "coincide");
    expect_failure("look_at up along the view",
                   "{\"version\": 1, \"meshes\": [], \"camera\": {\"transform\": {\"look_at\": "
                   "{\"eye\": [0, 0, 5], \"target\": [0, 0, 0]}}}}",
                   DWV_ERROR_INVALID_ARGUMENT, "camera.transform.look_at", "parallel");

    /* World and camera */
    expect_failure("world typo", "{\"version\": 1, \"meshes\": [], \"world\": {\"colour\": [1, 1, 1]}}",
                   DWV_ERROR_FORMAT, "world: unknown key 'colour'", NULL);
    expect_failure("ortho_scale on a perspective camera",
                   "{\"version\": 1, \"meshes\": [], \"camera\": {\"ortho_scale\": 1, \"transform\": {}}}",
                   DWV_ERROR_FORMAT, "camera: unknown key 'ortho_scale'", NULL);
    expect_failure("camera without transform", "{\"version\": 1, \"meshes\": [], \"camera\": {}}", DWV_ERROR_FORMAT,
                   "camera", "transform");
    expect_failure("scaled camera",
                   "{\"version\": 1, \"meshes\": [], \"camera\": {\"transform\": {\"scale\": 2}}}",
                   DWV_ERROR_INVALID_ARGUMENT, "camera: dwv_scene_set_camera", NULL);

    /* Bake settings */
    expect_failure("width 0", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"width\": 0}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.width", NULL);
    expect_failure("too many pixels",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"width\": 16384, \"height\": 16384}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake", "pixels");
    expect_failure("fractional samples", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"samples\": 2.5}}",
                   DWV_ERROR_FORMAT, "bake.samples", "whole number");
    expect_failure("unknown technique",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"technique\": \"magic\"}}",
                   DWV_ERROR_UNKNOWN_NAME, "bake.technique", "magic");
    expect_failure("unknown channel walks",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"channel_walks\": \"apart\"}}",
                   DWV_ERROR_UNKNOWN_NAME, "bake.channel_walks: ", "'apart'");
    expect_failure("channel walks in capitals",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"channel_walks\": \"SEPARATE\"}}",
                   DWV_ERROR_UNKNOWN_NAME, "bake.channel_walks: ", "'SEPARATE'");
    expect_failure("channel walks as a number",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"channel_walks\": 2}}",
                   DWV_ERROR_FORMAT, "bake.channel_walks", "expected a string, found a number");
    expect_failure("empty channel walks",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"channel_walks\": \"\"}}",
                   DWV_ERROR_FORMAT, "bake.channel_walks", "empty");
    expect_failure("negative time", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"time_limit\": -1}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.time_limit", NULL);
    expect_failure("seed string", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"seed\": \"12a\"}}",
                   DWV_ERROR_FORMAT, "bake.seed", NULL);
    expect_failure("seed beyond 2^64",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"seed\": \"18446744073709551616\"}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.seed", NULL);
    expect_failure("camera bake without camera", "{\"version\": 1, \"meshes\": [], \"bake\": {\"samples\": 4}}",
                   DWV_ERROR_FORMAT, "bake", "camera");
    expect_failure("uv bake of an unnamed mesh",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA "}], "
                   "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"t\"}}",
                   DWV_ERROR_UNKNOWN_NAME, "bake.uv_mesh", "'t'");
    expect_failure("uv bake of a mesh without UVs",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"name\": \"t\", \"material\": \"m\", " TETRA "}], "
                   "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"t\"}}",
                   DWV_ERROR_INVALID_ARGUMENT, "bake.uv_mesh", "no UVs");
    expect_failure("uv margin on a camera bake",
                   "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"uv_margin\": 4}}", DWV_ERROR_FORMAT,
                   "bake", "uv_margin");
    expect_failure("uv margin 65",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"name\": \"t\", \"material\": \"m\", " TETRA
                   ", \"uvs\": [0,0,1,0,0,1, 0,0,1,0,0,1, 0,0,1,0,0,1, 0,0,1,0,0,1]}], "
                   "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"t\", \"uv_margin\": 65}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.uv_margin", NULL);
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    CHECK(load_text("{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", " TETRA "}, {\"name\": \"t\", "
                    "\"material\": \"m\", " TETRA ", \"uvs\": [0,0,1,0,0,1, 0,0,1,0,0,1, 0,0,1,0,0,1, 0,0,1,0,0,1]}], "
                    "\"bake\": {\"target\": \"uv\", \"uv_mesh\": \"t\", \"uv_margin\": 3, \"threads\": 2, "
                    "\"max_events\": 1000, \"tile_size\": 16, \"seed\": 9007199254740992}}",
                    &options) == DWV_SUCCESS,
          "uv bake: %s", dwv_last_error_message());
    CHECK(options.target == DWV_BAKE_UV && options.uv_mesh == 1u && options.uv_margin == 3u && options.threads == 2u &&
              options.max_events == 1000u && options.tile_size == 16u && options.seed == 9007199254740992ull,
          "uv bake options");

    /* channel_walks: each name sets its value over the caller's; without the key the caller's stays. */
    static const struct {
        const char *name;
        dwv_channel_walks_t value, caller;
    } walks[] = {{"auto", DWV_CHANNEL_WALKS_AUTO, DWV_CHANNEL_WALKS_SEPARATE},
                 {"shared", DWV_CHANNEL_WALKS_SHARED, DWV_CHANNEL_WALKS_AUTO},
                 {"separate", DWV_CHANNEL_WALKS_SEPARATE, DWV_CHANNEL_WALKS_SHARED}};
    for (size_t i = 0; i < sizeof walks / sizeof walks[0]; ++i) {
        char json[256];
        snprintf(json, sizeof json,
                 "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"channel_walks\": \"%s\"}}",
                 walks[i].name);
        dwv_bake_options_t walk_options = DWV_BAKE_OPTIONS_INIT;
        walk_options.channel_walks = walks[i].caller;
        CHECK(load_text(json, &walk_options) == DWV_SUCCESS, "channel_walks %s: %s", walks[i].name,
              dwv_last_error_message());
        CHECK(walk_options.channel_walks == walks[i].value, "channel_walks %s: read %u", walks[i].name,
              walk_options.channel_walks);
        walk_options.channel_walks = walks[i].caller;
        CHECK(load_text("{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"samples\": 4}}", &walk_options) ==
                  DWV_SUCCESS,
              "bake without channel_walks: %s", dwv_last_error_message());
        CHECK(walk_options.channel_walks == walks[i].caller, "channel_walks %u not kept when absent: %u",
              walks[i].caller, walk_options.channel_walks);
    }
    /* Light paths (issue 18): read, kept when absent, ranges and names checked. */
    dwv_bake_options_t paths = DWV_BAKE_OPTIONS_INIT;
    CHECK(load_text("{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"max_bounces\": 3, \"diffuse_bounces\": 2, "
                    "\"glossy_bounces\": 1, \"transmission_bounces\": 0, \"min_light_bounces\": 5, "
                    "\"subsurface_after_diffuse\": \"walk\"}}",
                    &paths) == DWV_SUCCESS,
          "light paths: %s", dwv_last_error_message());
    CHECK(paths.max_bounces == 3u && paths.diffuse_bounces == 2u && paths.glossy_bounces == 1u &&
              paths.transmission_bounces == 0u && paths.min_light_bounces == 5u &&
              paths.subsurface_after_diffuse == DWV_SUBSURFACE_AFTER_DIFFUSE_WALK,
          "light paths read as %u %u %u %u %u %d", paths.max_bounces, paths.diffuse_bounces, paths.glossy_bounces,
          paths.transmission_bounces, paths.min_light_bounces, (int)paths.subsurface_after_diffuse);
    CHECK(load_text("{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"samples\": 4}}", &paths) == DWV_SUCCESS &&
              paths.max_bounces == 3u && paths.subsurface_after_diffuse == DWV_SUBSURFACE_AFTER_DIFFUSE_WALK,
          "light paths not kept when absent");
    expect_failure("1025 bounces", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"glossy_bounces\": 1025}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.glossy_bounces", NULL);
    expect_failure("after diffuse", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"subsurface_after_diffuse\": \"x\"}}",
                   DWV_ERROR_UNKNOWN_NAME, "subsurface_after_diffuse", NULL);
    test_pixel_filter();
}

static void test_numbers_and_strings(void)
{
    expect_failure("1e999", "{\"version\": 1, \"meshes\": [], \"world\": {\"strength\": 1e999}}", DWV_ERROR_FORMAT,
                   "world.strength", "too large");
    expect_failure("-1e999", "{\"version\": 1, \"meshes\": [], \"world\": {\"color\": [1, -1e999, 1]}}",
                   DWV_ERROR_FORMAT, "world.color[1]", "too large");
    expect_failure("beyond float",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", "
                   "\"positions\": [0,0,0, 1e39,0,0, 0,1,0], \"indices\": [0, 1, 2]}]}",
                   DWV_ERROR_OUT_OF_RANGE, "meshes[0].positions[3]", "float");
    expect_failure("huge width", "{\"version\": 1, \"meshes\": [], " CAMERA ", \"bake\": {\"width\": 1e300}}",
                   DWV_ERROR_OUT_OF_RANGE, "bake.width", NULL);
    expect_failure("huge version", "{\"version\": 1e300, \"meshes\": []}", DWV_ERROR_OUT_OF_RANGE, "version", NULL);

    /* Very long strings are cut short in messages (and the message stays whole). */
    size_t n = 100000u;
    char *json = malloc(2u * n + 256u);
    char *name = malloc(n + 1u);
    memset(name, 'x', n);
    name[n] = '\0';
    snprintf(json, 2u * n + 256u, "{\"version\": 1, \"%s\": 1, \"meshes\": []}", name);
    expect_failure("long unknown key", json, DWV_ERROR_FORMAT, "unknown key 'xxxxxxxxxx", "...'");
    snprintf(json, 2u * n + 256u, "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"%s\", " TETRA "}]}", name);
    expect_failure("long material name", json, DWV_ERROR_UNKNOWN_NAME, "meshes[0].material: unknown material 'xxx",
                   "...'");
    snprintf(json, 2u * n + 256u, "{\"version\": 1, \"materials\": {\"%s\": {\"kind\": 1}}, \"meshes\": []}", name);
    expect_failure("long material key in a path", json, DWV_ERROR_FORMAT, "materials.xxxxx", "expected a string");
    /* A long name cut inside a multi-byte character: the message stays valid UTF-8 (no half character). */
    for (size_t i = 0; i + 1 < 200; i += 2) name[i] = (char)0xce, name[i + 1] = (char)0xba; /* kappa */
    name[1] = 'a';
    name[200] = '\0';
    snprintf(json, 2u * n + 256u, "{\"version\": 1, \"materials\": {\"a%s\": {\"kind\": 1}}, \"meshes\": []}", name + 1);
    expect_failure("long UTF-8 key", json, DWV_ERROR_FORMAT, "materials.a", "...");
    {
        const char *message = dwv_last_error_message();
        const char *dots = strstr(message, "...");
        CHECK(dots && ((unsigned char)dots[-1] < 0x80u || (unsigned char)dots[-2] == 0xceu),
              "cut inside a character: %s", message);
    }
    free(name);
    free(json);
}

static void test_mesh_files(void)
{
    /* A missing mesh file: an I/O error naming the JSON path and the file. */
    expect_failure("missing mesh file",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"nowhere.obj\"}]}",
                   DWV_ERROR_IO, "meshes[0].file", "nowhere.obj");
    expect_failure("a folder as mesh file",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"d.obj\"}]}",
                   DWV_ERROR_IO, "meshes[0].file", "regular file");
    expect_failure("wrong extension",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"mesh.stl\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", ".obj and .ply");

    /* A NaN vertex: the capi's check refuses it, with the JSON path and the file. */
    const char nan_obj[] = "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n";
    write_file("nan.obj", nan_obj, sizeof nan_obj - 1);
    expect_failure("NaN vertex in an OBJ",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"nan.obj\"}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "meshes[0] ('nan.obj')", "not finite");
    const char nan_ply[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n";
    write_file("nan.ply", nan_ply, sizeof nan_ply - 1);
    expect_failure("NaN vertex in a PLY",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"nan.ply\"}]}",
                   DWV_ERROR_INVALID_ARGUMENT, "meshes[0] ('nan.ply')", "not finite");

    /* Garbage with a mesh file's name. */
    unsigned char garbage[4096];
    uint64_t state = 99u;
    for (size_t i = 0; i < sizeof garbage; ++i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        garbage[i] = (unsigned char)(state >> 56);
    }
    write_file("garbage.obj", garbage, sizeof garbage);
    write_file("garbage.ply", garbage, sizeof garbage);
    write_file("empty.obj", "", 0);
    expect_failure("garbage OBJ",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"garbage.obj\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "garbage.obj");
    expect_failure("garbage PLY",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"garbage.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "garbage.ply");
    expect_failure("empty OBJ",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"empty.obj\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "empty.obj");
    /* A PLY header that claims billions of vertices it does not hold. */
    const char absurd[] = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                          "property float y\nproperty float z\nelement face 4000000000\n"
                          "property list uchar int vertex_indices\nend_header\n\x01\x02\x03";
    write_file("absurd.ply", absurd, sizeof absurd - 1);
    expect_failure("absurd PLY counts",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"absurd.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "absurd.ply");
    /* PLY files that crashed Assimp 5.2 (found by tests/fuzz/fuzz_mesh_file): a header without
     * end_header, and a binary body shorter than its header says. Now refused before Assimp. */
    const char no_end[] = "ply\nformat binary_little_endian 1.perty list uchar int vertex_indice\0\x80]\0\0\0\0"
                          "\0\0\0\0\0\0\0\0\0\0\x80?\0\0\0\0\x03\0\0\0\0\x01\0\0\0\x02\0\0\0";
    write_file("no_end.ply", no_end, sizeof no_end - 1);
    expect_failure("PLY without end_header",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"no_end.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "end_header");
    const char short_body[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                              "\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f"
                              "\0\0\0\0\xff\0\0\0\0\x01\0\0\0";
    write_file("short_body.ply", short_body, sizeof short_body - 1);
    expect_failure("PLY body shorter than its header",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"short_body.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "shorter");
    const char few[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n";
    write_file("few.ply", few, sizeof few - 1);
    expect_failure("ASCII PLY line short of values",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"few.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "too few");
    /* A well-formed binary PLY whose first coordinate is a tiny denormal: Assimp 5.2 flagged its
     * triangle as a polygon and its triangulation asserted (abort); now a message or a scene. */
    const char denormal[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "\x06\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f"
                            "\x03\0\0\0\0\x01\0\0\0\x02\0\0\0";
    write_file("denormal.ply", denormal, sizeof denormal - 1);
    {
        const char *json = "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"denormal.ply\"}]}";
        dwv_scene_t *scene = NULL;
        dwv_result_t r = dwv_scene_load_json(json, strlen(json), temp_dir, &scene, NULL);
        CHECK((r == DWV_SUCCESS) == (scene != NULL) && (r == DWV_SUCCESS || strstr(dwv_last_error_message(), "denormal.ply")),
              "denormal PLY: %d %s", (int)r, dwv_last_error_message());
        dwv_scene_release(scene);
    }
    /* More of what fuzzing found Assimp 5.2 mishandles: a name that starts with digits (it asked
     * for gigabytes) and an empty list (a face of no corners, a crash in its post-processing). */
    const char digits[] = "ply\nformat ascii 1.0\nelement 3333333333333333vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    write_file("digits.ply", digits, sizeof digits - 1);
    expect_failure("PLY element name of digits",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"digits.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "element");
    const char empty_list[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n0\n3 0 1 2\n";
    write_file("empty_list.ply", empty_list, sizeof empty_list - 1);
    expect_failure("PLY empty list",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"empty_list.ply\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "list");
    /* A well-formed binary PLY loads. */
    const char binary[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f"
                          "\0\0\0\0\x03\0\0\0\0\x01\0\0\0\x02\0\0\0";
    write_file("binary.ply", binary, sizeof binary - 1);
    CHECK(load_text("{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"binary.ply\"}]}",
                    NULL) == DWV_SUCCESS,
          "binary PLY: %s", dwv_last_error_message());

    /* Points and lines only: no triangles. */
    const char lines[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n";
    write_file("lines.obj", lines, sizeof lines - 1);
    expect_failure("lines only",
                   "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"lines.obj\"}]}",
                   DWV_ERROR_FORMAT, "meshes[0].file", "lines.obj");

    /* A quad and a pentagon are triangulated; a relative path inside a folder resolves. */
    const char polygons[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 1\nv 3 0 1\nv 3 1 1\nv 2.5 2 1\nv 2 1 1\n"
                            "f 1 2 3 4\nf 5 6 7 8 9\n";
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", temp_dir);
    mkdir(sub, 0700);
    write_file("sub/polygons.obj", polygons, sizeof polygons - 1);
    CHECK(load_text("{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"sub/polygons.obj\"}]}",
                    NULL) == DWV_SUCCESS,
          "polygons: %s", dwv_last_error_message());
    /* The same through a scene file in that folder: paths are relative to the scene file. */
    const char scene[] = "{\"version\": 1, " MATERIAL ", \"meshes\": [{\"material\": \"m\", \"file\": \"polygons.obj\"}]}";
    write_file("sub/scene.json", scene, sizeof scene - 1);
    char scene_path[600];
    snprintf(scene_path, sizeof scene_path, "%s/sub/scene.json", temp_dir);
    dwv_scene_t *loaded = NULL;
    CHECK(dwv_scene_load(scene_path, &loaded, NULL) == DWV_SUCCESS, "relative to the scene file: %s",
          dwv_last_error_message());
    dwv_scene_release(loaded);
    /* dwv_scene_load's messages start with the scene file's path. */
    const char bad[] = "{\"version\": 1, \"meshes\": [], \"world\": {\"strength\": \"x\"}}";
    write_file("sub/bad.json", bad, sizeof bad - 1);
    snprintf(scene_path, sizeof scene_path, "%s/sub/bad.json", temp_dir);
    prime_message();
    CHECK(dwv_scene_load(scene_path, &loaded, NULL) == DWV_ERROR_FORMAT && fresh_message_with("bad.json: world.strength"),
          "bad.json: %s", dwv_last_error_message());
}

int main(void)
{
    snprintf(temp_dir, sizeof temp_dir, "/tmp/dwv_scene_file_XXXXXX");
    CHECK(mkdtemp(temp_dir) != NULL, "mkdtemp");
    char folder[300];
    snprintf(folder, sizeof folder, "%s/d.obj", temp_dir);
    mkdir(folder, 0700);

    test_arguments();
    test_examples();
    test_default_scene();
    test_syntax();
    test_schema();
    test_numbers_and_strings();
    test_mesh_files();

    char command[600];
    snprintf(command, sizeof command, "rm -rf '%s'", temp_dir);
    CHECK(system(command) == 0, "cleaning %s", temp_dir);
    return check_report("test_scene_file");
}
