// The runtime's scenario actions on an exported rig: each attachment's pull after an update.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <cmath>
#include <iostream>

namespace chaintube::exporting::testing {
namespace {

/// The test rig sample exported to `folder`/rig.glb and loaded by the runtime: two hoses, each
/// fixed at both ends (left-feed: bracket_left to valve_inlet; right-return: bracket_right to
/// the valve), no gravity.
rig::HoseRuntime loadTestRig(const TemporaryFolder& folder)
{
    const fs::path output = folder / "rig.glb";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    return rig::HoseRuntime::load(output);
}

/// Where attachment `attachment` of a hose holds it: its innermost fixed point (the one its
/// free span starts from).
Vec3 innerFixedPoint(const rig::HoseRuntime& runtime, int hose, int attachment)
{
    const rig::RigAttachment& a =
        runtime.description(hose).attachments.at(static_cast<size_t>(attachment));
    const int inner = a.firstPoint == 0 ? a.lastPoint : a.firstPoint;
    return runtime.hose(hose).point(inner);
}

TEST(HoseRuntimeTension, ASpanPulledTautPullsBothAttachmentsTowardsTheHandAndIsSlackOnceReleased)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadTestRig(folder);
    const int hose = runtime.findHose("left-feed");
    ASSERT_GE(hose, 0);
    ASSERT_EQ(runtime.attachmentCount(hose), 2);
    EXPECT_EQ(runtime.attachmentCount(-1), 0);
    EXPECT_THROW(runtime.attachmentPull(hose, 2), std::out_of_range);
    // As exported the hose lies along its route, longer than the chord between its ends: slack.
    for (int a = 0; a < 2; ++a) {
        EXPECT_EQ(runtime.attachmentPull(hose, a).tautness, 0.0) << a;
        EXPECT_EQ(runtime.attachmentPull(hose, a).direction, Vec3::Zero()) << a;
    }

    // A hand draws the middle point 1 m sideways: out of reach, so both spans are drawn straight.
    const Vec3 start = innerFixedPoint(runtime, hose, 0);
    const Vec3 end = innerFixedPoint(runtime, hose, 1);
    Vec3 sideways = (end - start).cross(Vec3::UnitY());
    ASSERT_GT(sideways.norm(), 1e-6);
    sideways.normalize();
    const int middle = runtime.hose(hose).pointCount() / 2;
    const Vec3 target = 0.5 * (start + end) + sideways;
    EXPECT_EQ(runtime.grab(hose, middle, target).status, Status::Clamped);
    runtime.update();
    const Vec3 held = runtime.hose(hose).point(middle);
    for (int a = 0; a < 2; ++a) {
        const AttachmentPull& pull = runtime.attachmentPull(hose, a);
        EXPECT_GT(pull.tautness, 0.9) << a;
        EXPECT_NEAR(pull.direction.norm(), 1.0, 1e-9) << a;
        // The span is straight: it pulls its attachment towards the held point.
        const Vec3 towardsHand = (held - innerFixedPoint(runtime, hose, a)).normalized();
        EXPECT_GT(pull.direction.dot(towardsHand), 0.99) << a;
        EXPECT_GE(pull.strain, 0.0) << a;
        const Vec3 force = pull.force(1e4);
        EXPECT_TRUE(force.allFinite()) << a;
        if (pull.strain > 0.0) EXPECT_GT(force.normalized().dot(pull.direction), 0.999) << a;
        EXPECT_EQ(pull.force(-1.0), Vec3::Zero()) << a;
        std::cout << "[ tension ] taut: attachment " << a << " tautness " << pull.tautness
                  << ", strain " << pull.strain << ", force at EA 1e4 N " << force.norm() << " N\n";
    }

    // Let go: the hose keeps its shape (no gravity) but nothing pins its middle any more, and
    // the chord between its attachments is shorter than the hose: slack at once.
    ASSERT_TRUE(runtime.release(hose));
    runtime.update();
    for (int a = 0; a < 2; ++a) {
        const AttachmentPull& pull = runtime.attachmentPull(hose, a);
        EXPECT_EQ(pull.tautness, 0.0) << a;
        EXPECT_EQ(pull.direction, Vec3::Zero()) << a;
        EXPECT_EQ(pull.force(1e4), Vec3::Zero()) << a;
    }
}

TEST(HoseRuntimeTension, AMovedPartThatDrawsTheHoseStraightIsHeldBackTowardsTheOtherEnd)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadTestRig(folder);
    const int hose = runtime.findHose("right-return");
    const int valve = runtime.findNode("valve");
    ASSERT_GE(hose, 0);
    ASSERT_GE(valve, 0);
    ASSERT_EQ(runtime.description(hose).attachments.at(1).node, valve);
    // Move the valve away from the bracket, 2 cm a frame, until the hose is drawn straight.
    const Vec3 bracket = innerFixedPoint(runtime, hose, 0);
    const Vec3 away = (innerFixedPoint(runtime, hose, 1) - bracket).normalized();
    rig::NodeTransform local = runtime.node(valve).local;
    const Frame parent = runtime.node(valve).parent >= 0
                             ? runtime.nodeWorldFrame(runtime.node(valve).parent)
                             : Frame();
    double slackUntil = 0.0;
    int frame = 0;
    for (; frame < 40 && runtime.attachmentPull(hose, 1).tautness < 0.9; ++frame) {
        EXPECT_GE(runtime.attachmentPull(hose, 1).tautness, slackUntil) << "frame " << frame;
        slackUntil = runtime.attachmentPull(hose, 1).tautness;
        local.translation += parent.rotation.inverse() * (0.02 * away);
        (void)runtime.setNodeTransform(valve, local);
        runtime.update();
    }
    ASSERT_LT(frame, 40) << "the hose never drew taut";
    const AttachmentPull& atValve = runtime.attachmentPull(hose, 1);
    const AttachmentPull& atBracket = runtime.attachmentPull(hose, 0);
    EXPECT_GT(atValve.tautness, 0.9);
    EXPECT_GT(atBracket.tautness, 0.9);
    // The hose holds the valve back towards the bracket, and draws the bracket towards the valve.
    const Vec3 valveEnd = innerFixedPoint(runtime, hose, 1);
    const Vec3 bracketToValve = (valveEnd - innerFixedPoint(runtime, hose, 0)).normalized();
    EXPECT_GT(atValve.direction.dot(-bracketToValve), 0.95);
    EXPECT_GT(atBracket.direction.dot(bracketToValve), 0.95);
    std::cout << "[ tension ] valve moved " << 0.02 * frame << " m: tautness " << atValve.tautness
              << ", strain " << atValve.strain << "\n";
}

} // namespace
} // namespace chaintube::exporting::testing
