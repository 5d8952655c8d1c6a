/* glint — the program's commands. Each takes the arguments after its name and returns the exit
 * code. */
#ifndef GLINT_COMMANDS_H
#define GLINT_COMMANDS_H

#include "scene.h"

int cmd_render(int argc, char **argv);
int cmd_info(int argc, char **argv);
/* Error against time per method and setting, against a reference (cmd_bench.c). */
int cmd_bench(int argc, char **argv);
/* Shards of one render combined into one reference (cmd_merge.c). */
int cmd_merge(int argc, char **argv);
/* One image's error against a reference (cmd_compare.c). */
int cmd_compare(int argc, char **argv);
/* The interactive viewer. */
int cmd_view(int argc, char **argv);

/* Loads SCENE (a file or builtin:NAME; NULL: the default built-in), attaches --env and picks the
 * material variant (--variant) when given. Prints the error and returns NULL on failure. */
scene *load_scene_or_default(const char *path, const char *env_path, float env_rotation, const char *variant);

#endif
