/* The `dwivedi` command: verbs and shared argument handling. A client of capi only. */
#ifndef DWV_CLI_H
#define DWV_CLI_H

#include <stdint.h>
#include <stdio.h>

/* Exit codes: 0 success, 1 the work failed, 2 bad usage (one line on stderr). */
enum { CLI_OK = 0, CLI_FAILED = 1, CLI_USAGE = 2 };

typedef struct cli_verb {
    const char *name;
    const char *summary;
    int (*run)(int argc, char **argv); /* argv[0] is the verb */
    void (*help)(FILE *out);
} cli_verb;

extern const cli_verb cli_verb_v0;
extern const cli_verb cli_verb_bench;
extern const cli_verb cli_verb_estimate;
extern const cli_verb cli_verb_bake;
extern const cli_verb cli_verb_merge;

/* `dwivedi bench bake` (bench_bake.c), reached through the bench verb. */
int cli_bench_bake(int argc, char **argv);
void cli_bench_bake_help(FILE *out);

/* Prints "dwivedi VERB: message" on stderr as one line and returns CLI_USAGE. */
int cli_usage_error(const char *verb, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* The value after flag argv[*i] (advancing *i), or NULL after reporting a usage error. */
const char *cli_flag_value(const char *verb, int argc, char **argv, int *i);
/* Whole-string conversions; 0 on success, CLI_USAGE after reporting. NaN and inf are accepted as
 * numbers here so that the library can reject them with its own message. */
int cli_parse_double(const char *verb, const char *flag, const char *text, double *out);
int cli_parse_u64(const char *verb, const char *flag, const char *text, uint64_t *out);
/* argv[i] is -h or --help. */
int cli_is_help(const char *arg);
/* A double as JSON: %.17g, or null where it is not finite. */
void cli_json_number(FILE *out, double value);

#endif
