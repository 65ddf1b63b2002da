#include "test_util.h"

#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

TEST(Route, CornersAreRoundedWithTheMinimumBendRadius)
{
    HoseSpec spec;
    spec.segmentLength = 0.01;
    spec.material.expansionCoefficient = 0.1;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    const Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)}, spec);
    // Two legs of 1 m minus the arc's tangent lengths plus a quarter circle.
    EXPECT_NEAR(hose.restLengthTotal(), 2.0 - 2 * 0.1 + 0.5 * std::numbers::pi * 0.1, 2e-4);
    const HoseMetrics m = measure(hose);
    EXPECT_GT(m.smallestBendRadius, 0.1 * (1 - 1e-6));
    EXPECT_LT(m.smallestBendRadius, 0.105);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(Route, ShortLegsLimitTheArcAndTheViolationIsReported)
{
    HoseSpec spec;
    spec.segmentLength = 0.005;
    spec.material.bendLimit = BendLimit::minBendRadius(0.5);
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, 0.1, 0)}, spec);
    EXPECT_GT(violation(hose).angle, 0.0) << "a 0.5 m radius does not fit 0.1 m legs";
    const UpdateResult settled = hose.settle();
    EXPECT_TRUE(allFinite(hose));
    if (settled.status == Status::Ok) EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(Route, ResampleGivesEqualArcLengthSpacing)
{
    const std::vector<Vec3> line = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 2, 0)};
    const std::vector<Vec3> points = resampleByArcLength(line, 6);
    ASSERT_EQ(points.size(), 7u);
    EXPECT_EQ(points.front(), line.front());
    EXPECT_EQ(points.back(), line.back());
    EXPECT_NEAR((points[1] - points[0]).norm(), 0.5, 1e-15);
    EXPECT_NEAR(points[2].x(), 1.0, 1e-15);
    EXPECT_NEAR(points[4].y(), 1.0, 1e-15);
}

TEST(Route, ACornerNextToAGentleOneTakesMoreThanHalfOfTheirSharedLeg)
{
    HoseSpec spec;
    spec.segmentLength = 0.005;
    spec.material.expansionCoefficient = 0.05;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    // A right angle, then 0.15 m on a turn of about 3°: the right angle needs 0.1 m of the
    // shared leg, more than half of it; the gentle turn needs 2.6 mm.
    const std::vector<Vec3> route = {Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(0.5, 0.15, 0),
                                     Vec3(0.525, 0.65, 0)};
    EXPECT_TRUE(tightCorners(route, 0.1).empty());
    const Hose hose = Hose::alongRoute(route, spec);
    const HoseMetrics m = measure(hose);
    EXPECT_GT(m.smallestBendRadius, 0.1 * (1 - 1e-6));
    EXPECT_EQ(violation(hose).angle, 0.0);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(Route, AnEndLegBelongsWholeToItsCorner)
{
    HoseSpec spec;
    spec.segmentLength = 0.004;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    // A first leg of 0.12 m before a right angle: the arc takes 0.1 m of it.
    const std::vector<Vec3> route = {Vec3(0, 0, 0), Vec3(0.12, 0, 0), Vec3(0.12, 1, 0)};
    EXPECT_TRUE(tightCorners(route, 0.1).empty());
    const Hose hose = Hose::alongRoute(route, spec);
    EXPECT_GT(measure(hose).smallestBendRadius, 0.1 * (1 - 1e-6));
    EXPECT_EQ(violation(hose).angle, 0.0);
}

TEST(Route, CornersTooTightForTheirLegsAreNamedWithTheRadiusTheyGet)
{
    // Two right angles 0.1 m apart, each wanting 0.1 m of the leg between them: they share it
    // half and half, and both get a 50 mm arc. A duplicate point keeps the indices as given.
    const std::vector<Vec3> route = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0), Vec3(1, 0.1, 0),
                                     Vec3(2, 0.1, 0)};
    const std::vector<TightCorner> tight = tightCorners(route, 0.1);
    ASSERT_EQ(tight.size(), 2u);
    EXPECT_EQ(tight[0].routePoint, 1);
    EXPECT_EQ(tight[1].routePoint, 3);
    for (const TightCorner& corner : tight) {
        EXPECT_NEAR(corner.reachedRadius, 0.05, 1e-12);
        EXPECT_NEAR(corner.turn, 0.5 * std::numbers::pi, 1e-12);
    }
    EXPECT_TRUE(tightCorners(route, 0.05 * (1 - 1e-6)).empty());
    // An exact reversal cannot be rounded at all.
    const auto reversal = tightCorners({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0, 0)}, 0.1);
    ASSERT_EQ(reversal.size(), 1u);
    EXPECT_EQ(reversal[0].reachedRadius, 0.0);
}
