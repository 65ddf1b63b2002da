#include "test_util.h"

#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

TEST(Metrics, StraightRelaxedHoseHasNoProblems)
{
    const Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec());
    const HoseMetrics m = measure(hose);
    EXPECT_FALSE(m.hasProblems());
    EXPECT_DOUBLE_EQ(m.maxStretch, 1.0);
    EXPECT_GT(m.smallestBendRadius, 1e300);
}

TEST(Metrics, OverstretchAndBendBelowMinimumAreFoundWhereTheyAre)
{
    HoseSpec spec;
    spec.outerDiameter = 0.01;
    spec.material.expansionCoefficient = 0.1;
    spec.material.bendLimit = BendLimit::minBendRadius(0.5);
    // A shape loaded with rest lengths shorter than its segments (the solver never leaves one).
    const Hose hose = Hose::fromAxis({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0)},
                                     {1.0, 0.5, 1.0}, spec);
    const HoseMetrics m = measure(hose);
    EXPECT_TRUE(m.overstretched());
    EXPECT_EQ(m.lengthViolationSegment, 1);
    EXPECT_NEAR(m.lengthViolation, (1.0 - 0.55) / 0.5, 1e-12);

    spec.material.bendLimit = BendLimit::minBendRadius(1.0);
    const Hose bent = Hose::fromAxis({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)}, spec);
    const HoseMetrics b = measure(bent);
    ASSERT_EQ(b.bendBelowMinimum.size(), 1u);
    EXPECT_EQ(b.bendBelowMinimum[0], 1);
    EXPECT_NEAR(b.smallestBendRadius, 1.0 / (2 * std::sin(std::numbers::pi / 4)), 1e-12);
}

TEST(Metrics, RingSelfIntersectionWhenTheRadiusExceedsTheBendsReach)
{
    // Uniform 60° turns with unit segments: rings cross when r > l / (2 tan 30°) = 0.866.
    for (double radius : {0.8, 0.9}) {
        HoseSpec spec = paperSpec(3, 0.1, 90);
        spec.outerDiameter = 2 * radius;
        const double a = 60 * kDegree;
        const Hose hose = Hose::fromAxis(
            {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1 + std::cos(a), std::sin(a), 0),
             Vec3(1 + std::cos(a) + std::cos(2 * a), std::sin(a) + std::sin(2 * a), 0)},
            spec);
        const HoseMetrics m = measure(hose);
        EXPECT_NEAR(m.worstRingOverlap, radius * 2 * std::tan(a / 2), 1e-9);
        EXPECT_EQ(m.selfIntersectingSegments.empty(), radius < 0.866) << radius;
    }
}
