#include "01_triangle/measure.hpp"

#include <algorithm>
#include <iostream>
#include <map>
#include <random>

#include "core/render.hpp"
#include "core/timing.hpp"

namespace boxes {

namespace {

Vec3 randomInCone(std::mt19937_64& rng, Vec3 axis, float cosMax) {
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    float cosTheta = 1.0f - uniform(rng) * (1.0f - cosMax);
    float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    float phi = 2.0f * kPi * uniform(rng);
    Vec3 t = std::abs(axis.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    Vec3 b1 = glm::normalize(glm::cross(axis, t));
    Vec3 b2 = glm::cross(axis, b1);
    return cosTheta * axis + sinTheta * (std::cos(phi) * b1 + std::sin(phi) * b2);
}

}  // namespace

CrackRaySet makeCrackRays(const Mesh& mesh, size_t edgeRays, size_t vertexRays, uint64_t seed,
                          Vec3 offset) {
    std::mt19937_64 rng(seed);
    // Edges shared by two triangles, and the triangles around each vertex.
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> edges;
    std::vector<std::vector<uint32_t>> around(mesh.positions.size());
    for (uint32_t t = 0; t < mesh.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
            edges[{std::min(a, b), std::max(a, b)}].push_back(t);
            around[a].push_back(t);
        }
    std::vector<std::pair<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>>> shared;
    for (auto& e : edges)
        if (e.second.size() == 2) shared.push_back(e);
    Vec3 lo(kInfinity<float>), hi(-kInfinity<float>);
    for (const Vec3& p : mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    float distance = glm::length(hi - lo);  // origins stand a bounding diagonal away
    // The translated mesh, rounded to float, is the one the rays must find.
    auto position = [&](uint32_t i) { return mesh.positions[i] + offset; };
    auto faceNormal = [&](uint32_t t) {
        const auto& idx = mesh.triangles[t];
        return glm::cross(position(idx[1]) - position(idx[0]), position(idx[2]) - position(idx[0]));
    };

    CrackRaySet set;
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const float cos60 = 0.5f;
    // A direction from which every target triangle faces the ray (at 11 degrees or more):
    // then the projected triangles cover a neighbourhood of the target, so an exact test
    // must hit one of them even where rounding moves the ray a little.
    auto frontDirection = [&](const std::vector<uint32_t>& tris, Vec3& dir) {
        Vec3 sum(0.0f);
        for (uint32_t t : tris) sum += glm::normalize(faceNormal(t));
        if (!(glm::length(sum) > 1e-3f)) return false;
        for (int attempt = 0; attempt < 8; ++attempt) {
            dir = randomInCone(rng, glm::normalize(sum), cos60);
            bool front = true;
            for (uint32_t t : tris)
                front = front && glm::dot(dir, glm::normalize(faceNormal(t))) >= 0.2f;
            if (front) return true;
        }
        return false;
    };
    for (size_t i = 0; i < edgeRays && !shared.empty(); ++i) {
        const auto& [edge, tris] = shared[rng() % shared.size()];
        float s = uniform(rng);
        Vec3 target = position(edge.first) + s * (position(edge.second) - position(edge.first));
        // Near an end of the edge, rounding may move the target into the triangles around
        // that end: they belong to the edge's neighbourhood too.
        std::vector<uint32_t> targets = around[edge.first];
        for (uint32_t t : around[edge.second])
            if (std::find(targets.begin(), targets.end(), t) == targets.end()) targets.push_back(t);
        Vec3 dir;
        if (!frontDirection(targets, dir)) continue;
        Vec3 origin = target + distance * dir;
        set.edgeRays.push_back({Ray(origin, target - origin), targets});
    }
    for (size_t i = 0; i < vertexRays; ++i) {
        uint32_t v = uint32_t(rng() % mesh.positions.size());
        if (around[v].size() < 3) continue;
        Vec3 dir;
        if (!frontDirection(around[v], dir)) continue;
        Vec3 origin = position(v) + distance * dir;
        set.vertexRays.push_back({Ray(origin, position(v) - origin), around[v]});
    }
    return set;
}

template <typename T>
size_t countCracks(const Mesh& mesh, const std::vector<CrackRay>& rays, TriangleTest test,
                   Vec3 offset) {
    size_t cracks = 0;
    for (const CrackRay& r : rays) {
        RayT<T> ray = r.ray.as<T>();
        bool hit = false;
        for (uint32_t t : r.triangles) {
            // The translated mesh is rounded to float first: that is the mesh a float
            // renderer holds, and the double test sees the same vertices.
            TriangleT<T> tri{Vec3T<T>(mesh.vertex(t, 0) + offset),
                             Vec3T<T>(mesh.vertex(t, 1) + offset),
                             Vec3T<T>(mesh.vertex(t, 2) + offset)};
            if (intersectTriangle(test, ray, tri)) {
                hit = true;
                break;
            }
        }
        cracks += !hit;
    }
    return cracks;
}
template size_t countCracks<float>(const Mesh&, const std::vector<CrackRay>&, TriangleTest, Vec3);
template size_t countCracks<double>(const Mesh&, const std::vector<CrackRay>&, TriangleTest, Vec3);

Table measureCracks(const std::vector<CrackCase>& cases, size_t raysPerFeature, uint64_t seed) {
    Table table(
        "cracks",
        "Cracks: rays aimed exactly at shared edges and vertices that no triangle there reports",
        {"mesh", "placement", "feature", "rays"});
    for (TriangleTest test : kAllTriangleTests)
        for (const char* p : {"float", "double"})
            table.columns.push_back(std::string(triangleTestName(test)) + " " + p + " /1M");
    table.note =
        "closed meshes; rays from outside, every target triangle facing the ray; "
        "cracks per million rays; offset = mesh translated by (1000,-700,300) in float";
    for (const CrackCase& c : cases) {
        CrackRaySet set = makeCrackRays(*c.data, raysPerFeature, raysPerFeature, seed, c.offset);
        bool far = c.offset != Vec3(0.0f);
        for (int feature = 0; feature < 2; ++feature) {
            const auto& rays = feature == 0 ? set.edgeRays : set.vertexRays;
            std::vector<Cell> row = {c.mesh, std::string(far ? "far" : "origin"),
                                     std::string(feature == 0 ? "edges" : "vertices"),
                                     (long long)rays.size()};
            for (TriangleTest test : kAllTriangleTests) {
                size_t f = countCracks<float>(*c.data, rays, test, c.offset);
                size_t d = countCracks<double>(*c.data, rays, test, c.offset);
                double scale = rays.empty() ? 0.0 : 1e6 / double(rays.size());
                row.push_back(double(f) * scale);
                row.push_back(double(d) * scale);
            }
            table.row(row);
        }
    }
    return table;
}

Table measureTriangleSpeed(const Mesh& mesh, uint64_t seed, int repeats) {
    // Half the rays aim inside their triangle, half just outside it.
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const size_t pairs = 4096;
    std::vector<Ray> rays;
    std::vector<Triangle> tris;
    for (size_t i = 0; i < pairs; ++i) {
        uint32_t t = uint32_t(rng() % mesh.triangleCount());
        Triangle tri{mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
        float u = uniform(rng), v = uniform(rng);
        if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
        if (i % 2) u += 1.0f;  // outside
        Vec3 target = (1.0f - u - v) * tri.a + u * tri.b + v * tri.c;
        Vec3 origin = target + Vec3(uniform(rng) - 0.5f, uniform(rng) - 0.5f, 2.0f);
        rays.emplace_back(origin, target - origin);
        tris.push_back(tri);
    }
    Table table("triangle_speed",
                "Time per ray/triangle test (median of repeats over 4096 pairs, half hits)",
                {"test", "precision", "ns/test", "min ns", "max ns", "hits", "answers differing"});
    table.note =
        "one thread; each sample times the whole batch of pairs; answers differing: pairs whose "
        "hit or miss differs from the watertight test in double";
    table.timeAndError("ns/test", "min ns", "max ns", "answers differing");
    // The reference answers: the watertight test in double on the same float inputs.
    std::vector<bool> reference;
    for (size_t i = 0; i < pairs; ++i)
        reference.push_back(
            intersectTriangle(TriangleTest::Watertight, rays[i].as<double>(),
                              TriangleT<double>{Vec3T<double>(tris[i].a), Vec3T<double>(tris[i].b),
                                                Vec3T<double>(tris[i].c)})
                .has_value());
    auto run = [&](TriangleTest test, auto precision) {
        using T = decltype(precision);
        std::vector<RayT<T>> r;
        std::vector<TriangleT<T>> t;
        for (size_t i = 0; i < pairs; ++i) {
            r.push_back(rays[i].as<T>());
            t.push_back({Vec3T<T>(tris[i].a), Vec3T<T>(tris[i].b), Vec3T<T>(tris[i].c)});
        }
        long long hits = 0;
        Timing timing = measureBatched(repeats, [&] {
            long long h = 0;
            for (size_t i = 0; i < pairs; ++i) h += intersectTriangle(test, r[i], t[i]).has_value();
            keepValue(h);
            hits = h;
        });
        long long differing = 0;
        for (size_t i = 0; i < pairs; ++i)
            differing += intersectTriangle(test, r[i], t[i]).has_value() != reference[i];
        double scale = 1e9 / double(pairs);
        table.row({std::string(triangleTestName(test)),
                   std::string(sizeof(T) == 4 ? "float" : "double"), timing.median * scale,
                   timing.min * scale, timing.max * scale, hits, differing});
    };
    for (TriangleTest test : kAllTriangleTests) {
        run(test, 0.0f);
        run(test, 0.0);
    }
    return table;
}

Table accuracyVersusTime(const Table& speed, const Table& cracks) {
    Table t(
        "accuracy_vs_time",
        "Accuracy against time: each test's speed beside its cracks (all meshes and placements)",
        {"variant", "ns/test", "min ns", "max ns", "cracks /1M"},
        "ns/test (median, min, max) from the speed table; the error: cracks per million over "
        "every crack ray, against the geometry (every ray is aimed at a shared edge or vertex "
        "of a closed mesh, so some triangle there must report it)");
    t.timeAndError("ns/test", "min ns", "max ns", "cracks /1M");
    for (size_t i = 0; i < speed.rows.size(); ++i) {
        const auto& row = speed.rows[i];
        std::string name = std::get<std::string>(row[0]) + " " + std::get<std::string>(row[1]);
        double rays = 0.0, missed = 0.0;
        size_t column = 4 + i;  // cracks columns follow the same order of tests and precisions
        for (const auto& c : cracks.rows) {
            double n = double(std::get<long long>(c[3]));
            rays += n;
            missed += std::get<double>(c[column]) * n / 1e6;
        }
        t.row({name, std::get<double>(row[2]), std::get<double>(row[3]), std::get<double>(row[4]),
               rays > 0 ? missed / rays * 1e6 : 0.0});
    }
    return t;
}

size_t markDisagreements(const TriangleGrid& grid, const Camera& camera, Image& image,
                         int threads) {
    std::vector<uint8_t> differ(size_t(image.width()) * size_t(image.height()), 0);
    CameraBasisT<float> basis = camera.basis();
    parallelRows(image.height(), threads, [&](int y, int) {
        for (int x = 0; x < image.width(); ++x) {
            Ray ray(camera.eye, camera.directionThrough(basis, x + 0.5f, y + 0.5f, image.width(),
                                                        image.height()));
            uint32_t a = grid.nearestTriangle(ray, TriangleTest::PlaneTest);
            uint32_t b = grid.nearestTriangle(ray, TriangleTest::MollerTrumbore);
            uint32_t c = grid.nearestTriangle(ray, TriangleTest::Watertight);
            differ[size_t(y) * size_t(image.width()) + size_t(x)] = a != b || b != c;
        }
    });
    // Ringed: a single magenta pixel is lost on a projector.
    return markPixels(image, differ, Vec3(1.0f, 0.0f, 1.0f));
}

void measureTriangleTests(const StepRun& run, const TriangleGrid& grid, size_t crackRays,
                          Report& report) {
    const CommonOptions& o = run.options;
    const Scene& scene = run.scene;
    Image marked = run.image;
    size_t differ = markDisagreements(grid, scene.camera, marked, o.threads);
    std::string disagreePath = pngWithSuffix(run.png, "-disagree");
    marked.writePng(disagreePath);
    report.images.push_back(
        {disagreePath, differ == 0
                           ? std::string("no pixel where the three tests pick different triangles")
                           : "ringed in magenta: the " + std::to_string(differ) + " of " +
                                 std::to_string(marked.width() * marked.height()) +
                                 " pixels where the three tests pick different triangles"});
    report.facts["pixels_disagreeing"] = differ;
    std::cerr << "01_triangle: measuring speed...\n";
    report.add(measureTriangleSpeed(scene.mesh, o.seed, 7));
    std::cerr << "01_triangle: counting cracks...\n";
    Mesh sh1 = loadObj(o.dataDir + "/meshes/sh1.obj");
    Mesh bunny = scene.name == "bunny" ? scene.mesh : loadObj(o.dataDir + "/meshes/bunny.obj");
    Vec3 far(1000.0f, -700.0f, 300.0f);
    report.add(measureCracks({{"bunny", &bunny, Vec3(0.0f)},
                              {"bunny", &bunny, far},
                              {"sh1", &sh1, Vec3(0.0f)},
                              {"sh1", &sh1, far}},
                             crackRays, o.seed));
    report.add(accuracyVersusTime(report.tables[0], report.tables[1]));
    report.plots.push_back({{"table", "accuracy_vs_time"},
                            {"x", "ns/test"},
                            {"y", "cracks /1M"},
                            {"series", "variant"},
                            {"logy", true},
                            {"pareto", true},
                            {"title",
                             "Triangle tests: cracks per million crack rays against time per "
                             "test, with the Pareto front"}});
}

}  // namespace boxes
