// The chain projection of lib/src/projection.h: a range whose constraints are its segments'
// lengths alone takes one tridiagonal solve a Newton step instead of the rows of every
// constraint kind; both must give the same projection.
#include "projection.h"
#include "test_util.h"

#include <algorithm>
#include <random>

using namespace chaintube;
using namespace chaintube::test;

namespace {

/// A wave in the xy plane and its segments' lengths.
std::vector<Vec3> wave(int points)
{
    std::vector<Vec3> axis;
    for (int i = 0; i < points; ++i) {
        const double x = double(i) / (points - 1);
        axis.emplace_back(x, 0.1 * std::sin(6.0 * x), 0.02 * std::cos(9.0 * x));
    }
    return axis;
}

struct Projected
{
    detail::ProjectionOutcome outcome;
    std::vector<Vec3> points;
};

/// Projects a hose whose shape is `shape` and whose rest lengths are `rest` (inextensible, no
/// bend limit): its first and last points and `fixed` held. `farContact`: one contact plane 10 m
/// below the hose, a row that never works but that takes the projection through the rows of
/// every constraint kind.
Projected project(const std::vector<Vec3>& shape, const std::vector<double>& rest,
                  const std::vector<int>& fixed, bool farContact)
{
    HoseSpec spec;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.0);
    Hose hose = Hose::fromAxis(shape, rest, spec);
    Projected result;
    {
        detail::ChainProjection projection(hose);
        projection.setRange(0, hose.pointCount() - 1);
        projection.useMassesFromRestLengths(-1);
        std::vector<double>& w = projection.inverseMass();
        w.front() = w.back() = 0.0;
        for (int i : fixed)
            w[static_cast<size_t>(i)] = 0.0;
        if (farContact)
            projection.setContact(hose.pointCount() / 2, Vec3::UnitY(), Vec3(0.0, -10.0, 0.0), 0.0);
        result.outcome = projection.run(16, 1e-12);
    }
    result.points = hose.points();
    return result;
}

} // namespace

TEST(ChainProjection, LengthsAloneProjectAsTheRowsOfEveryConstraintKindDo)
{
    std::mt19937_64 rng(20261128);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int points : {3, 17, 101}) {
        const std::vector<Vec3> axis = wave(points);
        std::vector<double> rest;
        for (int s = 0; s + 1 < points; ++s)
            rest.push_back(
                (axis[static_cast<size_t>(s) + 1] - axis[static_cast<size_t>(s)]).norm());
        const double meanRest = rest.front();
        // No other point fixed; two neighbours fixed (the segment between them has no row, so
        // the system falls in two); a single point fixed.
        std::vector<std::vector<int>> fixedSets = {{}};
        if (points > 3) {
            fixedSets.push_back({points / 2});
            fixedSets.push_back({points / 3, points / 3 + 1});
        }
        for (const std::vector<int>& fixed : fixedSets) {
            for (int trial = 0; trial < 4; ++trial) {
                std::vector<Vec3> shape = axis;
                for (size_t i = 1; i + 1 < shape.size(); ++i) {
                    if (std::find(fixed.begin(), fixed.end(), int(i)) != fixed.end()) continue;
                    shape[i] += 0.1 * meanRest * Vec3(u(rng), u(rng) - 0.5, u(rng));
                }
                const Projected lengths = project(shape, rest, fixed, false);
                const Projected rows = project(shape, rest, fixed, true);
                SCOPED_TRACE(::testing::Message()
                             << points << " points, " << fixed.size() << " fixed, trial " << trial);
                EXPECT_TRUE(lengths.outcome.converged);
                EXPECT_TRUE(rows.outcome.converged);
                EXPECT_EQ(lengths.outcome.iterations, rows.outcome.iterations);
                EXPECT_GT(lengths.outcome.iterations, 0);
                double gap = 0.0;
                for (size_t i = 0; i < shape.size(); ++i) {
                    ASSERT_TRUE(lengths.points[i].allFinite());
                    gap = std::max(gap, (lengths.points[i] - rows.points[i]).norm());
                }
                EXPECT_LE(gap, 1e-12 * meanRest);
                for (int i : fixed) // where they were, to the rounding of the hose's origin
                    EXPECT_LE(
                        (lengths.points[static_cast<size_t>(i)] - shape[static_cast<size_t>(i)])
                            .norm(),
                        1e-15);
                for (size_t s = 0; s < rest.size(); ++s)
                    EXPECT_NEAR((lengths.points[s + 1] - lengths.points[s]).norm(), rest[s],
                                1e-9 * rest[s])
                        << "segment " << s;
            }
        }
    }
}
