/* The checks the C tests of the runtime's C ABI share: CHECK(condition, printf-style message),
 * ok(status, call) for a call that must succeed, refused(status, expected, fragment, what) for
 * one that must fail with `expected` and a message containing `fragment`; `checks` and
 * `failures` count them for the test's exit status. One test program includes it once. */
#ifndef CHAINTUBE_CAPI_CHECK_H
#define CHAINTUBE_CAPI_CHECK_H

#include "chaintube/runtime_c.h"

#include <stdio.h>
#include <string.h>

static int failures = 0;
static long checks = 0;

#define CHECK(condition, ...)                                                                      \
    do {                                                                                           \
        ++checks;                                                                                  \
        if (!(condition)) {                                                                        \
            fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #condition);                   \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fprintf(stderr, "\n");                                                                 \
            ++failures;                                                                            \
        }                                                                                          \
    } while (0)

/* A call that must succeed; returns whether it did. */
static inline int ok(chaintube_status status, const char* call)
{
    ++checks;
    if (status == CHAINTUBE_OK) return 1;
    fprintf(stderr, "FAIL %s returned %s: %s\n", call, chaintube_status_name(status),
            chaintube_last_error());
    ++failures;
    return 0;
}

/* A call that must be refused with `expected` and a message containing `fragment`. */
static inline void refused(chaintube_status status, chaintube_status expected, const char* fragment,
                           const char* what)
{
    ++checks;
    if (status != expected || !strstr(chaintube_last_error(), fragment)) {
        fprintf(stderr, "FAIL %s: %s \"%s\", expected %s and \"%s\"\n", what,
                chaintube_status_name(status), chaintube_last_error(),
                chaintube_status_name(expected), fragment);
        ++failures;
    }
}

#endif
