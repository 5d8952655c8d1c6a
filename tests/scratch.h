/* glint tests — a scratch directory for one run of a test program, and small file helpers.
 * scratch_open("NAME") makes $GLINT_TEST_TMP/NAME.PID (or under /tmp); scratch_close(status)
 * removes it when the run passed (a failed run keeps its files to look at). */
#ifndef GLINT_TEST_SCRATCH_H
#define GLINT_TEST_SCRATCH_H

#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char scratch_dir[1024]; /* this run's scratch directory */

/* Base64 of n bytes into out (4 * ceil(n / 3) + 1 bytes): data: URIs for glTF tests. */
static inline void base64(const unsigned char *in, size_t n, char *out) {
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = tab[v >> 18 & 63];
        out[o++] = tab[v >> 12 & 63];
        out[o++] = i + 1 < n ? tab[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? tab[v & 63] : '=';
    }
    out[o] = 0;
}

static inline void path_in(char *out, size_t outlen, const char *name) {
    snprintf(out, outlen, "%s/%s", scratch_dir, name);
}

static inline int put_file(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t n = size ? fwrite(data, 1, size, f) : 0;
    return fclose(f) == 0 && n == size ? 0 : -1;
}

/* Reads a whole file (malloc'd, *size set), or NULL. */
static inline unsigned char *get_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char *buf = NULL;
    size_t cap = 0, len = 0;
    for (;;) {
        if (len == cap) {
            cap = cap ? 2 * cap : 65536;
            unsigned char *p = realloc(buf, cap);
            if (!p) break;
            buf = p;
        }
        size_t n = fread(buf + len, 1, cap - len, f);
        len += n;
        if (n == 0) break;
    }
    fclose(f);
    *size = len;
    return buf;
}

static inline int file_exists(const char *path) {
    struct stat st;
    return lstat(path, &st) == 0;
}

/* Files in the scratch directory whose name marks them as the atomic writer's temporaries. */
static inline int stray_temp_files(const char *where) {
    DIR *d = opendir(where);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp")) {
            fprintf(stderr, "stray temporary file: %s/%s\n", where, e->d_name);
            n++;
        }
    if (d) closedir(d);
    return n;
}

static inline void remove_tree(const char *path) {
    struct stat st;
    if (lstat(path, &st) != 0) return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        struct dirent *e;
        while (d && (e = readdir(d))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            char sub[2048];
            if (snprintf(sub, sizeof sub, "%s/%s", path, e->d_name) < (int)sizeof sub) remove_tree(sub);
        }
        if (d) closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

static inline int one_line(const char *s) { return s[0] && !strchr(s, '\n') && !strchr(s, '\r'); }

/* Returns 0, or -1 after a message. */
static inline int scratch_open(const char *name) {
    const char *base = getenv("GLINT_TEST_TMP");
    snprintf(scratch_dir, sizeof scratch_dir, "%s/%s.%ld", base && base[0] ? base : "/tmp", name, (long)getpid());
    remove_tree(scratch_dir);
    if (mkdir(scratch_dir, 0777) == 0) return 0;
    fprintf(stderr, "%s: cannot create %s: %s\n", name, scratch_dir, strerror(errno));
    return -1;
}

static inline int scratch_close(int status) {
    if (status == 0) remove_tree(scratch_dir);
    return status;
}

#endif
