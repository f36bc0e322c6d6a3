// Step 06: the same scene and camera drawn by rasterization, in software on the CPU, and
// compared with the ray tracer pixel for pixel. SDL2 only shows the image.
#include <SDL2/SDL_keycode.h>
#include <imgui.h>

#include <cstdio>
#include <iostream>

#include "06_raster/compare.hpp"
#include "06_raster/culling.hpp"
#include "06_raster/measure.hpp"
#include "06_raster/pipeline.hpp"
#include "core/app.hpp"
#include "core/orbit.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

using namespace boxes;

namespace {

ShadowMode parseShadows(const std::string& name) {
    if (name == "none") return ShadowMode::None;
    if (name == "map") return ShadowMode::Map;
    return ShadowMode::Rays;
}

template <typename T>
void writeBuffer(const std::string& path, const std::vector<T>& values) {
    writeFileAtomically(path, values.data(), values.size() * sizeof(T));
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("06_raster", [&] {
        CLI::App app{
            "Step 06: the same scene and camera drawn by rasterization (software, CPU), "
            "compared with the ray tracer pixel for pixel."};
        CommonOptions opts;
        addCommonOptions(app, opts, "bunny");
        RasterSettings rs;
        double nearFlag = 0.0, farFlag = 0.0;
        CLI::Option* nearOption = app.add_option(
            "--near", nearFlag, "near plane distance along the view (default: from the scene)");
        CLI::Option* farOption = app.add_option(
            "--far", farFlag, "far plane distance along the view (default: from the scene)");
        std::string idsPath, depthPath;
        app.add_option("--ids", idsPath,
                       "write the visible triangle per pixel: uint32, row-major, row 0 at the top, "
                       "0xFFFFFFFF where nothing");
        app.add_option("--depth", depthPath,
                       "write the depth per pixel: float32 distance along the view direction, +inf "
                       "where nothing");
        std::string shadows = "rays";
        app.add_option("--shadows", shadows, "shadows: none, map (shadow map) or rays (hybrid)")
            ->check(CLI::IsMember({"none", "map", "rays"}))
            ->capture_default_str();
        double bias = 0.0;
        app.add_option("--bias", bias,
                       "shadow map depth bias in world units (0: 2e-3 of the scene's diagonal)")
            ->check(CLI::Range(0.0, 1e30));
        int mapSize = 2048;
        app.add_option("--map-size", mapSize, "shadow map size in texels")
            ->check(CLI::Range(16, 8192));
        app.add_flag("--backface", rs.backfaceCulling, "cull back faces");
        bool affine = false, checker = false, compare = false, measure = false, noCull = false;
        app.add_flag("--no-cull", noCull,
                     "draw every triangle (no frustum culling with step 04's hierarchy)");
        app.add_flag("--affine", affine,
                     "interpolate affinely in screen space (warps) instead of with 1/w");
        app.add_flag("--checker", checker,
                     "modulate the surfaces with a checker (shows interpolation)");
        app.add_flag(
            "--compare", compare,
            "also ray trace the view and print how the two agree (and write FILE-diff.png)");
        app.add_flag("--measure", measure, "run the step's measurements and print the tables");
        parseCommandLine(app, argc, argv);

        Scene scene = sceneFromOptions(opts);
        attachGrid(scene);
        RasterScene raster = RasterScene::fromScene(scene);
        std::unique_ptr<FrustumCuller> culler;
        if (scene.hasMesh()) culler = std::make_unique<FrustumCuller>(scene.mesh);
        bool culling = !noCull;
        CullStats cull;
        if (nearOption->count()) {
            if (!(nearFlag > 0.0) || !std::isfinite(nearFlag))
                throw InputError("--near must be greater than 0");
            rs.near = nearFlag;
        }
        if (farOption->count()) {
            if (!(farFlag > 0.0) || !std::isfinite(farFlag) ||
                (rs.near > 0.0 && !(farFlag > rs.near)))
                throw InputError("--far must be greater than --near (and than 0)");
            rs.far = farFlag;
        }
        rs.width = opts.width;
        rs.height = opts.height;
        rs.perspectiveCorrect = !affine;
        nearFarFor(raster, scene.camera, rs);  // bad --near/--far: an error before any output
        ShadeSettings ss;
        ss.shadows = parseShadows(shadows);
        ss.mapBias = bias;
        ss.mapSize = mapSize;
        ss.checker = checker;

        if (opts.headless) {
            Report report;
            report.program = "06_raster";
            std::string out = headlessPath(opts, report.program);
            FrameBuffers buffers;
            FrameStats stats = rasterizeCulled(raster, culling ? culler.get() : nullptr,
                                               scene.camera, rs, buffers, cull);
            ShadedFrame shaded = shadeFrame(scene, raster, scene.camera, buffers, ss);
            shaded.image.writePng(out);
            report.images.push_back({out, "scene '" + scene.name + "' rasterized, shadows: " +
                                              shadowModeName(ss.shadows)});
            if (!idsPath.empty()) writeBuffer(idsPath, meshIds(raster, buffers));
            if (!depthPath.empty()) writeBuffer(depthPath, meshDepths(raster, buffers));
            report.facts["triangles"] = raster.triangles.size();
            report.facts["triangles_after_culling"] = stats.trianglesIn;
            report.facts["triangles_drawn"] = stats.trianglesDrawn;
            const size_t frustumCulled =
                culling && culler ? raster.meshTriangles - cull.trianglesKept : 0;
            report.facts["triangles_culled"] =
                frustumCulled + stats.culledOutside + stats.culledBackface;
            report.facts["triangles_frustum_culled"] = frustumCulled;
            report.facts["boxes_visited"] = cull.boxesVisited;
            report.facts["boxes_culled"] = cull.boxesCulled;
            report.facts["boxes_kept"] = cull.boxesKept;
            report.facts["cull_ms"] = cull.milliseconds;
            report.facts["triangles_outside"] = stats.culledOutside;
            report.facts["triangles_backface_or_empty"] = stats.culledBackface;
            report.facts["triangles_clipped"] = stats.clipped;
            report.facts["fragments"] = stats.fragments;
            report.facts["pixels_covered"] = stats.pixelsCovered;
            report.facts["raster_ms"] = stats.milliseconds;
            report.facts["shade_ms"] = shaded.milliseconds;
            report.facts["frame_ms"] = stats.milliseconds + shaded.milliseconds;
            std::cerr << "06_raster: wrote " << out << " (" << rs.width << "x" << rs.height << ", "
                      << stats.trianglesDrawn << " of " << raster.triangles.size()
                      << " triangles drawn, " << stats.pixelsCovered << " pixels covered, raster "
                      << formatSeconds(stats.milliseconds * 1e-3) << ", shading "
                      << formatSeconds(shaded.milliseconds * 1e-3) << ")\n";
            if (compare) {
                TracedFrame traced = traceFrame(scene, scene.camera, rs.width, rs.height, true, 1);
                VisibilityComparison c = compareVisibility(
                    rs.width, rs.height, meshIds(raster, buffers), meshDepths(raster, buffers),
                    traced.ids, traced.depth, &scene.mesh);
                std::string diff = pngWithSuffix(out, "-diff");
                differenceImage(rs.width, rs.height, meshIds(raster, buffers), traced.ids)
                    .writePng(diff);
                report.images.push_back(
                    {diff,
                     "grey: same triangle; red: only the rasterizer; blue: only "
                     "the ray tracer; yellow: different triangles"});
                ShadowComparison sc =
                    compareShadows(meshIds(raster, buffers), shaded.litByFirstLight, traced.ids,
                                   traced.litByFirstLight);
                report.facts["compare"] = {
                    {"pixels_covered_raster", c.coveredRaster},
                    {"pixels_covered_traced", c.coveredTraced},
                    {"same_triangle_share", c.agreement()},
                    {"differ_on_edges", c.differOnEdge},
                    {"differ_elsewhere", c.differElsewhere},
                    {"coverage_difference_share", c.coverageDifference()},
                    {"max_depth_error", c.maxDepthError},
                    {"mean_depth_error", c.meanDepthError},
                    {"shadow_pixels_disagreeing", sc.acne + sc.leaks},
                    {"shadow_pixels_compared", sc.compared},
                    {"raster_frame_ms", stats.milliseconds + shaded.milliseconds},
                    {"traced_frame_ms", traced.milliseconds}};
                std::printf(
                    "pixels covered: raster %zu, ray tracer %zu (difference %.4f%% of the image)\n",
                    c.coveredRaster, c.coveredTraced, 100.0 * c.coverageDifference());
                std::printf(
                    "same triangle: %.4f%% of covered pixels (%zu differ on triangle edges, %zu "
                    "elsewhere)\n",
                    100.0 * c.agreement(), c.differOnEdge, c.differElsewhere);
                std::printf("depth error where they agree: max %.3g, mean %.3g (relative)\n",
                            c.maxDepthError, c.meanDepthError);
                std::printf("shadows (%s) against the ray tracer's: %zu of %zu pixels disagree\n",
                            shadowModeName(ss.shadows), sc.acne + sc.leaks, sc.compared);
                std::printf(
                    "time per frame, single thread: raster %.1f ms (+ shading %.1f ms), ray tracer "
                    "%.1f ms "
                    "(visibility and shadow rays)\n",
                    stats.milliseconds, shaded.milliseconds, traced.milliseconds);
            }
            if (measure) {
                MeasureSettings ms;
                ms.width = rs.width;
                ms.height = rs.height;
                std::vector<MeasureView> views =
                    measureViews(opts.dataDir, findSharedMeshes(opts.dataDir), opts.aspect());
                report.add(measureVisibility(views, ms));
                report.add(measureFrameTimes(views, ms));
                report.add(measureCulling(views, ms));
                std::cerr << "06_raster: shadows...\n";
                report.add(measureShadowBias(views[0], ms));
                report.add(measureShadowMethods(views[0], ms));
                std::cerr << "06_raster: interpolation...\n";
                report.add(measureInterpolation(views[0], ms, pngStem(out), report.images));
                report.plots.push_back(
                    {{"table", "shadow_bias"},
                     {"x", "bias (x diagonal)"},
                     {"y", "disagree %"},
                     {"series", "map size"},
                     {"logx", true},
                     {"title", "Shadow map bias: acne at small bias, peter-panning at large"}});
            }
            if (opts.json || !opts.reportPath.empty() || measure || compare)
                writeReport(report, opts);
            return 0;
        }

        // The window: rasterizer, ray tracer, or their difference, on the same moving camera.
        enum class View { Raster, Traced, Difference };
        OrbitController orbit(scene.camera);
        View view = View::Raster;
        bool dirty = true;
        Image image;
        double rasterMs = 0.0, shadeMs = 0.0, tracedMs = 0.0;
        FrameStats stats;
        VisibilityComparison diff;
        RenderSettings settings = opts.renderSettings();
        WindowCallbacks cb;
        cb.keys = {{SDLK_r, "switch rasterizer / ray tracer (same view)"},
                   {SDLK_d,
                    "show where they differ (red: raster only, blue: ray tracer only, yellow: "
                    "other triangle)"},
                   {SDLK_h, "shadows: none / shadow map / shadow rays"},
                   {SDLK_b, "back-face culling on / off"},
                   {SDLK_p, "perspective-correct / affine interpolation"},
                   {SDLK_c, "checker on the surfaces (shows the interpolation)"},
                   {SDLK_f, "frustum culling with step 04's hierarchy on / off"}};
        cb.onKey = [&](int key) {
            switch (key) {
                case SDLK_r:
                    view = view == View::Raster ? View::Traced : View::Raster;
                    break;
                case SDLK_d:
                    view = view == View::Difference ? View::Raster : View::Difference;
                    break;
                case SDLK_h:
                    ss.shadows = ShadowMode((int(ss.shadows) + 1) % 3);
                    break;
                case SDLK_b:
                    rs.backfaceCulling = !rs.backfaceCulling;
                    break;
                case SDLK_p:
                    rs.perspectiveCorrect = !rs.perspectiveCorrect;
                    break;
                case SDLK_c:
                    ss.checker = !ss.checker;
                    break;
                case SDLK_f:
                    culling = !culling;
                    break;
                default:
                    return false;
            }
            return dirty = true;
        };
        orbit.addTo(cb, [&] { dirty = true; });
        cb.frame = [&](double) -> const Image& {
            if (!dirty) return image;
            const Camera& camera = orbit.camera();
            FrameBuffers buffers;
            stats = rasterizeCulled(raster, culling ? culler.get() : nullptr, camera, rs, buffers,
                                    cull);
            ShadedFrame shaded = shadeFrame(scene, raster, camera, buffers, ss);
            rasterMs = stats.milliseconds;
            shadeMs = shaded.milliseconds;
            if (view == View::Raster) {
                image = std::move(shaded.image);
            } else if (view == View::Traced) {
                Stopwatch watch;
                image = renderImage(scene, camera, settings);
                tracedMs = watch.milliseconds();
            } else {
                TracedFrame traced =
                    traceFrame(scene, camera, rs.width, rs.height, false, opts.threads);
                tracedMs = traced.milliseconds;
                std::vector<uint32_t> ids = meshIds(raster, buffers);
                diff = compareVisibility(rs.width, rs.height, ids, meshDepths(raster, buffers),
                                         traced.ids, traced.depth, &scene.mesh);
                image = differenceImage(rs.width, rs.height, ids, traced.ids);
            }
            dirty = false;
            return image;
        };
        cb.panel = [&] {
            const char* names[] = {"rasterizer", "ray tracer", "difference"};
            ImGui::Text("showing: %s", names[int(view)]);
            ImGui::Text("raster: %.1f ms + shading %.1f ms (1 thread)", rasterMs, shadeMs);
            if (view != View::Raster) ImGui::Text("ray tracer: %.1f ms", tracedMs);
            ImGui::Text("triangles drawn %zu of %zu, pixels %zu", stats.trianglesDrawn,
                        raster.triangles.size(), stats.pixelsCovered);
            if (culling && culler)
                ImGui::Text("frustum culling: %zu boxes culled, %zu kept, %zu triangles kept",
                            cull.boxesCulled, cull.boxesKept, cull.trianglesKept);
            else
                ImGui::Text("frustum culling: off");
            ImGui::Text("shadows: %s, back faces %s, %s", shadowModeName(ss.shadows),
                        rs.backfaceCulling ? "culled" : "drawn",
                        rs.perspectiveCorrect ? "perspective-correct" : "affine");
            if (view == View::Difference)
                ImGui::Text("same triangle %.3f%%, %zu differ on edges, %zu elsewhere",
                            100.0 * diff.agreement(), diff.differOnEdge, diff.differElsewhere);
        };
        runWindow(opts.windowOptions("Step 06: rasterization"), cb);
        return 0;
    });
}
