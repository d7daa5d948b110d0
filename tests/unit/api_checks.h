/* Checks that a refused call of the public API leaves a message of its own: prime_message() leaves
 * a known message behind before the call, so that fresh_message_with() can tell a message the call
 * set from a stale one. */
#ifndef DWV_TESTS_API_CHECKS_H
#define DWV_TESTS_API_CHECKS_H

#include <string.h>

#include <dwivedi.h>

static const char PRIMER_NAME[] = "no-such-technique-primer";

/* Leaves a known message behind, so that a check can tell a new message from a stale one. */
static inline void prime_message(void)
{
    dwv_technique_t ignored;
    (void)dwv_technique_from_name(PRIMER_NAME, &ignored);
}

/* The thread's message is not empty, not the primer's, and names `keyword`. */
static inline int fresh_message_with(const char *keyword)
{
    const char *message = dwv_last_error_message();
    return message[0] != '\0' && strstr(message, PRIMER_NAME) == NULL && strstr(message, keyword) != NULL;
}

#endif
