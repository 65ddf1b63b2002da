// The runtime at any frame rate (HoseRuntime::update(seconds)): the rig-options sample's
// bracket-loop, its ends fixed to the two brackets, with gravity on, follows the same timed path
// of bracket_right at 45, 72, 90 and 120 Hz without whipping, every segment in its band;
// update(1/90) is update(); bad frame times are refused. (How near the runs end to each other
// is printed, not asserted: this loop's bends bind along it, where a gravity step creeps and
// comes to rest where it stops coming lower, lib/README.md, "Gravity at any frame rate"; the
// 1 mm agreement is asserted on a hose that settles, tests/lib/frame_rate_test.cpp.)
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>

namespace chaintube::exporting::testing {
namespace {

constexpr double kGravity = 9.81;    // m/s²
constexpr double kPathSeconds = 1.0; // the bracket's path, then held still
constexpr double kRunSeconds = 5.0;

// bracket_right's offset at time t (seconds): a 4 cm × 3 cm × 3 cm loop in 1 s, then back where
// it was.
Vec3 bracketPath(double t)
{
    if (t >= kPathSeconds) return Vec3::Zero();
    const double phase = 2.0 * std::numbers::pi * t / kPathSeconds;
    return Vec3(-0.04 * std::sin(phase), 0.03 * (1.0 - std::cos(phase)),
                0.03 * std::sin(phase) * std::cos(phase));
}

struct LoopRun
{
    std::vector<Vec3> shape;  // bracket-loop's axis after kRunSeconds
    double worstWhip = 0.0;   // largest move of a point in a frame / (drive + free fall)
    double worstLength = 0.0; // beyond the band, relative, after every update
};

LoopRun runAt(const fs::path& glb, double rate)
{
    rig::HoseRuntime runtime = rig::HoseRuntime::load(glb);
    const int loop = runtime.findHose("bracket-loop");
    const int bracket = runtime.findNode("bracket_right");
    EXPECT_GE(loop, 0);
    EXPECT_GE(bracket, 0);
    EXPECT_TRUE(runtime.description(loop).gravity.enabled);
    const rig::NodeTransform home = runtime.node(bracket).local;
    const double frame = 1.0 / rate;
    const int frames = static_cast<int>(std::lround(kRunSeconds * rate));
    LoopRun run;
    for (int k = 1; k <= frames; ++k) {
        const std::vector<Vec3> before = runtime.hose(loop).points();
        rig::NodeTransform moved = home;
        moved.translation += bracketPath(k * frame);
        static_cast<void>(runtime.setNodeTransform(bracket, moved));
        runtime.update(frame);
        const Hose& hose = runtime.hose(loop);
        double top = -std::numeric_limits<double>::infinity();
        double bottom = std::numeric_limits<double>::infinity();
        const std::vector<Vec3> after = hose.points();
        for (const std::vector<Vec3>* shape : {&before, &after})
            for (const Vec3& p : *shape) {
                top = std::max(top, p.y());
                bottom = std::min(bottom, p.y());
            }
        // What drives the hose: the largest move of a point an attachment fixes.
        double drive = 0.0;
        for (int i = 0; i < hose.pointCount(); ++i)
            if (hose.isFixed(i))
                drive = std::max(drive, (hose.point(i) - before[static_cast<size_t>(i)]).norm());
        const double allowed =
            drive + (std::sqrt(2.0 * kGravity * (top - bottom)) + kGravity * frame) * frame;
        for (int i = 0; i < hose.pointCount(); ++i)
            run.worstWhip = std::max(
                run.worstWhip, (hose.point(i) - before[static_cast<size_t>(i)]).norm() / allowed);
        run.worstLength = std::max(run.worstLength, hose.measureViolation().lengthViolation);
    }
    run.shape = runtime.hose(loop).points();
    return run;
}

} // namespace

TEST(HoseRuntimeFrameRate, TheSameBracketPathAt45To120HzNeverWhipsAndKeepsEveryLength)
{
    TemporaryFolder folder;
    const fs::path glb = exportLoopWithGravity(folder);
    const LoopRun reference = runAt(glb, 90.0);
    for (double rate : {45.0, 72.0, 90.0, 120.0}) {
        const LoopRun run = rate == 90.0 ? reference : runAt(glb, rate);
        ASSERT_EQ(run.shape.size(), reference.shape.size());
        double difference = 0.0;
        for (size_t i = 0; i < run.shape.size(); ++i)
            difference = std::max(difference, (run.shape[i] - reference.shape[i]).norm());
        std::printf("[ figures ] runtime, bracket-loop at %.0f Hz: largest difference from 90 Hz "
                    "%.3g m, whip ratio %.3f, length violation %.2g\n",
                    rate, difference, run.worstWhip, run.worstLength);
        EXPECT_LE(run.worstWhip, 1.0) << rate << " Hz";
        EXPECT_LE(run.worstLength, 1e-9) << rate << " Hz";
    }
}

TEST(HoseRuntimeFrameRate, ABadFrameTimeIsRefusedAndChangesNothing)
{
    TemporaryFolder folder;
    const fs::path glb = exportLoopWithGravity(folder);
    rig::HoseRuntime runtime = rig::HoseRuntime::load(glb);
    const int loop = runtime.findHose("bracket-loop");
    const int bracket = runtime.findNode("bracket_right");
    ASSERT_GE(loop, 0);
    ASSERT_GE(bracket, 0);
    rig::NodeTransform moved = runtime.node(bracket).local;
    moved.translation += Vec3(-0.03, 0.02, 0.0);
    static_cast<void>(runtime.setNodeTransform(bracket, moved));
    const std::vector<Vec3> before = runtime.hose(loop).points();
    const std::uint64_t revision = runtime.hose(loop).revision();
    for (double seconds : {0.0, -0.01, 0.10000001, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
        EXPECT_THROW(runtime.update(seconds), InvalidArgument) << seconds;
        EXPECT_EQ(runtime.hose(loop).points(), before) << seconds;
        EXPECT_EQ(runtime.hose(loop).revision(), revision) << seconds;
    }
    try {
        runtime.update(0.5);
        ADD_FAILURE() << "update(0.5) was accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("seconds"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("0.5"), std::string::npos) << error.what();
    }
    // The longest frame accepted.
    EXPECT_GE(runtime.update(Gravity::kMaxFrameSeconds), 1);
    EXPECT_NE(runtime.hose(loop).points(), before);
    EXPECT_LE(runtime.hose(loop).measureViolation().lengthViolation, 1e-9);
    // A frame of 1/90 s is update()'s, bit for bit.
    rig::HoseRuntime timed = rig::HoseRuntime::load(glb);
    rig::HoseRuntime other = rig::HoseRuntime::load(glb);
    static_cast<void>(timed.setNodeTransform(bracket, moved));
    static_cast<void>(other.setNodeTransform(bracket, moved));
    for (int frame = 0; frame < 30; ++frame) {
        timed.update(1.0 / 90.0);
        other.update();
        ASSERT_EQ(timed.hose(loop).points(), other.hose(loop).points()) << "frame " << frame;
    }
}

} // namespace chaintube::exporting::testing
