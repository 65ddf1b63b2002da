#include "test_util.h"

#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

TEST(Resolution, ChosenResolutionMeetsTheToleranceAndIsTheCoarsestThatDoes)
{
    for (double tolerance : {1e-4, 1e-3, 5e-3}) {
        const Resolution r = resolutionFor(tolerance, BendLimit::minBendRadius(0.1), 0.01);
        EXPECT_LE(r.centrelineError, tolerance * (1 + 1e-12));
        EXPECT_LE(r.ringError, tolerance);
        // One side fewer would miss the tolerance (unless at the minimum of 3).
        if (r.ringSides > 3) {
            EXPECT_GT(0.01 * (1 - std::cos(std::numbers::pi / (r.ringSides - 1))), tolerance);
        }
        // The sagitta bound is tight: a 1 % longer segment exceeds the tolerance.
        const double longer = 1.01 * r.segmentLength;
        EXPECT_GT(0.1 - std::sqrt(0.01 - 0.25 * longer * longer), tolerance);
    }
}

TEST(Resolution, AnArcSampledAtTheChosenSegmentLengthStaysWithinTolerance)
{
    const double radius = 0.2, tolerance = 1e-3;
    const Resolution r = resolutionFor(tolerance, BendLimit::minBendRadius(radius), 0.01);
    HoseSpec spec;
    spec.segmentLength = r.segmentLength;
    spec.material.bendLimit = BendLimit::minBendRadius(radius);
    spec.material.expansionCoefficient = 0.0;
    // Lay a half circle of radius R as a route of many points and compare with the circle.
    std::vector<Vec3> route;
    for (int k = 0; k <= 400; ++k)
        route.emplace_back(radius * std::sin(std::numbers::pi * k / 400),
                           radius * (1 - std::cos(std::numbers::pi * k / 400)), 0);
    const Hose hose = Hose::alongRoute(route, spec);
    double worst = 0.0;
    for (int s = 0; s + 1 < hose.pointCount(); ++s) {
        const Vec3 middle = 0.5 * (hose.point(s) + hose.point(s + 1));
        worst = std::max(worst, std::abs((middle - Vec3(0, radius, 0)).norm() - radius));
    }
    EXPECT_LE(worst, tolerance * 1.05);
    EXPECT_GT(worst, tolerance * 0.5) << "not needlessly fine";
}

TEST(Resolution, RefusesNonPositiveTolerance)
{
    EXPECT_THROW(resolutionFor(0.0, BendLimit::minBendRadius(0.1), 0.01), InvalidArgument);
    EXPECT_THROW(resolutionFor(1e-3, BendLimit::minBendRadius(0.1), -1), InvalidArgument);
    // No bend limit: the hose's own radius bounds the bend.
    EXPECT_GT(resolutionFor(1e-3, BendLimit::minBendRadius(0.0), 0.01).segmentLength, 0.0);
}
