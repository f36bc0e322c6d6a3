#include "06_raster/measure.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "01_triangle/triangle_grid.hpp"
#include "04_bvh/trace.hpp"
#include "06_raster/culling.hpp"
#include "06_raster/texture.hpp"
#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

RasterSettings rasterSettings(const MeasureSettings& m) {
    RasterSettings s;
    s.width = m.width;
    s.height = m.height;
    return s;
}

double medianMs(int repeats, const std::function<void()>& fn) {
    return measure(repeats, fn).median * 1e3;
}

// The median, min and max of repeats in milliseconds.
Timing timingMs(int repeats, const std::function<void()>& fn) {
    Timing t = measure(repeats, fn);
    t.median *= 1e3, t.min *= 1e3, t.max *= 1e3;
    return t;
}

}  // namespace

void attachGrid(Scene& scene) {
    scene.geometries.clear();
    if (scene.hasMesh())
        scene.geometries.push_back(std::make_shared<TriangleGrid>(scene.mesh, scene.meshMaterial));
}

std::string findInteriorMap(const std::string& folder, std::string* why) {
    namespace fs = std::filesystem;
    std::string named = folder;
    if (named.empty()) {
        const char* env = std::getenv("BOXES_MESHES");
        if (env && *env) named = env;
    }
    std::error_code ec;
    if (!named.empty()) {
        fs::path obj = fs::path(named) / "oa_thor.obj";
        if (!fs::exists(obj, ec))
            throw InputError("--meshes/BOXES_MESHES " + printable(named) +
                             ": no oa_thor.obj in that folder");
        return fs::weakly_canonical(obj, ec).string();
    }
    const fs::path cache = BOXES_MESH_CACHE, tool = BOXES_MESH_TOOL, root = BOXES_SOURCE_ROOT;
    const fs::path obj = cache / "oa_thor.obj";
    // meshes.py checks the cached file's provenance against the package's version and
    // converts the map when it is missing or stale (about 2 s); exit code 3: no package.
    // It belongs to the tools package, so it runs as a module from the clone's root.
    if (fs::exists(tool, ec) && (root.string() + cache.string()).find('\'') == std::string::npos) {
        std::string command = "cd '" + root.string() +
                              "' && python3 -m tools.bench.meshes oa_thor --cache '" +
                              cache.string() + "' >/dev/null 2>&1";
        int rc = std::system(command.c_str());
        if (rc == 0 && fs::exists(obj, ec)) return obj.string();
        if (why)
            *why =
                "the interior map cannot be made (Debian's openarena-088-data: "
                "tools/deps.sh bench installs it; then python3 -m tools.bench.meshes oa_thor "
                "in " +
                root.string() + " makes " + obj.string() + ")";
        return "";
    }
    if (fs::exists(obj, ec)) return obj.string();
    if (why) *why = "no " + obj.string() + " and no " + tool.string() + " to make it";
    return "";
}

std::vector<MeasureView> measureViews(const std::string& dataDir, const std::string& interiorMap,
                                      float aspect) {
    std::vector<MeasureView> views;
    SceneOptions options{dataDir, aspect};
    {
        MeasureView v{"bunny (outside)", makeScene("bunny", options), {}};
        v.camera = v.scene.camera;
        views.push_back(std::move(v));
    }
    {
        MeasureView v{"sh1 (outside)", makeScene("sh1", options), {}};
        v.camera = v.scene.camera;
        views.push_back(std::move(v));
    }
    if (!interiorMap.empty()) {
        MeasureView v{"oa_thor (inside)", makeScene(interiorMap, options), {}};
        v.camera =
            Camera::lookingAt(Vec3(960, -384, 2), Vec3(960, 600, 2), Vec3(0, 0, 1), 90.0f, aspect);
        views.push_back(std::move(v));
    }
    for (MeasureView& v : views) attachGrid(v.scene);
    return views;
}

Table measureVisibility(const std::vector<MeasureView>& views, const MeasureSettings& m) {
    Table t("visibility",
            "Primary visibility: the rasterizer against the ray tracer, pixel for pixel",
            {"view", "triangles", "covered raster", "covered traced", "same triangle %",
             "differ on edges", "differ elsewhere", "coverage diff % of image", "max depth error"},
            std::to_string(m.width) + "x" + std::to_string(m.height) +
                "; same triangle: share of pixels covered by either where both name the same mesh "
                "triangle; 'on edges': the other's triangle is seen within one pixel; depth error "
                "relative, where they agree");
    for (const MeasureView& v : views) {
        std::cerr << "06_raster: visibility on " << v.name << "...\n";
        RasterScene raster = RasterScene::fromScene(v.scene);
        FrameBuffers buffers;
        rasterizeFrame(raster, v.camera, rasterSettings(m), buffers);
        TracedFrame traced = traceFrame(v.scene, v.camera, m.width, m.height, false, 0);
        VisibilityComparison c =
            compareVisibility(m.width, m.height, meshIds(raster, buffers),
                              meshDepths(raster, buffers), traced.ids, traced.depth, &v.scene.mesh);
        t.row({v.name, (long long)raster.meshTriangles, (long long)c.coveredRaster,
               (long long)c.coveredTraced, 100.0 * c.agreement(), (long long)c.differOnEdge,
               (long long)c.differElsewhere, 100.0 * c.coverageDifference(), c.maxDepthError});
    }
    return t;
}

Table measureFrameTimes(const std::vector<MeasureView>& views, const MeasureSettings& m) {
    Table t(
        "frame_time", "Time per frame, single thread: rasterizer against ray tracer (ms, median)",
        {"view", "triangles", "raster visibility", "raster shaded", "raster + shadow map",
         "raster + shadow rays", "traced visibility", "traced shaded (Whitted)",
         "visibility speed-up"},
        std::to_string(m.width) + "x" + std::to_string(m.height) + ", median of " +
            std::to_string(m.repeats) +
            " frames; raster shaded: deferred shading of the z-buffer without shadows; the shadow "
            "map is rebuilt every frame (" +
            std::to_string(m.mapSize()) + "^2); the ray tracer uses step 01's uniform grid");
    for (const MeasureView& v : views) {
        std::cerr << "06_raster: timing frames on " << v.name << "...\n";
        RasterScene raster = RasterScene::fromScene(v.scene);
        RasterSettings rs = rasterSettings(m);
        FrameBuffers buffers;
        double rasterMs =
            medianMs(m.repeats, [&] { rasterizeFrame(raster, v.camera, rs, buffers); });
        auto shaded = [&](ShadowMode mode) {
            ShadeSettings ss;
            ss.shadows = mode;
            ss.mapSize = m.mapSize();
            return medianMs(m.repeats, [&] {
                rasterizeFrame(raster, v.camera, rs, buffers);
                keepValue(shadeFrame(v.scene, raster, v.camera, buffers, ss).image.pixels()[0].x);
            });
        };
        double none = shaded(ShadowMode::None), map = shaded(ShadowMode::Map),
               rays = shaded(ShadowMode::Rays);
        double traced = medianMs(
            m.repeats, [&] { traceFrame(v.scene, v.camera, m.width, m.height, false, 1); });
        RenderSettings settings;
        settings.width = m.width;
        settings.height = m.height;
        settings.threads = 1;
        double whitted = medianMs(
            m.repeats, [&] { keepValue(renderImage(v.scene, v.camera, settings).pixels()[0].x); });
        t.row({v.name, (long long)raster.meshTriangles, rasterMs, none, map, rays, traced, whitted,
               traced / std::max(rasterMs, 1e-9)});
    }
    return t;
}

Table measureShadowBias(const MeasureView& v, const MeasureSettings& m) {
    Table t("shadow_bias",
            "Shadow map depth bias against the ray tracer's shadows: acne and peter-panning",
            {"bias (x diagonal)", "acne pixels", "peter-panning pixels", "disagree %", "map size",
             "ms map + shading", "min ms", "max ms"});
    t.note =
        v.name +
        ", first light; acne: the map shadows a point the ray tracer lights; "
        "peter-panning: the map lights a point the ray tracer shadows; over pixels where both "
        "see the same triangle and the light can reach; ms: building the maps and shading, per "
        "map size (the bias does not change the work), median of " +
        std::to_string(m.repeats) + " (min, max), single thread";
    t.timeAndError("ms map + shading", "min ms", "max ms", "disagree %");
    RasterScene raster = RasterScene::fromScene(v.scene);
    FrameBuffers buffers;
    rasterizeFrame(raster, v.camera, rasterSettings(m), buffers);
    TracedFrame traced = traceFrame(v.scene, v.camera, m.width, m.height, true, 0);
    std::vector<uint32_t> ids = meshIds(raster, buffers);
    for (int size : {m.mapSize() / 2, m.mapSize()}) {
        std::vector<ShadowMap> maps;
        ShadeSettings timed;
        timed.shadows = ShadowMode::Map;
        timed.mapSize = size;
        Timing ms = timingMs(m.repeats, [&] {
            maps.clear();
            for (const PointLight& light : v.scene.lights)
                maps.push_back(buildShadowMap(raster, light, size));
            keepValue(shadeFrame(v.scene, raster, v.camera, buffers, timed, &maps).milliseconds);
        });
        for (double relative : {0.0, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2}) {
            ShadeSettings ss;
            ss.shadows = ShadowMode::Map;
            ss.mapBias = relative > 0.0 ? relative * double(raster.diagonal()) : 1e-30;
            ShadedFrame f = shadeFrame(v.scene, raster, v.camera, buffers, ss, &maps);
            ShadowComparison c =
                compareShadows(ids, f.litByFirstLight, traced.ids, traced.litByFirstLight);
            t.row({relative, (long long)c.acne, (long long)c.leaks, 100.0 * c.disagreement(),
                   (long long)size, ms.median, ms.min, ms.max});
        }
    }
    return t;
}

Table measureShadowMethods(const MeasureView& v, const MeasureSettings& m) {
    Table t(
        "shadows", "Shadows two ways against the ray tracer's shadow rays",
        {"method", "pixels compared", "disagree", "disagree %", "ms per frame", "min ms", "max ms"},
        v.name + ", first light, single thread, median of " + std::to_string(m.repeats) +
            " (min, max); the frame time includes rasterizing and shading (and building the map); "
            "the reference: the ray tracer's shadow rays (its time: 2 frames)");
    t.timeAndError("ms per frame", "min ms", "max ms", "disagree %");
    RasterScene raster = RasterScene::fromScene(v.scene);
    RasterSettings rs = rasterSettings(m);
    FrameBuffers buffers;
    TracedFrame traced = traceFrame(v.scene, v.camera, m.width, m.height, true, 1);
    for (ShadowMode mode : {ShadowMode::Map, ShadowMode::Rays}) {
        ShadeSettings ss;
        ss.shadows = mode;
        ss.mapSize = m.mapSize();
        ShadedFrame f;
        Timing ms = timingMs(m.repeats, [&] {
            rasterizeFrame(raster, v.camera, rs, buffers);
            f = shadeFrame(v.scene, raster, v.camera, buffers, ss);
        });
        ShadowComparison c = compareShadows(meshIds(raster, buffers), f.litByFirstLight, traced.ids,
                                            traced.litByFirstLight);
        t.row({std::string(shadowModeName(mode)), (long long)c.compared,
               (long long)(c.acne + c.leaks), 100.0 * c.disagreement(), ms.median, ms.min, ms.max});
    }
    {
        // The hybrid again, its shadow rays through step 04's hierarchy instead of the grid.
        Scene bvhScene = v.scene;
        bvhScene.geometries.clear();
        if (bvhScene.hasMesh())
            bvhScene.geometries.push_back(std::make_shared<MeshBvhGeometry>(
                bvhScene.mesh, bvhScene.meshMaterial, BvhBuildOptions{}));
        ShadeSettings ss;
        ss.shadows = ShadowMode::Rays;
        ShadedFrame f;
        Timing ms = timingMs(m.repeats, [&] {
            rasterizeFrame(raster, v.camera, rs, buffers);
            f = shadeFrame(bvhScene, raster, v.camera, buffers, ss);
        });
        ShadowComparison c = compareShadows(meshIds(raster, buffers), f.litByFirstLight, traced.ids,
                                            traced.litByFirstLight);
        t.row({std::string("shadow rays (hybrid) through step 04's BVH"), (long long)c.compared,
               (long long)(c.acne + c.leaks), 100.0 * c.disagreement(), ms.median, ms.min, ms.max});
    }
    // The reference itself: its frame above and one more (the slowest frame of the table,
    // so two samples, not m.repeats).
    std::vector<double> tracedMs = {
        traced.milliseconds,
        traceFrame(v.scene, v.camera, m.width, m.height, true, 1).milliseconds};
    Timing tracedTime = summarize(tracedMs);
    t.row({std::string("ray tracer (visibility + shadow rays)"), 0LL, 0LL, 0.0, tracedTime.median,
           tracedTime.min, tracedTime.max});
    return t;
}

Table measureCulling(const std::vector<MeasureView>& views, const MeasureSettings& m) {
    Table t(
        "culling",
        "View-frustum culling with step 04's hierarchy: boxes culled and kept, triangles drawn",
        {"view", "test", "boxes visited", "boxes culled", "boxes kept", "triangles kept",
         "triangles drawn", "ms per frame", "identical", "min ms", "max ms", "pixels differing"},
        "binned-SAH hierarchy over the mesh; test: none, planes (p-vertex), planes + corners; "
        "ms: median of " +
            std::to_string(m.repeats) +
            " frames (culling walk + rasterizing, single thread; min, max); identical: the "
            "triangle "
            "and depth buffers equal the unculled frame's; pixels differing: pixels where either "
            "buffer differs from the unculled frame's, the reference");
    t.timeAndError("ms per frame", "min ms", "max ms", "pixels differing");
    std::vector<MeasureView> cases;
    for (const MeasureView& v : views) cases.push_back(v);
    // The bunny's head from close by: a good share of the mesh lies outside the view.
    MeasureView close = views[0];
    close.name = "bunny (close-up)";
    close.camera.eye = Vec3(-0.35f, 0.55f, 0.9f);
    close.camera.view = Vec3(-0.45f, 0.5f, 0.0f) - close.camera.eye;
    close.camera.fovYDegrees = 40.0f;
    cases.insert(cases.begin() + 1, close);
    for (const MeasureView& v : cases) {
        std::cerr << "06_raster: culling on " << v.name << "...\n";
        RasterScene raster = RasterScene::fromScene(v.scene);
        FrustumCuller culler(v.scene.mesh);
        RasterSettings rs = rasterSettings(m);
        FrameBuffers reference, buffers;
        CullStats cull;
        rasterizeCulled(raster, nullptr, v.camera, rs, reference, cull);
        for (int test = -1; test < 2; ++test) {
            const FrustumCuller* c = test < 0 ? nullptr : &culler;
            CullTest which = test == 1 ? CullTest::PlanesAndCorners : CullTest::Planes;
            FrameStats stats;
            Timing ms = timingMs(m.repeats, [&] {
                stats = rasterizeCulled(raster, c, v.camera, rs, buffers, cull, which);
            });
            bool same = buffers.triangle == reference.triangle && buffers.depth == reference.depth;
            long long differing = 0;
            for (size_t i = 0; i < buffers.triangle.size(); ++i)
                differing += buffers.triangle[i] != reference.triangle[i] ||
                             !(buffers.depth[i] == reference.depth[i]);
            const char* name = test < 0 ? "none" : test == 0 ? "planes" : "planes + corners";
            t.row({v.name, std::string(name), (long long)cull.boxesVisited,
                   (long long)cull.boxesCulled, (long long)cull.boxesKept,
                   (long long)(c ? cull.trianglesKept : raster.meshTriangles),
                   (long long)stats.trianglesDrawn, ms.median, std::string(same ? "yes" : "NO"),
                   ms.min, ms.max, differing});
        }
    }
    return t;
}

Table measureInterpolation(const MeasureView& bunny, const MeasureSettings& m,
                           const std::string& pngStem,
                           std::vector<std::pair<std::string, std::string>>& images) {
    Table t(
        "interpolation",
        "Affine against perspective-correct interpolation: position error against the ray tracer",
        {"view", "weights", "mean error (x diagonal)", "max error (x diagonal)", "ms/frame",
         "min ms", "max ms"},
        "the interpolated surface point against the ray tracer's hit point, over pixels where "
        "both see the same triangle; ms/frame: rasterizing with those weights, median of " +
            std::to_string(m.repeats) + " (min, max), single thread");
    t.timeAndError("ms/frame", "min ms", "max ms", "max error (x diagonal)");
    // A floor of two triangles seen at a grazing angle: large triangles, strong perspective.
    MeasureView floor{"floor quad (grazing)", Scene{}, {}};
    floor.scene.name = "floor";
    floor.scene.mesh.positions = {{-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}};
    floor.scene.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
    floor.scene.mesh.computeVertexNormals();
    floor.scene.lights.push_back({Vec3(0, 6, 0), Vec3(60.0f), kInfinity<float>});
    floor.camera = Camera::lookingAt(Vec3(0, 2.5f, 13.0f), Vec3(0, 0, 2.0f), Vec3(0, 1, 0), 60.0f,
                                     float(m.width) / float(m.height));
    attachGrid(floor.scene);
    for (const MeasureView* v : {static_cast<const MeasureView*>(&floor), &bunny}) {
        RasterScene raster = RasterScene::fromScene(v->scene);
        TracedFrame traced = traceFrame(v->scene, v->camera, m.width, m.height, false, 0);
        CameraBasisT<float> basis = v->camera.basis();
        for (bool correct : {false, true}) {
            RasterSettings rs = rasterSettings(m);
            rs.perspectiveCorrect = correct;
            FrameBuffers buffers;
            Timing ms =
                timingMs(m.repeats, [&] { rasterizeFrame(raster, v->camera, rs, buffers); });
            double sum = 0.0, worst = 0.0;
            size_t n = 0;
            for (int y = 0; y < m.height; ++y)
                for (int x = 0; x < m.width; ++x) {
                    size_t i = buffers.index(x, y);
                    SurfaceHit hit;
                    if (traced.ids[i] == kNoPrimitive || buffers.triangle[i] != traced.ids[i])
                        continue;
                    if (!surfaceAt(raster, buffers, x, y, hit)) continue;
                    Vec3 d = v->camera.directionThrough(basis, float(x) + 0.5f, float(y) + 0.5f,
                                                        m.width, m.height);
                    Vec3 exact = v->camera.eye + d * (traced.depth[i] / glm::dot(d, basis.forward));
                    double e = glm::length(glm::dvec3(hit.point) - glm::dvec3(exact)) /
                               double(raster.diagonal());
                    sum += e;
                    worst = std::max(worst, e);
                    ++n;
                }
            t.row({v->name, std::string(correct ? "perspective-correct" : "affine"),
                   n ? sum / double(n) : 0.0, worst, ms.median, ms.min, ms.max});
            if (v == &floor && !pngStem.empty()) {
                ShadeSettings ss;
                ss.shadows = ShadowMode::None;
                ss.checker = true;
                std::string path = pngStem + (correct ? "-perspective.png" : "-affine.png");
                shadeFrame(v->scene, raster, v->camera, buffers, ss).image.writePng(path);
                images.push_back(
                    {path, correct ? "a checker on the floor, perspective-correct weights"
                                   : "the same floor with affine weights: the checker warps"});
            }
        }
    }
    return t;
}

namespace {

// Times each variant `repeats` times, one frame of each per round, so a change in the
// machine's load affects every variant alike.
std::vector<Timing> timeInterleaved(int repeats, const std::vector<std::function<void()>>& fns) {
    std::vector<std::vector<double>> samples(fns.size());
    for (int r = 0; r < repeats; ++r)
        for (size_t k = 0; k < fns.size(); ++k) {
            Stopwatch watch;
            fns[k]();
            samples[k].push_back(watch.seconds());
        }
    std::vector<Timing> times;
    for (auto& s : samples) times.push_back(summarize(s));
    return times;
}

size_t buffersDiffering(const FrameBuffers& a, const FrameBuffers& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.depth.size(); ++i)
        n += a.triangle[i] != b.triangle[i] || a.depth[i] != b.depth[i] ||
             a.weight1[i] != b.weight1[i] || a.weight2[i] != b.weight2[i];
    return n;
}

}  // namespace

Table measureVertexPrecalc(const std::vector<MeasureView>& views, const MeasureSettings& m) {
    Table t("vertex_precalc",
            "Precalculation: the vertex work done once per vertex, per triangle corner, per pixel",
            {"view", "vertex work", "ms/frame", "min ms", "max ms", "speed-up", "vertex transforms",
             "transforms per vertex", "pixels differing"},
            std::to_string(m.width) + "x" + std::to_string(m.height) +
                ", rasterizing only (no shading), one thread, median of " +
                std::to_string(m.repeats + 2) +
                " frames interleaved; vertex work: the transform to clip space (and per pixel also "
                "the divide by w and the viewport); speed-up against per pixel; pixels differing: "
                "triangle, depth or weights differ from the once-per-vertex frame's, bit for bit");
    const VertexWork works[] = {VertexWork::PerPixel, VertexWork::PerCorner,
                                VertexWork::OncePerVertex};
    for (const MeasureView& v : views) {
        std::cerr << "06_raster: vertex work on " << v.name << "...\n";
        RasterScene raster = RasterScene::fromScene(v.scene);
        std::vector<FrameBuffers> buffers(3);
        std::vector<FrameStats> stats(3);
        std::vector<std::function<void()>> frames;
        for (size_t k = 0; k < 3; ++k)
            frames.push_back([&, k] {
                RasterSettings rs = rasterSettings(m);
                rs.vertexWork = works[k];
                stats[k] = rasterizeFrame(raster, v.camera, rs, buffers[k]);
            });
        std::vector<Timing> times = timeInterleaved(m.repeats + 2, frames);
        for (size_t k = 0; k < 3; ++k)
            t.row({v.name, std::string(vertexWorkName(works[k])), times[k].median * 1e3,
                   times[k].min * 1e3, times[k].max * 1e3, times[0].median / times[k].median,
                   (long long)stats[k].vertexTransforms,
                   double(stats[k].vertexTransforms) / double(raster.positions.size()),
                   (long long)buffersDiffering(buffers[k], buffers[2])});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "pixels differing");
    return t;
}

Table measureTexture(const MeasureSettings& m, const std::string& pngStem,
                     std::vector<std::pair<std::string, std::string>>& images) {
    Table t("texture",
            "Texture coordinates on a floor: perspective-correct and affine against the ray tracer",
            {"renderer", "ms/frame", "min ms", "max ms", "pixels differing", "differing % of floor",
             "colour differs", "max texcoord error (texels)"},
            std::to_string(m.width) + "x" + std::to_string(m.height) +
                ", a 20 x 20 texel checker on a floor quad of two triangles seen at a low angle, "
                "no shadows, one thread, median of " +
                std::to_string(m.repeats) +
                " frames; pixels differing: another texel than the ray tracer's (or the floor on "
                "one side only); colour differs: a channel differs by more than 1e-3 (linear) from "
                "the ray tracer's image; texcoord error where both see the floor");
    TexturedFloor floor = texturedFloor(float(m.width) / float(m.height));
    attachGrid(floor.scene);
    const Camera& camera = floor.scene.camera;
    RasterScene raster = texturedRasterScene(floor);
    std::vector<glm::vec2> tracedUv;
    Image traced =
        traceTexturedFloor(floor.scene, floor.frame, camera, m.width, m.height, &tracedUv);
    Timing tracedTime = measure(m.repeats, [&] {
        keepValue(
            traceTexturedFloor(floor.scene, floor.frame, camera, m.width, m.height).pixels()[0].x);
    });
    for (bool correct : {true, false}) {
        RasterSettings rs = rasterSettings(m);
        rs.perspectiveCorrect = correct;
        FrameBuffers buffers;
        Image image = rasterTexturedFloor(floor.scene, raster, camera, rs, buffers);
        Timing time = measure(m.repeats, [&] {
            keepValue(rasterTexturedFloor(floor.scene, raster, camera, rs, buffers).pixels()[0].x);
        });
        TextureComparison c = compareTexturedFloor(image, traced, raster, buffers, tracedUv);
        t.row({std::string(correct ? "rasterizer, perspective-correct" : "rasterizer, affine"),
               time.median * 1e3, time.min * 1e3, time.max * 1e3, (long long)c.differing,
               100.0 * c.differingShare(), (long long)c.colourDiffering, c.maxTexcoordError});
        if (!pngStem.empty()) {
            std::string path = pngStem + (correct ? "-texture.png" : "-texture-affine.png");
            image.writePng(path);
            images.push_back({path, correct ? "the textured floor rasterized, texture coordinates "
                                              "interpolated perspective-correct"
                                            : "the same floor with affine texture coordinates: "
                                              "the texels bend at the quad's diagonal"});
        }
    }
    t.row({std::string("ray tracer (the reference)"), tracedTime.median * 1e3, tracedTime.min * 1e3,
           tracedTime.max * 1e3, 0LL, 0.0, 0LL, 0.0});
    if (!pngStem.empty()) {
        std::string path = pngStem + "-texture-traced.png";
        traced.writePng(path);
        images.push_back({path, "the textured floor ray traced: the reference"});
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "pixels differing");
    return t;
}

void compareWithRayTracer(const StepRun& run, const RasterView& view, const RasterFrame& frame,
                          Report& report) {
    const Scene& scene = run.scene;
    const int w = view.raster.width, h = view.raster.height;
    const std::vector<uint32_t> ids = meshIds(view.scene, frame.buffers);
    TracedFrame traced = traceFrame(scene, scene.camera, w, h, true, 1);
    VisibilityComparison c = compareVisibility(w, h, ids, meshDepths(view.scene, frame.buffers),
                                               traced.ids, traced.depth, &scene.mesh);
    std::string diff = pngWithSuffix(run.png, "-diff");
    differenceImage(w, h, ids, traced.ids).writePng(diff);
    report.images.push_back({diff,
                             "grey: same triangle; red: only the rasterizer; blue: only "
                             "the ray tracer; yellow: different triangles"});
    ShadowComparison sc =
        compareShadows(ids, frame.shaded.litByFirstLight, traced.ids, traced.litByFirstLight);
    const double rasterMs = frame.stats.milliseconds, shadeMs = frame.shaded.milliseconds;
    report.facts["compare"] = {{"pixels_covered_raster", c.coveredRaster},
                               {"pixels_covered_traced", c.coveredTraced},
                               {"same_triangle_share", c.agreement()},
                               {"differ_on_edges", c.differOnEdge},
                               {"differ_elsewhere", c.differElsewhere},
                               {"coverage_difference_share", c.coverageDifference()},
                               {"max_depth_error", c.maxDepthError},
                               {"mean_depth_error", c.meanDepthError},
                               {"shadow_pixels_disagreeing", sc.acne + sc.leaks},
                               {"shadow_pixels_compared", sc.compared},
                               {"raster_frame_ms", rasterMs + shadeMs},
                               {"traced_frame_ms", traced.milliseconds}};
    std::printf("pixels covered: raster %zu, ray tracer %zu (difference %.4f%% of the image)\n",
                c.coveredRaster, c.coveredTraced, 100.0 * c.coverageDifference());
    std::printf(
        "same triangle: %.4f%% of covered pixels (%zu differ on triangle edges, %zu "
        "elsewhere)\n",
        100.0 * c.agreement(), c.differOnEdge, c.differElsewhere);
    std::printf("depth error where they agree: max %.3g, mean %.3g (relative)\n", c.maxDepthError,
                c.meanDepthError);
    std::printf("shadows (%s) against the ray tracer's: %zu of %zu pixels disagree\n",
                shadowModeName(view.shading.shadows), sc.acne + sc.leaks, sc.compared);
    std::printf(
        "time per frame, single thread: raster %.1f ms (+ shading %.1f ms), ray tracer "
        "%.1f ms "
        "(visibility and shadow rays)\n",
        rasterMs, shadeMs, traced.milliseconds);
}

void compareTextureWithRayTracer(const StepRun& run, const TexturedFloor& floor,
                                 const RasterView& view, const RasterFrame& frame, Report& report) {
    const int w = view.raster.width, h = view.raster.height;
    std::vector<glm::vec2> tracedUv;
    Image traced = traceTexturedFloor(run.scene, floor.frame, run.camera, w, h, &tracedUv);
    std::string path = pngWithSuffix(run.png, "-traced");
    traced.writePng(path);
    report.images.push_back({path, "the textured floor ray traced: the reference"});
    TextureComparison c =
        compareTexturedFloor(frame.shaded.image, traced, view.scene, frame.buffers, tracedUv);
    report.facts["texture"] = {{"floor_pixels", c.floorPixels},
                               {"pixels_differing", c.differing},
                               {"colour_differing", c.colourDiffering},
                               {"max_texcoord_error", c.maxTexcoordError}};
    std::printf(
        "textured floor (%s): %zu of %zu floor pixels show another texel than the ray "
        "tracer's (%zu differ in colour), texture coordinates off by at most %.3g texels\n",
        view.raster.perspectiveCorrect ? "perspective-correct" : "affine", c.differing,
        c.floorPixels, c.colourDiffering, c.maxTexcoordError);
}

void measureRaster(const StepRun& run, Report& report, const std::string& meshes) {
    MeasureSettings ms;
    ms.width = run.options.width;
    ms.height = run.options.height;
    const CommonOptions& o = run.options;
    std::string why;
    const std::string interior = findInteriorMap(meshes, &why);
    if (interior.empty()) std::cerr << "06_raster: the interior map left out: " << why << "\n";
    std::vector<MeasureView> views = measureViews(o.dataDir, interior, o.aspect());
    report.add(measureVisibility(views, ms));
    report.add(measureFrameTimes(views, ms));
    report.add(measureCulling(views, ms));
    std::cerr << "06_raster: shadows...\n";
    report.add(measureShadowBias(views[0], ms));
    report.add(measureShadowMethods(views[0], ms));
    std::cerr << "06_raster: interpolation...\n";
    report.add(measureInterpolation(views[0], ms, pngStem(run.png), report.images));
    std::cerr << "06_raster: vertex work and textures...\n";
    report.add(measureVertexPrecalc({views[0], views[1]}, ms));
    report.add(measureTexture(ms, pngStem(run.png), report.images));
    report.plots.push_back(
        {{"table", "shadow_bias"},
         {"x", "bias (x diagonal)"},
         {"y", "disagree %"},
         {"series", "map size"},
         {"logx", true},
         {"title", "Shadow map bias: acne at small bias, peter-panning at large"}});
    report.plots.push_back(
        {{"table", "shadows"},
         {"x", "ms per frame"},
         {"y", "disagree %"},
         {"series", "method"},
         {"pareto", true},
         {"title",
          "Shadows: pixels that disagree with the ray tracer against time per frame, with the "
          "Pareto front"}});
}

}  // namespace boxes
