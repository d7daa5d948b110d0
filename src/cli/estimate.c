/* dwivedi estimate: walk-level estimates with a known scoring on the analytic shapes. */
#include <math.h>
#include <string.h>

#include "cli.h"
#include <dwivedi.h>

static void help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi estimate --scene halfspace|slab|sphere [--thickness D] [--radius R]\n"
            "           --albedo A [--sigma-t S] [--anisotropy G] [--incidence normal|diffuse|COSINE]\n"
            "           [--light front|back|both] --technique T --walks N [--seed S] [--threads N]\n"
            "           [--max-events N] [--json]\n\n"
            "Runs N random walks that enter the medium at its front point and scores their exits:\n"
            "1 through a lit face (half-space, slab), the exit normal's cosine to the light on the\n"
            "sphere. A front-lit half-space with normal incidence gives the total diffuse\n"
            "reflectance; a back-lit slab its total transmittance.\n\n"
            "  --scene        halfspace (z >= 0), slab (0 <= z <= D), sphere (radius R)\n"
            "  --thickness D  slab thickness (default 1)      --radius R  sphere radius (default 1)\n"
            "  --albedo A     single-scattering albedo in [0, 1] (A or R,G,B for three channels)\n"
            "  --sigma-t S    extinction (S or R,G,B); lengths are in mean free paths without it\n"
            "  --anisotropy G Henyey-Greenstein g in (-1, 1) (default 0)\n"
            "  --incidence    normal (default), diffuse (cosine-weighted), or a cosine in (0, 1]\n"
            "  --light        front (default), back, both: which exits score\n"
            "  --technique    auto, classical, poe, closest, incident, backward, cycles, sheet\n"
            "  --walks N      number of walks, 2 to 10^12\n"
            "  --seed S       random seed (default 0); the result does not depend on --threads\n"
            "  --threads N    worker threads (default: all cores)\n"
            "  --max-events N cap on scattering events per walk (default 10^6); capped weight is\n"
            "                 reported as truncated_weight\n"
            "  --json         one JSON object: mean, stderr, variance (per walk), walks, events,\n"
            "                 seconds, efficiency (1 / (variance x seconds per walk)),\n"
            "                 truncated_weight, truncated_walks, channels, technique\n");
}

/* "X" or "X,Y,Z" into values[]; returns the count (1 or 3) or 0 after a usage error. */
static int parse_channels(const char *verb, const char *flag, const char *text, double values[3])
{
    char buffer[256];
    if (strlen(text) >= sizeof buffer) {
        cli_usage_error(verb, "%s: value too long", flag);
        return 0;
    }
    strcpy(buffer, text);
    int count = 0;
    for (char *part = buffer, *next; part; part = next) {
        next = strchr(part, ',');
        if (next) *next++ = '\0';
        if (count == 3) {
            cli_usage_error(verb, "%s: give one value or three (R,G,B)", flag);
            return 0;
        }
        if (cli_parse_double(verb, flag, part, &values[count])) return 0;
        ++count;
    }
    if (count == 2) {
        cli_usage_error(verb, "%s: give one value or three (R,G,B)", flag);
        return 0;
    }
    return count;
}

static void print_channels(const double *v, uint32_t channels)
{
    if (channels == 1) {
        cli_json_number(stdout, v[0]);
        return;
    }
    printf("[");
    for (uint32_t c = 0; c < channels; ++c) {
        if (c) printf(", ");
        cli_json_number(stdout, v[c]);
    }
    printf("]");
}

static int run(int argc, char **argv)
{
    static const char verb[] = "estimate";
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    double albedo[3] = {0}, sigma[3] = {1.0, 1.0, 1.0};
    int albedo_count = 0, sigma_count = 0, have_scene = 0, have_technique = 0, have_walks = 0, json = 0;
    for (int i = 1; i < argc; ++i) {
        const char *flag = argv[i], *value = NULL;
        if (strcmp(flag, "--json") == 0) {
            json = 1;
            continue;
        }
        static const char *const flags[] = {"--scene", "--thickness", "--radius", "--albedo", "--sigma-t",
                                            "--anisotropy", "--incidence", "--light", "--technique", "--walks",
                                            "--seed", "--threads", "--max-events"};
        int known = 0;
        for (size_t f = 0; f < sizeof flags / sizeof flags[0]; ++f) known |= strcmp(flag, flags[f]) == 0;
        if (!known) return cli_usage_error(verb, "unknown argument '%.64s'", flag);
        if (!(value = cli_flag_value(verb, argc, argv, &i))) return CLI_USAGE;
        uint64_t whole;
        if (strcmp(flag, "--scene") == 0) {
            if (strcmp(value, "halfspace") == 0) o.shape = DWV_SHAPE_HALFSPACE;
            else if (strcmp(value, "slab") == 0) o.shape = DWV_SHAPE_SLAB;
            else if (strcmp(value, "sphere") == 0) o.shape = DWV_SHAPE_SPHERE;
            else return cli_usage_error(verb, "--scene: unknown scene '%.64s' (halfspace, slab or sphere)", value);
            have_scene = 1;
        } else if (strcmp(flag, "--thickness") == 0) {
            if (cli_parse_double(verb, flag, value, &o.thickness)) return CLI_USAGE;
        } else if (strcmp(flag, "--radius") == 0) {
            if (cli_parse_double(verb, flag, value, &o.radius)) return CLI_USAGE;
        } else if (strcmp(flag, "--albedo") == 0) {
            if (!(albedo_count = parse_channels(verb, flag, value, albedo))) return CLI_USAGE;
        } else if (strcmp(flag, "--sigma-t") == 0) {
            if (!(sigma_count = parse_channels(verb, flag, value, sigma))) return CLI_USAGE;
        } else if (strcmp(flag, "--anisotropy") == 0) {
            if (cli_parse_double(verb, flag, value, &o.medium.anisotropy)) return CLI_USAGE;
        } else if (strcmp(flag, "--incidence") == 0) {
            if (strcmp(value, "normal") == 0) {
                o.incidence = DWV_INCIDENCE_COSINE;
                o.incidence_cosine = 1.0;
            } else if (strcmp(value, "diffuse") == 0) {
                o.incidence = DWV_INCIDENCE_DIFFUSE;
            } else {
                o.incidence = DWV_INCIDENCE_COSINE;
                if (cli_parse_double(verb, flag, value, &o.incidence_cosine)) return CLI_USAGE;
            }
        } else if (strcmp(flag, "--light") == 0) {
            if (strcmp(value, "front") == 0) o.light = DWV_LIGHT_FRONT;
            else if (strcmp(value, "back") == 0) o.light = DWV_LIGHT_BACK;
            else if (strcmp(value, "both") == 0) o.light = DWV_LIGHT_BOTH;
            else return cli_usage_error(verb, "--light: unknown light '%.64s' (front, back or both)", value);
        } else if (strcmp(flag, "--technique") == 0) {
            if (dwv_technique_from_name(value, &o.technique) != DWV_SUCCESS)
                return cli_usage_error(verb, "--technique: %s", dwv_last_error_message());
            have_technique = 1;
        } else if (strcmp(flag, "--walks") == 0) {
            if (cli_parse_u64(verb, flag, value, &o.walks)) return CLI_USAGE;
            have_walks = 1;
        } else if (strcmp(flag, "--seed") == 0) {
            if (cli_parse_u64(verb, flag, value, &o.seed)) return CLI_USAGE;
        } else if (strcmp(flag, "--threads") == 0 || strcmp(flag, "--max-events") == 0) {
            if (cli_parse_u64(verb, flag, value, &whole)) return CLI_USAGE;
            if (whole > UINT32_MAX) return cli_usage_error(verb, "%s: '%.64s' is too large", flag, value);
            if (flag[2] == 't') o.threads = (uint32_t)whole;
            else o.max_events = (uint32_t)whole;
        }
    }
    if (!have_scene) return cli_usage_error(verb, "--scene is required");
    if (!albedo_count) return cli_usage_error(verb, "--albedo is required");
    if (!have_technique) return cli_usage_error(verb, "--technique is required");
    if (!have_walks) return cli_usage_error(verb, "--walks is required");
    uint32_t channels = albedo_count == 3 || sigma_count == 3 ? 3u : 1u;
    o.medium.channels = channels;
    for (uint32_t c = 0; c < 3; ++c) {
        o.medium.albedo[c] = albedo[albedo_count == 3 ? c : 0];
        o.medium.sigma_t[c] = sigma[sigma_count == 3 ? c : 0];
    }

    dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;
    dwv_result_t status = dwv_estimate(&o, &r);
    if (status == DWV_ERROR_OUT_OF_MEMORY) {
        fprintf(stderr, "dwivedi estimate: %s\n", dwv_last_error_message());
        return CLI_FAILED;
    }
    if (status != DWV_SUCCESS) return cli_usage_error(verb, "%s", dwv_last_error_message());

    if (json) {
        printf("{\"technique\": \"%s\", \"channels\": %u, \"mean\": ", dwv_technique_name(o.technique), r.channels);
        print_channels(r.mean, r.channels);
        printf(", \"stderr\": ");
        print_channels(r.std_error, r.channels);
        printf(", \"variance\": ");
        print_channels(r.variance, r.channels);
        printf(", \"walks\": %llu, \"events\": %llu, \"seconds\": ", (unsigned long long)r.walks,
               (unsigned long long)r.events);
        cli_json_number(stdout, r.seconds);
        printf(", \"efficiency\": ");
        cli_json_number(stdout, r.efficiency);
        printf(", \"truncated_weight\": ");
        print_channels(r.truncated_weight, r.channels);
        printf(", \"truncated_walks\": %llu}\n", (unsigned long long)r.truncated_walks);
    } else {
        for (uint32_t c = 0; c < r.channels; ++c)
            printf("mean[%u]            %.10g +- %.3g (1 sigma)\n", c, r.mean[c], r.std_error[c]);
        printf("variance per walk  %.6g\n", r.variance[0]);
        printf("walks              %llu\n", (unsigned long long)r.walks);
        printf("events             %llu (%.1f per walk, %.2f ns per event)\n", (unsigned long long)r.events,
               (double)r.events / (double)r.walks, r.events ? 1e9 * r.seconds / (double)r.events : 0.0);
        printf("seconds            %.4g\n", r.seconds);
        printf("efficiency         %.6g\n", r.efficiency);
        printf("truncated weight   %.3g (%llu walks hit the event cap)\n", r.truncated_weight[0],
               (unsigned long long)r.truncated_walks);
    }
    return CLI_OK;
}

const cli_verb cli_verb_estimate = {"estimate", "random-walk estimates on a half-space, slab or sphere", run, help};
