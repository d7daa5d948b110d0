/* dwivedi: the command-line tool. Each verb lives in its own file and reaches the library only
 * through capi. */
#include <string.h>

#include "cli.h"
#include <dwivedi.h>

static const cli_verb *const verbs[] = {&cli_verb_bake, &cli_verb_merge, &cli_verb_estimate, &cli_verb_v0, &cli_verb_bench};
#define VERB_COUNT (sizeof verbs / sizeof verbs[0])

static void print_help(FILE *out)
{
    fprintf(out,
            "usage: dwivedi <verb> [options]\n"
            "       dwivedi --help | --version\n\n"
            "Dwivedi-guided random-walk subsurface scattering (library %s).\n\nverbs:\n",
            dwv_version_string());
    for (size_t i = 0; i < VERB_COUNT; ++i) fprintf(out, "  %-10s %s\n", verbs[i]->name, verbs[i]->summary);
    fprintf(out, "\n'dwivedi <verb> --help' describes a verb. Exit codes: 0 done, 1 failed, 2 bad usage.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) return cli_usage_error(NULL, "no verb given");
    if (cli_is_help(argv[1])) {
        print_help(stdout);
        return CLI_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("dwivedi %s\n", dwv_version_string());
        return CLI_OK;
    }
    for (size_t i = 0; i < VERB_COUNT; ++i) {
        if (strcmp(argv[1], verbs[i]->name) != 0) continue;
        for (int a = 2; a < argc; ++a) {
            if (cli_is_help(argv[a])) {
                verbs[i]->help(stdout);
                return CLI_OK;
            }
        }
        return verbs[i]->run(argc - 1, argv + 1);
    }
    return cli_usage_error(NULL, "unknown verb '%.64s'", argv[1]);
}
