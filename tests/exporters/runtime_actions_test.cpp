// The runtime's scenario actions on an exported rig: each attachment's pull after an update; an
// end unplugged and plugged into another part; a hose cut in two.
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

TEST(HoseRuntimeTension, ASpanDrawnTautByItsPartIsSlackOnceThePartGoesBack)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadTestRig(folder);
    const int hose = runtime.findHose("right-return");
    const int valve = runtime.findNode("valve");
    ASSERT_GE(hose, 0);
    ASSERT_EQ(runtime.attachmentCount(hose), 2);
    EXPECT_EQ(runtime.attachmentCount(-1), 0);
    EXPECT_THROW(runtime.attachmentPull(hose, 2), std::out_of_range);
    // As exported the hose lies along its route, longer than the chord between its ends: slack.
    for (int a = 0; a < 2; ++a) {
        EXPECT_EQ(runtime.attachmentPull(hose, a).tautness, 0.0) << a;
        EXPECT_EQ(runtime.attachmentPull(hose, a).direction, Vec3::Zero()) << a;
    }
    // The valve goes 10 cm away from the bracket: the hose is drawn straight and stretched.
    const Vec3 away =
        (innerFixedPoint(runtime, hose, 1) - innerFixedPoint(runtime, hose, 0)).normalized();
    const rig::NodeTransform home = runtime.node(valve).local;
    const Frame parent = runtime.node(valve).parent >= 0
                             ? runtime.nodeWorldFrame(runtime.node(valve).parent)
                             : Frame();
    rig::NodeTransform moved = home;
    for (int frame = 0; frame < 5; ++frame) {
        moved.translation += parent.rotation.inverse() * (0.02 * away);
        (void)runtime.setNodeTransform(valve, moved);
        runtime.update();
    }
    for (int a = 0; a < 2; ++a) {
        const AttachmentPull& pull = runtime.attachmentPull(hose, a);
        EXPECT_GT(pull.tautness, 0.9) << a;
        EXPECT_NEAR(pull.direction.norm(), 1.0, 1e-9) << a;
        EXPECT_GT(pull.strain, 0.0) << a;
        const Vec3 force = pull.force(1e4);
        EXPECT_TRUE(force.allFinite()) << a;
        EXPECT_GT(force.normalized().dot(pull.direction), 0.999) << a;
        EXPECT_EQ(pull.force(-1.0), Vec3::Zero()) << a;
        std::cout << "[ tension ] taut: attachment " << a << " tautness " << pull.tautness
                  << ", strain " << pull.strain << ", force at EA 1e4 N " << force.norm() << " N\n";
    }
    // The valve goes back: slack again at both ends.
    (void)runtime.setNodeTransform(valve, home);
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
    // Each move converged in its frame (no budget): the fittings' bends as a direct move leaves
    // them (the path of a budget's partial moves leaves the hose another valid shape).
    runtime.setBudget(UpdateBudget{});
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
    // Each pulls along its first free segment, which leaves the fitting bent within the bend
    // limit: near, not exactly on, the chord.
    EXPECT_GT(atValve.direction.dot(-bracketToValve), 0.85);
    EXPECT_GT(atBracket.direction.dot(bracketToValve), 0.85);
    std::cout << "[ tension ] valve moved " << 0.02 * frame << " m: tautness " << atValve.tautness
              << ", strain " << atValve.strain << "\n";
}

/// The rig-options sample exported to `folder`/options.glb: valve-tail hangs under gravity from
/// the valve (its last point free), the floor plate and the valve are colliders.
rig::HoseRuntime loadRigOptions(const TemporaryFolder& folder)
{
    const fs::path output = folder / "options.glb";
    exportProjectFile(testDataDir() / "rig-options.ctproj", output, roots());
    return rig::HoseRuntime::load(output);
}

/// Every segment of the hose is within its stretch band (1e-9 m of rounding).
void expectInBand(const Hose& hose, const std::string& when)
{
    for (int s = 0; s + 1 < hose.pointCount(); ++s) {
        const double length = (hose.point(s + 1) - hose.point(s)).norm();
        EXPECT_GE(length, hose.minLength(s) - 1e-9) << when << ", segment " << s;
        EXPECT_LE(length, hose.maxLength(s) + 1e-9) << when << ", segment " << s;
    }
}

TEST(HoseRuntimeDetachAttach, AnUnpluggedEndFallsUnderGravityAndFollowsThePartItIsPluggedInto)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int tail = runtime.findHose("valve-tail");
    const int valve = runtime.findNode("valve");
    const int bracket = runtime.findNode("bracket_left");
    ASSERT_GE(tail, 0);
    ASSERT_GE(valve, 0);
    ASSERT_GE(bracket, 0);
    ASSERT_EQ(runtime.attachmentCount(tail), 1);
    ASSERT_EQ(runtime.attachment(tail, 0).node, valve);
    ASSERT_EQ(runtime.attachment(tail, 0).lastPoint, 1);
    EXPECT_EQ(runtime.hose(tail).colliders().size(), 1u); // the floor plate, not the valve
    const int n = runtime.hose(tail).pointCount();
    EXPECT_EQ(runtime.grabbablePoints(tail).size(), static_cast<size_t>(n - 2));

    // A hand holds the free end where it is; the valve end is unplugged and falls.
    ASSERT_EQ(runtime.grab(tail, n - 1, runtime.hose(tail).point(n - 1)).status, Status::Ok);
    runtime.update();
    const UpdateResult detached = runtime.detachEnd(tail, 0);
    EXPECT_NE(detached.status, Status::InvalidInput);
    EXPECT_FALSE(runtime.attachment(tail, 0).attached);
    EXPECT_EQ(runtime.hose(tail).colliders().size(), 1u); // the end starts in the valve
    EXPECT_EQ(runtime.grabbablePoints(tail).size(), static_cast<size_t>(n));
    const double startHeight = runtime.hose(tail).point(0).y();
    for (int frame = 0; frame < 10; ++frame) {
        runtime.update();
        expectInBand(runtime.hose(tail), "falling, frame " + std::to_string(frame));
        EXPECT_NE(runtime.frameResult(tail).status, Status::Infeasible) << frame;
    }
    const double drop = startHeight - runtime.hose(tail).point(0).y();
    EXPECT_GT(drop, 1e-3) << "the unplugged end did not fall";
    EXPECT_EQ(runtime.attachmentPull(tail, 0).tautness, 0.0);

    // Refused, nothing changed.
    std::string why;
    const auto refusedWith = [&](const auto& call, const std::string& expected) {
        const std::vector<Vec3> before = runtime.hose(tail).points();
        const int attachments = runtime.attachmentCount(tail);
        why.clear();
        EXPECT_EQ(call().status, Status::InvalidInput) << expected;
        EXPECT_NE(why.find(expected), std::string::npos) << why;
        EXPECT_EQ(runtime.hose(tail).points(), before) << expected;
        EXPECT_EQ(runtime.attachmentCount(tail), attachments) << expected;
    };
    refusedWith([&] { return runtime.detachEnd(tail, 0, &why); }, "already detached");
    refusedWith([&] { return runtime.detachEnd(tail, 3, &why); }, "attachment 3 is out of range");
    refusedWith([&] { return runtime.detachEnd(99, 0, &why); }, "hose 99 is out of range");
    refusedWith([&] { return runtime.attachEnd(tail, 2, bracket, Frame(), nullptr, &why); },
                "end 2");
    refusedWith([&] { return runtime.attachEnd(tail, 0, 100000, Frame(), nullptr, &why); },
                "node 100000 is out of range");
    Frame notFinite;
    notFinite.translation.y() = std::nan("");
    refusedWith([&] { return runtime.attachEnd(tail, 0, bracket, notFinite, nullptr, &why); },
                "not finite");

    // Plug the falling end into the left bracket, 1 cm above where it is, its segment pointing
    // the way it points now.
    const Vec3 outward = (runtime.hose(tail).point(0) - runtime.hose(tail).point(1)).normalized();
    Frame socket;
    socket.translation = runtime.hose(tail).point(0) + Vec3(0.0, 0.01, 0.0);
    socket.rotation = Quat::FromTwoVectors(Vec3::UnitZ(), outward);
    const Frame local = runtime.nodeWorldFrame(bracket).inverse() * socket;
    int index = -1;
    const UpdateResult plugged = runtime.attachEnd(tail, 0, bracket, local, &index);
    EXPECT_EQ(plugged.status, Status::Ok);
    EXPECT_EQ(index, 1);
    ASSERT_EQ(runtime.attachmentCount(tail), 2);
    EXPECT_TRUE(runtime.attachment(tail, 1).attached);
    EXPECT_EQ(runtime.attachment(tail, 1).node, bracket);
    EXPECT_LT((runtime.hose(tail).point(0) - socket.translation).norm(), 1e-9);
    EXPECT_GT((runtime.hose(tail).point(0) - runtime.hose(tail).point(1)).normalized().dot(outward),
              1.0 - 1e-9);
    expectInBand(runtime.hose(tail), "plugged");
    EXPECT_EQ(runtime.grabbablePoints(tail).front(), 2);
    EXPECT_EQ(runtime.hose(tail).colliders().size(), 1u); // the bracket is no collider
    refusedWith([&] { return runtime.attachEnd(tail, 0, valve, Frame(), nullptr, &why); },
                "already attached");
    runtime.update();

    // The bracket moves: the plugged end goes with it, the hose within its band.
    rig::NodeTransform moved = runtime.node(bracket).local;
    for (int frame = 0; frame < 3; ++frame) {
        moved.translation.x() += 0.02;
        (void)runtime.setNodeTransform(bracket, moved);
        runtime.update();
        const Vec3 expected = (runtime.nodeWorldFrame(bracket) * local).translation;
        EXPECT_LT((runtime.hose(tail).point(0) - expected).norm(), 1e-9) << frame;
        expectInBand(runtime.hose(tail), "bracket moved, frame " + std::to_string(frame));
        EXPECT_EQ(runtime.frameResult(tail).status, Status::Ok) << frame;
    }
    std::cout << "[ plug ] valve-tail: unplugged end fell " << drop
              << " m in 10 updates; plugged into bracket_left, followed it 0.06 m\n";
}

TEST(HoseRuntimeCut, AHoseCutInTwoKeepsItsPointsAndSharesItsJointsBetweenThePieces)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int loop = runtime.findHose("bracket-loop");
    const int bracketRight = runtime.findNode("bracket_right");
    ASSERT_GE(loop, 0);
    const int hoses = runtime.hoseCount();
    const int n = runtime.hose(loop).pointCount();
    const int middle = n / 2;
    const std::vector<Vec3> points = runtime.hose(loop).points();
    const std::vector<int> joints = runtime.description(loop).jointNodes;
    ASSERT_EQ(joints.size(), static_cast<size_t>(n));
    ASSERT_EQ(runtime.attachmentCount(loop), 2);

    // Refused, nothing changed.
    const auto refused = [&](int hose, int point, const std::string& expected) {
        std::string why;
        const rig::CutResult result = runtime.cut(hose, point, &why);
        EXPECT_EQ(result.status, Status::InvalidInput) << expected;
        EXPECT_EQ(result.newHose, -1) << expected;
        EXPECT_NE(why.find(expected), std::string::npos) << why;
        EXPECT_EQ(runtime.hoseCount(), hoses) << expected;
        EXPECT_EQ(runtime.hose(loop).points(), points) << expected;
    };
    refused(loop, 0, "expected an interior point");
    refused(loop, n - 1, "expected an interior point");
    refused(loop, n + 3, "expected an interior point");
    refused(99, 3, "hose 99 is out of range");
    refused(loop, 1, "point 1"); // fixed by the left bracket's attachment
    refused(runtime.findHose("pipe-on-plate"), 3, "static");

    const rig::CutResult cut = runtime.cut(loop, middle);
    ASSERT_EQ(cut.status, Status::Ok);
    ASSERT_EQ(cut.newHose, hoses);
    ASSERT_EQ(runtime.hoseCount(), hoses + 1);
    const int piece = cut.newHose;
    EXPECT_EQ(runtime.description(piece).id, "bracket-loop~" + std::to_string(hoses));
    // The points as they were, split at the cut point (in both pieces).
    ASSERT_EQ(runtime.hose(loop).pointCount(), middle + 1);
    ASSERT_EQ(runtime.hose(piece).pointCount(), n - middle);
    for (int i = 0; i <= middle; ++i)
        EXPECT_EQ(runtime.hose(loop).point(i), points[static_cast<size_t>(i)]) << i;
    for (int i = middle; i < n; ++i) // the piece's own origin: rounding in the last bits
        EXPECT_LT((runtime.hose(piece).point(i - middle) - points[static_cast<size_t>(i)]).norm(),
                  1e-12)
            << i;
    // Every joint of the skin is posed by exactly one piece: 0 … middle by the hose cut, the
    // rest by the new hose, whose first pose (the cut point) has no node.
    std::vector<int> posed;
    for (int h : {loop, piece})
        for (const rig::JointPose& pose : runtime.jointPoses(h))
            if (pose.node >= 0) posed.push_back(pose.node);
    EXPECT_EQ(posed, joints);
    ASSERT_EQ(runtime.jointPoses(piece).size(), static_cast<size_t>(n - middle));
    EXPECT_EQ(runtime.jointPoses(piece).front().node, -1);
    EXPECT_EQ(runtime.description(piece).jointNodes.front(), -1);
    EXPECT_EQ(runtime.description(piece).meshNode, runtime.description(loop).meshNode);
    EXPECT_EQ(runtime.description(piece).skin, runtime.description(loop).skin);
    // Each piece took its bracket's attachment; the cut ends are free.
    ASSERT_EQ(runtime.attachmentCount(loop), 1);
    ASSERT_EQ(runtime.attachmentCount(piece), 1);
    EXPECT_EQ(runtime.attachment(piece, 0).node, bracketRight);
    EXPECT_EQ(runtime.attachment(piece, 0).lastPoint, n - middle - 1);
    EXPECT_EQ(runtime.grabbablePoints(loop).back(), middle);
    EXPECT_EQ(runtime.grabbablePoints(piece).front(), 0);

    // The pieces move apart: pulling the new piece's cut end leaves the first piece as it is.
    const Vec3 end = runtime.hose(piece).point(0);
    EXPECT_NE(runtime.grab(piece, 0, end + Vec3(0.0, 0.05, 0.0)).status, Status::InvalidInput);
    runtime.update();
    EXPECT_GT((runtime.hose(piece).point(0) - end).norm(), 0.01);
    for (int i = 0; i <= middle; ++i)
        EXPECT_EQ(runtime.hose(loop).point(i), points[static_cast<size_t>(i)]) << i;
    expectInBand(runtime.hose(piece), "the new piece pulled");
    expectInBand(runtime.hose(loop), "the first piece");
    std::cout << "[ cut ] bracket-loop (" << n << " points) cut at " << middle << ": hose " << piece
              << " poses " << n - middle - 1 << " joints, the cut end pulled "
              << (runtime.hose(piece).point(0) - end).norm() << " m\n";
}

} // namespace
} // namespace chaintube::exporting::testing
