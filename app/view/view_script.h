/* glint — viewer automation scripts: one action a line, replayed through the viewer's own input
 * paths so the real window can be driven in tests (under xvfb-run).
 *
 *   # comment                 wait FRAMES            set NAME VALUE
 *   orbit DX_DEG DY_DEG       pan DX DY              zoom FACTOR
 *   key NAME                  screenshot FILE.png    export FILE.exr
 *   load SCENE                env MAP.exr|MAP.hdr    window-shot FILE.png
 *   move-light INDEX DX DY DZ save-bookmark N        restore-bookmark N
 *   reference FILE.exr        spin DEG_PER_S SECONDS stats
 *   frame                     reference-camera       sky
 *   quit                      pause                  resume
 *   sleep SECONDS             wait-file FILE         buttons
 *   wheel X Y STEPS           variant NAME|default   wait-held
 *   capture FILE.exr
 *
 * `window-shot` captures the window as drawn, panel included (for documentation); the actions
 * after it wait for the capture. `wait` waits for FRAMES new full-resolution frames; `stats`
 * prints one line of the viewer's counters to stdout; `key` presses a named key (r, f11, f12,
 * tab, escape, f, c, k, 1-9, ctrl+N, shift+N). `load`, `env` and `sky` wait until the render thread
 * has tried them (a failed one changes nothing); `env none` clears the environment. `frame` views
 * the whole scene, `reference-camera` goes back to the reference's. `sleep` lets time pass, changing
 * nothing (while a test sends real input events); `wait-file` waits until FILE exists (a test
 * makes it once its input events are sent); `wait-held` waits until refinement stands still
 * (paused or at a limit, the frame under way finished; at once when nothing holds it); `buttons`
 * prints where the panel's visible buttons are, one line each ("button X0 Y0 X1 Y1 LABEL", window
 * units), for a test to click; `wheel` puts the cursor at X Y (window units) and turns the wheel
 * there by STEPS (up positive) in the same frame, as a wheel event arriving with the cursor's move
 * does.
 * `move-light` moves light INDEX (as the panel lists them) by a world-space offset and selects it;
 * `spin` orbits continuously, a little every drawn frame, as a held mouse drag would. `variant`
 * shows the scene's material variant NAME (`default`: the file's materials), as the panel's choice
 * does, and waits until the scene is reloaded. `capture` saves the image the window shows, linear
 * (before tone mapping) and at the render's size (a preview magnified as the window draws it), as
 * an EXR (numbered, never overwriting) whose glint.reference header attribute describes it:
 * scene, environment, variant, the camera and light edits it was rendered with, and when it was
 * taken (seconds since the last change and since the start, its full-resolution frames, whether
 * a preview); glint compare measures it against a reference. */
#ifndef GLINT_VIEW_SCRIPT_H
#define GLINT_VIEW_SCRIPT_H

#include <stddef.h>

typedef enum {
    ACT_WAIT,
    ACT_SET,
    ACT_ORBIT,
    ACT_PAN,
    ACT_ZOOM,
    ACT_KEY,
    ACT_SCREENSHOT,
    ACT_EXPORT,
    ACT_LOAD,
    ACT_ENV,
    ACT_WINDOW_SHOT, /* the whole window, panel included */
    ACT_REFERENCE,
    ACT_MOVE_LIGHT,
    ACT_SAVE_BOOKMARK,
    ACT_RESTORE_BOOKMARK,
    ACT_SPIN,
    ACT_STATS,
    ACT_QUIT,
    ACT_FRAME,
    ACT_REFERENCE_CAMERA,
    ACT_SKY,
    ACT_PAUSE,     /* refinement stops... */
    ACT_RESUME,    /* ...and goes on */
    ACT_SLEEP,     /* the script waits SECONDS, the viewer runs on */
    ACT_WAIT_HELD, /* the script waits until refinement stands */
    ACT_WAIT_FILE, /* the script waits until a file exists */
    ACT_BUTTONS,   /* where the panel's buttons are */
    ACT_WHEEL,     /* the cursor moved and the wheel turned at once */
    ACT_VARIANT,
    ACT_CAPTURE, /* the image shown, linear, with its description */
} script_action_kind;

typedef struct {
    script_action_kind kind;
    int line;
    double a, b, c, d; /* numbers: frames, degrees, offsets, factor, light index and offset */
    char name[64];     /* set: parameter; key: key name */
    char text[1024];   /* set: value; screenshot, export, capture, load, env, window-shot, reference, wait-file: path */
} script_action;

typedef struct {
    script_action *actions;
    int count;
} view_script;

/* Parses a script file. Returns 0, or -1 with err = "FILE:LINE: problem" (or "FILE: problem"). */
int view_script_load(const char *path, view_script *out, char *err, size_t errlen);
/* Parses one line (already without its newline). Returns 1 for an action, 0 for a blank or
 * comment line, -1 with err = "problem" for a bad line. */
int view_script_parse_line(const char *line, script_action *out, char *err, size_t errlen);
void view_script_free(view_script *s);

#endif
