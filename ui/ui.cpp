// glint — the panel: Dear ImGui (Debian's libimgui 1.86) with its GLFW and OpenGL 3 backends.
// Only this file sees C++; the viewer talks to it through ui.h.
#include "ui.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <cstdint>
#include <cstdio>

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

extern "C" void ui_panel(ui_controls *c, const ui_stats *s) {
    if (!c->show_panel) return;
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(330, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.85f);
    if (!ImGui::Begin("glint", nullptr)) {
        ImGui::End();
        return;
    }
    ImGui::TextUnformatted(s->scene_name ? s->scene_name : "");

    if (ImGui::CollapsingHeader("Estimator", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (s->num_methods > 0) {
            int m = c->method;
            if (ImGui::Combo("method", &m, s->method_names, s->num_methods)) c->method = m;
        }
        ImGui::SliderInt("max depth", &c->max_depth, 1, 64);
        if (s->many_light) {
            static const char *clamps[3] = {"method default", "on", "off"};
            ImGui::Combo("clamping", &c->clamp, clamps, 3);
            ImGui::SliderFloat("clamp value", &c->clamp_value, 1e-3f, 100.0f, "%.3g", ImGuiSliderFlags_Logarithmic);
            ImGui::SliderFloat("radius mult", &c->radius_mult, 0.05f, 32.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
            ImGui::SliderFloat("radius shrink", &c->radius_shrink, 0.0f, 0.99f, c->radius_shrink > 0 ? "%.2f" : "off");
            ImGui::SliderInt("lights/frame", &c->vl_count, 16, 1 << 20, "%d", ImGuiSliderFlags_Logarithmic);
            ImGui::SliderInt("clusters", &c->columns, 0, 1 << 14, c->columns > 0 ? "%d" : "none",
                             ImGuiSliderFlags_Logarithmic);
            ImGui::SliderInt("lights/pixel", &c->per_pixel, -1, 256, c->per_pixel < 0 ? "all" : "%d");
            if (c->per_pixel == 0) c->per_pixel = 1;
            ImGui::SliderInt("candidates", &c->candidates, 1, 64, c->candidates > 1 ? "%d" : "1 (by power)",
                             ImGuiSliderFlags_Logarithmic);
            ImGui::SliderFloat("trace glossy below", &c->trace_glossy, 0.0f, 1.0f,
                               c->trace_glossy > 0.0f ? "alpha %.2f" : "never");
        }
    }

    if (s->highlights && ImGui::CollapsingHeader("Highlights", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::SliderInt("secondary rays", &c->secondary_rays, 1, s->max_secondary_rays, "%d",
                         ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
        ImGui::SliderInt("clusters (K)", &c->clusters, 1, s->max_clusters, "%d", ImGuiSliderFlags_AlwaysClamp);
        static const char *merges[3] = {"on", "off", "trace"};
        ImGui::Combo("merge", &c->merge, merges, 3);
    }

    if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::SliderFloat("exposure", &c->exposure, -8.0f, 8.0f, "%.1f stops");
        static const char *shows[UI_SHOW_COUNT] = {"all", "direct", "indirect", "highlights"};
        ImGui::Combo("show", &c->show, shows, UI_SHOW_COUNT);
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
    }

    if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (ImGui::Button("screenshot (F12)")) c->screenshot = 1;
        ImGui::SameLine();
        if (ImGui::Button("export EXR (F11)")) c->export_exr = 1;
        ImGui::InputText("path", c->path, sizeof c->path);
        if (ImGui::Button("load scene")) c->load_scene = 1;
        ImGui::SameLine();
        if (ImGui::Button("load environment")) c->load_env = 1;
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
    }
    ImGui::End();
}

extern "C" void ui_end_frame(void) {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

extern "C" int ui_wants_mouse(void) { return ImGui::GetIO().WantCaptureMouse; }
extern "C" int ui_wants_keyboard(void) { return ImGui::GetIO().WantCaptureKeyboard; }
