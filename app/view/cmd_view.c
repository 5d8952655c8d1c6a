/* glint view: the interactive, progressive viewer's command: its options, and the UI thread's
 * set-up, loop and tear-down. How the viewer works: view.h. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <GLFW/glfw3.h>

#include "cli.h"
#include "commands.h"
#include "view.h"

typedef struct {
    const char *scene_path, *env_path, *script_path;
    const char *variant; /* NULL: the file's default materials */
    int width, height;
    render_params params;
    int camera;
    const char *reference_path;
    long long spp;  /* refinement stops here; 0: never */
    double seconds; /* ...or after this long; 0: never */
} view_options;

static void print_view_help(void) {
    printf("usage: glint [view] [SCENE] [options]\n"
           "\n"
           "Opens the interactive viewer on SCENE (a .gltf/.glb or builtin:NAME, see glint --help;\n"
           "default: the default built-in scene).\n"
           "\n"
           "options:\n"
           "%s"
           "  --env FILE           environment map (.exr or .hdr)\n"
           "  --variant NAME       the scene's material variant NAME (the panel switches them)\n"
           "  --camera INDEX       start from the scene's camera INDEX\n"
           "  --reference FILE.exr an image of the render's size: error view and plot\n"
           "  --spp N              stop refining at N samples per pixel (frames) [never]\n"
           "  --time SECONDS       stop refining after this long [never]\n"
           "  --script FILE        replay a script of viewer actions (docs/viewer.md)\n"
           "\n"
           "%s"
           "\n"
           "keys and mouse (F1 in the window shows them):\n",
           params_render_help("size method max-depth seed plan exposure tonemap denoise",
                              "method=" DEFAULT_METHOD_NAME " denoise=on"),
           cli_vl_help());
    print_shortcuts(stdout);
}

static int parse_view_options(int argc, char **argv, view_options *o) {
    memset(o, 0, sizeof *o);
    o->width = DEFAULT_WIDTH;
    o->height = DEFAULT_HEIGHT;
    o->camera = -1;
    o->params.max_depth = DEFAULT_MAX_DEPTH;
    o->params.method = DEFAULT_METHOD;
    o->params.look.denoise = 1; /* the viewer's image is filtered while young, unless asked not to */
    const cli_opt opts[] = {
        {.name = "--env", .kind = CLI_TEXT, .out = &o->env_path},
        {.name = "--variant", .kind = CLI_TEXT, .out = &o->variant},
        {.name = "--camera", .kind = CLI_INT, .out = &o->camera, .lo = 0, .hi = CLI_CAMERA_MAX},
        {.name = "--reference", .kind = CLI_TEXT, .out = &o->reference_path},
        {.name = "--script", .kind = CLI_TEXT, .out = &o->script_path},
        {.name = "--spp", .kind = CLI_LONG, .out = &o->spp, .lo = 1, .hi = 100000000},
        {.name = "--time", .kind = CLI_FLOAT, .out = &o->seconds, .lo = 1e-3, .hi = 1e7},
    };
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int r;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_view_help();
            return 1;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0 ||
                   (r = cli_param_option(argc, argv, &i, &o->params, PARAM_GROUPS_ALL)) != 0) {
            if (r < 0) return -1;
        } else if (cli_scene_argument("view", a, &o->scene_path) != 0) {
            return -1;
        }
    }
    /* the window's size; the render's follows the window, whatever it becomes */
    if (o->params.width > 0) o->width = o->params.width, o->height = o->params.height;
    o->params.width = o->params.height = 0;
    return 0;
}

/* A frame is drawn when something changed, for this long after any input (Dear ImGui settles its
 * widgets' states over a few frames), and at least this often (what changes unannounced). llvmpipe
 * draws on the CPU the renderer needs: 60 frames a second cost it a tenth of two cores. */
#define REDRAW_AFTER_INPUT 0.25
#define IDLE_REDRAW_SECONDS 0.5

static void on_glfw_error(int code, const char *description) {
    (void)code;
    cli_warning("window system: %s", description);
}

int cmd_view(int argc, char **argv) {
    view_options o;
    int r = parse_view_options(argc, argv, &o);
    if (r) return r > 0 ? EXIT_OK : EXIT_USAGE;

    static ui_thread u; /* large (key table, buffers): not on the stack */
    memset(&u, 0, sizeof u);
    char err[1200];
    if (o.script_path) {
        if (view_script_load(o.script_path, &u.script, err, sizeof err) != 0) {
            cli_error("%s", err);
            return EXIT_USAGE;
        }
        u.script_path_for_errors = o.script_path;
    }

    scene *s = load_scene_or_default(o.scene_path, o.env_path, 0.0f, o.variant);
    if (!s) {
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    if (o.camera >= 0 && o.camera >= s->num_cameras) {
        cli_error("--camera: the scene has %d camera%s", s->num_cameras, s->num_cameras == 1 ? "" : "s");
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_USAGE;
    }

    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        cli_error("cannot open a window (no display?); glint render renders without one");
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    char title[1200];
    snprintf(title, sizeof title, "glint — %s", s->path);
    GLFWwindow *win = glfwCreateWindow(o.width, o.height, title, NULL, NULL);
    if (!win) {
        cli_error("cannot create an OpenGL 3.3 window");
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(win, &u);
    /* Our callbacks first: Dear ImGui's backend chains to them. */
    glfwSetKeyCallback(win, on_key);
    glfwSetScrollCallback(win, on_scroll);
    glfwSetDropCallback(win, on_drop);
    note_input_callbacks(win);
    if (ui_init(win) != 0) {
        cli_error("cannot initialise the panel");
        glfwDestroyWindow(win);
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }

    u.win = win;
    fill_scene_info(&u.info, s);
    /* The panel shows the values in use, so it edits the parameters with their defaults resolved. */
    u.ctl = (ui_controls){.params = o.params,
                          .camera = o.camera,
                          .show = UI_SHOW_ALL,
                          .show_panel = 1,
                          .spp_limit = o.spp,
                          .time_limit = o.seconds,
                          .variant = u.info.variant};
    u.ctl.params.vl = vl_params_resolve(&o.params.vl);
    u.applied_ctl = u.ctl;
    reset_lights(&u);
    bookmarks_load(&u);
    u.rel_error = u.shown_error = -1.0;
    u.step_ms = -1.0; /* the first image's time is measured from here */
    u.sent_at = cli_now();
    u.current_curve = -1;
    u.started_at = cli_now();
    view_fit_window(&u, o.width, o.height); /* the image at --size beside the panel */
    int fw, fh;
    view_image_size(&u, &fw, &fh);
    reset_view(&u);
    view_start start = {.cam = ctl_camera(&u.cam),
                        .params = o.params,
                        .width = fw > 0 ? fw : o.width,
                        .height = fh > 0 ? fh : o.height,
                        .env = o.env_path,
                        .denoise = u.ctl.params.look.denoise,
                        .wake = glfwPostEmptyEvent}; /* the UI thread, waiting for events, takes the image */
    if (!(u.vc = controller_start(s, &start, err, sizeof err))) {
        cli_error("%s", err);
        ui_shutdown();
        glfwDestroyWindow(win);
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    push_refinement(&u);
    if (o.reference_path) open_reference(&u, o.reference_path); /* a bad one is shown; the viewer runs on */

    glfwGetCursorPos(win, &u.mouse_x, &u.mouse_y);
    u.last_time = cli_now();
    while (!u.quit && !glfwWindowShouldClose(win)) {
        glfwWaitEventsTimeout(1.0 / 60.0);
        double now = cli_now(), dt = now - u.last_time;
        u.last_time = now;
        int news = fetch_published(&u);
        if (news & VIEW_NEW_IMAGE) u.need_tonemap = 1;
        unsigned long long shown_was = u.script_shown;
        int shot_asked = u.window_shot[0] != 0;
        run_script(&u);
        update_status(&u);
        if (u.input_events != u.drawn_events && !view_dragging(&u)) u.redraw_until = now + REDRAW_AFTER_INPUT;
        int settle = u.settle, acted = u.script_shown != shown_was || u.window_shot[0] || now < u.redraw_until;
        int draw = news || u.need_tonemap || acted || settle || now - u.drawn_at >= IDLE_REDRAW_SECONDS;

        if (draw) {
            ui_begin_frame();
            draw_image_and_panel(&u);
        }
        apply_controls(&u, handle_input(&u, dt));
        view_follow_size(&u, now);
        if (!draw) continue;

        glfwGetFramebufferSize(win, &fw, &fh);
        if (u.need_tonemap) {
            tonemap_and_upload(&u);
            u.need_tonemap = 0;
        }
        glViewport(0, 0, fw, fh);
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ui_end_frame();
        if (shot_asked && settle) capture_window(&u, fw, fh); /* asked before the frame that settled */
        glfwSwapBuffers(win);
        u.drawn_events = u.input_events;
        u.drawn_at = now;
        u.frames_drawn++;
        /* Dear ImGui sizes a window to what it held the frame before: a frame more after any
         * change but a new image's (whose overlay line keeps its size). */
        u.settle = !settle && (acted || news != VIEW_NEW_IMAGE);
    }

    view_stats last;
    controller_stop(u.vc, &last);
    if (o.script_path) { /* what the render side did up to the end, for tests: counts, not times */
        printf("exit frames_total=%llu late_parts=%llu\n", (unsigned long long)last.frames_total,
               (unsigned long long)last.late_parts);
        fflush(stdout);
    }
    capture_finish(&u);
    if (u.texture) {
        GLuint t = u.texture;
        glDeleteTextures(1, &t);
    }
    ui_shutdown();
    glfwDestroyWindow(win);
    glfwTerminate();
    image_rgb_free(&u.reference);
    free(u.front.rgb);
    free(u.pixels);
    int errors = u.script_errors;
    view_script_free(&u.script);
    return errors ? EXIT_FAILURE_ : EXIT_OK;
}
