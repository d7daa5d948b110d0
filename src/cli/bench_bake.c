/* dwivedi bench bake: the baker's figures on a scene (the default scene unless a file is given):
 * samples and events per second, 1 to 2 thread scaling, memory per triangle, and image RMSE
 * against run time per technique against a high-sample reference. A client of capi only. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include <dwivedi.h>

static const char VERB[] = "bench bake";
#define THROUGHPUT_ROUNDS 3

void cli_bench_bake_help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi bench bake [SCENE.json] [--width W] [--height H] [--spp N]\n"
            "           [--reference-spp N] [--max-spp N] [--techniques T,T,...] [--json]\n\n"
            "Figures of the baker on a scene (default: the built-in default scene), at W x H\n"
            "(default 160 x 90):\n"
            "  throughput  bakes of --spp samples per pixel (default 16) on 1 thread and on 2,\n"
            "              interleaved 3 times, the fastest of each kept: samples and scattering\n"
            "              events per second, the 1 -> 2 thread speed-up, and whether the images\n"
            "              are bit-identical (they must be)\n"
            "  memory      resident memory per triangle of committed scenes of 2^17 and 2^19\n"
            "              triangles (the difference, so fixed costs cancel)\n"
            "  rmse        per technique, bakes of 1, 2, 4 ... --max-spp (default 64) samples per\n"
            "              pixel: relative RMSE (RMSE / mean of the reference) against a reference\n"
            "              of --reference-spp (default 1024) by `auto` with another seed, and seconds\n"
            "Run nothing else heavy meanwhile; times are figures, not checks.\n");
}

/* Resident set size in bytes, from /proc/self/statm; 0 where unavailable. */
static double resident_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f) return 0.0;
    unsigned long size = 0, resident = 0;
    int got = fscanf(f, "%lu %lu", &size, &resident);
    fclose(f);
    return got == 2 ? (double)resident * (double)sysconf(_SC_PAGESIZE) : 0.0;
}

static int fail(const char *what)
{
    fprintf(stderr, "dwivedi bench bake: %s: %s\n", what, dwv_last_error_message());
    return CLI_FAILED;
}

typedef struct bench_settings {
    const char *scene_path;
    uint32_t width, height;
    uint64_t spp, reference_spp, max_spp;
    dwv_technique_t techniques[16];
    int technique_count;
    int json;
} bench_settings;

static dwv_result_t load_scene(const bench_settings *s, dwv_scene_t **scene, dwv_bake_options_t *o)
{
    dwv_result_t r = s->scene_path ? dwv_scene_load(s->scene_path, scene, o) : dwv_scene_create_default(scene, o);
    o->width = s->width;
    o->height = s->height;
    o->time_limit = 0.0;
    o->target_error = 0.0;
    o->progress = NULL;
    return r;
}

typedef struct throughput {
    double seconds[2], samples_per_second[2], events_per_second[2];
    int identical;
} throughput;

/* Bakes on 1 and on 2 threads, interleaved THROUGHPUT_ROUNDS times; the fastest of each count is
 * kept, so a burst of load from elsewhere on a shared machine does not decide the ratio. */
static int measure_throughput(dwv_scene_t *scene, dwv_bake_options_t o, uint64_t spp, throughput *t)
{
    dwv_image_t *images[2] = {NULL, NULL};
    o.samples = spp;
    t->identical = 1;
    for (int round = 0; round < THROUGHPUT_ROUNDS; ++round) {
        for (int k = 0; k < 2; ++k) {
            o.threads = (uint32_t)(k + 1);
            if (dwv_bake(scene, &o, &images[k]) != DWV_SUCCESS) {
                dwv_image_release(images[0]);
                return fail("bake");
            }
            dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
            dwv_image_stats(images[k], &st);
            if (round == 0 || st.seconds < t->seconds[k]) {
                t->seconds[k] = st.seconds;
                t->samples_per_second[k] = (double)st.samples / st.seconds;
                t->events_per_second[k] = (double)st.events / st.seconds;
            }
        }
        dwv_image_info_t a = DWV_IMAGE_INFO_INIT, b = DWV_IMAGE_INFO_INIT;
        dwv_image_info(images[0], &a);
        dwv_image_info(images[1], &b);
        t->identical &= memcmp(a.rgba, b.rgba, (size_t)a.width * a.height * 4u * sizeof(float)) == 0;
        dwv_image_release(images[0]);
        dwv_image_release(images[1]);
        images[0] = images[1] = NULL;
    }
    return 0;
}

/* A UV sphere of about `triangles` triangles, as one mesh. */
static int add_sphere(dwv_scene_t *scene, uint32_t material, uint32_t triangles)
{
    uint32_t rings = (uint32_t)sqrt((double)triangles / 2.0), segments = rings;
    uint32_t vertex_count = (rings + 1u) * segments, triangle_count = 2u * rings * segments;
    float *positions = malloc((size_t)vertex_count * 3u * sizeof *positions);
    uint32_t *indices = malloc((size_t)triangle_count * 3u * sizeof *indices);
    if (!positions || !indices) {
        free(positions);
        free(indices);
        fprintf(stderr, "dwivedi bench bake: out of memory\n");
        return CLI_FAILED;
    }
    const double pi = 3.14159265358979323846;
    for (uint32_t r = 0; r <= rings; ++r) {
        double theta = pi * r / rings;
        for (uint32_t s = 0; s < segments; ++s) {
            double phi = 2.0 * pi * s / segments;
            float *p = positions + 3u * (r * segments + s);
            p[0] = (float)(sin(theta) * cos(phi));
            p[1] = (float)(sin(theta) * sin(phi));
            p[2] = (float)cos(theta);
        }
    }
    uint32_t *t = indices;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t a = r * segments + s, b = r * segments + (s + 1u) % segments;
            uint32_t c = a + segments, d = b + segments;
            t[0] = a, t[1] = c, t[2] = b, t[3] = b, t[4] = c, t[5] = d;
            t += 6;
        }
    }
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = vertex_count;
    mesh.triangle_count = triangle_count;
    mesh.material_id = material;
    mesh.positions = positions;
    mesh.indices = indices;
    uint32_t mesh_id;
    dwv_result_t r = dwv_scene_add_mesh(scene, &mesh, &mesh_id);
    free(positions);
    free(indices);
    return r == DWV_SUCCESS ? 0 : fail("add_mesh");
}

/* Resident bytes of a committed scene holding one sphere of about `triangles` triangles. */
static int scene_bytes(uint32_t triangles, double *bytes, uint32_t *actual_triangles)
{
    double before = resident_bytes();
    dwv_scene_t *scene = NULL;
    dwv_material_t material = DWV_MATERIAL_INIT;
    uint32_t material_id = 0;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) return fail("scene_create");
    int status = 0;
    if (dwv_scene_add_material(scene, &material, &material_id) != DWV_SUCCESS) status = fail("add_material");
    if (!status) status = add_sphere(scene, material_id, triangles);
    if (!status && dwv_scene_commit(scene) != DWV_SUCCESS) status = fail("commit");
    *bytes = resident_bytes() - before;
    uint32_t rings = (uint32_t)sqrt((double)triangles / 2.0);
    *actual_triangles = 2u * rings * rings;
    dwv_scene_release(scene);
    return status;
}

typedef struct rmse_point {
    uint64_t spp;
    double seconds, relative_rmse, estimated_relative_error;
} rmse_point;

static double relative_rmse(const dwv_image_info_t *image, const dwv_image_info_t *reference)
{
    double squares = 0.0, sum = 0.0;
    size_t values = (size_t)image->width * image->height;
    for (size_t i = 0; i < values; ++i) {
        for (int c = 0; c < 3; ++c) {
            double d = (double)image->rgba[4u * i + c] - (double)reference->rgba[4u * i + c];
            squares += d * d;
            sum += reference->rgba[4u * i + c];
        }
    }
    return sum > 0.0 ? sqrt(squares / (3.0 * (double)values)) / (sum / (3.0 * (double)values)) : NAN;
}

static int run_bench(const bench_settings *s)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    if (load_scene(s, &scene, &o) != DWV_SUCCESS) return fail(s->scene_path ? s->scene_path : "default scene");
    int status = CLI_FAILED;
    dwv_image_t *reference = NULL;
    rmse_point *points = NULL;
    int steps = 0;
    for (uint64_t spp = 1; spp <= s->max_spp; spp *= 2) ++steps;

    throughput t;
    double bytes[2] = {0.0, 0.0};
    uint32_t triangles[2] = {0u, 0u};
    if (measure_throughput(scene, o, s->spp, &t)) goto done;
    if (scene_bytes(1u << 17, &bytes[0], &triangles[0]) || scene_bytes(1u << 19, &bytes[1], &triangles[1])) goto done;
    double per_triangle = (bytes[1] - bytes[0]) / ((double)triangles[1] - (double)triangles[0]);

    dwv_bake_options_t ro = o;
    ro.technique = DWV_TECHNIQUE_AUTO;
    ro.samples = s->reference_spp;
    ro.seed = 0x5eedf00dull;
    ro.threads = 0;
    if (dwv_bake(scene, &ro, &reference) != DWV_SUCCESS) {
        fail("reference bake");
        goto done;
    }
    dwv_image_info_t ref = DWV_IMAGE_INFO_INIT;
    dwv_image_info(reference, &ref);
    points = calloc((size_t)s->technique_count * (size_t)steps, sizeof *points);
    if (!points) {
        fprintf(stderr, "dwivedi bench bake: out of memory\n");
        goto done;
    }
    for (int k = 0; k < s->technique_count; ++k) {
        int step = 0;
        for (uint64_t spp = 1; spp <= s->max_spp; spp *= 2, ++step) {
            dwv_bake_options_t bo = o;
            bo.technique = s->techniques[k];
            bo.samples = spp;
            bo.seed = 1u + (uint64_t)step;
            bo.threads = 2;
            dwv_image_t *image = NULL;
            if (dwv_bake(scene, &bo, &image) != DWV_SUCCESS) {
                fail(dwv_technique_name(bo.technique));
                goto done;
            }
            dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
            dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
            dwv_image_info(image, &info);
            dwv_image_stats(image, &st);
            rmse_point *p = &points[(size_t)k * (size_t)steps + (size_t)step];
            p->spp = spp;
            p->seconds = st.seconds;
            p->relative_rmse = relative_rmse(&info, &ref);
            p->estimated_relative_error = st.estimated_relative_error;
            dwv_image_release(image);
        }
    }

    if (s->json) {
        printf("{\"scene\": \"%s\", \"width\": %u, \"height\": %u, \"spp\": %llu, \"reference_spp\": %llu,",
               s->scene_path ? s->scene_path : "default", o.width, o.height, (unsigned long long)s->spp,
               (unsigned long long)s->reference_spp);
        printf(" \"throughput\": [");
        for (int k = 0; k < 2; ++k) {
            printf("%s{\"threads\": %d, \"seconds\": ", k ? ", " : "", k + 1);
            cli_json_number(stdout, t.seconds[k]);
            printf(", \"samples_per_second\": ");
            cli_json_number(stdout, t.samples_per_second[k]);
            printf(", \"events_per_second\": ");
            cli_json_number(stdout, t.events_per_second[k]);
            printf("}");
        }
        printf("], \"thread_scaling\": ");
        cli_json_number(stdout, t.seconds[0] / t.seconds[1]);
        printf(", \"threads_bit_identical\": %s, \"memory\": {\"triangles\": [%u, %u], \"bytes\": [", t.identical ? "true" : "false",
               triangles[0], triangles[1]);
        cli_json_number(stdout, bytes[0]);
        printf(", ");
        cli_json_number(stdout, bytes[1]);
        printf("], \"bytes_per_triangle\": ");
        cli_json_number(stdout, per_triangle);
        printf("}, \"rmse\": {");
        for (int k = 0; k < s->technique_count; ++k) {
            printf("%s\"%s\": [", k ? ", " : "", dwv_technique_name(s->techniques[k]));
            for (int step = 0; step < steps; ++step) {
                const rmse_point *p = &points[(size_t)k * (size_t)steps + (size_t)step];
                printf("%s{\"spp\": %llu, \"seconds\": ", step ? ", " : "", (unsigned long long)p->spp);
                cli_json_number(stdout, p->seconds);
                printf(", \"relative_rmse\": ");
                cli_json_number(stdout, p->relative_rmse);
                printf(", \"estimated_relative_error\": ");
                cli_json_number(stdout, p->estimated_relative_error);
                printf("}");
            }
            printf("]");
        }
        printf("}}\n");
    } else {
        printf("scene %s at %u x %u\n", s->scene_path ? s->scene_path : "default", o.width, o.height);
        for (int k = 0; k < 2; ++k)
            printf("  %d thread%s: %llu spp in %.3f s, %.4g samples/s, %.4g events/s\n", k + 1, k ? "s" : " ",
                   (unsigned long long)s->spp, t.seconds[k], t.samples_per_second[k], t.events_per_second[k]);
        printf("  1 -> 2 threads: %.2fx; images bit-identical: %s\n", t.seconds[0] / t.seconds[1],
               t.identical ? "yes" : "NO");
        printf("  memory: %.0f bytes per triangle (%u -> %u triangles: %.1f -> %.1f MiB)\n", per_triangle,
               triangles[0], triangles[1], bytes[0] / 1048576.0, bytes[1] / 1048576.0);
        printf("  relative RMSE against a %llu spp reference (auto, another seed):\n",
               (unsigned long long)s->reference_spp);
        printf("    %-10s", "spp");
        for (uint64_t spp = 1; spp <= s->max_spp; spp *= 2) printf(" %17llu", (unsigned long long)spp);
        printf("\n");
        for (int k = 0; k < s->technique_count; ++k) {
            printf("    %-10s", dwv_technique_name(s->techniques[k]));
            for (int step = 0; step < steps; ++step) {
                const rmse_point *p = &points[(size_t)k * (size_t)steps + (size_t)step];
                printf(" %8.4f @%6.2fs", p->relative_rmse, p->seconds);
            }
            printf("\n");
        }
    }
    status = CLI_OK;
done:
    free(points);
    dwv_image_release(reference);
    dwv_scene_release(scene);
    return status;
}

static int parse_techniques(const char *text, bench_settings *s)
{
    char buffer[256];
    if (strlen(text) >= sizeof buffer) return cli_usage_error(VERB, "--techniques: too long");
    strcpy(buffer, text);
    s->technique_count = 0;
    for (char *part = buffer, *next; part; part = next) {
        next = strchr(part, ',');
        if (next) *next++ = '\0';
        if (s->technique_count == 16) return cli_usage_error(VERB, "--techniques: at most 16");
        if (dwv_technique_from_name(part, &s->techniques[s->technique_count]) != DWV_SUCCESS)
            return cli_usage_error(VERB, "--techniques: %s", dwv_last_error_message());
        ++s->technique_count;
    }
    return 0;
}

int cli_bench_bake(int argc, char **argv)
{
    bench_settings s = {NULL, 160u, 90u, 16u, 1024u, 64u, {0}, 0, 0};
    if (parse_techniques("classical,poe,closest,incident,backward,cycles,auto", &s)) return CLI_USAGE;
    for (int i = 1; i < argc; ++i) {
        const char *flag = argv[i], *value;
        uint64_t whole;
        if (strcmp(flag, "--json") == 0) {
            s.json = 1;
        } else if (strcmp(flag, "--techniques") == 0) {
            if (!(value = cli_flag_value(VERB, argc, argv, &i)) || parse_techniques(value, &s)) return CLI_USAGE;
        } else if (strcmp(flag, "--width") == 0 || strcmp(flag, "--height") == 0 || strcmp(flag, "--spp") == 0 ||
                   strcmp(flag, "--reference-spp") == 0 || strcmp(flag, "--max-spp") == 0) {
            if (!(value = cli_flag_value(VERB, argc, argv, &i)) || cli_parse_u64(VERB, flag, value, &whole))
                return CLI_USAGE;
            if (whole < 1u || whole > (1u << 24)) return cli_usage_error(VERB, "%s: must be 1 to 2^24", flag);
            if (strcmp(flag, "--width") == 0) s.width = (uint32_t)whole;
            else if (strcmp(flag, "--height") == 0) s.height = (uint32_t)whole;
            else if (strcmp(flag, "--spp") == 0) s.spp = whole;
            else if (strcmp(flag, "--reference-spp") == 0) s.reference_spp = whole;
            else s.max_spp = whole;
        } else if (flag[0] == '-' || s.scene_path) {
            return cli_usage_error(VERB, "unknown argument '%.64s'", flag);
        } else {
            s.scene_path = flag;
        }
    }
    return run_bench(&s);
}
