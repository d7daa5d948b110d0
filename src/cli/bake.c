/* dwivedi bake: bakes a scene file (or the built-in default scene) into PREFIX.exr (scene-linear,
 * with variance and sample counts), PREFIX.png (through an OCIO view) and PREFIX.json (stats).
 * The three are written under temporary names and renamed into place only once all three are
 * complete, so a failed or cancelled bake leaves the previous outputs as they were. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake_cli.h"
#include "cli.h"
#include <dwivedi.h>

static const char verb[] = "bake";
static const char *verb_name = "bake"; /* "merge" while merging: the messages say which */

static void help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi bake [SCENE.json] --out PREFIX [--spp N] [--time SECONDS] [--error REL]\n"
            "           [--technique T] [--channel-walks C] [--threads N] [--seed S] [--width W] [--height H]\n"
            "           [--ocio CONFIG] [--display NAME] [--view NAME] [--look NAME]\n"
            "           [--exposure E] [--gamma G] [--samples FIRST:COUNT] [--passes NAMES] [--blur-glossy B]\n"
            "           [--pixel-filter F] [--filter-width W] [--uv-jitter J] [--quiet]\n"
            "           [--mpi [--mpi-chunk N] [--mpi-timeout SECONDS]]\n\n"
            "Bakes SCENE.json (docs/scene-format.md), or without it the built-in default scene: a thin\n"
            "back-lit leaf-like shell beside a thick front-lit wax-like shape. Writes\n"
            "  PREFIX.exr   float RGBA, scene-linear Rec.709, plus variance and sample-count layers\n"
            "  PREFIX.png   the display image through an OpenColorIO view\n"
            "  PREFIX.json  spp, seconds, estimated_relative_error, mean_rgb, events, features,\n"
            "               error_vs_time, texture_bytes_per_texel (textured scenes) and more\n"
            "  PREFIX.layers.exr  with --passes (or the scene's bake.passes): a multilayer OpenEXR as\n"
            "               Blender's, Combined and each pass (DiffDir, DiffCol, ...) a layer\n"
            "all of them only when the bake completes: a failed or cancelled (Ctrl-C) bake exits non-zero\n"
            "and leaves earlier outputs untouched.\n\n"
            "  --spp N        samples per pixel (default: the scene's); the budgets --spp, --time and\n"
            "                 --error stop the bake at whichever comes first\n"
            "  --time S       wall-time budget in seconds          --error R  target relative error\n"
            "  --technique T  auto (default), classical, poe, closest, incident, backward, cycles,\n"
            "                 sheet\n"
            "  --channel-walks C  auto (default: auto's pilot chooses), shared (one walk carries the\n"
            "                 three colour channels, spectral MIS) or separate (one walk per channel)\n"
            "  --threads N    worker threads (default: all cores); the image does not depend on it\n"
            "  --seed S       random seed (default: the scene's, else 0)\n"
            "  --width W, --height H   image size (default: the scene's)\n"
            "  --ocio CONFIG  OpenColorIO config (default: $OCIO, else the config dwivedi ships)\n"
            "  --display, --view, --look, --exposure, --gamma   colour management as in Blender\n"
            "  --samples FIRST:COUNT   a chunk of a split bake (docs/farm.md): sample indices FIRST to\n"
            "                 FIRST+COUNT-1 of the --spp in all, written to PREFIX.dwvpart only (exact sums\n"
            "                 for 'dwivedi merge'); no --time or --error\n"
            "  --passes NAMES bake passes beside the combined image, Blender's names comma-separated:\n"
            "                 DiffDir, DiffInd, DiffCol, GlossDir, GlossInd, GlossCol, TransDir, TransInd,\n"
            "                 TransCol, Emit, Env (docs/output.md; a direct or indirect pass brings its colour)\n"
            "  --blur-glossy B  Cycles' Filter Glossy (default: the scene's bake.blur_glossy, else Blender's\n"
            "                 1.0; 0: none): specular layers met after a bounce roughened as Cycles does\n"
            "  --pixel-filter F  box, gaussian or blackman_harris (Blender's default); --filter-width W\n"
            "                 its width in pixels, 0.01 to 10 (default: the scene's bake.pixel_filter and\n"
            "                 bake.filter_width, else the box of one pixel); camera bakes only\n"
            "  --uv-jitter J  retry (Cycles 3.5+, the default) or mirror (Cycles up to 3.4): where UV bakes'\n"
            "                 samples sit in their texel (default: the scene's bake.uv_jitter, else retry)\n"
            "  --quiet        no progress bar (it is shown only on a terminal anyway)\n"
            "  --mpi          under mpirun (docs/farm.md): the ranks bake ranges of N samples each, handed\n"
            "                 out by rank 0, which merges them exactly and writes the outputs (bit for bit\n"
            "                 the one-process bake); --spp only (no --time, --error or --samples); threads\n"
            "                 per rank default to the cores bound to it, shared by the ranks on its node\n"
            "  --mpi-chunk N  samples per range (default: the --spp cut into 2 ranges per rank)\n"
            "  --mpi-timeout S  seconds a rank waits on another (start, replies, transfers, a rank's\n"
            "                 silence while it bakes) before all end with an error (default 300)\n");
}

static volatile sig_atomic_t interrupted = 0;

static void on_interrupt(int signal_number)
{
    (void)signal_number;
    interrupted = 1;
}

/* Parses argv into flags and options (the scene's own settings already in *o). Returns 0 or CLI_USAGE. */
static int parse_overrides(int argc, char **argv, cli_bake_flags *f, dwv_bake_options_t *o, int apply)
{
    for (int i = 1; i < argc; ++i) {
        const char *flag = argv[i], *value = NULL;
        if (strcmp(flag, "--quiet") == 0) {
            f->quiet = 1;
            continue;
        }
        if (strcmp(flag, "--mpi") == 0) {
            f->mpi = 1;
            continue;
        }
        if (flag[0] != '-' || flag[1] == '\0') {
            if (f->scene_path && f->scene_path != flag)
                return cli_usage_error(verb, "one scene file only ('%.64s' and '%.64s')", f->scene_path, flag);
            f->scene_path = flag;
            continue;
        }
        static const char *const flags[] = {"--out",     "--spp",   "--time",    "--error",   "--technique",
                                            "--threads", "--seed",  "--width",   "--height",  "--ocio",
                                            "--display", "--view",  "--look",    "--exposure", "--gamma",
                                            "--channel-walks", "--samples", "--mpi-chunk", "--mpi-timeout", "--passes",
                                            "--blur-glossy", "--pixel-filter", "--filter-width", "--uv-jitter"};
        int known = 0;
        for (size_t k = 0; k < sizeof flags / sizeof flags[0]; ++k) known |= strcmp(flag, flags[k]) == 0;
        if (!known) return cli_usage_error(verb, "unknown argument '%.64s'", flag);
        if (!(value = cli_flag_value(verb, argc, argv, &i))) return CLI_USAGE;
        uint64_t whole;
        double number;
        if (strcmp(flag, "--mpi-chunk") == 0) {
            if (cli_parse_u64(verb, flag, value, &f->mpi_chunk)) return CLI_USAGE;
            if (f->mpi_chunk == 0u) return cli_usage_error(verb, "--mpi-chunk: at least 1 sample");
        } else if (strcmp(flag, "--mpi-timeout") == 0) {
            if (cli_parse_double(verb, flag, value, &f->mpi_timeout)) return CLI_USAGE;
            if (!(f->mpi_timeout > 0.0 && f->mpi_timeout <= 1e6))
                return cli_usage_error(verb, "--mpi-timeout: '%.64s' seconds: more than 0, at most 1e6", value);
        } else if (strcmp(flag, "--samples") == 0) {
            const char *colon = strchr(value, ':');
            char head[32];
            if (!colon || (size_t)(colon - value) >= sizeof head)
                return cli_usage_error(verb, "--samples: '%.64s' is not FIRST:COUNT", value);
            memcpy(head, value, (size_t)(colon - value));
            head[colon - value] = '\0';
            if (cli_parse_u64(verb, flag, head, &f->first) || cli_parse_u64(verb, flag, colon + 1, &f->count))
                return CLI_USAGE;
            if (f->count == 0u) return cli_usage_error(verb, "--samples: COUNT must be at least 1");
            f->chunk = 1;
            if (apply) {
                o->sample_first = f->first;
                o->sample_count = f->count;
            }
        } else if (strcmp(flag, "--out") == 0) {
            if (value[0] == '\0') return cli_usage_error(verb, "--out: the prefix is empty");
            f->prefix = value;
        } else if (strcmp(flag, "--ocio") == 0) {
            f->display.config_path = value;
        } else if (strcmp(flag, "--display") == 0) {
            f->display.display = value;
        } else if (strcmp(flag, "--view") == 0) {
            f->display.view = value;
        } else if (strcmp(flag, "--look") == 0) {
            f->display.look = value;
        } else if (strcmp(flag, "--exposure") == 0) {
            if (cli_parse_double(verb, flag, value, &f->display.exposure)) return CLI_USAGE;
        } else if (strcmp(flag, "--gamma") == 0) {
            if (cli_parse_double(verb, flag, value, &f->display.gamma)) return CLI_USAGE;
        } else if (strcmp(flag, "--technique") == 0) {
            dwv_technique_t technique;
            if (dwv_technique_from_name(value, &technique) != DWV_SUCCESS)
                return cli_usage_error(verb, "--technique: %s", dwv_last_error_message());
            if (apply) o->technique = technique;
        } else if (strcmp(flag, "--passes") == 0) {
            uint32_t mask = 0u;
            for (const char *start = value; *start;) {
                const char *end = strchr(start, ',');
                size_t length = end ? (size_t)(end - start) : strlen(start);
                char name[32];
                if (length == 0u || length >= sizeof name)
                    return cli_usage_error(verb, "--passes: '%.64s' is not a comma-separated list of pass names", value);
                memcpy(name, start, length);
                name[length] = '\0';
                dwv_pass_t pass;
                if (dwv_pass_from_name(name, &pass) != DWV_SUCCESS)
                    return cli_usage_error(verb, "--passes: %s", dwv_last_error_message());
                mask |= DWV_PASS_BIT(pass);
                start = end ? end + 1 : start + length;
            }
            if (apply) o->passes = mask;
        } else if (strcmp(flag, "--channel-walks") == 0) {
            dwv_channel_walks_t channel_walks;
            if (dwv_channel_walks_from_name(value, &channel_walks) != DWV_SUCCESS)
                return cli_usage_error(verb, "--channel-walks: %s", dwv_last_error_message());
            if (apply) o->channel_walks = channel_walks;
        } else if (strcmp(flag, "--blur-glossy") == 0) {
            if (cli_parse_double(verb, flag, value, &number)) return CLI_USAGE;
            if (!isfinite(number) || number < 0.0)
                return cli_usage_error(verb, "--blur-glossy: '%.64s' must be finite and >= 0 (0: no blur)", value);
            if (apply) o->blur_glossy = number;
        } else if (strcmp(flag, "--pixel-filter") == 0) {
            dwv_pixel_filter_t pixel_filter;
            if (dwv_pixel_filter_from_name(value, &pixel_filter) != DWV_SUCCESS)
                return cli_usage_error(verb, "--pixel-filter: %s", dwv_last_error_message());
            if (apply) o->pixel_filter = pixel_filter;
        } else if (strcmp(flag, "--filter-width") == 0) {
            if (cli_parse_double(verb, flag, value, &number)) return CLI_USAGE;
            if (!(number >= 0.01 && number <= 10.0))
                return cli_usage_error(verb, "--filter-width: '%.64s' pixels is outside [0.01, 10]", value);
            if (apply) o->filter_width = number;
        } else if (strcmp(flag, "--uv-jitter") == 0) {
            int rule = strcmp(value, "retry") == 0    ? DWV_UV_JITTER_RETRY
                       : strcmp(value, "mirror") == 0 ? DWV_UV_JITTER_MIRROR
                                                      : -1;
            if (rule < 0) return cli_usage_error(verb, "--uv-jitter: '%.64s' is not retry or mirror", value);
            if (apply) o->uv_jitter = rule;
        } else if (strcmp(flag, "--time") == 0 || strcmp(flag, "--error") == 0) {
            if (cli_parse_double(verb, flag, value, &number)) return CLI_USAGE;
            f->budget = 1;
            if (apply) *(flag[2] == 't' ? &o->time_limit : &o->target_error) = number;
        } else {
            if (cli_parse_u64(verb, flag, value, &whole)) return CLI_USAGE;
            if (strcmp(flag, "--spp") == 0) {
                if (apply) o->samples = whole;
            } else if (strcmp(flag, "--seed") == 0) {
                if (apply) o->seed = whole;
            } else {
                if (whole > UINT32_MAX) return cli_usage_error(verb, "%s: '%.64s' is too large", flag, value);
                uint32_t *target = strcmp(flag, "--threads") == 0 ? &o->threads
                                   : strcmp(flag, "--width") == 0 ? &o->width
                                                                  : &o->height;
                if (apply) *target = (uint32_t)whole;
            }
        }
    }
    return 0;
}

typedef struct progress_state {
    int show;
    int drawn;
} progress_state;

static void draw_progress(progress_state *state, const dwv_bake_progress_t *p)
{
    if (!state->show) return;
    enum { WIDTH = 30 };
    double fraction = p->fraction < 0.0 ? 0.0 : p->fraction > 1.0 ? 1.0 : p->fraction;
    int filled = (int)(fraction * WIDTH + 0.5);
    char bar[WIDTH + 1];
    for (int i = 0; i < WIDTH; ++i) bar[i] = i < filled ? '#' : '.';
    bar[WIDTH] = '\0';
    fprintf(stderr, "\r[%s] %3.0f%%  %6.1f s  %llu spp  error ", bar, 100.0 * fraction, p->seconds,
            (unsigned long long)p->samples_per_pixel);
    if (isfinite(p->estimated_relative_error)) fprintf(stderr, "%7.3g%%  ", 100.0 * p->estimated_relative_error);
    else fprintf(stderr, "    --   ");
    fflush(stderr);
    state->drawn = 1;
}

static void end_progress(progress_state *state)
{
    if (state->drawn) fputc('\n', stderr);
    state->drawn = 0;
}

static double s_seconds(const dwv_image_t *image)
{
    dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
    return dwv_image_stats(image, &s) == DWV_SUCCESS ? s.seconds : 0.0;
}

/* path = prefix + suffix, or NULL after reporting when it does not fit. */
static char *join(const char *prefix, const char *suffix)
{
    size_t a = strlen(prefix), b = strlen(suffix);
    char *path = malloc(a + b + 1);
    if (!path) {
        fprintf(stderr, "dwivedi %s: out of memory\n", verb_name);
        return NULL;
    }
    memcpy(path, prefix, a);
    memcpy(path + a, suffix, b + 1);
    return path;
}

static void json_string(FILE *out, const char *text)
{
    fputc('"', out);
    for (const unsigned char *c = (const unsigned char *)text; *c; ++c) {
        if (*c == '"' || *c == '\\') fprintf(out, "\\%c", *c);
        else if (*c < 0x20) fprintf(out, "\\u%04x", *c);
        else fputc(*c, out);
    }
    fputc('"', out);
}

static void json_triple(FILE *out, const double v[3])
{
    fputc('[', out);
    for (int c = 0; c < 3; ++c) {
        if (c) fputs(", ", out);
        cli_json_number(out, v[c]);
    }
    fputc(']', out);
}

/* Writes the stats as JSON to `path`; 0 or -1 after reporting. */
static int write_stats_json(const char *path, const dwv_image_t *image, const dwv_bake_options_t *o,
                            const char *scene_name, const dwv_scene_t *scene)
{
    dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
    uint32_t count = 0;
    dwv_error_point_t *points = NULL;
    if (dwv_image_stats(image, &s) != DWV_SUCCESS ||
        dwv_image_error_vs_time(image, NULL, 0u, &count) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        return -1;
    }
    if (count > 0u) {
        points = calloc(count, sizeof *points);
        if (!points || dwv_image_error_vs_time(image, points, count, &count) != DWV_SUCCESS) {
            fprintf(stderr, "dwivedi %s: %s\n", verb_name, points ? dwv_last_error_message() : "out of memory");
            free(points);
            return -1;
        }
    }
    FILE *out = fopen(path, "wb");
    if (!out) {
        fprintf(stderr, "dwivedi %s: cannot write %s: %s\n", verb_name, path, strerror(errno));
        free(points);
        return -1;
    }
    fprintf(out, "{\n  \"scene\": ");
    json_string(out, scene_name);
    fprintf(out, ",\n  \"library_version\": \"%s\",\n  \"technique\": \"%s\",\n  \"width\": %u,\n  \"height\": %u,\n",
            dwv_version_string(), dwv_technique_name(s.technique) ? dwv_technique_name(s.technique) : "?", o->width,
            o->height);
    fprintf(out,
            "  \"spp\": %llu,\n  \"samples\": %llu,\n  \"walks\": %llu,\n  \"events\": %llu,\n  \"path_rays\": %llu,\n"
            "  \"seconds\": ",
            (unsigned long long)s.samples_per_pixel, (unsigned long long)s.samples, (unsigned long long)s.walks,
            (unsigned long long)s.events, (unsigned long long)s.path_rays);
    cli_json_number(out, s.seconds);
    fprintf(out, ",\n  \"estimated_relative_error\": ");
    cli_json_number(out, s.estimated_relative_error);
    fprintf(out, ",\n  \"mean_rgb\": ");
    json_triple(out, s.mean_rgb);
    fprintf(out, ",\n  \"truncated_weight\": ");
    json_triple(out, s.truncated_weight);
    fprintf(out, ",\n  \"threads\": %u,\n  \"warnings\": %llu,\n  \"features\": [", s.threads,
            (unsigned long long)s.warnings);
    int first = 1;
    for (uint32_t bit = 1u; bit != 0u; bit <<= 1) {
        if (!(s.features & bit) || !dwv_feature_name(bit)) continue;
        fprintf(out, "%s\"%s\"", first ? "" : ", ", dwv_feature_name(bit));
        first = 0;
    }
    fprintf(out, "]");
    uint64_t texture_bytes = 0, texels = 0;
    if (scene && dwv_scene_texture_memory(scene, &texture_bytes, &texels) == DWV_SUCCESS && texels > 0) {
        /* Texture memory per texel (issue 18): 1 byte per 8-bit channel, 4 per float channel. */
        fprintf(out, ",\n  \"texture_bytes\": %llu,\n  \"texture_texels\": %llu,\n  \"texture_bytes_per_texel\": ",
                (unsigned long long)texture_bytes, (unsigned long long)texels);
        cli_json_number(out, (double)texture_bytes / (double)texels);
    }
    fprintf(out, ",\n  \"error_vs_time\": [");
    for (uint32_t i = 0; i < count; ++i) {
        fprintf(out, "%s\n    {\"seconds\": ", i ? "," : "");
        cli_json_number(out, points[i].seconds);
        fprintf(out, ", \"estimated_relative_error\": ");
        cli_json_number(out, points[i].estimated_relative_error);
        fprintf(out, ", \"spp\": %llu}", (unsigned long long)points[i].samples_per_pixel);
    }
    fprintf(out, "%s]\n}\n", count ? "\n  " : "");
    free(points);
    int failed = ferror(out);
    failed |= fflush(out) != 0;
    failed |= fsync(fileno(out)) != 0;
    if (fclose(out) != 0 || failed) {
        fprintf(stderr, "dwivedi %s: cannot write %s: %s\n", verb_name, path, strerror(errno));
        remove(path);
        return -1;
    }
    return 0;
}

/* PREFIX + suffix with a '.' before PREFIX's file name: a hidden file beside the output, for the
 * temporary names (a process killed before its renames leaves `.NAME.exr.partial-PID`, which no
 * `*.exr` matches and no file browser shows, never a visible file that looks like an output). */
static char *hidden_join(const char *prefix, const char *suffix)
{
    const char *slash = strrchr(prefix, '/');
    size_t folder = slash ? (size_t)(slash - prefix) + 1u : 0u, rest = strlen(prefix) - folder, b = strlen(suffix);
    char *path = malloc(folder + 1u + rest + b + 1u);
    if (!path) {
        fprintf(stderr, "dwivedi %s: out of memory\n", verb_name);
        return NULL;
    }
    memcpy(path, prefix, folder);
    path[folder] = '.';
    memcpy(path + folder + 1u, prefix + folder, rest);
    memcpy(path + folder + 1u + rest, suffix, b + 1u);
    return path;
}

/* Writes the three outputs (four with bake passes: the multilayer PREFIX.layers.exr) under temporary
 * names, then renames them into place. */
int cli_bake_write_outputs(const char *prefix, const dwv_image_t *image, const dwv_bake_options_t *o,
                           const dwv_display_options_t *display, const char *scene_name, const dwv_scene_t *scene)
{
    static const char *const final_suffix[4] = {".exr", ".png", ".json", ".layers.exr"};
    uint32_t passes = 0u;
    if (dwv_image_passes(image, &passes) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        return -1;
    }
    const int outputs = passes != DWV_PASS_BIT(DWV_PASS_COMBINED) ? 4 : 3;
    char temp_suffix[4][64];
    for (int k = 0; k < outputs; ++k)
        snprintf(temp_suffix[k], sizeof temp_suffix[k], "%s.partial-%ld", final_suffix[k], (long)getpid());
    char *final_path[4] = {0}, *temp_path[4] = {0};
    int status = -1, written = 0;
    for (int k = 0; k < outputs; ++k) {
        if (!(final_path[k] = join(prefix, final_suffix[k])) || !(temp_path[k] = hidden_join(prefix, temp_suffix[k])))
            goto done;
    }
    if (dwv_image_write_exr(image, temp_path[0]) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        goto done;
    }
    written = 1;
    if (dwv_image_write_display_png(image, temp_path[1], display) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        goto done;
    }
    written = 2;
    if (write_stats_json(temp_path[2], image, o, scene_name, scene) != 0) goto done;
    written = 3;
    if (outputs == 4) {
        if (dwv_image_write_exr_layers(image, temp_path[3]) != DWV_SUCCESS) {
            fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
            goto done;
        }
        written = 4;
    }
    for (int k = 0; k < outputs; ++k) {
        if (rename(temp_path[k], final_path[k]) != 0) {
            fprintf(stderr, "dwivedi %s: cannot rename %s to %s: %s\n", verb_name, temp_path[k], final_path[k],
                    strerror(errno));
            goto done;
        }
    }
    written = 0;
    status = 0;
done:
    for (int k = 0; k < written; ++k) remove(temp_path[k]);
    for (int k = 0; k < outputs; ++k) {
        free(final_path[k]);
        free(temp_path[k]);
    }
    return status;
}

/* Checks, before any time is spent baking, what would otherwise fail only at the end: that a file
 * can be created beside PREFIX (a probe file, created and removed: access() says yes to root on any
 * folder) and that the OCIO config, display, view and look exist (a 1 x 1 image through them). */
int cli_bake_check_outputs(const char *prefix, const dwv_display_options_t *display)
{
    char suffix[64];
    snprintf(suffix, sizeof suffix, ".probe-%ld", (long)getpid());
    char *probe = join(prefix, suffix);
    if (!probe) return -1;
    FILE *f = fopen(probe, "wb");
    if (!f) {
        fprintf(stderr, "dwivedi %s: --out %s: cannot create files there (%s): %s\n", verb_name, prefix, probe, strerror(errno));
        free(probe);
        return -1;
    }
    fclose(f);
    remove(probe);
    free(probe);
    static const float grey[4] = {0.18f, 0.18f, 0.18f, 1.0f};
    dwv_image_t *pixel = NULL;
    uint8_t rgba8[4];
    int status = 0;
    if (dwv_image_create(1u, 1u, grey, &pixel) != DWV_SUCCESS ||
        dwv_image_to_display(pixel, display, rgba8, sizeof rgba8) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        status = -1;
    }
    dwv_image_release(pixel);
    return status;
}

int cli_bake_load(int argc, char **argv, cli_bake_flags *f, dwv_bake_options_t *o, dwv_scene_t **scene)
{
    const cli_bake_flags none = {NULL, NULL, 0, 0, 0u, 0u, DWV_DISPLAY_OPTIONS_INIT, 0, 0, 0u, CLI_MPI_TIMEOUT_DEFAULT};
    const dwv_bake_options_t defaults = DWV_BAKE_OPTIONS_INIT;
    *f = none;
    *o = defaults;
    *scene = NULL;
    /* first pass: syntax and the scene path; the scene's settings come next, then the flags win */
    if (parse_overrides(argc, argv, f, o, 0)) return CLI_USAGE;
    if (!f->prefix) return cli_usage_error(verb, "--out PREFIX is required");
    dwv_result_t r = f->scene_path ? dwv_scene_load(f->scene_path, scene, o) : dwv_scene_create_default(scene, o);
    if (r != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        return CLI_FAILED;
    }
    if (parse_overrides(argc, argv, f, o, 1)) {
        dwv_scene_release(*scene);
        *scene = NULL;
        return CLI_USAGE;
    }
    return CLI_OK;
}

/* Whether argv asks for --mpi (before anything else is parsed: MPI starts first). */
static int wants_mpi(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--mpi") == 0) return 1;
    return 0;
}

static int run(int argc, char **argv)
{
    if (wants_mpi(argc, argv)) {
#ifdef DWV_CLI_MPI
        return cli_mpi_bake(argc, argv);
#else
        fprintf(stderr, "dwivedi bake: --mpi: this dwivedi was built without MPI (install libopenmpi-dev, then "
                        "configure and build again; docs/farm.md)\n");
        return CLI_FAILED;
#endif
    }
    cli_bake_flags f;
    dwv_bake_options_t o;
    dwv_scene_t *scene = NULL;
    int loaded = cli_bake_load(argc, argv, &f, &o, &scene);
    if (loaded != CLI_OK) return loaded;
    if (f.mpi_chunk != 0u || f.mpi_timeout != CLI_MPI_TIMEOUT_DEFAULT) {
        dwv_scene_release(scene);
        return cli_usage_error(verb, "--mpi-chunk and --mpi-timeout need --mpi");
    }
    dwv_result_t r;
    if (f.chunk) {
        /* A chunk bakes its whole range: the scene file's budgets do not apply, explicit ones are refused. */
        if (f.budget) {
            dwv_scene_release(scene);
            return cli_usage_error(verb, "--samples bakes the whole range: no --time or --error");
        }
        o.time_limit = 0.0;
        o.target_error = 0.0;
    }
    if (cli_bake_check_outputs(f.prefix, &f.display) != 0) {
        dwv_scene_release(scene);
        return CLI_FAILED;
    }

    progress_state progress = {!f.quiet && isatty(STDERR_FILENO), 0};
    struct sigaction action, old_int, old_term;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &old_int);
    sigaction(SIGTERM, &action, &old_term);

    dwv_bake_t *bake = NULL;
    dwv_image_t *image = NULL;
    int exit_code = CLI_FAILED;
    r = dwv_bake_start(scene, &o, &bake);
    if (r != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        exit_code = r == DWV_ERROR_OUT_OF_MEMORY ? CLI_FAILED : CLI_USAGE;
        goto done;
    }
    for (int32_t finished = 0; !finished;) {
        if (dwv_bake_wait(bake, 0.1, &finished) != DWV_SUCCESS) break;
        if (interrupted) {
            dwv_bake_cancel(bake);
            interrupted = 0;
        }
        dwv_bake_progress_t p = DWV_BAKE_PROGRESS_INIT;
        if (dwv_bake_progress(bake, &p) == DWV_SUCCESS) draw_progress(&progress, &p);
    }
    end_progress(&progress);
    r = dwv_bake_finish(bake, &image);
    if (r == DWV_ERROR_CANCELLED) {
        fprintf(stderr, "dwivedi %s: cancelled; nothing written\n", verb_name);
        exit_code = 130;
        goto done;
    }
    if (r != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi %s: %s\n", verb_name, dwv_last_error_message());
        goto done;
    }
    if (f.chunk) {
        char *path = join(f.prefix, ".dwvpart");
        if (!path) goto done;
        r = dwv_image_write_partial(image, path);
        if (r != DWV_SUCCESS) {
            fprintf(stderr, "dwivedi bake: %s\n", dwv_last_error_message());
            free(path);
            goto done;
        }
        printf("baked samples %llu:%llu of %llu, %ux%u, %.2f s\nwrote %s\n", (unsigned long long)o.sample_first,
               (unsigned long long)o.sample_count, (unsigned long long)o.samples, o.width, o.height,
               s_seconds(image), path);
        free(path);
        exit_code = CLI_OK;
        goto done;
    }
    if (cli_bake_write_outputs(f.prefix, image, &o, &f.display, f.scene_path ? f.scene_path : "default", scene) != 0)
        goto done;

    dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
    dwv_image_stats(image, &s);
    printf("baked %ux%u, %llu spp, %.2f s, estimated relative error %.3g%%, %.3g M events/s\n", o.width, o.height,
           (unsigned long long)s.samples_per_pixel, s.seconds, 100.0 * s.estimated_relative_error,
           s.seconds > 0.0 ? 1e-6 * (double)s.events / s.seconds : 0.0);
    printf("wrote %s.exr, %s.png, %s.json", f.prefix, f.prefix, f.prefix);
    if (o.passes & ~DWV_PASS_BIT(DWV_PASS_COMBINED)) printf(", %s.layers.exr", f.prefix);
    printf("\n");
    exit_code = CLI_OK;
done:
    dwv_image_release(image);
    dwv_bake_release(bake);
    dwv_scene_release(scene);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    return exit_code;
}

static void merge_help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi merge PART.dwvpart... --out PREFIX [--ocio CONFIG] [--display NAME] [--view NAME]\n"
            "           [--look NAME] [--exposure E] [--gamma G]\n\n"
            "Merges the chunks of a split bake ('dwivedi bake ... --samples FIRST:COUNT', docs/farm.md) into\n"
            "PREFIX.exr, PREFIX.png and PREFIX.json, bit for bit what one 'dwivedi bake' of the same scene,\n"
            "options, seed and --spp makes. The chunks must come from one scene, options, seed and library\n"
            "version and cover the samples 0 to spp-1 exactly once, in any order; else nothing is written\n"
            "and the message names the chunk at fault. error_vs_time has a point per chunk prefix in sample\n"
            "order; its seconds are the chunks' bake seconds added up.\n");
}

static int merge_run(int argc, char **argv)
{
    static const char merge_verb[] = "merge";
    verb_name = merge_verb;
    dwv_display_options_t display = DWV_DISPLAY_OPTIONS_INIT;
    const char *prefix = NULL;
    const char **parts = calloc((size_t)argc + 1u, sizeof *parts);
    if (!parts) {
        fprintf(stderr, "dwivedi merge: out of memory\n");
        return CLI_FAILED;
    }
    uint32_t count = 0;
    int code = CLI_USAGE;
    for (int i = 1; i < argc; ++i) {
        const char *flag = argv[i], *value;
        if (flag[0] != '-' || flag[1] == '\0') {
            parts[count++] = flag;
            continue;
        }
        static const char *const flags[] = {"--out", "--ocio", "--display", "--view", "--look", "--exposure", "--gamma"};
        int known = 0;
        for (size_t k = 0; k < sizeof flags / sizeof flags[0]; ++k) known |= strcmp(flag, flags[k]) == 0;
        if (!known) {
            cli_usage_error(merge_verb, "unknown argument '%.64s'", flag);
            goto done;
        }
        if (!(value = cli_flag_value(merge_verb, argc, argv, &i))) goto done;
        if (strcmp(flag, "--out") == 0) {
            if (value[0] == '\0') {
                cli_usage_error(merge_verb, "--out: the prefix is empty");
                goto done;
            }
            prefix = value;
        } else if (strcmp(flag, "--ocio") == 0) display.config_path = value;
        else if (strcmp(flag, "--display") == 0) display.display = value;
        else if (strcmp(flag, "--view") == 0) display.view = value;
        else if (strcmp(flag, "--look") == 0) display.look = value;
        else if (cli_parse_double(merge_verb, flag, value, strcmp(flag, "--gamma") == 0 ? &display.gamma : &display.exposure))
            goto done;
    }
    if (!prefix) {
        cli_usage_error(merge_verb, "--out PREFIX is required");
        goto done;
    }
    if (count == 0u) {
        cli_usage_error(merge_verb, "no chunk files given");
        goto done;
    }
    code = CLI_FAILED;
    if (cli_bake_check_outputs(prefix, &display) != 0) goto done;
    dwv_image_t *image = NULL;
    if (dwv_merge_partials(parts, count, &image) != DWV_SUCCESS) {
        fprintf(stderr, "dwivedi merge: %s\n", dwv_last_error_message());
        goto done;
    }
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = info.width;
    o.height = info.height;
    if (cli_bake_write_outputs(prefix, image, &o, &display, "merged", NULL) == 0) {
        dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &s);
        printf("merged %u chunk(s): %ux%u, %llu spp, %.2f s of bakes, estimated relative error %.3g%%\n", count,
               info.width, info.height, (unsigned long long)s.samples_per_pixel, s.seconds,
               100.0 * s.estimated_relative_error);
        printf("wrote %s.exr, %s.png, %s.json\n", prefix, prefix, prefix);
        code = CLI_OK;
    }
    dwv_image_release(image);
done:
    free(parts);
    return code;
}

const cli_verb cli_verb_merge = {"merge", "merge the chunks of a split bake into EXR, PNG and JSON", merge_run, merge_help};

const cli_verb cli_verb_bake = {"bake", "bake a scene (or the default scene) to EXR, PNG and JSON", run, help};
