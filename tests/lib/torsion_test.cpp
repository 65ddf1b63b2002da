// Torsion as an optional degree of freedom (HoseSpec::torsion): rolling an attachment about
// the hose axis rolls the rings; between two attachments the twist is spread evenly.
#include "test_util.h"

#include <cmath>

using namespace chaintube;
using namespace chaintube::test;

namespace {
constexpr int kSegments = 20;

Hose straightHose(bool torsion, double twistLimit = 0.5)
{
    HoseSpec spec = paperSpec(kSegments);
    spec.torsion.enabled = torsion;
    spec.torsion.twistLimit = twistLimit;
    spec.profile = Profile::rectangle(0.02, 0.01);
    return Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
}

Frame rollAboutX(double angle)
{
    Frame f = Frame::identity();
    f.rotation = Quat(Eigen::AngleAxisd(angle, Vec3::UnitX()));
    return f;
}

// Signed angle about each ring's tangent from `reference` frames' alignment to `frames`'.
std::vector<double> rollsBetween(const std::vector<RingFrame>& reference,
                                 const std::vector<RingFrame>& frames)
{
    std::vector<double> rolls;
    for (size_t i = 0; i < frames.size(); ++i) {
        const Vec3& t = frames[i].tangent;
        rolls.push_back(std::atan2(t.dot(reference[i].alignment.cross(frames[i].alignment)),
                                   reference[i].alignment.dot(frames[i].alignment)));
    }
    return rolls;
}
} // namespace

TEST(Torsion, OffByDefaultRollingAnAttachmentChangesNoRing)
{
    Hose hose = straightHose(false);
    const int id = hose.attach(kSegments - 1, kSegments, Frame::identity());
    HoseSurface surface(hose);
    const std::vector<RingFrame> before = surface.frames();
    ASSERT_EQ(hose.moveAttachment(id, rollAboutX(1.0)).status, Status::Ok);
    surface.update(hose);
    for (double r : rollsBetween(before, surface.frames()))
        EXPECT_NEAR(r, 0.0, 1e-12);
    EXPECT_EQ(surface.maxTwistPerJoint(), 0.0);
}

TEST(Torsion, OneAttachmentRollsTheWholeHoseRigidly)
{
    Hose hose = straightHose(true);
    const int id = hose.attach(0, 1, Frame::identity());
    HoseSurface surface(hose);
    const std::vector<RingFrame> before = surface.frames();
    ASSERT_EQ(hose.moveAttachment(id, rollAboutX(0.7)).status, Status::Ok);
    surface.update(hose);
    for (double r : rollsBetween(before, surface.frames()))
        EXPECT_NEAR(r, 0.7, 1e-9);
    EXPECT_NEAR(surface.maxTwistPerJoint(), 0.0, 1e-12) << "a free end does not twist";
    // The vertices roll with the rings: the rectangle's first corner sits on the rolled axes.
    const std::span<const float> p = surface.positions();
    const Vec2 q = hose.profile().points()[0];
    const RingFrame& ring = surface.frames()[0];
    const Vec3 expected = ring.center + q.x() * ring.alignment + q.y() * ring.binormal;
    const Vec3 unrolled =
        before[0].center + q.x() * before[0].alignment + q.y() * before[0].binormal;
    EXPECT_LT((Vec3(p[0], p[1], p[2]) - expected).norm(), 1e-6);
    EXPECT_GT((expected - unrolled).norm(), 0.003) << "the corner moved";
}

TEST(Torsion, TwoAttachmentsSpreadTheTwistEvenlyAndReportTheLimit)
{
    for (double limit : {0.5, 0.05}) {
        Hose hose = straightHose(true, limit);
        hose.attach(0, 1, Frame::identity());
        const int end = hose.attach(kSegments - 1, kSegments, Frame::identity());
        HoseSurface surface(hose);
        const std::vector<RingFrame> before = surface.frames();
        const double angle = 1.2;
        ASSERT_EQ(hose.moveAttachment(end, rollAboutX(angle)).status, Status::Ok);
        surface.update(hose);
        const std::vector<double> rolls = rollsBetween(before, surface.frames());
        const int joints = (kSegments - 1) - 1;
        for (int i = 0; i <= kSegments; ++i) {
            const double expected = i <= 1               ? 0.0
                                    : i >= kSegments - 1 ? angle
                                                         : angle * (i - 1) / joints;
            EXPECT_NEAR(rolls[static_cast<size_t>(i)], expected, 1e-9) << "ring " << i;
        }
        EXPECT_NEAR(surface.maxTwistPerJoint(), angle / joints, 1e-12);
        EXPECT_NEAR(surface.twistViolation(), std::max(0.0, angle / joints - limit), 1e-12)
            << "limit " << limit;
    }
}

TEST(Torsion, TurnsAccumulateBeyondHalfATurn)
{
    Hose hose = straightHose(true);
    hose.attach(0, 1, Frame::identity());
    const int end = hose.attach(kSegments - 1, kSegments, Frame::identity());
    HoseSurface surface(hose);
    double angle = 0.0;
    for (int step = 0; step < 20; ++step) { // two full turns in steps of 0.2 π
        angle += 0.2 * 3.14159265358979323846;
        static_cast<void>(hose.moveAttachment(end, rollAboutX(angle)));
        surface.update(hose);
    }
    EXPECT_NEAR(surface.maxTwistPerJoint(), angle / (kSegments - 2), 1e-9) << "two turns, not zero";
    EXPECT_GT(surface.twistViolation(), 0.0) << "0.70 rad per joint is above the 0.5 limit";
}

TEST(Torsion, BendingTheAttachmentAlongWithTheHoseAddsNoTwist)
{
    Hose hose = straightHose(true);
    const int id = hose.attach(0, 1, Frame::identity());
    HoseSurface surface(hose);
    // Swing the clamp about Z (a bend, not a roll): the torsion-free frames follow; no twist.
    for (int step = 1; step <= 10; ++step) {
        Frame f = Frame::identity();
        f.rotation = Quat(Eigen::AngleAxisd(0.05 * step, Vec3::UnitZ()));
        static_cast<void>(hose.moveAttachment(id, f));
        surface.update(hose);
        EXPECT_NEAR(surface.maxTwistPerJoint(), 0.0, 1e-12);
        for (const RingFrame& ring : surface.frames()) {
            ASSERT_TRUE(ring.alignment.allFinite());
            EXPECT_NEAR(ring.alignment.norm(), 1.0, 1e-9);
            EXPECT_NEAR(ring.alignment.dot(ring.tangent), 0.0, 1e-9);
        }
    }
    const TwistSeed& seed = surface.twistSeed();
    ASSERT_EQ(seed.rolls.size(), 1u);
    EXPECT_NEAR(seed.rolls[0].roll, 0.0, 1e-6)
        << "a swing about an axis across the hose is not a roll";
}

TEST(Torsion, ASlidingClipHoldsTheRollASlidingTurningClipLetsItThrough)
{
    // Both ends fixed, a clip in the middle (segment 10, points 10 and 11), the far end rolled by
    // 1.2 rad. A sliding clip holds the hose's roll (its frame does not turn: roll 0), so the
    // twist is spread between the clip and the far end; a sliding-turning clip sets no roll, so
    // it is spread from the near end to the far end through the clip.
    const double angle = 1.2;
    for (const Hold hold : {Hold::Sliding, Hold::SlidingTurning}) {
        SCOPED_TRACE(toString(hold));
        Hose hose = straightHose(true);
        hose.attach(0, 1, Frame::identity());
        const int end = hose.attach(kSegments - 1, kSegments, Frame::identity());
        const int clip = hose.addClip(0.525, Frame::identity(), {hold});
        ASSERT_EQ(hose.attachments().back().id, clip);
        ASSERT_EQ(hose.attachments().back().first, 10);
        HoseSurface surface(hose);
        const std::vector<RingFrame> before = surface.frames();
        const UpdateResult moved = hose.moveAttachment(end, rollAboutX(angle));
        ASSERT_EQ(moved.status, Status::Ok);
        ASSERT_LE(hose.attachmentGap(clip), 1e-12) << "a roll about the axis slides nothing";
        surface.update(hose);
        const std::vector<double> rolls = rollsBetween(before, surface.frames());
        const bool holds = hold == Hold::Sliding;
        const int from = holds ? 11 : 1; // the last ring whose roll is held at 0
        const int joints = (kSegments - 1) - from;
        for (int i = 0; i <= kSegments; ++i) {
            const double expected = i <= from            ? 0.0
                                    : i >= kSegments - 1 ? angle
                                                         : angle * (i - from) / joints;
            EXPECT_NEAR(rolls[static_cast<size_t>(i)], expected, 1e-9) << "ring " << i;
        }
        // The clip's own rings: held at 0, or rolled by their share of the twist (0.6 and
        // 0.67 rad), far from 0 either way.
        if (holds) {
            EXPECT_NEAR(rolls[10], 0.0, 1e-9);
            EXPECT_NEAR(rolls[11], 0.0, 1e-9);
        } else {
            EXPECT_GT(rolls[10], 0.5);
            EXPECT_GT(rolls[11], 0.5);
        }
        EXPECT_NEAR(surface.maxTwistPerJoint(), angle / joints, 1e-12);
        EXPECT_EQ(surface.twistSeed().rolls.size(), holds ? 3u : 2u)
            << "a sliding-turning clip has no roll of its own";
    }
}
