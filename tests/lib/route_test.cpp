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
