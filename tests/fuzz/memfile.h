/* glint — a fuzzer's input as a file without touching the disk: a memory file (memfd_create),
 * opened by its /proc/self/fd path, a regular file to the readers. Shared by fuzz_image.c and
 * fuzz_merge.c (which define _GNU_SOURCE first, for memfd_create). */
#ifndef GLINT_FUZZ_MEMFILE_H
#define GLINT_FUZZ_MEMFILE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

typedef struct {
    int fd; /* -1 before the first memfile_put */
    char path[64];
} memfile;

/* Makes f hold exactly size bytes of data (made on first use); aborts when the system refuses. */
static inline void memfile_put(memfile *f, const uint8_t *data, size_t size) {
    if (f->fd < 0) {
        f->fd = memfd_create("glint_fuzz", MFD_CLOEXEC);
        if (f->fd < 0) perror("memfd_create"), abort();
        snprintf(f->path, sizeof f->path, "/proc/self/fd/%d", f->fd);
    }
    if (ftruncate(f->fd, 0) != 0) perror("ftruncate"), abort();
    for (size_t done = 0; done < size;) {
        ssize_t n = pwrite(f->fd, data + done, size - done, (off_t)done);
        if (n <= 0) perror("pwrite"), abort();
        done += (size_t)n;
    }
}

#endif
