/* glint — command-line plumbing shared by the commands: messages, strict number parsing. */
#ifndef GLINT_CLI_H
#define GLINT_CLI_H

#include <stdint.h>

#include "session.h"

/* Exit codes. */
enum { EXIT_OK = 0, EXIT_FAILURE_ = 1, EXIT_USAGE = 2 };

/* "glint: error: ..." and "glint: warning: ..." on stderr, one line each. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void cli_warning(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* A scene_warn_fn that prints warnings (user unused). */
void cli_print_warning(void *user, const char *message);

/* Parsers: return 0 on success, else print "glint: error: OPTION: ..." and return -1. */
int cli_parse_int(const char *option, const char *text, long long lo, long long hi, long long *out);
int cli_parse_u64(const char *option, const char *text, uint64_t *out);
int cli_parse_float(const char *option, const char *text, double lo, double hi, double *out);
/* "auto" or "full" (PLAN_AUTO, PLAN_FULL), as the parameter table's plan takes them (glint bench's
 * --plan and its runs' plan=, which are its own options). */
int cli_parse_plan(const char *option, const char *text, int *plan);
/* "WxH" as params_parse_size takes it (the memory rule included), its error reported as option's. */
int cli_parse_size(const char *option, const char *text, int *width, int *height);

/* An argument no option of `command` took: an unknown option (anything starting with '-'), else
 * the scene, of which there is at most one. Returns 0 (*scene_path set), or -1 after a usage error. */
int cli_scene_argument(const char *command, const char *arg, const char **scene_path);

/* Prints what SCENE may be and lists the built-in scenes with their descriptions (for --help). */
void cli_print_scenes(void);

/* Fetches the value of option argv[*i] (advancing *i); prints a usage error when missing. */
const char *cli_value(int argc, char **argv, int *i);

/* One option of a command's table (cli_table_option): its name, what its value is, where it goes
 * (and, for sizes, where the height goes), its range, and a flag set when it was given. */
typedef enum {
    CLI_FLAG,  /* no value: *(int *)out = 1 */
    CLI_INT,   /* an integer in [lo, hi]: int */
    CLI_LONG,  /* ... long long */
    CLI_U64,   /* uint64_t */
    CLI_FLOAT, /* a number in [lo, hi]: double */
    CLI_SIZE,  /* WxH: int width at out, int height at out2 */
    CLI_TEXT,  /* the value as given: const char * */
    CLI_PLAN,  /* auto|full: int */
    CLI_PARAM, /* the parameter table's entry of the option's name: into the render_params at out */
} cli_kind;
typedef struct {
    const char *name;
    cli_kind kind;
    void *out, *out2;
    double lo, hi;
    int *given;
} cli_opt;
/* The ranges the commands share. */
#define CLI_CAMERA_MAX 1000000
#define CLI_THREADS_MAX 1024
/* argv[*i] if it is one of the n options: 1 taken (with its value, advancing *i), 0 not one of
 * them, -1 a bad or missing value (reported). */
int cli_table_option(int argc, char **argv, int *i, const cli_opt *opts, int n);

/* The render parameters (params_table: the method, the path depth, the plan, the seed, the size, the
 * many-light ones), shared by glint render, info, bench, the viewer's options and its script's
 * `set`; each command takes those of the groups in `groups` (PARAM_GROUPS_*). cli_set_param takes
 * a name without the leading "--" and a value (a flag such as vpl-glossy: on/off). Returns 1 when
 * applied, 0 when name is not one of them, -1 on a bad value (reported). cli_param_option does the
 * same for argv[*i] and its value (none for a flag), advancing *i. */
int cli_set_param(const char *name, const char *value, render_params *p, unsigned groups);
int cli_param_option(int argc, char **argv, int *i, render_params *p, unsigned groups);
/* The many-light options' help text, one option per line (params_help). */
const char *cli_vl_help(void);

/* Seconds on a monotonic clock. */
double cli_now(void);

/* Fails (with a message) when the directory that would hold path does not exist or is not
 * writable: checked before a long render rather than after it. */
int cli_check_output_dir(const char *option, const char *path);

/* A file named on the command line and the option (or word) that named it. */
typedef struct {
    const char *role; /* "--out", "the scene", ... */
    const char *path; /* NULL: not given */
} cli_file;

/* Fails (with a usage error naming both roles) when two outputs name the same file or an output
 * names an input: one would silently replace the other. The same file is the same inode when it
 * exists, else the same directory (symbolic links resolved) and name. */
int cli_check_roles(const cli_file *outputs, int num_outputs, const cli_file *inputs, int num_inputs);

#endif
