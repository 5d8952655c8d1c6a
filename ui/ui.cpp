// glint — the panel: Dear ImGui (Debian's libimgui 1.86) with its GLFW and OpenGL 3 backends.
// Only this file sees C++; the viewer talks to it through ui.h.
#include "ui.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

extern "C" int ui_init(GLFWwindow *window) {
    IMGUI_CHECKVERSION();
    if (!ImGui::CreateContext()) return -1;
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini littering the working directory
    ImGui::StyleColorsDark();
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
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
}

extern "C" void ui_draw_image(unsigned texture) {
    if (!texture) return;
    ImVec2 size = ImGui::GetIO().DisplaySize;
    ImGui::GetBackgroundDrawList()->AddImage((ImTextureID)(intptr_t)texture, ImVec2(0, 0), size);
}

extern "C" void ui_draw_lights(const float *xy, int n, int selected) {
    ImDrawList *dl = ImGui::GetBackgroundDrawList();
    for (int i = 0; i < n; i++) {
        float x = xy[2 * i], y = xy[2 * i + 1];
        if (!std::isfinite(x) || !std::isfinite(y)) continue;
        ImU32 col = i == selected ? IM_COL32(255, 210, 60, 255) : IM_COL32(255, 255, 255, 140);
        dl->AddCircle(ImVec2(x, y), i == selected ? 9.0f : 6.0f, IM_COL32(0, 0, 0, 160), 0, 3.5f);
        dl->AddCircle(ImVec2(x, y), i == selected ? 9.0f : 6.0f, col, 0, 1.5f);
    }
}

static const ImU32 curve_colours[6] = {IM_COL32(255, 200, 60, 255),  IM_COL32(90, 200, 255, 255),
                                       IM_COL32(140, 255, 120, 255), IM_COL32(255, 110, 110, 255),
                                       IM_COL32(210, 140, 255, 255), IM_COL32(230, 230, 230, 255)};

// Relative error against time since the reset, log scale, one polyline per method and setting.
static void error_plot(const ui_stats *s) {
    float tmax = 0.0f, emin = INFINITY, emax = 0.0f;
    for (int c = 0; c < s->num_curves; c++)
        for (int i = 0; i < s->curves[c].n; i++) {
            float e = s->curves[c].error[i];
            if (!(e > 0.0f) || !std::isfinite(e)) continue;
            tmax = std::fmax(tmax, s->curves[c].seconds[i]);
            emin = std::fmin(emin, e);
            emax = std::fmax(emax, e);
        }
    if (!(emax > 0.0f)) {
        ImGui::TextUnformatted("error plot: no full-resolution frame yet");
        return;
    }
    float lo = std::floor(std::log10(emin)), hi = std::ceil(std::log10(emax));
    if (hi <= lo) hi = lo + 1.0f;
    if (!(tmax > 0.0f)) tmax = 1.0f;
    ImVec2 p0 = ImGui::GetCursorScreenPos();
    float w = std::fmax(ImGui::GetContentRegionAvail().x, 50.0f), h = 110.0f;
    ImGui::Dummy(ImVec2(w, h));
    ImDrawList *dl = ImGui::GetWindowDrawList();
    dl->AddRectFilled(p0, ImVec2(p0.x + w, p0.y + h), IM_COL32(15, 15, 20, 255));
    for (float d = lo + 1.0f; d < hi; d += 1.0f) { // decade lines
        float y = p0.y + h * (1.0f - (d - lo) / (hi - lo));
        dl->AddLine(ImVec2(p0.x, y), ImVec2(p0.x + w, y), IM_COL32(60, 60, 70, 255));
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
    }
    char label[32];
    std::snprintf(label, sizeof label, "1e%+.0f", (double)hi);
    dl->AddText(ImVec2(p0.x + 2, p0.y + 1), IM_COL32(200, 200, 200, 255), label);
    std::snprintf(label, sizeof label, "1e%+.0f", (double)lo);
    dl->AddText(ImVec2(p0.x + 2, p0.y + h - 15), IM_COL32(200, 200, 200, 255), label);
    std::snprintf(label, sizeof label, "%.1f s", (double)tmax);
    dl->AddText(ImVec2(p0.x + w - 8.0f * (float)std::strlen(label), p0.y + h - 15), IM_COL32(200, 200, 200, 255),
                label);
    for (int c = 0; c < s->num_curves; c++) ImGui::TextColored(ImColor(curve_colours[c % 6]), "%s", s->curves[c].label);
}

// One widget per many-light parameter of the group, from the table (params.h): choices as combo
// boxes, numbers as sliders whose lowest position stands for "off" where the parameter has one.
static void param_widgets(param_group group, vl_params *vl) {
    int n;
    const param_desc *table = params_table(&n);
    for (int i = 0; i < n; i++) {
        const param_desc *d = &table[i];
        if (d->group != group) continue;
        double v = param_get(d, vl);
        if (d->type == PARAM_CHOICE) {
            const char *labels[8];
            int k = 0, cur = 0;
            for (; k < d->num_choices && k < 8; k++) {
                labels[k] = d->choices[k].label;
                if (d->choices[k].value == (int)v) cur = k;
            }
            if (ImGui::Combo(d->label, &cur, labels, k)) param_put(d, vl, d->choices[cur].value);
            continue;
        }
        int has_off = d->off_word || d->zero_is_off;
        ImGuiSliderFlags flags = d->panel_log ? ImGuiSliderFlags_Logarithmic : 0;
        double shown = has_off && v < 0.0 ? d->panel_lo : v;
        const char *format = d->panel_lo_text && shown <= d->panel_lo ? d->panel_lo_text : d->panel_format;
        double edited;
        if (d->type == PARAM_INT) {
            int x = (int)shown;
            if (!ImGui::SliderInt(d->label, &x, (int)d->panel_lo, (int)d->panel_hi, format, flags)) continue;
            edited = x;
        } else {
            float x = (float)shown;
            if (!ImGui::SliderFloat(d->label, &x, (float)d->panel_lo, (float)d->panel_hi, format, flags)) continue;
            edited = x;
        }
        // The lowest position is "off" where there is one; anything else stays in the accepted range.
        if (has_off && edited <= d->panel_lo)
            edited = -1.0;
        else
            edited = std::fmin(std::fmax(edited, d->lo), d->below_hi ? std::nextafter(d->hi, 0.0) : d->hi);
        param_put(d, vl, edited);
    }
}

extern "C" void ui_panel(ui_controls *c, const ui_stats *s) {
    if (!c->show_panel) return;
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.85f);
    if (!ImGui::Begin("glint", nullptr)) {
        ImGui::End();
        return;
    }
    ImGui::TextUnformatted(s->scene_name ? s->scene_name : "");
    ImGui::PushItemWidth(-ImGui::GetFontSize() * 10.0f); /* room for the longest label */

    if (ImGui::CollapsingHeader("Estimator", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (s->num_methods > 0) {
            int m = (int)c->params.method;
            if (ImGui::Combo("method", &m, s->method_names, s->num_methods)) c->params.method = (render_method)m;
        }
        ImGui::SliderInt("max depth", &c->params.max_depth, 1, 64);
        if (s->many_light) param_widgets(PARAM_MANY_LIGHT, &c->params.vl);
    }

    if (s->highlights && ImGui::CollapsingHeader("Highlights", ImGuiTreeNodeFlags_DefaultOpen))
        param_widgets(PARAM_HIGHLIGHTS, &c->params.vl);

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
        ImGui::SliderFloat("exposure", &c->exposure, -8.0f, 8.0f, "%.1f stops");
        if (s->num_tonemaps > 0) ImGui::Combo("tone mapper", &c->tonemap, s->tonemap_names, s->num_tonemaps);
        static const char *shows[UI_SHOW_COUNT] = {"all", "direct", "indirect", "highlights", "error"};
        ImGui::Combo("show", &c->show, shows, s->reference ? UI_SHOW_COUNT : UI_SHOW_ERROR);
        if (c->show == UI_SHOW_ERROR)
            ImGui::TextUnformatted("per-pixel relative error:\nblue 1%, green 10%, red 100% and more");
    }

    if (s->reference && ImGui::CollapsingHeader("Reference", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::TextWrapped("%s", s->reference);
        if (s->rel_error >= 0.0)
            ImGui::Text("relative L2 error %.4f", s->rel_error);
        else
            ImGui::TextUnformatted("relative L2 error -");
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
        if (ImGui::Button("reset view (R)")) c->reset_view = 1;
        if (s->bookmarks) ImGui::TextWrapped("bookmarks (ctrl+N saves, shift+N restores): %s", s->bookmarks);
    }

    if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (ImGui::Button("screenshot (F12)")) c->screenshot = 1;
        ImGui::SameLine();
        if (ImGui::Button("export EXR (F11)")) c->export_exr = 1;
        ImGui::InputText("path", c->path, sizeof c->path);
        if (ImGui::Button("load scene")) c->load_scene = 1;
        ImGui::SameLine();
        if (ImGui::Button("load environment")) c->load_env = 1;
        ImGui::SameLine();
        if (ImGui::Button("load reference")) c->load_reference = 1;
        if (s->message && s->message[0]) ImGui::TextWrapped("%s", s->message);
    }

    if (ImGui::CollapsingHeader("Statistics", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::Text("%d x %d%s", s->width, s->height, s->previewing ? "  (preview while moving)" : "");
        ImGui::Text("frames %lld   spp %.0f", s->frames, s->spp);
        ImGui::Text("time %.1f s   frame %.0f ms", s->seconds, s->frame_ms);
        ImGui::Text("%.2f M rays/s", s->rays_per_second * 1e-6);
        if (s->rejected_samples) ImGui::Text("rejected samples %llu", s->rejected_samples);
        if (s->many_light) ImGui::Text("virtual lights %llu", s->virtual_lights);
        if (s->highlights) { /* always two lines, so the panel's height does not jump */
            if (s->hl_points > 0) {
                ImGui::Text("lobes lit %llu/frame (%.2f/hit)", s->hl_lobes, (double)s->hl_lobes / (double)s->hl_points);
                ImGui::Text("merging %.1f%% of render time", 100.0 * s->hl_merge_share);
            } else {
                ImGui::TextUnformatted("lobes lit -");
                ImGui::TextUnformatted("merging -");
            }
        }
        if (s->plan && s->plan[0] && ImGui::TreeNode("effect plan")) {
            ImGui::PushTextWrapPos(0.0f);
            ImGui::TextUnformatted(s->plan);
            ImGui::PopTextWrapPos();
            ImGui::TreePop();
        }
    }
    ImGui::PopItemWidth();
    ImGui::End();
}

extern "C" void ui_end_frame(void) {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

extern "C" int ui_wants_mouse(void) { return ImGui::GetIO().WantCaptureMouse; }
extern "C" int ui_wants_keyboard(void) { return ImGui::GetIO().WantCaptureKeyboard; }
