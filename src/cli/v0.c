/* dwivedi v0: the diffusion length of one albedo by one method. */
#include <string.h>

#include "cli.h"
#include <dwivedi.h>

static void help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi v0 --albedo A [--method exact|case|deon|fast] [--json]\n\n"
            "The diffusion length v0 and kappa0 = 1/v0, the root of alpha atanh(kappa) = kappa\n"
            "(Meng et al. 2016, supplemental Eq. 8), for the single-scattering albedo A in [0, 1].\n\n"
            "  --albedo A     single-scattering albedo, 0 <= A <= 1 (required)\n"
            "  --method M     exact (default): the root to double precision\n"
            "                 case: Case et al.'s series (supplemental Eqs. 10 and 11)\n"
            "                 deon: d'Eon and Krivanek 2020's fit (as in Cycles)\n"
            "                 fast: dwivedi's approximation for render time\n"
            "  --json         print one JSON object with keys albedo, method, v0, kappa,\n"
            "                 one_minus_kappa, log_one_minus_kappa; a number that is not finite\n"
            "                 (v0 at albedo 1, log_one_minus_kappa at albedo 0) is null\n");
}

static int run(int argc, char **argv)
{
    static const char verb[] = "v0";
    double albedo = 0.0;
    int have_albedo = 0, json = 0;
    const char *method_name = "exact";
    for (int i = 1; i < argc; ++i) {
        const char *value;
        if (strcmp(argv[i], "--albedo") == 0) {
            if (!(value = cli_flag_value(verb, argc, argv, &i))) return CLI_USAGE;
            if (cli_parse_double(verb, "--albedo", value, &albedo)) return CLI_USAGE;
            have_albedo = 1;
        } else if (strcmp(argv[i], "--method") == 0) {
            if (!(method_name = cli_flag_value(verb, argc, argv, &i))) return CLI_USAGE;
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else {
            return cli_usage_error(verb, "unknown argument '%.64s'", argv[i]);
        }
    }
    if (!have_albedo) return cli_usage_error(verb, "--albedo is required");
    dwv_v0_method_t method;
    if (dwv_v0_method_from_name(method_name, &method) != DWV_SUCCESS)
        return cli_usage_error(verb, "--method: unknown method '%.64s' (exact, case, deon or fast)", method_name);
    dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
    if (dwv_diffusion_length(albedo, method, &d) != DWV_SUCCESS)
        return cli_usage_error(verb, "--albedo: %s", dwv_last_error_message());

    if (json) {
        printf("{\"albedo\": ");
        cli_json_number(stdout, d.albedo);
        printf(", \"method\": \"%s\", \"v0\": ", dwv_v0_method_name(d.method));
        cli_json_number(stdout, d.v0);
        printf(", \"kappa\": ");
        cli_json_number(stdout, d.kappa);
        printf(", \"one_minus_kappa\": ");
        cli_json_number(stdout, d.one_minus_kappa);
        printf(", \"log_one_minus_kappa\": ");
        cli_json_number(stdout, d.log_one_minus_kappa);
        printf("}\n");
    } else {
        printf("albedo               %.17g\n", d.albedo);
        printf("method               %s\n", dwv_v0_method_name(d.method));
        printf("v0                   %.17g\n", d.v0);
        printf("kappa                %.17g\n", d.kappa);
        printf("one_minus_kappa      %.17g\n", d.one_minus_kappa);
        printf("log_one_minus_kappa  %.17g\n", d.log_one_minus_kappa);
        printf("log_ratio L          %.17g\n", d.log_ratio);
    }
    return CLI_OK;
}

const cli_verb cli_verb_v0 = {"v0", "diffusion length v0(albedo) by one of four methods", run, help};
