/* A minimal check harness for the C unit tests: every CHECK counts, failures print where and why,
 * and check_report() prints the closing line "N passed, N failed" and gives the exit code. */
#ifndef DWV_TESTS_CHECK_H
#define DWV_TESTS_CHECK_H

#include <stdio.h>

static int check_passed, check_failed;

#define CHECK(condition, ...)                                                          \
    do {                                                                               \
        if (condition) {                                                               \
            ++check_passed;                                                            \
        } else {                                                                       \
            ++check_failed;                                                            \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #condition); \
            fprintf(stderr, __VA_ARGS__);                                              \
            fputc('\n', stderr);                                                       \
        }                                                                              \
    } while (0)

static inline int check_report(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, check_passed, check_failed);
    return check_failed == 0 && check_passed > 0 ? 0 : 1;
}

#endif
