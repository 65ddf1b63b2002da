#include "engine.h"

#ifdef CHAINTUBE_HAVE_EXPORT
#include <chaintube/export/gltf_export.h>
#include <chaintube/export/runtime.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <span>

namespace chaintube::bench::realtime {

#ifdef CHAINTUBE_HAVE_EXPORT
namespace {
// One grabbed hose: the grabbable point nearest its middle, and that point's walk in a box of
// ± 5 cm round where it was laid, 2 cm a frame.
struct GrabbedHose
{
    int hose = 0;
    int point = 0;
    RandomWalk walk;
    ChainLimits limits;
};

std::vector<GrabbedHose> grabbedHoses(const rig::HoseRuntime& runtime)
{
    std::vector<GrabbedHose> grabbed;
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        const std::vector<int>& grabbable = runtime.description(h).grabbablePoints;
        if (grabbable.empty()) continue;
        const Hose& hose = runtime.hose(h);
        const int middle = hose.pointCount() / 2;
        const int point =
            *std::min_element(grabbable.begin(), grabbable.end(), [middle](int a, int b) {
                return std::abs(a - middle) < std::abs(b - middle);
            });
        const Vec3 laid = hose.point(point);
        const Vec3 half = Vec3::Constant(CaseConstants::engineWalkReach);
        const std::uint64_t seed = CaseConstants::walkSeed + 1 + static_cast<std::uint64_t>(h);
        grabbed.push_back(
            {h, point, RandomWalk(seed, laid, {laid - half, laid + half}, CaseConstants::walkStep),
             ChainLimits::of(hose)});
    }
    return grabbed;
}
} // namespace

EngineResult runEngine(const std::filesystem::path& scenesDir,
                       const std::filesystem::path& samplesDir,
                       const std::filesystem::path& workDir, int frames, int warmup)
{
    EngineResult result;
    const std::filesystem::path scene = scenesDir / "2CylinderEngine.glb";
    if (!std::filesystem::exists(scene)) {
        result.skipped = scene.string() +
                         " is absent (CMake cache variable CHAINTUBE_SCENES_DIR, or --scenes DIR)";
        return result;
    }
    const std::filesystem::path project = samplesDir / "engine-50-hoses.ctproj";
    const std::filesystem::path rigFile = workDir / "engine-50-hoses.glb";
    std::filesystem::create_directories(workDir);
    exporting::exportProjectFile(project, rigFile, {{"scenes", scenesDir}});
    rig::HoseRuntime warm = rig::HoseRuntime::load(rigFile);
    rig::HoseRuntime runtime = rig::HoseRuntime::load(rigFile);
    std::filesystem::remove_all(workDir);

    {
        std::vector<GrabbedHose> grabbed = grabbedHoses(warm);
        for (int f = 0; f < warmup; ++f) {
            for (GrabbedHose& g : grabbed)
                static_cast<void>(warm.grab(g.hose, g.point, g.walk.next())); // warm-up
            warm.update();
        }
    }

    std::vector<GrabbedHose> grabbed = grabbedHoses(runtime);
    result.ran = true;
    result.hoses = runtime.hoseCount();
    result.grabbedHoses = static_cast<int>(grabbed.size());
    result.colliders = static_cast<int>(runtime.colliders().size());
    int axisPoints = 0;
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        const Hose& hose = runtime.hose(h);
        axisPoints += hose.pointCount();
        if (runtime.description(h).gravity.enabled) ++result.gravityHoses;
        const Violation loaded = measureViolation(hose.points(), ChainLimits::of(hose));
        result.loaded.length = std::max(result.loaded.length, loaded.length);
        result.loaded.bend = std::max(result.loaded.bend, loaded.bend);
    }
    result.row = Row{"engine-50", "ChainTube runtime", axisPoints, result.grabbedHoses, {}};
    FrameChecks& checks = result.row.checks;
    checks.microseconds.reserve(static_cast<size_t>(frames));
    checks.cpuMicroseconds.reserve(static_cast<size_t>(frames));
    std::vector<Vec3> targets(grabbed.size());
    std::vector<UpdateResult> results(grabbed.size());
    FrameTimer timer;
    for (int f = 0; f < frames; ++f) {
        for (size_t k = 0; k < grabbed.size(); ++k)
            targets[k] = grabbed[k].walk.next();
        timer.start();
        for (size_t k = 0; k < grabbed.size(); ++k)
            results[k] = runtime.grab(grabbed[k].hose, grabbed[k].point, targets[k]);
        runtime.update(); // gravity steps, surfaces and joint poses of every changed hose
        timer.stop(checks);
        for (size_t k = 0; k < grabbed.size(); ++k) {
            const GrabbedHose& g = grabbed[k];
            const int nonFiniteBefore = checks.nonFinite;
            checkChainTubeUpdate(checks, runtime.hose(g.hose), g.limits, results[k], nullptr,
                                 g.point, targets[k]);
            const std::span<const float> surface = runtime.surface(g.hose).positions();
            const bool surfaceFinite = std::all_of(surface.begin(), surface.end(),
                                                   [](float v) { return std::isfinite(v); });
            if (!surfaceFinite && checks.nonFinite == nonFiniteBefore) ++checks.nonFinite;
        }
    }
    return result;
}
#else
EngineResult runEngine(const std::filesystem::path&, const std::filesystem::path&,
                       const std::filesystem::path&, int, int)
{
    EngineResult result;
    result.skipped = "built without the exporter (target chaintube_export)";
    return result;
}
#endif

} // namespace chaintube::bench::realtime
