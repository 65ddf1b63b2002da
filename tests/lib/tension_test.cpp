// The hose's pull on its attachments: slack, drawn taut, beyond reach, released.
#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

namespace {

/// A 1 m hose laid as an arc between ends 0.8 m apart along x, one segment fixed at each end.
struct Span
{
    Hose hose;
    int near = 0, far = 0;
};

Span slackSpan(double expansion)
{
    HoseSpec spec;
    spec.segmentCount = 40;
    spec.material.expansionCoefficient = expansion;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    const double half = arcHalfAngle(0.8);
    const double radius = 0.5 / half;
    std::vector<Vec3> axis;
    for (int i = 0; i <= spec.segmentCount; ++i) {
        const double a = -half + 2.0 * half * i / spec.segmentCount;
        axis.push_back(
            Vec3(0.4 + radius * std::sin(a), radius * (std::cos(a) - std::cos(half)), 0));
    }
    Span span{Hose::fromAxis(axis, spec)};
    const int n = span.hose.pointCount() - 1;
    span.near = span.hose.attach(0, 1, Frame::identity());
    span.far = span.hose.attach(n - 1, n, Frame::identity());
    return span;
}

} // namespace

TEST(AttachmentPull, ASlackHosePullsNothing)
{
    const Span span = slackSpan(0.0);
    for (const int id : {span.near, span.far}) {
        const AttachmentPull pull = attachmentPull(span.hose, id);
        EXPECT_EQ(pull.tautness, 0.0);
        EXPECT_EQ(pull.strain, 0.0);
        EXPECT_EQ(pull.direction, Vec3::Zero());
        EXPECT_EQ(pull.force(1e4), Vec3::Zero());
    }
}

TEST(AttachmentPull, AnEndPulledBeyondReachPullsBothPartsTowardsEachOtherAndReleasedPullsNothing)
{
    Span span = slackSpan(0.0);
    const double rest = span.hose.restLengthTotal();
    // Out along +x in 1 cm steps to 0.3 m beyond the start: drawn straight, then beyond reach.
    double lastTautness = 0.0;
    for (int k = 1; k <= 30; ++k) {
        static_cast<void>(span.hose.moveAttachment(span.far, translated(Vec3(0.01 * k, 0, 0))));
        const AttachmentPull pull = attachmentPull(span.hose, span.near);
        EXPECT_GE(pull.tautness, lastTautness - 1e-12) << "step " << k << ": never slackens";
        lastTautness = pull.tautness;
    }
    const double gap = span.hose.attachmentGap(span.far);
    ASSERT_GT(gap, 0.05) << "0.3 m beyond a 1 m hose's 0.8 m chord is out of reach";
    const AttachmentPull near = attachmentPull(span.hose, span.near);
    const AttachmentPull far = attachmentPull(span.hose, span.far);
    EXPECT_EQ(near.tautness, 1.0);
    EXPECT_EQ(far.tautness, 1.0);
    // The strain it would take to reach, and the pull along the hose, towards the other part.
    const double restFree = rest - span.hose.restLength(0) - span.hose.restLength(39);
    EXPECT_NEAR(near.strain, gap / restFree, 1e-12);
    // Along the hose where it leaves each part (the first free segment), towards the other.
    const int n = span.hose.pointCount() - 1;
    EXPECT_TRUE(near.direction.isApprox((span.hose.point(2) - span.hose.point(1)).normalized()));
    EXPECT_TRUE(
        far.direction.isApprox((span.hose.point(n - 2) - span.hose.point(n - 1)).normalized()));
    EXPECT_GT(near.direction.x(), 0.5);
    EXPECT_LT(far.direction.x(), -0.5);
    const double stiffness = 2e4; // N per unit strain
    EXPECT_NEAR(near.force(stiffness).norm(), stiffness * gap / restFree, 1e-9 * stiffness);
    EXPECT_NEAR(near.force(stiffness).normalized().dot(near.direction), 1.0, 1e-12);
    // Equal in size; each along its own first free segment, which the fixed end segments tilt
    // out of the chord.
    EXPECT_NEAR(near.force(stiffness).norm(), far.force(stiffness).norm(), 1e-9 * stiffness);
    EXPECT_EQ(near.force(-1.0), Vec3::Zero());
    // Released: back to where it was, the hose is slack again and pulls nothing.
    for (int k = 29; k >= 0; --k)
        static_cast<void>(span.hose.moveAttachment(span.far, translated(Vec3(0.01 * k, 0, 0))));
    EXPECT_LE(span.hose.attachmentGap(span.far), 1e-9);
    const AttachmentPull released = attachmentPull(span.hose, span.near);
    EXPECT_EQ(released.tautness, 0.0);
    EXPECT_EQ(released.force(stiffness), Vec3::Zero());
}

TEST(AttachmentPull, AStretchableHoseDrawnBeyondItsLengthPullsInProportionToItsStretch)
{
    Span span = slackSpan(0.1);
    const double rest = span.hose.restLengthTotal();
    const double restFree = rest - span.hose.restLength(0) - span.hose.restLength(39);
    // Ends 1.02 m + the fixed segments apart: within the 10 % band, stretched.
    const double chordWanted = restFree * 1.03;
    const double move = chordWanted + span.hose.restLength(0) + span.hose.restLength(39) - 0.8;
    for (int k = 1; k <= 40; ++k)
        static_cast<void>(
            span.hose.moveAttachment(span.far, translated(Vec3(move * k / 40.0, 0, 0))));
    ASSERT_LE(span.hose.attachmentGap(span.far), 1e-9) << "within the stretch band: met";
    const AttachmentPull pull = attachmentPull(span.hose, span.near);
    const double chord = (span.hose.point(span.hose.pointCount() - 2) - span.hose.point(1)).norm();
    EXPECT_GT(chord, restFree);
    EXPECT_EQ(pull.tautness, 1.0);
    EXPECT_NEAR(pull.strain, (chord - restFree) / restFree, 1e-12);
    EXPECT_NEAR(pull.force(1e4).norm(), 1e4 * (chord - restFree) / restFree, 1e-6);
}

TEST(AttachmentPull, AFreeSideAndAnUnknownIdPullNothingAndAHeldPointPullsLikeAPin)
{
    HoseSpec spec;
    spec.segmentCount = 20;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    const int end = hose.attach(0, 1, Frame::identity());
    EXPECT_EQ(attachmentPull(hose, end).tautness, 0.0) << "the other end is free";
    EXPECT_EQ(attachmentPull(hose, 12345).direction, Vec3::Zero());
    // Held at its middle and pulled straight on along it: the span to the hand is taut.
    static_cast<void>(hose.grab(10, Vec3(0.6, 0, 0)));
    ASSERT_EQ(hose.heldPoint(), 10);
    const AttachmentPull held = attachmentPull(hose, end);
    EXPECT_EQ(held.tautness, 1.0);
    EXPECT_GT(held.direction.x(), 0.99);
    EXPECT_EQ(held.strain, 0.0) << "an inextensible hose drawn straight is not stretched";
    EXPECT_EQ(held.force(1e4), Vec3::Zero());
}

TEST(AttachmentPull, AClipBetweenTwoTautSidesIsPulledBothWays)
{
    HoseSpec spec;
    spec.segmentCount = 40;
    spec.material.bendLimit = BendLimit::minBendRadius(0.05);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    const int a = hose.attach(0, 1, Frame::identity());
    const int b = hose.attach(39, 40, Frame::identity());
    const int middle = hose.attach(20, 20, Frame::identity());
    static_cast<void>(a);
    static_cast<void>(b);
    const AttachmentPull pull = attachmentPull(hose, middle);
    EXPECT_EQ(pull.tautness, 1.0);
    EXPECT_LT(pull.direction.norm(), 1e-9) << "equal and opposite: no net direction";
    EXPECT_LT(pull.force(1e4).norm(), 1e-9);
}
