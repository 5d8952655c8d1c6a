/* glint — the tests' tiny harness: CHECK records a failure and carries on, so one run reports
 * every broken expectation; check_exit() turns the count into the process status. */
#ifndef GLINT_CHECK_H
#define GLINT_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_failures_ = 0;
static int check_count_ = 0;

#define CHECK(cond, ...)                                                                                               \
    do {                                                                                                               \
        check_count_++;                                                                                                \
        if (!(cond)) {                                                                                                 \
            check_failures_++;                                                                                         \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);                                   \
            fprintf(stderr, __VA_ARGS__);                                                                              \
            fputc('\n', stderr);                                                                                       \
        }                                                                                                              \
    } while (0)

/* |a - b| <= tol, and neither is NaN. */
#define CHECK_NEAR(a, b, tol, ...)                                                                                     \
    do {                                                                                                               \
        double check_a_ = (double)(a), check_b_ = (double)(b), check_t_ = (double)(tol);                               \
        check_count_++;                                                                                                \
        if (!(fabs(check_a_ - check_b_) <= check_t_)) {                                                                \
            check_failures_++;                                                                                         \
            fprintf(stderr, "%s:%d: %s = %.9g, expected %s = %.9g within %.3g: ", __FILE__, __LINE__, #a, check_a_,    \
                    #b, check_b_, check_t_);                                                                           \
            fprintf(stderr, __VA_ARGS__);                                                                              \
            fputc('\n', stderr);                                                                                       \
        }                                                                                                              \
    } while (0)

/* Exit status for ctest: 0 all passed, 1 a failure, 77 (SKIP_RETURN_CODE) when nothing ran. */
static inline int check_exit(const char *name) {
    if (check_failures_) {
        fprintf(stderr, "%s: %d of %d checks failed\n", name, check_failures_, check_count_);
        return 1;
    }
    if (check_count_ == 0) {
        fprintf(stderr, "%s: no checks ran\n", name);
        return 1;
    }
    printf("%s: %d checks passed\n", name, check_count_);
    return 0;
}

#define CHECK_SKIP 77

#endif
