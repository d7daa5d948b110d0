#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int cli_usage_error(const char *verb, const char *format, ...)
{
    /* One line, whatever the user typed: control characters echoed from arguments become '?'. */
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    for (char *c = message; *c; ++c)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
    fprintf(stderr, "dwivedi%s%s: %s (see 'dwivedi%s%s --help')\n", verb ? " " : "", verb ? verb : "", message,
            verb ? " " : "", verb ? verb : "");
    return CLI_USAGE;
}

const char *cli_flag_value(const char *verb, int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        cli_usage_error(verb, "%s needs a value", argv[*i]);
        return NULL;
    }
    ++*i;
    return argv[*i];
}

int cli_parse_double(const char *verb, const char *flag, const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    double value = strtod(text, &end);
    if (end == text || *end != '\0') return cli_usage_error(verb, "%s: '%.64s' is not a number", flag, text);
    if (errno == ERANGE && isinf(value))
        return cli_usage_error(verb, "%s: '%.64s' is too large", flag, text);
    *out = value;
    return 0;
}

int cli_parse_u64(const char *verb, const char *flag, const char *text, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    if (text[0] == '-' || text[0] == '\0')
        return cli_usage_error(verb, "%s: '%.64s' is not a non-negative whole number", flag, text);
    uintmax_t value = strtoumax(text, &end, 10);
    if (*end != '\0') return cli_usage_error(verb, "%s: '%.64s' is not a non-negative whole number", flag, text);
    if (errno == ERANGE || value > UINT64_MAX) return cli_usage_error(verb, "%s: '%.64s' is too large", flag, text);
    *out = (uint64_t)value;
    return 0;
}

int cli_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

void cli_json_number(FILE *out, double value)
{
    if (isfinite(value)) fprintf(out, "%.17g", value);
    else fputs("null", out);
}
