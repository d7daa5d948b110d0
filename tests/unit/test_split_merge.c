/* Split bakes (docs/farm.md): chunks of sample ranges merged by dwv_merge_partials give the bits
 * of one bake of the same scene, options, seed and samples (pixels, variance, counts, estimated
 * error), for 1, 2 and 3 unequal chunks in any order; missing, duplicate, overlapping, truncated,
 * corrupt and foreign chunks are refused with a message naming the file. */
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include <dwivedi.h>

#define W 24u
#define H 14u
#define SPP 12u

static dwv_scene_t *scene;
static dwv_bake_options_t base;
static char folder[] = "/tmp/dwv_split_XXXXXX";

static dwv_image_t *bake_range(uint64_t first, uint64_t count, uint64_t seed, dwv_technique_t technique)
{
    dwv_bake_options_t o = base;
    o.sample_first = first;
    o.sample_count = count;
    o.seed = seed;
    o.technique = technique;
    dwv_image_t *image = NULL;
    dwv_result_t r = dwv_bake(scene, &o, &image);
    CHECK(r == DWV_SUCCESS, "bake %llu:%llu: %s", (unsigned long long)first, (unsigned long long)count,
          dwv_last_error_message());
    return image;
}

static const char *chunk(const char *name, uint64_t first, uint64_t count, uint64_t seed, dwv_technique_t technique)
{
    static char paths[16][256];
    static int next;
    char *path = paths[next++ % 16];
    snprintf(path, 256, "%s/%s.dwvpart", folder, name);
    dwv_image_t *image = bake_range(first, count, seed, technique);
    CHECK(image && dwv_image_write_partial(image, path) == DWV_SUCCESS, "write %s: %s", path, dwv_last_error_message());
    dwv_image_release(image);
    return path;
}

static int same_image(const dwv_image_t *a, const dwv_image_t *b)
{
    dwv_image_info_t x = DWV_IMAGE_INFO_INIT, y = DWV_IMAGE_INFO_INIT;
    dwv_image_info(a, &x);
    dwv_image_info(b, &y);
    dwv_bake_stats_t s = DWV_BAKE_STATS_INIT, t = DWV_BAKE_STATS_INIT;
    dwv_image_stats(a, &s);
    dwv_image_stats(b, &t);
    size_t n = (size_t)W * H;
    return x.width == y.width && memcmp(x.rgba, y.rgba, 16 * n) == 0 && memcmp(x.variance, y.variance, 12 * n) == 0 &&
           memcmp(x.samples, y.samples, 4 * n) == 0 &&
           memcmp(&s.estimated_relative_error, &t.estimated_relative_error, sizeof(double)) == 0 &&
           memcmp(s.mean_rgb, t.mean_rgb, sizeof s.mean_rgb) == 0 && s.samples == t.samples;
}

static void expect_refused(const char *what, const char *const *paths, uint32_t count, const char *named, const char *word)
{
    dwv_image_t *image = NULL;
    dwv_result_t r = dwv_merge_partials(paths, count, &image);
    const char *m = dwv_last_error_message();
    CHECK(r != DWV_SUCCESS && image == NULL, "%s: refused", what);
    CHECK(strstr(m, named) != NULL, "%s: the message names %s: %s", what, named, m);
    CHECK(strstr(m, word) != NULL, "%s: the message says '%s': %s", what, word, m);
}

int main(void)
{
    CHECK(mkdtemp(folder) != NULL, "temporary folder");
    base = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    CHECK(dwv_scene_create_default(&scene, &base) == DWV_SUCCESS, "default scene: %s", dwv_last_error_message());
    base.width = W;
    base.height = H;
    base.samples = SPP;
    base.threads = 2;
    base.time_limit = 0.0;
    base.target_error = 0.0;

    dwv_bake_options_t whole_options = base;
    dwv_image_t *whole = NULL;
    CHECK(dwv_bake(scene, &whole_options, &whole) == DWV_SUCCESS, "whole bake");

    const char *one = chunk("one", 0, SPP, 0, base.technique);
    const char *a = chunk("a", 0, 6, 0, base.technique), *b = chunk("b", 6, 6, 0, base.technique);
    const char *p = chunk("p", 0, 5, 0, base.technique), *q = chunk("q", 5, 3, 0, base.technique);
    const char *r = chunk("r", 8, 4, 0, base.technique);
    struct {
        const char *name;
        const char *paths[3];
        uint32_t count;
    } splits[] = {{"1 chunk", {one}, 1}, {"2 chunks", {a, b}, 2}, {"3 unequal chunks, shuffled", {r, p, q}, 3}};
    for (size_t k = 0; k < sizeof splits / sizeof splits[0]; ++k) {
        dwv_image_t *merged = NULL;
        CHECK(dwv_merge_partials(splits[k].paths, splits[k].count, &merged) == DWV_SUCCESS, "%s: %s", splits[k].name,
              dwv_last_error_message());
        CHECK(merged && same_image(merged, whole), "%s: the merged image is bit-identical to one bake", splits[k].name);
        uint32_t points = 0;
        dwv_image_error_vs_time(merged, NULL, 0u, &points);
        CHECK(points == splits[k].count, "%s: one error point per chunk prefix (%u)", splits[k].name, points);
        dwv_image_release(merged);
    }
    /* The planted difference: a chunk of another range in place of one is caught by the comparison. */
    {
        const char *other = chunk("other_seed", 6, 6, 5, base.technique);
        const char *paths[2] = {a, other};
        expect_refused("foreign seed", paths, 2, other, "another seed");
        const char *tech = chunk("other_technique", 6, 6, 0, DWV_TECHNIQUE_CLASSICAL);
        const char *paths2[2] = {a, tech};
        expect_refused("foreign options", paths2, 2, tech, "other options");
    }
    {
        const char *paths[2] = {p, r};
        expect_refused("missing range", paths, 2, r, "missing");
        const char *tail[2] = {p, q};
        expect_refused("missing tail", tail, 2, q, "missing");
        const char *dup[3] = {a, b, b};
        expect_refused("duplicate", dup, 3, b, "duplicates");
        const char *overlap[3] = {a, q, r};
        expect_refused("overlap", overlap, 3, q, "overlaps");
    }
    {
        /* truncated and corrupt copies of b */
        char cut[300], bad[300];
        snprintf(cut, sizeof cut, "%s/cut.dwvpart", folder);
        snprintf(bad, sizeof bad, "%s/bad.dwvpart", folder);
        FILE *in = fopen(b, "rb");
        static unsigned char bytes[1 << 20];
        size_t size = fread(bytes, 1, sizeof bytes, in);
        fclose(in);
        FILE *out = fopen(cut, "wb");
        fwrite(bytes, 1, size - 100, out);
        fclose(out);
        bytes[size / 2] ^= 1u;
        out = fopen(bad, "wb");
        fwrite(bytes, 1, size, out);
        fclose(out);
        const char *paths[2] = {a, cut};
        expect_refused("truncated", paths, 2, cut, "truncated");
        const char *paths2[2] = {a, bad};
        expect_refused("corrupt", paths2, 2, bad, "corrupt");
        char absent[300];
        snprintf(absent, sizeof absent, "%s/absent.dwvpart", folder);
        const char *paths3[2] = {a, absent};
        expect_refused("absent file", paths3, 2, absent, "cannot open");
    }
    /* Whole bakes keep no sums; a range outside the samples is refused. */
    CHECK(dwv_image_write_partial(whole, "/tmp/never.dwvpart") != DWV_SUCCESS && access("/tmp/never.dwvpart", F_OK) != 0,
          "a whole bake writes no partial file");
    dwv_bake_options_t o = base;
    o.sample_first = 10;
    o.sample_count = 3;
    dwv_image_t *none = NULL;
    CHECK(dwv_bake(scene, &o, &none) == DWV_ERROR_OUT_OF_RANGE, "range beyond the samples refused");
    /* A caller of the older header (struct_size ending before sample_first) gets a whole bake. */
    dwv_bake_options_t old = base;
    old.struct_size = (uint32_t)offsetof(dwv_bake_options_t, sample_first);
    old.sample_first = 99; /* beyond its struct_size: never read */
    old.sample_count = 99;
    dwv_image_t *old_image = NULL;
    /* (its struct also ends before the light paths: the one-bounce image) */
    dwv_bake_options_t one_bounce = base;
    one_bounce.max_bounces = one_bounce.diffuse_bounces = one_bounce.glossy_bounces = 0u;
    one_bounce.transmission_bounces = 0u;
    dwv_image_t *one_bounce_image = NULL;
    CHECK(dwv_bake(scene, &one_bounce, &one_bounce_image) == DWV_SUCCESS, "one bounce: %s", dwv_last_error_message());
    CHECK(dwv_bake(scene, &old, &old_image) == DWV_SUCCESS && same_image(old_image, one_bounce_image),
          "older struct_size: the whole bake (%s)", dwv_last_error_message());
    dwv_image_release(old_image);
    dwv_image_release(one_bounce_image);
    dwv_image_release(whole);
    dwv_scene_release(scene);
    char command[400];
    snprintf(command, sizeof command, "rm -rf '%s'", folder);
    if (system(command) != 0) fprintf(stderr, "could not remove %s\n", folder);
    return check_report("test_split_merge");
}
