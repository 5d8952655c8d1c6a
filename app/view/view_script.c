#define _POSIX_C_SOURCE 200809L
#include "view_script.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Splits s into at most max whitespace-separated words (in place). Returns the count, or max + 1
 * when there are more. */
static int split_words(char *s, char **words, int max) {
    int n = 0;
    for (char *p = s; *p;) {
        while (isspace((unsigned char)*p)) p++;
        if (!*p) break;
        if (n == max) return max + 1;
        words[n++] = p;
        while (*p && !isspace((unsigned char)*p)) p++;
        if (*p) *p++ = 0;
    }
    return n;
}

static int parse_number(const char *text, double *out) {
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end || errno || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int view_script_parse_line(const char *line, script_action *out, char *err, size_t errlen) {
    char buf[1200];
    if (strlen(line) >= sizeof buf) return snprintf(err, errlen, "line too long"), -1;
    snprintf(buf, sizeof buf, "%s", line);
    char *hash = strchr(buf, '#');
    if (hash) *hash = 0;
    char *w[5];
    int n = split_words(buf, w, 5);
    if (n == 0) return 0;
    memset(out, 0, sizeof *out);
    static const struct {
        const char *name;
        script_action_kind kind;
        int args;    /* words after the command */
        int numbers; /* how many of them are numbers */
        int path;    /* the one argument is a path */
    } commands[] = {
        {"wait", ACT_WAIT, 1, 1, 0},
        {"set", ACT_SET, 2, 0, 0},
        {"orbit", ACT_ORBIT, 2, 2, 0},
        {"pan", ACT_PAN, 2, 2, 0},
        {"zoom", ACT_ZOOM, 1, 1, 0},
        {"key", ACT_KEY, 1, 0, 0},
        {"screenshot", ACT_SCREENSHOT, 1, 0, 1},
        {"export", ACT_EXPORT, 1, 0, 1},
        {"load", ACT_LOAD, 1, 0, 1},
        {"env", ACT_ENV, 1, 0, 1},
        {"window-shot", ACT_WINDOW_SHOT, 1, 0, 1},
        {"reference", ACT_REFERENCE, 1, 0, 1},
        {"move-light", ACT_MOVE_LIGHT, 4, 4, 0},
        {"save-bookmark", ACT_SAVE_BOOKMARK, 1, 1, 0},
        {"restore-bookmark", ACT_RESTORE_BOOKMARK, 1, 1, 0},
        {"spin", ACT_SPIN, 2, 2, 0},
        {"stats", ACT_STATS, 0, 0, 0},
        {"quit", ACT_QUIT, 0, 0, 0},
        {"frame", ACT_FRAME, 0, 0, 0},
        {"reference-camera", ACT_REFERENCE_CAMERA, 0, 0, 0},
        {"sky", ACT_SKY, 0, 0, 0},
        {"pause", ACT_PAUSE, 0, 0, 0},
        {"resume", ACT_RESUME, 0, 0, 0},
        {"sleep", ACT_SLEEP, 1, 1, 0},
        {"wait-held", ACT_WAIT_HELD, 0, 0, 0},
        {"wait-file", ACT_WAIT_FILE, 1, 0, 1},
        {"buttons", ACT_BUTTONS, 0, 0, 0},
        {"wheel", ACT_WHEEL, 3, 3, 0},
        {"variant", ACT_VARIANT, 1, 0, 1},
        {"capture", ACT_CAPTURE, 1, 0, 1},
    };
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        if (strcmp(w[0], commands[i].name) != 0) continue;
        if (n - 1 != commands[i].args)
            return snprintf(err, errlen, "'%s' takes %d argument%s", w[0], commands[i].args,
                            commands[i].args == 1 ? "" : "s"),
                   -1;
        out->kind = commands[i].kind;
        double *nums[4] = {&out->a, &out->b, &out->c, &out->d};
        for (int k = 0; k < commands[i].numbers; k++)
            if (parse_number(w[1 + k], nums[k]) != 0)
                return snprintf(err, errlen, "'%s': '%s' is not a number", w[0], w[1 + k]), -1;
        if (out->kind == ACT_WAIT && (out->a < 0 || out->a > 1e6 || out->a != floor(out->a)))
            return snprintf(err, errlen, "'wait' needs a whole number of frames (0 to 1000000)"), -1;
        if (out->kind == ACT_ZOOM && !(out->a > 0)) return snprintf(err, errlen, "'zoom' needs a positive factor"), -1;
        if (out->kind == ACT_MOVE_LIGHT && (out->a < 0 || out->a > 1e6 || out->a != floor(out->a)))
            return snprintf(err, errlen, "'move-light' needs a light index (0, 1, ...)"), -1;
        if ((out->kind == ACT_SAVE_BOOKMARK || out->kind == ACT_RESTORE_BOOKMARK) &&
            (out->a < 1 || out->a > 9 || out->a != floor(out->a)))
            return snprintf(err, errlen, "'%s' needs a bookmark number 1 to 9", w[0]), -1;
        if (out->kind == ACT_SLEEP && !(out->a >= 0 && out->a <= 3600))
            return snprintf(err, errlen, "'sleep' needs 0 to 3600 seconds"), -1;
        if (out->kind == ACT_SPIN && !(out->b >= 0 && out->b <= 3600))
            return snprintf(err, errlen, "'spin' needs 0 to 3600 seconds"), -1;
        if (out->kind == ACT_SET || out->kind == ACT_KEY) snprintf(out->name, sizeof out->name, "%s", w[1]);
        if (out->kind == ACT_SET) snprintf(out->text, sizeof out->text, "%s", w[2]);
        if (commands[i].path) snprintf(out->text, sizeof out->text, "%s", w[1]);
        return 1;
    }
    return snprintf(err, errlen, "unknown action '%s'", w[0]), -1;
}

int view_script_load(const char *path, view_script *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f) return snprintf(err, errlen, "%s: %s", path, strerror(errno)), -1;
    char *line = NULL;
    size_t cap = 0;
    int cap_actions = 0, lineno = 0, status = 0;
    while (getline(&line, &cap, f) >= 0) {
        lineno++;
        line[strcspn(line, "\r\n")] = 0;
        script_action a;
        char sub[256];
        int r = view_script_parse_line(line, &a, sub, sizeof sub);
        if (r < 0) {
            snprintf(err, errlen, "%s:%d: %s", path, lineno, sub);
            status = -1;
            break;
        }
        if (r == 0) continue;
        a.line = lineno;
        if (out->count == cap_actions) {
            cap_actions = cap_actions ? 2 * cap_actions : 32;
            script_action *grown = realloc(out->actions, sizeof(script_action) * (size_t)cap_actions);
            if (!grown) {
                snprintf(err, errlen, "%s: out of memory", path);
                status = -1;
                break;
            }
            out->actions = grown;
        }
        out->actions[out->count++] = a;
    }
    if (status == 0 && ferror(f)) {
        snprintf(err, errlen, "%s: read error", path);
        status = -1;
    }
    free(line);
    fclose(f);
    if (status != 0) view_script_free(out);
    return status;
}

void view_script_free(view_script *s) {
    free(s->actions);
    s->actions = NULL;
    s->count = 0;
}
