// Effects on demand: rays traced with the scene analysis against a fair baseline, the same
// renderer that skips zero-weight rays but proves nothing about the scene.
#include <filesystem>
#include <memory>

#include "05_efficiency/bvh_mesh.hpp"
#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

namespace {

// A built-in scene (or an OBJ file) with its mesh in step 04's hierarchy, on the heap: the
// hierarchy refers to the scene's mesh, which must not move.
std::unique_ptr<Scene> effectsScene(const std::string& name, const LabOptions& o) {
    auto scene = std::make_unique<Scene>(makeScene(name, {o.dataDir}));
    if (scene->hasMesh())
        scene->geometries.push_back(std::make_shared<LabBvhMesh>(scene->mesh, scene->meshMaterial));
    return scene;
}

struct PartVariant {
    const char* name;
    AnalysisParts parts;
};

// Every part but one: what that part saves given the others (alone, some parts save
// nothing: occluders per light rely on the lights' balls, which light ranges give).
std::vector<PartVariant> partVariants() {
    AnalysisParts noOcc, noPlane, noConvex, noRanges;
    noOcc.occludersPerLight = false;
    noPlane.planeSides = false;
    noConvex.convexSelf = false;
    noRanges.lightRanges = false;
    return {{"occluders per light", noOcc},
            {"plane sides", noPlane},
            {"convex self-shadowing", noConvex},
            {"light ranges", noRanges}};
}

}  // namespace

const std::vector<std::string>& effectsSceneNames() {
    static const std::vector<std::string> names = {
        "single-sphere", "diffuse", "mirrors", "glass", "spheres", "small-lights", "bunny"};
    return names;
}

Table measureEffects(const LabOptions& o) {
    Table t(
        "effects",
        "Effects on demand: rays and time with the scene analysis against the fair baseline "
        "(zero-weight rays skipped, no analysis)",
        {"scene", "variant", "shadow", "reflection", "refraction", "total rays", "x baseline",
         "ms/frame", "min ms", "max ms", "max 8-bit error", "bit-identical"},
        "160x120, max depth 5, one thread, median of repeats interleaved round-robin; baseline: "
        "RenderSettings::analysis = AnalysisParts::none() (the renderer still skips lights "
        "behind the surface and reflection or refraction of weight 0); 'every ray': "
        "forceAllEffects, zero weights traced too (what a renderer without any test would "
        "do); x baseline: total rays over the baseline's; the error is against the baseline image; "
        "bit-identical: the float images "
        "equal");
    struct Variant {
        const char* name;
        AnalysisParts parts;
        bool force;
    };
    const Variant variants[] = {{"every ray (zero weights too)", AnalysisParts::none(), true},
                                {"baseline: no analysis", AnalysisParts::none(), false},
                                {"scene analysis", AnalysisParts{}, false}};
    for (const std::string& name : effectsSceneNames()) {
        const auto owned = effectsScene(name, o);
        const Scene& scene = *owned;
        std::vector<std::unique_ptr<Renderer>> renderers;
        std::vector<std::function<void()>> frames;
        std::vector<RayCounts> counts(std::size(variants));
        std::vector<Image> images;
        for (size_t i = 0; i < std::size(variants); ++i) {
            RenderSettings s = oneThread(sized(o, 160), sized(o, 120));
            s.analysis = variants[i].parts;
            s.forceAllEffects = variants[i].force;
            renderers.push_back(std::make_unique<Renderer>(scene, scene.camera, s));
            images.push_back(renderers.back()->render(&counts[i]));
            frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
        }
        std::vector<Timing> tm = measureInterleaved(o.repeats, frames);
        const double base = double(counts[1].total());
        for (size_t i = 0; i < std::size(variants); ++i) {
            const RayCounts& c = counts[i];
            t.row({name, std::string(variants[i].name), (long long)c.shadow,
                   (long long)c.reflection, (long long)c.refraction, (long long)c.total(),
                   double(c.total()) / base, ms(tm[i].median), ms(tm[i].min), ms(tm[i].max),
                   maxStep8(images[i], images[1]),
                   std::string(identical(images[i], images[1]) ? "yes" : "NO")});
        }
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "max 8-bit error");
    return t;
}

Table measureEffectParts(const LabOptions& o) {
    Table t("effects_parts",
            "Effects on demand, part by part: the shadow rays each part of the analysis saves",
            {"scene", "variant", "shadow rays", "saved by the part", "ms/frame", "min ms", "max ms",
             "max 8-bit error"});
    t.note =
        "160x120, max depth 5, one thread, median of repeats interleaved round-robin; 'all "
        "but': every other part on, and the part saves its rays minus the rays with every "
        "part on (what it adds given the others; the parts overlap, so the savings do not add "
        "up to the whole); 'every part' saves against the baseline (no analysis); reflection "
        "and refraction rays are the same in every variant; error against the baseline image";
    const std::vector<PartVariant> variants = partVariants();
    for (const std::string& name : effectsSceneNames()) {
        const auto owned = effectsScene(name, o);
        const Scene& scene = *owned;
        std::vector<AnalysisParts> settings = {AnalysisParts::none(), AnalysisParts{}};
        for (const PartVariant& v : variants) settings.push_back(v.parts);
        std::vector<std::unique_ptr<Renderer>> renderers;
        std::vector<std::function<void()>> frames;
        std::vector<long long> shadow;
        std::vector<Image> images;
        for (const AnalysisParts& parts : settings) {
            RenderSettings s = oneThread(sized(o, 160), sized(o, 120));
            s.analysis = parts;
            renderers.push_back(std::make_unique<Renderer>(scene, scene.camera, s));
            RayCounts c;
            images.push_back(renderers.back()->render(&c));
            shadow.push_back((long long)c.shadow);
            frames.push_back([r = renderers.back().get()] { keepValue(r->render()); });
        }
        std::vector<Timing> tm = measureInterleaved(o.repeats, frames);
        for (size_t i = 0; i < settings.size(); ++i) {
            std::string variant = i == 0   ? "baseline: no analysis"
                                  : i == 1 ? "every part"
                                           : "all but " + std::string(variants[i - 2].name);
            long long saved = i == 0 ? 0 : i == 1 ? shadow[0] - shadow[1] : shadow[i] - shadow[1];
            t.row({name, variant, shadow[i], saved, ms(tm[i].median), ms(tm[i].min), ms(tm[i].max),
                   maxStep8(images[i], images[0])});
        }
    }
    t.timeAndError("ms/frame", "min ms", "max ms", "max 8-bit error");
    return t;
}

Table measureEffectIdentity(const LabOptions& o) {
    Table t(
        "effects_identity",
        "Effects on demand at the run's image size: every built-in scene and every shipped mesh, "
        "bit-identical with and without the analysis",
        {"scene", "pixels", "rays, baseline", "rays, analysis", "saved %", "bit-identical"});
    const int w = o.quick ? sized(o, 160) : o.width, h = o.quick ? sized(o, 120) : o.height;
    t.note = std::to_string(w) + "x" + std::to_string(h) +
             ", max depth 5, every thread; baseline: AnalysisParts::none(); meshes in step 04's "
             "hierarchy; a shipped mesh is drawn as --scene FILE.obj draws it";
    std::vector<std::string> names;
    for (const auto& [name, what] : builtinScenes()) names.push_back(name);
    std::vector<std::string> meshes;
    for (const auto& e : std::filesystem::directory_iterator(o.dataDir + "/meshes"))
        if (e.path().extension() == ".obj") meshes.push_back(e.path().string());
    std::sort(meshes.begin(), meshes.end());
    names.insert(names.end(), meshes.begin(), meshes.end());
    for (const std::string& name : names) {
        const auto owned = effectsScene(name, o);
        const Scene& scene = *owned;
        RenderSettings s;
        s.width = w;
        s.height = h;
        s.threads = o.threads;
        RayCounts on, off;
        Image a = Renderer(scene, scene.camera, s).render(&on);
        s.analysis = AnalysisParts::none();
        Image b = Renderer(scene, scene.camera, s).render(&off);
        std::string label = name;
        if (name.find('/') != std::string::npos)
            label = std::filesystem::path(name).filename().string();
        t.row({label, (long long)w * h, (long long)off.total(), (long long)on.total(),
               100.0 * (double(off.total()) - double(on.total())) / double(off.total()),
               std::string(identical(a, b) ? "yes" : "NO")});
        if (!identical(a, b) || on.total() > off.total())
            throw std::runtime_error("effects on demand changed the image or added rays on '" +
                                     label + "'");
    }
    return t;
}

}  // namespace boxes
