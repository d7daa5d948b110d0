/* dwivedi_bake_counts: bakes a scene with one technique and prints what auto's pilot counts to
 * price a sample (src/bake/pilot.c, PILOT_COST_*): samples, walk events, Embree rays, closest-point
 * queries, mixture terms and the rays of paths after the first scattering (indirect light), with the
 * bake's seconds. tools/fit_pilot_cost.py runs it over scenes
 * and techniques and fits the pilot's cost per count by least squares, to wall time or to
 * callgrind's instruction count in bake.c's `worker`. The counts are internal (the image object,
 * src/bake/image.h), not part of the C API, hence a program linked against the static archive.
 *
 * usage: dwivedi_bake_counts SCENE.json|default TECHNIQUE[/CHANNELS] WIDTH HEIGHT SPP SEED REPEATS
 * (CHANNELS: a dwv_channel_walks_t name, auto, shared or separate; default auto)
 * prints one JSON object: the counts of the first bake (every repeat bakes the same image) and
 * the seconds of each repeat (REPEATS 0 to 1000; 0 bakes once). Exit 2 for bad arguments, 1 for a
 * scene or a bake that failed, with a message on stderr and nothing on stdout. */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/image_handle.h"
#include <dwivedi.h>

#define MAX_REPEATS 1000u

/* A whole number in [0, max] written in decimal digits only (no sign, no blanks), else exit 2
 * with a message; the library checks what it accepts of each (dimensions, samples). */
static unsigned long long parse(const char *text, const char *what, unsigned long long max)
{
    char *end = NULL;
    errno = 0;
    unsigned long long value = text[0] >= '0' && text[0] <= '9' ? strtoull(text, &end, 10) : 0;
    if (end == NULL || end == text || *end != '\0' || errno == ERANGE || value > max) {
        fprintf(stderr, "dwivedi_bake_counts: %s must be a whole number from 0 to %llu, not '%s'\n", what, max,
                text);
        exit(2);
    }
    return value;
}

int main(int argc, char **argv)
{
    if (argc != 8) {
        fprintf(stderr, "usage: dwivedi_bake_counts SCENE.json|default TECHNIQUE[/CHANNELS] WIDTH HEIGHT SPP SEED REPEATS\n");
        return 2;
    }
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    dwv_result_t r = strcmp(argv[1], "default") == 0 ? dwv_scene_create_default(&scene, &options)
                                                     : dwv_scene_load(argv[1], &scene, &options);
    if (r != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi_bake_counts: %s: %s\n", argv[1], dwv_last_error_message());
        return 1;
    }
    char technique[64];
    const char *slash = strchr(argv[2], '/');
    size_t length = slash ? (size_t)(slash - argv[2]) : strlen(argv[2]);
    if (length >= sizeof technique) length = sizeof technique - 1u; /* too long for any name: refused below */
    memcpy(technique, argv[2], length);
    technique[length] = '\0';
    if (dwv_technique_from_name(technique, &options.technique) != DWV_SUCCESS ||
        (slash && dwv_channel_walks_from_name(slash + 1, &options.channel_walks) != DWV_SUCCESS)) {
        fprintf(stderr, "dwivedi_bake_counts: %s\n", dwv_last_error_message());
        dwv_scene_release(scene);
        return 2;
    }
    options.target = DWV_BAKE_CAMERA;
    options.width = (uint32_t)parse(argv[3], "WIDTH", UINT32_MAX);
    options.height = (uint32_t)parse(argv[4], "HEIGHT", UINT32_MAX);
    options.samples = parse(argv[5], "SPP", UINT64_MAX);
    options.seed = parse(argv[6], "SEED", UINT64_MAX);
    options.threads = 1;
    options.time_limit = 0.0;
    options.target_error = 0.0;
    unsigned long long repeats = parse(argv[7], "REPEATS", MAX_REPEATS);
    if (repeats == 0) repeats = 1;
    /* Everything is printed after the last bake, so that a failed one leaves no partial JSON. */
    double seconds[MAX_REPEATS];
    dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
    unsigned long long rays = 0, point_queries = 0, mixture_terms = 0;
    for (unsigned long long k = 0; k < repeats; ++k) {
        dwv_image_t *image = NULL;
        if (dwv_bake(scene, &options, &image) != DWV_SUCCESS) {
            fprintf(stderr, "dwivedi_bake_counts: bake: %s\n", dwv_last_error_message());
            dwv_scene_release(scene);
            return 1;
        }
        dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &s);
        seconds[k] = s.seconds;
        if (k == 0) { /* every repeat bakes the same image: its counts are the first's */
            const dwvb_image *counts = dwv_image_object(image);
            stats = s;
            rays = counts->rays;
            point_queries = counts->point_queries;
            mixture_terms = counts->mixture_terms;
        }
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
    printf("{\"scene\": \"%s\", \"technique\": \"%s\", \"seconds\": [", argv[1], argv[2]);
    for (unsigned long long k = 0; k < repeats; ++k) printf("%s%.9g", k ? ", " : "", seconds[k]);
    printf("], \"samples\": %llu, \"walks\": %llu, \"events\": %llu, \"rays\": %llu, \"point_queries\": %llu, "
           "\"mixture_terms\": %llu, \"path_rays\": %llu, \"mean_rgb\": [%.9g, %.9g, %.9g]}\n",
           (unsigned long long)stats.samples, (unsigned long long)stats.walks, (unsigned long long)stats.events, rays,
           point_queries, mixture_terms, (unsigned long long)stats.path_rays, stats.mean_rgb[0], stats.mean_rgb[1], stats.mean_rgb[2]);
    return 0;
}
