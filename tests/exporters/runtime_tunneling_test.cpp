// Contact that cannot tunnel, through the runtime: a rig whose collider node is a 2 mm plate,
// moved by HoseRuntime::setNodeTransform at 2 m/s (90 Hz) through a hose fixed at both ends,
// never crosses it, nor does the hose when one of its points is grabbed as fast past the plate
// standing still (HoseRuntime::grab under the real-time budget; the library's passes:
// tests/lib/tunneling_test.cpp).
#include "export_test_support.h"

#include <algorithm>
#include <chaintube/export/runtime.h>
#include <chaintube/test_support/crossing.h>
#include <chaintube/test_support/sanitizer.h>
#include <cmath>
#include <cstdio>
#include <random>

namespace chaintube::exporting::testing {
namespace {

/// Passes through the runtime (each loads the rig afresh); under the sanitizers a quarter.
constexpr int kPasses = test_support::kUnderAddressSanitizer ? 250 : 1000;

/// The motion rig with only the hose from the pillar to the lever (fixed at both ends) and its
/// base plate, scaled to a plate of 64 × 2 × 40 mm, as the collider: project and scene written
/// into `folder`, exported there; returns the exported file.
fs::path exportPlateRig(const fs::path& folder)
{
    Json scene = Json::parse(readBytes(samplesDir() / "scenes" / "motion-rig.gltf"));
    for (Json& node : scene["nodes"])
        if (node["name"] == "base_plate") node["scale"] = {0.08, 0.2, 0.1};
    fs::create_directories(folder / "scenes");
    writeBytes(folder / "scenes" / "motion-rig.gltf", scene.dump());
    Json project = Json::parse(readBytes(samplesDir() / "motion-rig.ctproj"));
    Json kept = Json::array();
    for (const Json& hose : project["hoses"])
        if (hose["id"] == "lever-feed") kept.push_back(hose);
    project["hoses"] = kept;
    project["motions"] = Json::array();
    project["colliders"] = Json::array({{{"scene", "rig"}, {"node", "/motion-rig/base_plate"}}});
    writeBytes(folder / "plate-rig.ctproj", project.dump(2));
    const fs::path output = folder / "plate-rig.glb";
    exportProjectFile(folder / "plate-rig.ctproj", output, roots());
    return output;
}

// The plate in its collider's frame (the node's scale baked into the vertices).
test_support::Shape plateInItsNodeFrame()
{
    test_support::Shape plate =
        test_support::makeShape(test_support::Kind::BoxPlate, 0.032, 0.02, 0.002);
    for (auto& [normal, offset] : plate.planes) // the thin axis is the node's y
        normal = Vec3(normal.x(), normal.z(), normal.y());
    return plate;
}

TEST(HoseRuntimeTunneling, AThinPlateColliderMovedAt2MetresASecondThroughAHoseNeverCrossesIt)
{
    TemporaryFolder folder;
    const fs::path rigFile = exportPlateRig(folder.path());
    const test_support::Shape plate = plateInItsNodeFrame();
    const std::uint64_t seed = 52;
    std::printf("[ seed     ] runtime plate passes: %llu\n", static_cast<unsigned long long>(seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> gauss;
    const double step = 2.0 / 90.0; // 2 m/s at 90 Hz
    int passes = 0, touched = 0, crossings = 0, offConstraints = 0, unreported = 0, allFrames = 0;
    double worstLength = 0.0, worstBend = 0.0;
    for (int attempt = 0; passes < kPasses && attempt < 4 * kPasses; ++attempt) {
        rig::HoseRuntime runtime = rig::HoseRuntime::load(rigFile);
        const int hose = runtime.findHose("lever-feed");
        const int node = runtime.findNode("base_plate");
        ASSERT_GE(hose, 0);
        ASSERT_GE(node, 0);
        ASSERT_EQ(runtime.colliders().size(), 1u);
        const MeshCollider& collider = *runtime.colliders().front();
        const Hose& h = runtime.hose(hose);
        const double tolerance = h.collisionOptions().tolerance;
        // A random turn of the plate and a direction mostly across the hose's plane (z = 0),
        // where the arc can swing round its chord: pushed up to 2 cm beyond a point of its middle.
        rig::NodeTransform pose = runtime.node(node).local;
        pose.rotation = Quat(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
        Vec3 direction(gauss(rng), gauss(rng), gauss(rng));
        direction.z() = std::copysign(std::max(std::abs(direction.z()), direction.head<2>().norm()),
                                      direction.z());
        direction.normalize();
        const int at = 5 + static_cast<int>(unit(rng) * 6.0);
        const Vec3 onHose = h.point(at) + unit(rng) * (h.point(at + 1) - h.point(at));
        const Vec3 onPlate(0.032 * (2 * unit(rng) - 1), 0.0, 0.02 * (2 * unit(rng) - 1));
        const double beyond = 0.02 * unit(rng);
        const double reach = std::hypot(0.032, 0.02) + h.outerRadius() + 0.01;
        const Vec3 end = onHose + beyond * direction - pose.rotation * onPlate;
        const Vec3 start = end - (reach + beyond) * direction;
        const int frames = static_cast<int>(std::ceil((reach + beyond) / step));
        // To the start without coming near the hose: down to the floor, out along z, then
        // across to the start; a pass whose way there touches the hose is drawn again.
        const std::vector<Vec3> initial = h.points();
        const double away = start.z() < 0.0 ? -1.0 : 1.0;
        for (const Vec3& leg : {Vec3(0, 0.005, away), Vec3(start.x(), start.y(), away), start}) {
            pose.translation = leg;
            for (const rig::HoseUpdate& u : runtime.setNodeTransform(node, pose))
                ASSERT_NE(u.result.status, Status::InvalidInput);
        }
        if (h.points() != initial || clearance(h, collider).distance <= h.outerRadius()) continue;
        ++passes;
        bool crossed = false, moved = false;
        for (int f = 1; f <= frames; ++f) {
            const std::vector<Vec3> before = h.points();
            const Frame frameBefore = collider.frame();
            pose.translation = start + (double(f) / frames) * (end - start);
            int contacts = 0;
            for (const rig::HoseUpdate& u : runtime.setNodeTransform(node, pose))
                if (u.hose == hose) contacts = u.result.contacts;
            runtime.update();
            const std::vector<Vec3> after = h.points();
            crossed |= test_support::axisCrossed(plate, before, frameBefore, after,
                                                 collider.frame(), tolerance);
            const UpdateResult v = h.measureViolation();
            offConstraints += v.lengthViolation > 1e-9 || v.angleViolation > 1e-9;
            worstLength = std::max(worstLength, v.lengthViolation);
            worstBend = std::max(worstBend, v.angleViolation);
            ++allFrames;
            moved |= after != before;
            // Where the hose ends touching the plate, the update said so.
            unreported += clearance(h, collider).distance < tolerance && contacts == 0;
        }
        touched += moved;
        if (crossed && crossings++ == 0)
            ADD_FAILURE() << "first crossing in pass " << passes << " (attempt " << attempt << ")";
    }
    std::printf("[ tally    ] runtime plate passes: %d (%d touched the hose), %d frames: %d "
                "crossings, %d frames off the constraints (worst length %.3g, bend %.3g), %d "
                "touching without contacts\n",
                passes, touched, allFrames, crossings, offConstraints, worstLength, worstBend,
                unreported);
    EXPECT_EQ(passes, kPasses);
    EXPECT_EQ(crossings, 0);
    // Every length and bend held in every frame (seed 52: 0 of 3567 frames).
    EXPECT_EQ(offConstraints, 0);
    EXPECT_EQ(unreported, 0);
    EXPECT_GT(touched, kPasses / 4) << "the passes reach the hose";
}

TEST(HoseRuntimeTunneling,
     AGrabbedPointMovedAt2MetresASecondPastAThinPlateNeverCarriesTheHoseAcross)
{
    TemporaryFolder folder;
    const fs::path rigFile = exportPlateRig(folder.path());
    const test_support::Shape plate = plateInItsNodeFrame();
    const std::uint64_t seed = 52;
    std::printf("[ seed     ] runtime grab passes: %llu\n", static_cast<unsigned long long>(seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> gauss;
    const double travel = 0.1;
    int passes = 0, touched = 0, crossings = 0, offConstraints = 0, unreported = 0, allFrames = 0;
    int worstIterations = 0;
    for (int attempt = 0; passes < kPasses && attempt < 4 * kPasses; ++attempt) {
        rig::HoseRuntime runtime = rig::HoseRuntime::load(rigFile); // the realtime budget
        const int hose = runtime.findHose("lever-feed");
        const int node = runtime.findNode("base_plate");
        ASSERT_GE(hose, 0);
        ASSERT_GE(node, 0);
        const MeshCollider& collider = *runtime.colliders().front();
        const Hose& h = runtime.hose(hose);
        const double tolerance = h.collisionOptions().tolerance;
        // A point of the hose's middle grabbed along a random direction; the plate, turned at
        // random, stands 3–7 cm along the way, up to 2 cm aside, any point of it there.
        const int grabbed = 4 + static_cast<int>(unit(rng) * (h.pointCount() - 8));
        const Vec3 from = h.point(grabbed);
        const Vec3 direction = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
        rig::NodeTransform pose = runtime.node(node).local;
        pose.rotation = Quat(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
        const Vec3 onPlate(0.032 * (2 * unit(rng) - 1), 0.0, 0.02 * (2 * unit(rng) - 1));
        const Vec3 aside = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const Vec3 at = from + direction * (travel * (0.3 + 0.4 * unit(rng))) +
                        0.02 * unit(rng) * aside - pose.rotation * onPlate;
        const double step = 2.0 * (0.25 + 0.75 * unit(rng)) / 90.0; // up to 2 m/s at 90 Hz
        const int frames = static_cast<int>(std::ceil(travel / step));
        // There without coming near the hose (as in the plate passes above).
        const std::vector<Vec3> initial = h.points();
        const double away = at.z() < 0.0 ? -1.0 : 1.0;
        for (const Vec3& leg : {Vec3(0, 0.005, away), Vec3(at.x(), at.y(), away), at}) {
            pose.translation = leg;
            for (const rig::HoseUpdate& u : runtime.setNodeTransform(node, pose))
                ASSERT_NE(u.result.status, Status::InvalidInput);
        }
        runtime.update();
        if (h.points() != initial || clearance(h, collider).distance <= h.outerRadius()) continue;
        ++passes;
        bool crossed = false, blocked = false;
        for (int f = 1; f <= frames; ++f) {
            const std::vector<Vec3> before = h.points();
            const Vec3 target = from + std::min(1.0, double(f) / frames) * travel * direction;
            ASSERT_NE(runtime.grab(hose, grabbed, target).status, Status::InvalidInput);
            runtime.update();
            const UpdateResult& r = runtime.frameResult(hose);
            const std::vector<Vec3> after = h.points();
            crossed |= test_support::axisCrossed(plate, before, collider.frame(), after,
                                                 collider.frame(), tolerance);
            const UpdateResult v = h.measureViolation();
            offConstraints += v.lengthViolation > 1e-9 || v.angleViolation > 1e-9;
            ++allFrames;
            blocked |= r.blocked;
            worstIterations = std::max(worstIterations, r.iterations);
            unreported += clearance(h, collider).distance < tolerance && r.contacts == 0;
        }
        touched += blocked;
        if (crossed && crossings++ == 0)
            ADD_FAILURE() << "first crossing in pass " << passes << " (attempt " << attempt << ")";
    }
    std::printf("[ tally    ] runtime grab passes: %d (%d blocked by the plate), %d frames: %d "
                "crossings, %d frames off the constraints, %d touching without contacts; Newton "
                "steps a frame at most %d\n",
                passes, touched, allFrames, crossings, offConstraints, unreported, worstIterations);
    EXPECT_EQ(passes, kPasses);
    EXPECT_EQ(crossings, 0);
    EXPECT_EQ(offConstraints, 0);
    EXPECT_EQ(unreported, 0);
    EXPECT_GT(touched, kPasses / 4) << "the passes reach the plate";
}

} // namespace
} // namespace chaintube::exporting::testing
