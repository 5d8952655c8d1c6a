/* glint tests — the glint program run as a user would: in a scratch directory of its own, stdin
 * empty, stdout and stderr captured. For tests that take the program's path as their argument. */
#ifndef GLINT_CLI_HARNESS_H
#define GLINT_CLI_HARNESS_H

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

static const char *glint;                     /* the program under test */
static char tmp[512];                         /* its working directory */
static char out_text[65536], err_text[65536]; /* the last run's stdout and stderr */

/* Reads file `name` (relative to tmp) into buf, NUL-terminated; returns its length (0: none). */
static size_t read_file(const char *name, char *buf, size_t cap) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    buf[0] = 0;
    FILE *f = fopen(p, "rb");
    if (!f) return 0;
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = 0;
    fclose(f);
    return n;
}

/* Runs glint with the given arguments (a shell command tail) in tmp; returns the exit status, or
 * -1 when it did not exit normally (a crash). */
static int run(const char *args) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >stdout.txt 2>stderr.txt </dev/null", tmp, glint, args);
    int status = system(cmd);
    read_file("stdout.txt", out_text, sizeof out_text);
    read_file("stderr.txt", err_text, sizeof err_text);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Takes the program from argv[1] and makes tmp an empty directory $GLINT_TEST_TMP/name (or under
 * /tmp). Returns 0, or the status main should exit with. */
static int harness_start(int argc, char **argv, const char *name) {
    if (argc < 2) {
        fprintf(stderr, "usage: test_%s GLINT\n", name);
        return 2;
    }
    glint = argv[1];
    const char *t = getenv("GLINT_TEST_TMP");
    snprintf(tmp, sizeof tmp, "%s/%s", t ? t : "/tmp", name);
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", tmp, tmp);
    return system(cmd) == 0 ? 0 : 1;
}

#endif
