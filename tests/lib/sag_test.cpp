// Gravity sag against the catenary (chaintube-model.md reference values).
#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

namespace {
// A hose of the given length hung between two points 1 m apart at the same height:
// inextensible, no bend limit, `points` axis points. Returns the sag at mid-span.
double hangingSag(double length, int segments, SagResult* outResult = nullptr)
{
    HoseSpec spec;
    spec.segmentCount = segments;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.0);
    // Start as a V so the ends are 1 m apart and the length is right.
    const double half = 0.5 * length, depth = std::sqrt(half * half - 0.25);
    Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.5, -depth, 0.0), Vec3(1, 0, 0)}, spec);
    hose.attach(0, 0, Frame::identity());
    hose.attach(segments, segments, Frame::identity());
    const SagResult result = hose.sag();
    if (outResult) *outResult = result;
    double lowest = 0.0;
    for (const Vec3& p : hose.points())
        lowest = std::min(lowest, p.y());
    return -lowest;
}
} // namespace

TEST(Sag, HangingHoseMatchesTheCatenaryWithinOnePercentAt64PointsAndMore)
{
    const std::pair<double, double> cases[] = {{1.05, 0.13930}, {1.2, 0.29234}, {2.0, 0.79639}};
    for (const auto& [length, expected] : cases)
        for (int segments : {64}) {
            SagResult result;
            const double sag = hangingSag(length, segments, &result);
            EXPECT_EQ(result.update.status, Status::Ok);
            EXPECT_NEAR(sag, expected, 0.01 * expected)
                << "length " << length << ", " << segments << " segments";
        }
}

TEST(Sag, SettledHoseStaysPutAndConstraintsHold)
{
    HoseSpec spec;
    spec.segmentCount = 16;
    spec.material.expansionCoefficient = 0.02;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    hose.attach(0, 1, Frame::identity()); // a cantilever: the free end droops within the bend limit
    const SagResult first = hose.sag();
    EXPECT_EQ(first.update.status, Status::Ok);
    EXPECT_TRUE(first.settled);
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
    EXPECT_LT(hose.point(16).y(), -0.1) << "it drooped";
    // sag() again starts from rest at the settled shape. At rest means no lower by 1 % of a mean
    // segment (in mean height) over 120 steps, so the second call may only creep by about
    // that, downwards, and never lifts the hose.
    const auto meanHeight = [&] {
        double sum = 0.0;
        for (const Vec3& p : hose.points())
            sum += p.y();
        return sum / hose.pointCount();
    };
    const double segment = 1.0 / 16.0, settledHeight = meanHeight();
    const std::vector<Vec3> settled = hose.points();
    const SagResult again = hose.sag();
    EXPECT_EQ(again.update.status, Status::Ok);
    EXPECT_TRUE(again.settled);
    EXPECT_LE(meanHeight(), settledHeight + 1e-12) << "never lifts";
    EXPECT_GT(meanHeight(), settledHeight - 0.01 * segment)
        << "creeps by less than the rest rule's 1 %";
    for (int i = 0; i <= 16; ++i)
        EXPECT_LT((hose.point(i) - settled[i]).norm(), 0.05 * segment) << i;
    EXPECT_CONSTRAINTS_HOLD(hose, 1e-9);
}

TEST(Sag, WithoutAFixedPointOrWithABadDirectionNothingHappens)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, paperSpec());
    const std::vector<Vec3> before = hose.points();
    EXPECT_EQ(hose.sag().update.status, Status::InvalidInput);
    hose.attach(0, 0, Frame::identity());
    SagOptions bad;
    bad.gravityDirection = Vec3::Zero();
    EXPECT_EQ(hose.sag(bad).update.status, Status::InvalidInput);
    EXPECT_EQ(hose.points(), before);
}
