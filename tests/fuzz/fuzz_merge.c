/* glint — `glint merge A.exr B.exr --out REF.exr` under a fuzzer: the input is two shards, the
 * first's length in its first four bytes (little-endian; what is left is the second), each
 * reaching the merge through a memory file (memfd_create) opened by its /proc/self/fd path. Any
 * pair must merge or be refused; a merge must leave a reference that loads again, every value in
 * it finite, and its description readable (the moments of shards far apart once overflowed to
 * infinities that no later merge could read). A crash, a sanitizer report, a hang or a runaway
 * allocation is a finding. Built with libFuzzer (clang) as fuzz_merge, and with replay.c's main()
 * in any build. */
#define _GNU_SOURCE /* memfd_create */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "image_io.h"
#include "memfile.h"
#include "reference.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void bad(const char *what) {
    fprintf(stderr, "fuzz_merge: %s\n", what);
    abort();
}

/* The two shards' memory files. */
static memfile shard[2] = {{-1, ""}, {-1, ""}};

/* Where the merge writes: a folder of its own, made once, the output removed before each merge (so
 * that one found there is this input's) and at exit. */
static char folder[64], out[96];
static void remove_output(void) {
    remove(out);
    rmdir(folder);
}
static void make_folder(void) {
    if (folder[0]) return;
    snprintf(folder, sizeof folder, "%s/fuzz_merge.XXXXXX", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
    if (!mkdtemp(folder)) bad("cannot make a folder");
    snprintf(out, sizeof out, "%s/merged.exr", folder);
    atexit(remove_output);
}

/* A merged reference: loads, every value finite, its description readable. */
static void check_merged(void) {
    char err[1024];
    exr_image img;
    if (exr_image_load(out, &img, err, sizeof err) != 0) bad("the merged reference does not load");
    for (int c = 0; c < img.num_channels; c++)
        for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++)
            if (!isfinite(img.planes[c][i])) bad("a value of the merged reference is not finite");
    exr_image_free(&img);
    reference_info info;
    if (reference_load(out, &info, err, sizeof err) != 0) bad("the merged reference's description does not read");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size < 4) return 0;
    make_folder();
    size_t first = (size_t)data[0] | (size_t)data[1] << 8 | (size_t)data[2] << 16 | (size_t)data[3] << 24;
    first = first < size - 4 ? first : size - 4;
    memfile_put(&shard[0], data + 4, first);
    memfile_put(&shard[1], data + 4 + first, size - 4 - first);
    remove(out);
    char *argv[] = {shard[0].path, shard[1].path, "--out", out, "--quiet", NULL};
    if (cmd_merge(5, argv) == 0) check_merged();
    return 0;
}
