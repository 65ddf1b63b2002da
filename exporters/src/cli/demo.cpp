#include "demo.h"

#include <chaintube/chaintube.h>
#include <chrono>
#include <cmath>
#include <iomanip>

namespace chaintube::cli {

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;

void report(std::ostream& out, const char* what, const Hose& hose, const UpdateResult& result)
{
    const HoseMetrics m = measure(hose);
    out << "  " << std::left << std::setw(44) << what << " status " << std::setw(10)
        << toString(result.status) << " moved " << std::setw(4) << result.movedPoints << " stretch "
        << std::fixed << std::setprecision(3) << m.minStretch << "…" << m.maxStretch
        << "  smallest bend radius " << std::setprecision(4)
        << (m.smallestBendRadius > 1e6 ? 0.0 : m.smallestBendRadius) << " m"
        << "  grab error " << std::scientific << std::setprecision(2) << result.grabError << "\n"
        << std::defaultfloat;
}
} // namespace

int runDemo(std::ostream& out)
{
    out << "ChainTube demo: the paper's setting, then a 50-hose frame\n\n";
    // The paper's hose: 12 segments, expansion 20 %, 40° deflection per joint.
    HoseSpec paper;
    paper.outerDiameter = 0.02;
    paper.segmentCount = 12;
    paper.material.expansionCoefficient = 0.2;
    paper.material.bendLimit = BendLimit::deflectionAngle(40 * kDegree);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.6, paper);
    out << "Hose: " << hose.pointCount() << " axis points, rest length " << hose.restLengthTotal()
        << " m, expansion 20 %, deflection limit 40° per joint\n";
    report(out, "drag point 6 up by 0.1 m (Fig. 6-9)", hose,
           hose.grab(6, hose.point(6) + Vec3(0, 0.1, 0)));
    report(out, "drag end point 12 back to x = 0.3", hose, hose.grab(12, Vec3(0.3, 0.3, 0.0)));
    const int clamp = hose.attach(0, 1, Frame::identity());
    report(out, "fix points 0-1, pull end 5 m away", hose, hose.grab(12, Vec3(5.0, 0.0, 0.0)));
    Frame moved;
    moved.translation = Vec3(0.0, 0.2, 0.1);
    moved.rotation = Quat(Eigen::AngleAxisd(30 * kDegree, Vec3::UnitZ()));
    report(out, "move the fixed segment (0.2 m, 30°)", hose, hose.moveAttachment(clamp, moved));

    // 50 hoses × 100 points × 16-sided rings, every hose dragged each frame.
    HoseSpec spec;
    spec.outerDiameter = 0.016;
    spec.segmentCount = 99;
    spec.material.expansionCoefficient = 0.1;
    spec.material.bendLimit = BendLimit::minBendRadius(0.08);
    Scene scene;
    for (int i = 0; i < 50; ++i)
        scene.addHose(Hose::straight(Vec3(0.0, 0.0, 0.05 * i), Vec3::UnitX(), 1.0, spec));
    scene.updateSurfaces();
    const int frames = 200;
    const auto start = std::chrono::steady_clock::now();
    int clampedOrWorse = 0;
    for (int f = 0; f < frames; ++f) {
        for (int i = 0; i < scene.hoseCount(); ++i) {
            Hose& h = scene.hose(i);
            const double phase = 0.05 * f + 0.3 * i;
            const Vec3 target =
                h.point(50) + Vec3(0.0, 0.01 * std::sin(phase), 0.01 * std::cos(phase));
            if (!h.grab(50, target).ok()) ++clampedOrWorse;
        }
        scene.updateSurfaces();
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const SurfaceTopology& topology = scene.surface(0).topology();
    out << "\nScene: 50 hoses × " << scene.hose(0).pointCount() << " points × "
        << topology.ringVertexCount - 1 << "-sided rings (" << 50 * topology.vertexCount
        << " vertices, " << 50 * topology.indices.size() / 3 << " triangles)\n"
        << "  " << frames << " frames, every hose dragged each frame: " << std::fixed
        << std::setprecision(3) << 1e3 * seconds / frames
        << " ms per frame (axis + rings + normals)"
        << "; updates not ok: " << clampedOrWorse << "\n";
    double worstStretch = 1.0;
    for (int i = 0; i < scene.hoseCount(); ++i)
        worstStretch = std::max(worstStretch, measure(scene.hose(i)).maxStretch);
    out << "  largest stretch after the run: " << std::setprecision(4) << worstStretch
        << " (limit 1.1)\n";
    return 0;
}

} // namespace chaintube::cli
