/* dwivedi_bake_counts: bakes a scene with one technique and prints what auto's pilot counts to
 * price a sample (src/bake/bake.c, PILOT_COST_*): samples, walk events, Embree rays, closest-point
 * queries and mixture terms, with the bake's seconds. tools/fit_pilot_cost.py runs it over scenes
 * and techniques and fits the pilot's cost per count by least squares, to wall time or to
 * callgrind's instruction count in bake.c's `worker`. The counts are internal (the image object,
 * src/bake/image.h), not part of the C API, hence a program linked against the static archive.
 *
 * usage: dwivedi_bake_counts SCENE.json|default TECHNIQUE WIDTH HEIGHT SPP SEED REPEATS
 * prints one JSON object: the counts of the first bake (every repeat bakes the same image) and
 * the seconds of each repeat. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/image_handle.h"
#include "dwivedi.h"

static unsigned long parse(const char *text, const char *what)
{
    char *end = NULL;
    unsigned long value = strtoul(text, &end, 10);
    if (end == text || *end != '\0') {
        fprintf(stderr, "dwivedi_bake_counts: %s must be a whole number, not '%s'\n", what, text);
        exit(2);
    }
    return value;
}

int main(int argc, char **argv)
{
    if (argc != 8) {
        fprintf(stderr, "usage: dwivedi_bake_counts SCENE.json|default TECHNIQUE WIDTH HEIGHT SPP SEED REPEATS\n");
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
    if (dwv_technique_from_name(argv[2], &options.technique) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi_bake_counts: %s\n", dwv_last_error_message());
        return 2;
    }
    options.target = DWV_BAKE_CAMERA;
    options.width = (uint32_t)parse(argv[3], "WIDTH");
    options.height = (uint32_t)parse(argv[4], "HEIGHT");
    options.samples = parse(argv[5], "SPP");
    options.seed = parse(argv[6], "SEED");
    options.threads = 1;
    options.time_limit = 0.0;
    options.target_error = 0.0;
    unsigned long repeats = parse(argv[7], "REPEATS");
    printf("{\"scene\": \"%s\", \"technique\": \"%s\", \"seconds\": [", argv[1], argv[2]);
    for (unsigned long k = 0; k < (repeats ? repeats : 1); ++k) {
        dwv_image_t *image = NULL;
        if (dwv_bake(scene, &options, &image) != DWV_SUCCESS) {
            fprintf(stderr, "dwivedi_bake_counts: bake: %s\n", dwv_last_error_message());
            return 1;
        }
        dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &stats);
        const dwvb_image *counts = dwv_image_object(image);
        printf("%s%.9g", k ? ", " : "", stats.seconds);
        if (k + 1 >= repeats)
            printf("], \"samples\": %llu, \"walks\": %llu, \"events\": %llu, \"rays\": %llu, \"point_queries\": %llu, "
                   "\"mixture_terms\": %llu, \"mean_rgb\": [%.9g, %.9g, %.9g]}\n",
                   (unsigned long long)stats.samples, (unsigned long long)stats.walks, (unsigned long long)stats.events,
                   (unsigned long long)counts->rays, (unsigned long long)counts->point_queries,
                   (unsigned long long)counts->mixture_terms, stats.mean_rgb[0], stats.mean_rgb[1], stats.mean_rgb[2]);
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
    return 0;
}
