// glint — the panel: Dear ImGui (Debian's libimgui 1.86) with its GLFW and OpenGL 3 backends.
// Only this file sees C++; the viewer talks to it through ui.h.
#include "ui.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace {
GLFWwindow *g_window;
float g_content_scale = 0.0f; // the window's content scale the fonts and sizes were made for
float g_scale = 1.0f;         // sizes in window units: the content scale over the framebuffer's pixels per unit
float g_dock_w = 0.0f;        // the panel's width as the user left it (window units); 0: the default
bool g_collapsed = false;
bool g_resizing = false;   // its edge is dragged: its width changed since the left button went down
float g_image_dock = 0.0f; // this frame's: the image is drawn beside it
// The panel's buttons where they were drawn (the visible ones), for scripts that click them
struct drawn_button {
    char label[48];
    float rect[4];
};
drawn_button g_buttons[48];
int g_num_buttons;
} // namespace

// Fonts and sizes for the window's content scale (HiDPI): glyphs rasterised at the framebuffer's
// resolution, everything else sized in window units, so text is sharp and the mouse maps 1:1.
static void fit_content_scale(void) {
    float xs = 1.0f, ys = 1.0f;
    glfwGetWindowContentScale(g_window, &xs, &ys);
    float cs = std::fmin(std::fmax(std::fmax(xs, ys), 0.5f), 4.0f);
    if (cs == g_content_scale) return;
    int ww, wh, fw, fh;
    glfwGetWindowSize(g_window, &ww, &wh);
    glfwGetFramebufferSize(g_window, &fw, &fh);
    float ratio = ww > 0 && fw > 0 ? (float)fw / (float)ww : 1.0f; // framebuffer pixels per window unit
    ImGuiIO &io = ImGui::GetIO();
    io.Fonts->Clear();
    static const char *dejavu = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    FILE *f = cs > 1.2f ? std::fopen(dejavu, "rb") : nullptr; // the built-in font is a 13-pixel bitmap
    if (f) {
        std::fclose(f);
        io.Fonts->AddFontFromFileTTF(dejavu, std::round(14.0f * cs));
    } else {
        ImFontConfig cfg;
        cfg.SizePixels = std::round(13.0f * cs);
        io.Fonts->AddFontDefault(&cfg);
    }
    io.FontGlobalScale = 1.0f / ratio;
    g_scale = cs / ratio;
    ImGuiStyle style;
    ImGui::StyleColorsDark(&style);
    style.ScaleAllSizes(g_scale);
    ImGui::GetStyle() = style;
    if (g_content_scale > 0.0f) { // a change while running (the window moved to another screen)
        ImGui_ImplOpenGL3_DestroyFontsTexture();
        ImGui_ImplOpenGL3_CreateFontsTexture();
    }
    g_content_scale = cs;
}

extern "C" int ui_init(GLFWwindow *window) {
    IMGUI_CHECKVERSION();
    if (!ImGui::CreateContext()) return -1;
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini littering the working directory
    g_window = window;
    g_content_scale = 0.0f;
    fit_content_scale();
    if (!ImGui_ImplGlfw_InitForOpenGL(window, true)) return -1;
    if (!ImGui_ImplOpenGL3_Init("#version 330 core")) return -1;
    return 0;
}

extern "C" void ui_shutdown(void) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

extern "C" void ui_begin_frame(void) {
    fit_content_scale();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
}

// The panel's width: as the user dragged it, within limits that keep it and the image on-screen.
static float dock_width(float window_w) {
    float w = g_dock_w > 0.0f ? g_dock_w : 360.0f * g_scale;
    float lo = std::fmin(200.0f * g_scale, 0.6f * window_w), hi = 0.6f * window_w;
    return std::fmax(std::fmin(w, hi), lo);
}

// Collapsed, the panel keeps a narrow column at the window's edge for its title bar's arrow: the
// image stays beside it, never under it.
static float collapsed_width(void) { return ImGui::GetStyle().WindowMinSize.x; }

extern "C" float ui_dock_width(const ui_controls *c) {
    if (!c->show_panel) return 0.0f;
    if (g_collapsed) return collapsed_width();
    int ww = 0;
    glfwGetWindowSize(g_window, &ww, nullptr);
    return dock_width((float)ww);
}

extern "C" float ui_dock_width_beside(const ui_controls *c, float image_w) {
    if (!c->show_panel) return 0.0f;
    if (g_collapsed) return collapsed_width();
    // dock_width(image_w + d) == d: the default, unless that is over 60% of the window
    return std::fmin(g_dock_w > 0.0f ? g_dock_w : 360.0f * g_scale, 1.5f * image_w);
}

extern "C" int ui_panel_resizing(void) { return g_resizing; }

extern "C" float ui_scale(void) { return g_scale; }

extern "C" float ui_content_scale(void) { return g_content_scale; }

extern "C" void ui_draw_image(unsigned texture, const float rect[4]) {
    if (!texture) return;
    ImGui::GetBackgroundDrawList()->AddImage((ImTextureID)(intptr_t)texture, ImVec2(rect[0], rect[1]),
                                             ImVec2(rect[2], rect[3]));
}

extern "C" void ui_draw_lights(const float *xy, int n, int selected) {
    ImDrawList *dl = ImGui::GetBackgroundDrawList();
    for (int i = 0; i < n; i++) {
        float x = xy[2 * i], y = xy[2 * i + 1];
        if (!std::isfinite(x) || !std::isfinite(y)) continue;
        ImU32 col = i == selected ? IM_COL32(255, 210, 60, 255) : IM_COL32(255, 255, 255, 140);
        float r = (i == selected ? 9.0f : 6.0f) * g_scale;
        dl->AddCircle(ImVec2(x, y), r, IM_COL32(0, 0, 0, 160), 0, 3.5f * g_scale);
        dl->AddCircle(ImVec2(x, y), r, col, 0, 1.5f * g_scale);
    }
}

static const ImU32 curve_colours[6] = {IM_COL32(255, 200, 60, 255),  IM_COL32(90, 200, 255, 255),
                                       IM_COL32(140, 255, 120, 255), IM_COL32(255, 110, 110, 255),
                                       IM_COL32(210, 140, 255, 255), IM_COL32(230, 230, 230, 255)};

// Relative error against time since the reset, log scale, one polyline per method and setting
// (the estimate's) with the image shown's as dots of the same colour.
static void error_plot(const ui_stats *s) {
    float tmax = 0.0f, emin = INFINITY, emax = 0.0f;
    for (int c = 0; c < s->num_curves; c++)
        for (int shown = 0; shown < 2; shown++) {
            const ui_curve *k = &s->curves[c];
            for (int i = 0; i < (shown ? k->shown_n : k->n); i++) {
                float e = shown ? k->shown_error[i] : k->error[i];
                if (!(e > 0.0f) || !std::isfinite(e)) continue;
                tmax = std::fmax(tmax, shown ? k->shown_seconds[i] : k->seconds[i]);
                emin = std::fmin(emin, e);
                emax = std::fmax(emax, e);
            }
        }
    if (!(emax > 0.0f)) {
        ImGui::TextUnformatted("error plot: nothing measured yet");
        return;
    }
    float noise = (float)s->reference_noise; // the floor no curve can go below on average
    if (noise > 0.0f && std::isfinite(noise)) {
        emin = std::fmin(emin, noise);
        emax = std::fmax(emax, noise);
    }
    if (!(tmax > 0.0f)) tmax = 1.0f;
    ImVec2 p0 = ImGui::GetCursorScreenPos();
    float w = std::fmax(ImGui::GetContentRegionAvail().x, 50.0f), h = 110.0f * g_scale;
    // Log scale with a label's height of room above and below: neither a curve nor the noise floor
    // runs under the axis labels
    float line = ImGui::GetTextLineHeight(), room = line + 4.0f;
    float lo = std::log10(emin), hi = std::log10(emax);
    float pad = std::fmax(room * (hi - lo) / std::fmax(h - 2.0f * room, 1.0f), 0.1f);
    lo -= pad;
    hi += pad;
    ImGui::Dummy(ImVec2(w, h));
    ImDrawList *dl = ImGui::GetWindowDrawList();
    dl->AddRectFilled(p0, ImVec2(p0.x + w, p0.y + h), IM_COL32(15, 15, 20, 255));
    for (float d = std::ceil(lo); d < hi; d += 1.0f) { // decade lines
        float y = p0.y + h * (1.0f - (d - lo) / (hi - lo));
        dl->AddLine(ImVec2(p0.x, y), ImVec2(p0.x + w, y), IM_COL32(60, 60, 70, 255));
    }
    if (noise > 0.0f && std::isfinite(noise)) { // dashed
        float y = p0.y + h * (1.0f - (std::log10(noise) - lo) / (hi - lo)), dash = 6.0f * g_scale;
        for (float x = p0.x; x < p0.x + w; x += 2.0f * dash)
            dl->AddLine(ImVec2(x, y), ImVec2(std::fmin(x + dash, p0.x + w), y), IM_COL32(200, 200, 200, 200), 1.5f);
    }
    ImVector<ImVec2> pts;
    for (int c = 0; c < s->num_curves; c++) {
        pts.resize(0);
        for (int i = 0; i < s->curves[c].n; i++) {
            float e = s->curves[c].error[i];
            if (!(e > 0.0f) || !std::isfinite(e)) continue;
            float x = p0.x + w * s->curves[c].seconds[i] / tmax;
            float y = p0.y + h * (1.0f - (std::log10(e) - lo) / (hi - lo));
            pts.push_back(ImVec2(x, y));
        }
        if (pts.Size == 1)
            dl->AddCircleFilled(pts[0], 2.0f, curve_colours[c % 6]);
        else if (pts.Size > 1)
            dl->AddPolyline(pts.Data, pts.Size, curve_colours[c % 6], 0, 1.5f);
        const ui_curve *k = &s->curves[c];
        for (int i = 0; i < k->shown_n; i++) {
            float e = k->shown_error[i];
            if (!(e > 0.0f) || !std::isfinite(e)) continue;
            float x = p0.x + w * k->shown_seconds[i] / tmax;
            float y = p0.y + h * (1.0f - (std::log10(e) - lo) / (hi - lo));
            dl->AddCircleFilled(ImVec2(x, y), 1.5f * g_scale, curve_colours[c % 6]);
        }
    }
    char label[32];
    std::snprintf(label, sizeof label, "%.2g", std::pow(10.0, (double)hi));
    dl->AddText(ImVec2(p0.x + 2, p0.y + 1), IM_COL32(200, 200, 200, 255), label);
    std::snprintf(label, sizeof label, "%.2g", std::pow(10.0, (double)lo));
    dl->AddText(ImVec2(p0.x + 2, p0.y + h - line - 1), IM_COL32(200, 200, 200, 255), label);
    std::snprintf(label, sizeof label, "%.1f s", (double)tmax);
    dl->AddText(ImVec2(p0.x + w - ImGui::CalcTextSize(label).x - 2, p0.y + h - line - 1), IM_COL32(200, 200, 200, 255),
                label);
    for (int c = 0; c < s->num_curves; c++) ImGui::TextColored(ImColor(curve_colours[c % 6]), "%s", s->curves[c].label);
}

// What a setting does and trades (its --help text), while the mouse rests on it.
static void help_tooltip(const char *help) {
    if (help && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", help);
}

// One widget per parameter of the group, from the table (params.h): choices as combo boxes, numbers
// as sliders whose lowest position stands for "off" where the parameter has one; each explains
// itself on hover.
static void param_widgets(param_group group, render_params *p) {
    int n;
    const param_desc *table = params_table(&n);
    for (int i = 0; i < n; i++) {
        const param_desc *d = &table[i];
        if (d->group != group || d->no_panel) continue;
        double v = param_get(d, p);
        if (d->type == PARAM_CHOICE && d->flag) { // on or off: a checkbox (choices[0] is on)
            bool on = (int)v == d->choices[0].value;
            if (ImGui::Checkbox(d->label, &on)) param_put(d, p, d->choices[on ? 0 : 1].value);
            help_tooltip(d->help);
            continue;
        }
        if (d->type == PARAM_CHOICE) {
            const char *labels[8];
            int k = 0, cur = 0;
            for (; k < d->num_choices && k < 8; k++) {
                labels[k] = d->choices[k].label;
                if (d->choices[k].value == (int)v) cur = k;
            }
            if (ImGui::Combo(d->label, &cur, labels, k)) param_put(d, p, d->choices[cur].value);
            help_tooltip(d->help);
            continue;
        }
        int has_off = d->off_word || d->zero_is_off;
        ImGuiSliderFlags flags = d->panel_log ? ImGuiSliderFlags_Logarithmic : 0;
        double shown = has_off && v < 0.0 ? d->panel_lo : v;
        const char *format = d->panel_lo_text && shown <= d->panel_lo ? d->panel_lo_text : d->panel_format;
        double edited;
        bool changed;
        if (d->type == PARAM_INT) {
            int x = (int)shown;
            changed = ImGui::SliderInt(d->label, &x, (int)d->panel_lo, (int)d->panel_hi, format, flags);
            edited = x;
        } else {
            float x = (float)shown;
            changed = ImGui::SliderFloat(d->label, &x, (float)d->panel_lo, (float)d->panel_hi, format, flags);
            edited = x;
        }
        help_tooltip(d->help);
        if (!changed) continue;
        // The lowest position is "off" where there is one; anything else stays in the accepted range.
        if (has_off && edited <= d->panel_lo)
            edited = -1.0;
        else
            edited = std::fmin(std::fmax(edited, d->lo), d->below_hi ? std::nextafter(d->hi, 0.0) : d->hi);
        char text[32], why[256];
        std::snprintf(text, sizeof text, "%g", edited);
        param_set_value(d, p, edited, text, why, sizeof why); // refused: the slider stays where it was
    }
}

// A button of the panel, its place kept while visible (ui_drawn_button).
static bool button(const char *label) {
    bool pressed = ImGui::Button(label);
    if (ImGui::IsItemVisible() && g_num_buttons < (int)(sizeof g_buttons / sizeof g_buttons[0])) {
        drawn_button *b = &g_buttons[g_num_buttons++];
        std::snprintf(b->label, sizeof b->label, "%s", label);
        ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
        b->rect[0] = lo.x, b->rect[1] = lo.y, b->rect[2] = hi.x, b->rect[3] = hi.y;
    }
    return pressed;
}

extern "C" int ui_drawn_button(int i, const char **label, float rect[4]) {
    if (i < 0 || i >= g_num_buttons) return 0;
    *label = g_buttons[i].label;
    for (int k = 0; k < 4; k++) rect[k] = g_buttons[i].rect[k];
    return 1;
}

// Grey text for notes.
static void note(const char *fmt, ...) IM_FMTARGS(1);
static void note(const char *fmt, ...) {
    char buf[1400];
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextUnformatted(buf);
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
}

// Why refinement stands still, or NULL while it runs.
static const char *held_reason(const ui_controls *c, const ui_stats *s, char *buf, size_t n) {
    if (!s->held) return nullptr;
    if (c->paused) return "paused (Space resumes)";
    if (c->spp_limit > 0 && s->render.frames >= c->spp_limit)
        std::snprintf(buf, n, "done: %lld spp limit reached", c->spp_limit);
    else
        std::snprintf(buf, n, "done: %.3g s limit reached", c->time_limit);
    return buf;
}

// Progress first: what the image has, how fast it grows, pause and the limits.
static void progress_section(ui_controls *c, const ui_stats *s) {
    char buf[160];
    double fraction = -1.0;
    if (c->spp_limit > 0) fraction = s->spp / (double)c->spp_limit;
    if (c->time_limit > 0) fraction = std::fmax(fraction, s->seconds / c->time_limit);
    if (fraction >= 0.0) {
        if (c->spp_limit > 0)
            std::snprintf(buf, sizeof buf, "%.0f / %lld spp", s->spp, c->spp_limit);
        else
            std::snprintf(buf, sizeof buf, "%.1f / %.3g s", s->seconds, c->time_limit);
        ImGui::ProgressBar((float)std::fmin(fraction, 1.0), ImVec2(-FLT_MIN, 0), buf);
    }
    ImGui::Text("%.0f spp (frames %lld) in %.1f s", s->spp, s->render.frames, s->seconds);
    const char *why = held_reason(c, s, buf, sizeof buf);
    if (why)
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s", why);
    else
        ImGui::TextUnformatted(s->render.denoised ? "refining; the image shown is filtered (N)" : "refining");
    /* Standing notes: the error plot paused away from the reference's camera, no light. */
    if (s->status && s->status[0]) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s", s->status);
    if (button(c->paused ? "resume (Space)" : "pause (Space)")) c->paused = !c->paused;
    ImGui::SameLine();
    if (button("help (F1)")) c->show_help = !c->show_help;
    int spp = (int)std::fmin((double)c->spp_limit, 1e8);
    if (ImGui::InputInt("stop at spp", &spp, 16, 256)) c->spp_limit = spp < 0 ? 0 : spp;
    float t = (float)c->time_limit;
    if (ImGui::InputFloat("stop at seconds", &t, 1.0f, 10.0f, "%.1f")) c->time_limit = t < 0.0f ? 0.0 : t;
    note("0: never stop");
    if (s->render.parts > 1)
        ImGui::Text("%d x %d   frame %.0f ms in %d parts (%d done)   %.2f M rays/s", s->width, s->height,
                    s->render.frame_ms, s->render.parts, s->render.parts_done, s->render.rays_per_second * 1e-6);
    else
        ImGui::Text("%d x %d   frame %.0f ms   %.2f M rays/s", s->width, s->height, s->render.frame_ms,
                    s->render.rays_per_second * 1e-6);
    if (s->reference) {
        if (s->rel_error >= 0.0)
            ImGui::Text("relative L2 error %.4f (the estimate)", s->rel_error);
        else
            ImGui::TextUnformatted("relative L2 error -");
        if (s->shown_error >= 0.0) ImGui::Text("%.4f of the image shown (dotted)", s->shown_error);
    }
}

// Bookmarks 1-9: a button restores each one that is set; "save" stores the view in a slot.
static void bookmark_buttons(ui_controls *c, const ui_stats *s) {
    ImGui::TextUnformatted("bookmarks (shift+N restores, ctrl+N saves)");
    for (int k = 1; k <= 9; k++) {
        char label[16];
        std::snprintf(label, sizeof label, "%d##go", k);
        bool set = (s->bookmarks_set >> k) & 1u;
        if (k > 1) ImGui::SameLine();
        if (!set) ImGui::PushStyleVar(ImGuiStyleVar_Alpha, 0.35f);
        if (button(label) && set) c->bookmark_restore = k;
        if (!set) ImGui::PopStyleVar();
    }
    ImGui::TextUnformatted("save the view as");
    for (int k = 1; k <= 9; k++) {
        char label[16];
        std::snprintf(label, sizeof label, "%d##save", k);
        ImGui::SameLine();
        if (button(label)) c->bookmark_save = k;
    }
    if (s->bookmarks) note("%s", s->bookmarks);
}

// The panel, docked at the window's right edge over its whole height: the width is the user's
// (dragging its left edge), kept between limits so that it and the image stay on-screen.
static void panel(ui_controls *c, const ui_stats *s) {
    ImVec2 display = ImGui::GetIO().DisplaySize;
    float w = g_collapsed ? collapsed_width() : dock_width(display.x);
    ImGui::SetNextWindowPos(ImVec2(display.x, 0.0f), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
    ImGui::SetNextWindowSize(ImVec2(w, display.y), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.94f);
    // Collapsed, its column shows the arrow alone on the panel's colour (the title, one ID
    // with "###", would not fit).
    if (g_collapsed)
        ImGui::GetBackgroundDrawList()->AddRectFilled(ImVec2(display.x - w, 0.0f), display,
                                                      ImGui::GetColorU32(ImGuiCol_WindowBg));
    bool open = ImGui::Begin(g_collapsed ? "###panel" : "glint: settings and progress###panel", nullptr,
                             ImGuiWindowFlags_NoMove);
    // A drag of the left edge resized it this frame: keep the width asked for.
    float now_w = ImGui::GetWindowWidth();
    if (open && !g_collapsed && std::fabs(now_w - w) > 0.5f) {
        g_dock_w = now_w;
        g_resizing = true;
    }
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) g_resizing = false;
    g_collapsed = !open;
    if (!open) {
        g_image_dock = collapsed_width();
        ImGui::End();
        return;
    }
    g_image_dock = w;
    ImGui::TextUnformatted(s->scene_name ? s->scene_name : "");
    ImGui::PushItemWidth(-ImGui::GetFontSize() * 11.0f); // room for the longest label
    if (s->num_variants > 0) { // KHR_materials_variants: switching reloads the scene, the view stays
        int v = c->variant + 1;
        if (ImGui::Combo("material variant", &v, s->variant_labels, s->num_variants + 1)) c->variant = v - 1;
    }

    if (ImGui::CollapsingHeader("Progress", ImGuiTreeNodeFlags_DefaultOpen)) progress_section(c, s);

    if (ImGui::CollapsingHeader("Estimator", ImGuiTreeNodeFlags_DefaultOpen)) {
        param_widgets(PARAM_RENDER, &c->params);
        if (s->many_light) param_widgets(PARAM_MANY_LIGHT, &c->params);
        // Cost and bias where known: the last full frame's time and the plan's reasons.
        if (s->cost_ms <= 0.0)
            note("cost: measuring (the first full frame of these settings)");
        else if (s->cost_before_ms > 0.0)
            note("cost: %.0f ms a full frame, %.2gx the %.0f ms before the last change", s->cost_ms,
                 s->cost_ms / s->cost_before_ms, s->cost_before_ms);
        else
            note("cost: %.0f ms a full frame", s->cost_ms);
        if (s->render.plan && s->render.plan[0] &&
            ImGui::TreeNodeEx("what runs, and why (effect plan)", ImGuiTreeNodeFlags_DefaultOpen)) {
            note("%s", s->render.plan);
            ImGui::TreePop();
        }
    }
    if (s->highlights && ImGui::CollapsingHeader("Highlights", ImGuiTreeNodeFlags_DefaultOpen))
        param_widgets(PARAM_HIGHLIGHTS, &c->params);

    if (s->num_lights > 0 && ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) {
        int l = c->light;
        if (ImGui::Combo("light", &l, s->light_names, s->num_lights)) c->light = l;
        if (c->light >= 0) {
            ImGui::SliderFloat("intensity", &c->light_gain, 0.01f, 100.0f, "x %.3g",
                               ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
            ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
            ImGui::TextWrapped(s->light_movable ? "move: arrows, PageUp/PageDown, ctrl+drag; ctrl+click picks"
                                                : "directional: no position; ctrl+click picks");
            ImGui::PopStyleColor();
        }
    }

    if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
        param_widgets(PARAM_DISPLAY, &c->params); // exposure, tone mapper, denoise (N)
        const char *shows[UI_SHOW_COUNT];
        for (int i = 0; i < UI_SHOW_COUNT; i++) shows[i] = ui_show_name(i);
        ImGui::Combo("show", &c->show, shows, s->reference ? UI_SHOW_COUNT : UI_SHOW_ERROR);
        if (c->show == UI_SHOW_ERROR)
            ImGui::TextUnformatted("per-pixel relative error:\nblue 1%, green 10%, red 100% and more");
        if (c->show == UI_SHOW_WORK)
            ImGui::TextUnformatted("rays each pixel took, against the most:\nblack none, red half, yellow the most");
        if (c->show == UI_SHOW_ESTIMATOR)
            ImGui::TextUnformatted("each pixel's samples: blue path tracing,\norange the virtual lights (auto: mixed)");
    }

    if (s->reference && ImGui::CollapsingHeader("Reference", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::TextWrapped("%s", s->reference);
        if (s->rel_error >= 0.0)
            ImGui::Text("relative L2 error %.4f (the estimate)", s->rel_error);
        else
            ImGui::TextUnformatted("relative L2 error -");
        if (s->shown_error >= 0.0) ImGui::Text("%.4f of the image shown (dotted)", s->shown_error);
        if (s->reference_noise >= 0.0)
            note("the reference's own noise: %.4f (the dashed line); below it, error is the reference's",
                 s->reference_noise);
        else
            note("the reference's own noise: unknown (no description in its file)");
        error_plot(s);
    }

    if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) {
        char label[32];
        std::snprintf(label, sizeof label, c->camera < 0 ? "free" : "scene camera %d", c->camera);
        if (ImGui::BeginCombo("camera", label)) {
            if (ImGui::Selectable("free", c->camera < 0)) c->camera = -1;
            for (int i = 0; i < s->num_cameras; i++) {
                std::snprintf(label, sizeof label, "scene camera %d", i);
                if (ImGui::Selectable(label, c->camera == i)) c->camera = i;
            }
            ImGui::EndCombo();
        }
        if (button("reset view (R)")) c->reset_view = 1;
        ImGui::SameLine();
        if (button("frame scene (F)")) c->frame_scene = 1;
        if (s->reference) {
            ImGui::SameLine();
            if (button("reference camera (C)")) c->reference_view = 1;
        }
        bookmark_buttons(c, s);
    }

    if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (button("screenshot (F12)")) c->screenshot = 1;
        ImGui::SameLine();
        if (button("export EXR (F11)")) c->export_exr = 1;
        ImGui::InputText("path", c->path, sizeof c->path);
        if (button("load scene")) c->load_scene = 1;
        ImGui::SameLine();
        if (button("load environment")) c->load_env = 1;
        ImGui::SameLine();
        if (button("load reference")) c->load_reference = 1;
        if (button("uniform sky on/off (K)")) c->uniform_sky = 1;
        if (s->message && s->message[0]) ImGui::TextWrapped("%s", s->message);
    }

    if (ImGui::CollapsingHeader("Statistics")) {
        ImGui::Text("%d x %d, %.1f samples a pixel shown", s->width, s->height, s->render.mean_count);
        ImGui::Text("frames %lld   spp %.0f", s->render.frames, s->spp);
        ImGui::Text("time %.1f s   frame %.0f ms", s->seconds, s->render.frame_ms);
        ImGui::Text("%.2f M rays/s", s->render.rays_per_second * 1e-6);
        if (s->render.rejected) ImGui::Text("rejected samples %llu", (unsigned long long)s->render.rejected);
        if (s->many_light) ImGui::Text("virtual lights %llu", (unsigned long long)s->render.virtual_lights);
        if (s->highlights) { /* always two lines, so the panel's height does not jump */
            if (s->render.hl_points > 0 && s->render.frames > 0) {
                ImGui::Text("lobes lit %.0f/frame (%.2f/hit)", (double)s->render.hl_lobes / (double)s->render.frames,
                            (double)s->render.hl_lobes / (double)s->render.hl_points);
                ImGui::Text("merging %.1f%% of render time", 100.0 * s->render.hl_merge_share);
            } else {
                ImGui::TextUnformatted("lobes lit -");
                ImGui::TextUnformatted("merging -");
            }
        }
    }
    ImGui::PopItemWidth();
    ImGui::End();
}

// The overlay in the image's top-left corner: method, samples, time, speed, error.
static void overlay(const ui_controls *c, const ui_stats *s) {
    float pad = 8.0f * g_scale;
    ImGui::SetNextWindowPos(ImVec2(pad, pad), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.75f);
    const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                   ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoNav |
                                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoSavedSettings;
    if (ImGui::Begin("##overlay", nullptr, flags)) {
        char err[64] = "";
        if (s->reference && s->rel_error >= 0.0 && s->shown_error >= 0.0)
            std::snprintf(err, sizeof err, "   error %.4f (shown %.4f)", s->rel_error, s->shown_error);
        else if (s->reference && s->rel_error >= 0.0)
            std::snprintf(err, sizeof err, "   error %.4f", s->rel_error);
        double fps = s->render.frame_ms > 0.0 ? 1e3 / s->render.frame_ms : 0.0;
        ImGui::Text("%s   %.0f spp   %.1f s   %.1f fps%s", s->method ? s->method : "", s->spp, s->seconds, fps, err);
        char buf[160];
        const char *why = held_reason(c, s, buf, sizeof buf);
        if (why) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s", why);
        ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
        ImGui::TextUnformatted(c->show_panel ? "F1 or ?: keys" : "F1 or ?: keys   Tab: panel");
        ImGui::PopStyleColor();
    }
    ImGui::End();
}

// Every shortcut, over the image's centre, or the window's when the image is narrower; never
// larger than the window (it scrolls then).
static void help(ui_controls *c, const ui_stats *s) {
    static ImVec2 last_size(0.0f, 0.0f);
    ImVec2 display = ImGui::GetIO().DisplaySize;
    float image_w = display.x - g_image_dock;
    float cx = last_size.x <= image_w ? 0.5f * image_w : 0.5f * display.x;
    float x = std::fmax(0.0f, std::fmin(cx - 0.5f * last_size.x, display.x - last_size.x));
    float y = std::fmax(0.0f, 0.5f * (display.y - last_size.y));
    ImGui::SetNextWindowPos(ImVec2(x, y), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), display);
    ImGui::SetNextWindowBgAlpha(0.92f);
    bool open = true;
    if (ImGui::Begin("keys and mouse (F1 or ? closes)", &open,
                     ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse |
                         ImGuiWindowFlags_HorizontalScrollbar)) {
        if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
            for (int i = 0; i < s->num_shortcuts; i++) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextColored(ImVec4(1.0f, 0.85f, 0.45f, 1.0f), "%s", s->shortcut_keys[i]);
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(s->shortcut_actions[i]);
            }
            ImGui::EndTable();
        }
    }
    last_size = ImGui::GetWindowSize();
    ImGui::End();
    if (!open) c->show_help = 0;
}

extern "C" void ui_panel(ui_controls *c, const ui_stats *s) {
    g_image_dock = 0.0f;
    g_num_buttons = 0;
    if (c->show_panel) panel(c, s);
    overlay(c, s);
    if (c->show_help) help(c, s);
}

extern "C" void ui_end_frame(void) {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

extern "C" int ui_wants_mouse(void) { return ImGui::GetIO().WantCaptureMouse; }
extern "C" int ui_wants_keyboard(void) { return ImGui::GetIO().WantCaptureKeyboard; }
