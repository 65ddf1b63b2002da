// The runtime's scenario actions on an exported rig: each attachment's pull after an update; an
// end unplugged and plugged into another part; a hose cut in two; a hose reeled out and in.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <cmath>
#include <functional>
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

// --- Reel in, pay out -----------------------------------------------------------------------

constexpr double kReelFrame = 1.0 / 90.0; // seconds
constexpr double kReelSpeed = 0.5;        // metres a second

/// What a reel walk saw.
struct ReelWalk
{
    int frames = 0;
    int clampedFrames = 0;
    double paidOut = 0.0;
    double paidIn = 0.0;
    double largestMoveOverPaid = 0.0; ///< a frame's largest point move / its |paid|
    int mostPoints = 0;
    int reelIterations = 0;     ///< the reel calls' Newton steps (ReelResult::update)
    int mostReelIterations = 0; ///< those of the costliest frame
};

/// Pays `distance` out at end `end` of a hose at kReelSpeed, kReelFrame a frame, then (`back`)
/// in again, one runtime update a frame, checking every frame: no point moved by the reel more
/// than kReelMoveFactor times what it paid (chaintube/reel.h), then after the update every segment
/// in its band, no constraint violated, the joint count and nodes as exported, the attachments'
/// point indices on the points the hose fixes, the grabbable points every free point. A frame whose
/// call is clamped pays what it could; the rest waits for the next frame (at most 4 × distance /
/// step frames a way).
ReelWalk reelOutAndBack(rig::HoseRuntime& runtime, int hose, HoseEnd end, double distance,
                        bool back = true)
{
    ReelWalk walk;
    const std::vector<int> jointNodes = runtime.description(hose).jointNodes;
    const size_t joints = runtime.jointPoses(hose).size();
    const double total0 = runtime.hose(hose).restLengthTotal();
    const double step = kReelSpeed * kReelFrame;
    const int maxFrames = static_cast<int>(4.0 * distance / step) + 4;
    for (int direction : {+1, -1}) {
        if (direction < 0 && !back) break;
        double left = distance;
        for (int frame = 0; left > 1e-12 && frame < maxFrames; ++frame) {
            const Hose& h = runtime.hose(hose);
            const std::vector<Vec3> before = h.points();
            // The outlet and the side its free hose is on, before the call.
            const int n0 = h.pointCount();
            int outlet = -1;
            for (const Hose::Attachment& a : h.attachments())
                if (!a.isClip() && (end == HoseEnd::Start ? a.first == 0 : a.last == n0 - 1))
                    outlet = end == HoseEnd::Start ? a.last : a.first;
            const int side = end == HoseEnd::Start ? +1 : -1;
            const ReelResult r = runtime.reel(hose, end, direction * std::min(left, step), 0.0,
                                              std::numeric_limits<double>::infinity());
            EXPECT_NE(r.status, Status::InvalidInput) << r.message;
            walk.clampedFrames += r.status == Status::Clamped;
            walk.reelIterations += r.update.iterations;
            walk.mostReelIterations = std::max(walk.mostReelIterations, r.update.iterations);
            left -= std::abs(r.paid);
            (direction > 0 ? walk.paidOut : walk.paidIn) += std::abs(r.paid);
            const std::vector<Vec3> reeled = h.points(); // before the update's gravity step
            runtime.update();
            ++walk.frames;
            const std::string when =
                (direction > 0 ? "out, frame " : "in, frame ") + std::to_string(frame);
            expectInBand(h, when);
            EXPECT_EQ(h.measureViolation().status, Status::Ok) << when;
            EXPECT_NE(runtime.frameResult(hose).status, Status::Infeasible) << when;
            const int n = h.pointCount();
            walk.mostPoints = std::max(walk.mostPoints, n);
            EXPECT_EQ(n, n0 + r.segmentsAdded - r.segmentsRemoved) << when;
            // Each point that was there before: where it is now.
            double largest = 0.0;
            for (int i = 0; i < n0; ++i) {
                int to = i;
                const bool beyond = side > 0 ? i > outlet : i < outlet;
                if (r.segmentsAdded + r.segmentsRemoved > 1) continue;      // not in one step
                if (r.segmentsRemoved == 1 && i == outlet + side) continue; // merged away
                if (side > 0 && beyond) to = i + r.segmentsAdded - r.segmentsRemoved;
                if (side < 0 && !beyond && i != outlet + side)
                    to = i + r.segmentsAdded - r.segmentsRemoved;
                largest = std::max(
                    largest,
                    (reeled[static_cast<size_t>(to)] - before[static_cast<size_t>(i)]).norm());
            }
            if (r.paid != 0.0) {
                EXPECT_LE(largest, kReelMoveFactor * std::abs(r.paid) * (1.0 + 1e-9) + 1e-12)
                    << when;
                walk.largestMoveOverPaid =
                    std::max(walk.largestMoveOverPaid, largest / std::abs(r.paid));
            }
            // The skin keeps its joints; each joint is on the hose.
            EXPECT_EQ(runtime.jointPoses(hose).size(), joints) << when;
            EXPECT_EQ(runtime.description(hose).jointNodes, jointNodes) << when;
            for (const rig::JointPose& pose : runtime.jointPoses(hose)) {
                EXPECT_TRUE(pose.world.translation.allFinite()) << when;
                EXPECT_NEAR(pose.world.rotation.norm(), 1.0, 1e-9) << when;
            }
            // Bookkeeping follows the points.
            std::vector<char> fixed(static_cast<size_t>(n), 0);
            for (int a = 0; a < runtime.attachmentCount(hose); ++a) {
                const rig::LiveAttachment& live = runtime.attachment(hose, a);
                EXPECT_TRUE(live.attached);
                for (int i = live.firstPoint; i <= live.lastPoint; ++i) {
                    EXPECT_TRUE(h.isFixed(i)) << when << ", attachment " << a << " point " << i;
                    fixed[static_cast<size_t>(i)] = 1;
                }
            }
            std::vector<int> free;
            for (int i = 0; i < n; ++i)
                if (!fixed[static_cast<size_t>(i)]) free.push_back(i);
            EXPECT_EQ(runtime.grabbablePoints(hose), free) << when;
            EXPECT_EQ(runtime.description(hose).pointCount(), n) << when;
            EXPECT_EQ(runtime.description(hose).restLengths.size(), static_cast<size_t>(n - 1));
        }
        EXPECT_LE(left, 1e-12) << (direction > 0 ? "paying out" : "reeling in") << " stalled";
    }
    EXPECT_NEAR(runtime.hose(hose).restLengthTotal(), total0 + (back ? 0.0 : distance), 1e-9);
    return walk;
}

TEST(HoseRuntimeReel, PaidOutThreeTenthsOfAMetreAndBackEveryFrameIsValid)
{
    // valve-tail on rig-options: fixed to the valve (points 0, 1: the reel's outlet), its end
    // free, hanging under gravity from a bend on its limit at the outlet. A frame whose step
    // would move a point more than kReelMoveFactor times the length paid is Clamped and the
    // length waits for the next frame (lib/README.md, "Reel in, pay out").
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int hose = runtime.findHose("valve-tail");
    ASSERT_GE(hose, 0);
    const int n = runtime.hose(hose).pointCount();
    const std::vector<double> rest = runtime.description(hose).restLengths;
    const ReelWalk walk = reelOutAndBack(runtime, hose, HoseEnd::Start, 0.3);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    EXPECT_GT(walk.mostPoints, n + 5); // the new length appeared as points at the reel
    const Hose& h = runtime.hose(hose);
    // Back at the exported length and segments: the joints are on the points again.
    const std::vector<rig::JointPose>& poses = runtime.jointPoses(hose);
    ASSERT_EQ(poses.size(), static_cast<size_t>(n));
    bool sameSegments = h.pointCount() == n;
    for (int s = 0; sameSegments && s + 1 < n; ++s)
        sameSegments = std::abs(h.restLength(s) - rest[static_cast<size_t>(s)]) <= 1e-9;
    EXPECT_TRUE(sameSegments);
    for (size_t j = 0; sameSegments && j < poses.size(); ++j) {
        EXPECT_LT((poses[j].world.translation - h.point(static_cast<int>(j))).norm(), 1e-9) << j;
    }
    std::cout << "[ reel ] valve-tail 0.3 m out and back at 0.5 m/s, 90 Hz: " << walk.frames
              << " frames (" << walk.clampedFrames
              << " clamped, the rest paid the next frame), up to " << walk.mostPoints
              << " points (exported " << n << "), largest move " << walk.largestMoveOverPaid
              << " x the length paid a frame\n";
}

TEST(HoseRuntimeReel, IntoASpanToTheValveAndBackEveryFrameAtTheSpeedAskedAndValid)
{
    // left-feed on the test rig: fixed to bracket_left (points 0, 1: the outlet) and to the
    // valve's inlet. The span takes 0.3 m by its shape and gives it back, bent beyond the outlet
    // as it is: every frame pays what it asks (lib/README.md, "Reel in, pay out").
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadTestRig(folder);
    const int hose = runtime.findHose("left-feed");
    ASSERT_GE(hose, 0);
    const int n = runtime.hose(hose).pointCount();
    const double total0 = runtime.hose(hose).restLengthTotal();
    const ReelWalk walk = reelOutAndBack(runtime, hose, HoseEnd::Start, 0.3);
    EXPECT_NEAR(walk.paidOut, 0.3, 1e-12);
    EXPECT_NEAR(walk.paidIn, 0.3, 1e-12);
    EXPECT_EQ(walk.clampedFrames, 0);
    EXPECT_EQ(walk.frames, 2 * 54);
    EXPECT_GT(walk.mostPoints, n + 5);
    EXPECT_LE(walk.largestMoveOverPaid, kReelMoveFactor + 1e-9);
    EXPECT_NEAR(runtime.hose(hose).restLengthTotal(), total0, 1e-9);
    EXPECT_EQ(runtime.hose(hose).pointCount(), n);
    std::cout << "[ reel ] left-feed: 0.3 m paid into its span and back in " << walk.frames
              << " frames (" << walk.clampedFrames << " clamped), largest move "
              << walk.largestMoveOverPaid << " x the length paid, reel Newton steps "
              << walk.reelIterations << " (" << walk.mostReelIterations
              << " in the costliest frame)\n";
}

TEST(HoseRuntimeReel, JointsReeledInWaitAtTheOutletAndTheFarEndsJointStaysOnTheFarEnd)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int hose = runtime.findHose("valve-tail");
    ASSERT_GE(hose, 0);
    const int n = runtime.hose(hose).pointCount();
    const int outlet = runtime.attachment(hose, 0).lastPoint;
    std::vector<double> arcs(1, 0.0); // the exported rest arc length of each point
    for (int s = 0; s + 1 < n; ++s)
        arcs.push_back(arcs.back() + runtime.hose(hose).restLength(s));
    double paidIn = 0.0;
    for (int frame = 0; frame < 60 && paidIn < 0.1 - 1e-12; ++frame) {
        const ReelResult r = runtime.reel(
            hose, HoseEnd::Start, -std::min(kReelSpeed * kReelFrame, 0.1 - paidIn), 0.0, 1.0);
        ASSERT_NE(r.status, Status::InvalidInput) << r.message;
        paidIn -= r.paid;
        runtime.update();
        const Hose& h = runtime.hose(hose);
        const std::vector<rig::JointPose>& poses = runtime.jointPoses(hose);
        ASSERT_EQ(poses.size(), static_cast<size_t>(n));
        EXPECT_LT((poses.back().world.translation - h.point(h.pointCount() - 1)).norm(), 1e-9);
        EXPECT_LT((poses.front().world.translation - h.point(0)).norm(), 1e-9);
        // Joint j beyond the outlet is reeled in once its exported distance from the outlet is
        // less than what was reeled in: it waits at the outlet.
        for (int j = outlet + 1; j < n; ++j)
            if (arcs[static_cast<size_t>(j)] - arcs[static_cast<size_t>(outlet)] < paidIn - 1e-9) {
                EXPECT_LT(
                    (poses[static_cast<size_t>(j)].world.translation - h.point(outlet)).norm(),
                    1e-9)
                    << "frame " << frame << ", joint " << j;
            }
    }
    EXPECT_NEAR(paidIn, 0.1, 1e-12);
    int atOutlet = 0;
    for (const rig::JointPose& pose : runtime.jointPoses(hose))
        atOutlet += (pose.world.translation - runtime.hose(hose).point(outlet)).norm() < 1e-9;
    EXPECT_GE(atOutlet, 2);
    std::cout << "[ reel ] valve-tail: 0.1 m reeled in, " << atOutlet
              << " joints at the outlet, the far end's joint on the far end\n";
}

TEST(HoseRuntimeReel, ThroughAClipTheDrumSideStaysAndTheLengthAppearsBeyondTheClip)
{
    // The motion rig's cable through two clips: the clip nearer its first point is the reel's
    // outlet, the drum towards the first point (the hose up to the clip stands for the drum).
    TemporaryFolder folder;
    const fs::path output = folder / "motion.glb";
    exportProjectFile(samplesDir() / "motion-rig.ctproj", output, roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(output);
    const int cable = runtime.findHose("carriage-cable");
    ASSERT_GE(cable, 0);
    ASSERT_EQ(runtime.description(cable).clips.size(), 2u);
    const int outlet = runtime.clip(cable, 0).slide > runtime.clip(cable, 1).slide ? 0 : 1;
    const int other = 1 - outlet;
    const int drumPoints = runtime.clip(cable, outlet).last + 1;
    const std::vector<Vec3> before = runtime.hose(cable).points();
    const double total = runtime.hose(cable).restLengthTotal();
    const double outletSlide = runtime.clip(cable, outlet).slide;
    const double otherSlide = runtime.clip(cable, other).slide;
    const size_t joints = runtime.jointPoses(cable).size();
    double paid = 0.0;
    for (int frame = 0; frame < 40 && paid < 0.05 - 1e-12; ++frame) {
        const ReelResult r =
            runtime.reelThroughClip(cable, outlet, HoseEnd::Start,
                                    std::min(kReelSpeed * kReelFrame, 0.05 - paid), 0.0, 10.0);
        ASSERT_NE(r.status, Status::InvalidInput) << r.message;
        paid += r.paid;
        runtime.update();
        const Hose& h = runtime.hose(cable);
        expectInBand(h, "through the clip, frame " + std::to_string(frame));
        EXPECT_EQ(h.measureViolation().status, Status::Ok) << frame;
        for (int i = 0; i < drumPoints; ++i) // the drum's side keeps its shape
            EXPECT_LT((h.point(i) - before[static_cast<size_t>(i)]).norm(), 1e-12) << i;
        EXPECT_EQ(runtime.jointPoses(cable).size(), joints);
        EXPECT_LT((runtime.jointPoses(cable).back().world.translation - h.point(h.pointCount() - 1))
                      .norm(),
                  1e-9); // the far end's joint stays on the far end
        EXPECT_NEAR(runtime.clip(cable, outlet).slide, outletSlide, 1e-12);
        EXPECT_NEAR(runtime.clip(cable, other).slide, otherSlide, 1e-12);
        EXPECT_NEAR(h.restLengthTotal(), total + paid, 1e-12);
    }
    EXPECT_NEAR(paid, 0.05, 1e-12);
    EXPECT_GT(runtime.hose(cable).pointCount(), static_cast<int>(before.size()));
    // A clip index out of range is refused; the hose stays as it is.
    const std::vector<Vec3> now = runtime.hose(cable).points();
    const ReelResult refused = runtime.reelThroughClip(cable, 2, HoseEnd::Start, 0.01, 0.0, 10.0);
    EXPECT_EQ(refused.status, Status::InvalidInput);
    EXPECT_NE(refused.message.find("clip 2 is out of range"), std::string::npos) << refused.message;
    EXPECT_EQ(runtime.hose(cable).points(), now);
    std::cout << "[ reel ] carriage-cable: 0.05 m paid out through clip " << outlet << ", "
              << runtime.hose(cable).pointCount() - static_cast<int>(before.size())
              << " points added beyond it, the drum side unchanged\n";
}

TEST(HoseRuntimeReel, BadInputIsRefusedWithAMessageAndChangesNothing)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int tail = runtime.findHose("valve-tail");
    const int loop = runtime.findHose("bracket-loop");
    const int pipe = runtime.findHose("pipe-on-plate");
    ASSERT_GE(tail, 0);
    ASSERT_GE(loop, 0);
    ASSERT_GE(pipe, 0);
    const double inf = std::numeric_limits<double>::infinity();
    const auto unchanged = [&](const std::function<ReelResult()>& call, Status expected,
                               const std::string& fragment) {
        std::vector<std::vector<Vec3>> points;
        std::vector<std::vector<int>> grabbable;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            points.push_back(runtime.hose(h).points());
            grabbable.push_back(runtime.grabbablePoints(h));
        }
        const ReelResult r = call();
        EXPECT_EQ(r.status, expected) << fragment;
        EXPECT_EQ(r.paid, 0.0) << fragment;
        EXPECT_NE(r.message.find(fragment), std::string::npos) << r.message;
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            EXPECT_EQ(runtime.hose(h).points(), points[static_cast<size_t>(h)]) << fragment;
            EXPECT_EQ(runtime.grabbablePoints(h), grabbable[static_cast<size_t>(h)]) << fragment;
        }
    };
    const double total = runtime.hose(loop).restLengthTotal();
    unchanged([&] { return runtime.reel(99, HoseEnd::Start, 0.01, 0, inf); }, Status::InvalidInput,
              "hose 99 is out of range");
    unchanged([&] { return runtime.reel(-1, HoseEnd::Start, 0.01, 0, inf); }, Status::InvalidInput,
              "hose -1 is out of range");
    unchanged([&] { return runtime.reel(pipe, HoseEnd::Start, 0.01, 0, inf); },
              Status::InvalidInput, "static");
    unchanged([&] { return runtime.reel(tail, HoseEnd::End, 0.01, 0, inf); }, Status::InvalidInput,
              "expected an end fixed by an attachment");
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, 0.01, 2.0, 1.0); },
              Status::InvalidInput, "maxLength");
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, std::nan(""), 0, inf); },
              Status::InvalidInput, "reel length");
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, 0.01, -1.0, inf); },
              Status::InvalidInput, "minLength");
    unchanged([&] { return runtime.reelThroughClip(loop, 0, HoseEnd::Start, 0.01, 0, inf); },
              Status::InvalidInput, "clip 0 is out of range");
    // A length already outside [min, max] moves only towards them: asked away, Clamped.
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, 0.01, 0.0, total - 0.05); },
              Status::Clamped, "maximum");
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, -0.01, total + 0.05, inf); },
              Status::Clamped, "minimum");
    // An unplugged end is no reel.
    ASSERT_NE(runtime.detachEnd(loop, 0).status, Status::InvalidInput);
    unchanged([&] { return runtime.reel(loop, HoseEnd::Start, 0.01, 0, inf); },
              Status::InvalidInput, "expected an end fixed by an attachment");
}

TEST(HoseRuntimeReel, AHoseReeledThenHeldAndCutKeepsItsBookkeeping)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = loadRigOptions(folder);
    const int loop = runtime.findHose("bracket-loop");
    ASSERT_GE(loop, 0);
    const std::vector<int> joints = runtime.description(loop).jointNodes;
    const int n = runtime.hose(loop).pointCount();
    // Hold a point beyond the outlet, then pay out: the held point is renumbered and stays held.
    const int held = n / 2;
    ASSERT_NE(runtime.grab(loop, held, runtime.hose(loop).point(held)).status,
              Status::InvalidInput);
    const Vec3 hand = runtime.hose(loop).point(held);
    int added = 0;
    for (int frame = 0; frame < 12; ++frame) {
        const ReelResult r = runtime.reel(loop, HoseEnd::Start, kReelSpeed * kReelFrame, 0.0, 10.0);
        ASSERT_NE(r.status, Status::InvalidInput) << r.message;
        added += r.segmentsAdded - r.segmentsRemoved;
        runtime.update();
        expectInBand(runtime.hose(loop), "paying out, frame " + std::to_string(frame));
    }
    ASSERT_GT(added, 0);
    const Hose& h = runtime.hose(loop);
    EXPECT_EQ(h.pointCount(), n + added);
    EXPECT_EQ(h.heldPoint(), held + added);
    EXPECT_LT((h.point(held + added) - hand).norm(), 1e-9);
    EXPECT_EQ(runtime.attachment(loop, 1).lastPoint, n + added - 1);
    EXPECT_EQ(runtime.attachment(loop, 1).firstPoint, n + added - 2);
    // A grab by a new index reaches the point it names.
    const int moved = held + added - 2;
    const Vec3 target = h.point(moved) + Vec3(0.0, 0.01, 0.0);
    EXPECT_NE(runtime.grab(loop, moved, target).status, Status::InvalidInput);
    runtime.update();
    EXPECT_LT((runtime.hose(loop).point(moved) - target).norm(), 1e-6);
    // Cut after the reel: every joint of the skin posed by exactly one piece.
    const rig::CutResult cut = runtime.cut(loop, (n + added) / 2);
    ASSERT_EQ(cut.status, Status::Ok);
    std::vector<int> posed;
    for (int piece : {loop, cut.newHose}) {
        for (const rig::JointPose& pose : runtime.jointPoses(piece))
            if (pose.node >= 0) posed.push_back(pose.node);
        EXPECT_EQ(runtime.jointPoses(piece).size(), runtime.description(piece).jointNodes.size());
    }
    EXPECT_EQ(posed, joints);
    EXPECT_EQ(runtime.attachment(cut.newHose, 0).lastPoint,
              runtime.hose(cut.newHose).pointCount() - 1);
    runtime.update();
    expectInBand(runtime.hose(loop), "first piece");
    expectInBand(runtime.hose(cut.newHose), "second piece");
}

} // namespace
} // namespace chaintube::exporting::testing
