/* glint — interactive, progressive rendering of glossy global illumination. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "commands.h"

/* A sanitizer build (scripts/test.sh's build-test/) run as a user runs it: LeakSanitizer's
 * suppressions built in, so that a real leak stands out. fontconfig keeps its configuration, read
 * once when cairo first draws text (a plot's labels), until exit: a fixed few hundred bytes.
 * tests/lsan.supp says the same for the test programs. */
#if defined(__SANITIZE_ADDRESS__)
#define GLINT_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GLINT_LSAN 1
#endif
#endif
#ifdef GLINT_LSAN
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig\n"; }
#endif

static void print_help(void) {
    printf("glint %s — progressive rendering of glossy global illumination\n"
           "\n"
           "usage:\n"
           "  glint [view] [SCENE] [options]   open the interactive viewer (see glint view --help)\n"
           "  glint render [SCENE] [options]   render headless to EXR/PNG (see glint render --help)\n"
           "  glint info [SCENE]               print a summary of the scene\n"
           "  glint merge PART.exr... --out REF.exr\n"
           "                                   combine the shards of a render (glint render --shard)\n"
           "  glint bench [SCENE] --reference REF.exr [options]\n"
           "                                   error against time per method (see glint bench --help)\n"
           "  glint compare IMAGE.exr REFERENCE.exr [--layer NAME]\n"
           "                                   one image's error against a reference (a viewer's capture)\n"
           "  glint --help | --version\n"
           "\n",
           GLINT_VERSION);
    cli_print_scenes();
}

int main(int argc, char **argv) {
    if (argc < 2) return cmd_view(0, argv + 1);
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_help();
        return EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("glint %s (material model %s)\n", GLINT_VERSION, BSDF_MODEL_STAMP);
        return EXIT_OK;
    }
    if (strcmp(argv[1], "render") == 0) return cmd_render(argc - 2, argv + 2);
    if (strcmp(argv[1], "info") == 0) return cmd_info(argc - 2, argv + 2);
    if (strcmp(argv[1], "bench") == 0) return cmd_bench(argc - 2, argv + 2);
    if (strcmp(argv[1], "merge") == 0) return cmd_merge(argc - 2, argv + 2);
    if (strcmp(argv[1], "compare") == 0) return cmd_compare(argc - 2, argv + 2);
    if (strcmp(argv[1], "view") == 0) return cmd_view(argc - 2, argv + 2);
    /* `glint SCENE [options]` and `glint --option ...` open the viewer too. */
    struct stat st;
    if (argv[1][0] == '-' || stat(argv[1], &st) == 0 || scene_builtin_name(argv[1]))
        return cmd_view(argc - 1, argv + 1);
    cli_error("unknown command or missing scene file '%s' (see glint --help)", argv[1]);
    return EXIT_USAGE;
}
