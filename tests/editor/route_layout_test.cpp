// Laying out a hose by clicks, without Qt: where a clicked route point goes (out of the
// clicked surface along its normal, on the side clicked from) and the size of a new hose
// (its diameter from the scene's size, the bend radius and axis resolution from the diameter).
#include "chaintube/editor/route_layout.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace chaintube::editor {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Box boxOfSize(const Vec3& corner, const Vec3& size)
{
    Box box;
    box.extend(corner);
    box.extend(corner + size);
    return box;
}

Vec3 randomUnit(std::mt19937& random)
{
    std::normal_distribution<double> normal;
    Vec3 v;
    do
        v = Vec3(normal(random), normal(random), normal(random));
    while (v.norm() < 1e-3);
    return v.normalized();
}

TEST(OffsetFromSurface, GoesOutAlongTheNormalByTheDistanceOnTheSideClickedFrom)
{
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-5.0, 5.0);
    for (double scale : {1e-6, 1e-3, 1.0, 1e3}) {
        for (int trial = 0; trial < 200; ++trial) {
            const Vec3 point =
                scale * Vec3(coordinate(random), coordinate(random), coordinate(random));
            const Vec3 normal = randomUnit(random);
            Vec3 view = randomUnit(random);
            if (std::abs(view.dot(normal)) < 1e-3) continue;
            const double distance = 0.0125 * scale;
            // Either orientation of the normal and any length: the same point, on the side
            // the ray came from.
            for (const Vec3& given : {Vec3(normal), Vec3(-normal), Vec3(3.5 * normal)}) {
                const SurfaceOffset out = offsetFromSurface(point, given, 2.0 * view, distance);
                ASSERT_TRUE(out.alongSurfaceNormal);
                EXPECT_NEAR(out.direction.norm(), 1.0, 1e-12);
                EXPECT_NEAR(std::abs(out.direction.dot(normal)), 1.0, 1e-12);
                EXPECT_LT(out.direction.dot(view), 0.0) << "towards the camera";
                EXPECT_NEAR((out.position - point).norm(), distance, 1e-12 * scale * 10);
                EXPECT_NEAR((out.position - point).dot(out.direction), distance,
                            1e-12 * scale * 10);
            }
        }
    }
}

TEST(OffsetFromSurface, ABackFaceHitGoesOutOnTheCameraSide)
{
    // Looking down (−Y) at a floor whose triangle is wound to face down (a back face).
    const SurfaceOffset out =
        offsetFromSurface(Vec3(1, 0, 2), Vec3(0, -1, 0), Vec3(0, -1, 0), 0.015);
    EXPECT_TRUE(out.alongSurfaceNormal);
    EXPECT_TRUE(out.direction.isApprox(Vec3(0, 1, 0)));
    EXPECT_TRUE(out.position.isApprox(Vec3(1, 0.015, 2)));
    // Looking up at the same floor from below: it goes out below.
    const SurfaceOffset below =
        offsetFromSurface(Vec3(1, 0, 2), Vec3(0, 1, 0), Vec3(0.2, 1, 0), 0.015);
    EXPECT_TRUE(below.position.isApprox(Vec3(1, -0.015, 2)));
}

TEST(OffsetFromSurface, WithoutANormalGoesBackAlongTheRayTowardsTheCamera)
{
    const Vec3 view = Vec3(1, -2, 0.5).normalized();
    for (const Vec3& normal : {Vec3(Vec3::Zero()), Vec3(kNaN, 0, 1), Vec3(kInf, 0, 0)}) {
        const SurfaceOffset out = offsetFromSurface(Vec3(0, 1, 0), normal, 4.0 * view, 0.01);
        EXPECT_FALSE(out.alongSurfaceNormal);
        EXPECT_TRUE(out.direction.isApprox(-view));
        EXPECT_TRUE(out.position.isApprox(Vec3(0, 1, 0) - 0.01 * view));
        EXPECT_TRUE(out.position.allFinite());
    }
}

TEST(OffsetFromSurface, WithoutARayKeepsTheNormalAndWithNeitherGoesUp)
{
    const SurfaceOffset keeps =
        offsetFromSurface(Vec3::Zero(), Vec3(0, 0, -2), Vec3(kNaN, 0, 0), 0.01);
    EXPECT_TRUE(keeps.alongSurfaceNormal);
    EXPECT_TRUE(keeps.position.isApprox(Vec3(0, 0, -0.01)));
    const SurfaceOffset up = offsetFromSurface(Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), 0.01);
    EXPECT_FALSE(up.alongSurfaceNormal);
    EXPECT_TRUE(up.position.isApprox(Vec3(0, 0.01, 0)));
}

TEST(OffsetFromSurface, ANegativeOrNonFiniteDistanceLeavesThePointOnTheSurface)
{
    for (double distance : {-0.01, kNaN, kInf, -kInf, 0.0}) {
        const SurfaceOffset out =
            offsetFromSurface(Vec3(1, 2, 3), Vec3(0, 1, 0), Vec3(0, -1, 0), distance);
        EXPECT_EQ(out.position, Vec3(1, 2, 3)) << distance;
    }
}

TEST(RoutePointDistance, IsTheRadiusPlusTheClearancePlusAMicrometre)
{
    EXPECT_DOUBLE_EQ(routePointDistance(0.005, 0.005), 0.0025 + 0.005 + 1e-6);
    EXPECT_DOUBLE_EQ(routePointDistance(0.02, 0.0), 0.01 + 1e-6);
    for (double clearance : {-0.01, kNaN, kInf})
        EXPECT_DOUBLE_EQ(routePointDistance(0.02, clearance), 0.01 + 1e-6) << clearance;
}

TEST(DefaultHoseDiameter, IsTheSceneDiagonalOverFiftyRoundedToACommonHoseSize)
{
    const std::vector<double> common = {0.002, 0.003, 0.004, 0.005, 0.006, 0.008, 0.010,
                                        0.012, 0.016, 0.020, 0.025, 0.032, 0.040, 0.050};
    // A 0.2 m assembly (0.2 × 0.1 × 0.15 m: diagonal 0.269 m → 5.4 mm) gets a 5 mm hose.
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(boxOfSize(Vec3::Zero(), Vec3(0.2, 0.1, 0.15))), 0.005);
    // The test rig (0.8 × 0.21 × 0.5 m: 0.97 m → 19.3 mm) 20 mm, a 1.6 m scene 32 mm.
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(boxOfSize(Vec3(-0.4, 0, -0.25), Vec3(0.8, 0.21, 0.5))),
                     0.020);
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(boxOfSize(Vec3::Zero(), Vec3(0, 1.6, 0))), 0.032);
    // Every result is a common size, never shrinks as the scene grows, and stays within the
    // clamp; the same box anywhere in the world gives the same size.
    double previous = 0.0;
    for (double diagonal = 1e-4; diagonal < 1e4; diagonal *= 1.07) {
        const Vec3 size = diagonal * Vec3(2, 1, 2) / 3.0;
        const double diameter = defaultHoseDiameter(boxOfSize(Vec3(-3, 7, 1e3), size));
        EXPECT_NE(std::find(common.begin(), common.end(), diameter), common.end()) << diameter;
        EXPECT_GE(diameter, previous);
        EXPECT_GE(diameter, kMinDefaultHoseDiameter);
        EXPECT_LE(diameter, kMaxDefaultHoseDiameter);
        EXPECT_EQ(diameter, defaultHoseDiameter(boxOfSize(Vec3::Zero(), size)));
        // Within the clamp, at most a step of the series (≤ 1.5×) away from diagonal / 50.
        const double wanted = diagonal / 50.0;
        if (wanted > 0.002 && wanted < 0.05) {
            EXPECT_LT(diameter / wanted, 1.5);
            EXPECT_GT(diameter / wanted, 1.0 / 1.5);
        }
        previous = diameter;
    }
    EXPECT_DOUBLE_EQ(previous, kMaxDefaultHoseDiameter);
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(boxOfSize(Vec3::Zero(), Vec3(1e-5, 0, 0))),
                     kMinDefaultHoseDiameter);
}

TEST(DefaultHoseDiameter, AnEmptyOrZeroSizeOrNonFiniteSceneGetsTwentyMillimetres)
{
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(Box()), kFallbackHoseDiameter);
    Box point;
    point.extend(Vec3(1, 2, 3));
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(point), kFallbackHoseDiameter);
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(boxOfSize(Vec3::Zero(), Vec3(kInf, 1, 1))),
                     kFallbackHoseDiameter);
    Box nan;
    nan.min = Vec3(kNaN, 0, 0);
    nan.max = Vec3(1, 1, 1);
    EXPECT_DOUBLE_EQ(defaultHoseDiameter(nan), kFallbackHoseDiameter);
    EXPECT_DOUBLE_EQ(kFallbackHoseDiameter, 0.02);
}

TEST(DefaultMinBendRadius, IsFiveOuterDiameters)
{
    for (double diameter : {0.002, 0.006, 0.02, 0.05})
        EXPECT_DOUBLE_EQ(defaultMinBendRadius(diameter), 5.0 * diameter);
}

TEST(NewHoseSegmentCount, SegmentsOfAtMostThreeCentimetresAndHalfTheBendRadius)
{
    // 20 mm hose (bend radius 100 mm): 3 cm segments, at least 12.
    EXPECT_EQ(newHoseSegmentCount(0.9, 0.02), 30);
    EXPECT_EQ(newHoseSegmentCount(0.2, 0.02), 12);
    // 6 mm hose (bend radius 30 mm): 15 mm segments.
    EXPECT_EQ(newHoseSegmentCount(0.3, 0.006), 20);
    EXPECT_EQ(newHoseSegmentCount(100.0, 0.006), 400);
    for (double length : {0.0, -1.0, kNaN, kInf})
        EXPECT_EQ(newHoseSegmentCount(length, 0.006), 12) << length;
    for (double routeLength = 0.05; routeLength < 20.0; routeLength *= 1.3)
        for (double diameter : {0.002, 0.006, 0.02, 0.05}) {
            const int count = newHoseSegmentCount(routeLength, diameter);
            EXPECT_GE(count, 12);
            EXPECT_LE(count, 400);
            if (count > 12 && count < 400) {
                EXPECT_LE(routeLength / count,
                          1.05 * std::min(0.03, 0.5 * defaultMinBendRadius(diameter)));
            }
        }
}

TEST(NewHoseMaterial, KeepsAPresetWhoseBendRadiusSuitsTheDiameter)
{
    const Material pvc{0.05, BendLimit{BendLimit::Kind::MinBendRadius, 0.10}};
    const NewHoseMaterial kept = newHoseMaterial(pvc, 0.02, 0.03);
    EXPECT_TRUE(kept.presetKept);
    EXPECT_EQ(kept.material, pvc);
    // Every standard preset (80 … 165 mm) suits a 20 mm hose.
    for (double radius : {0.08, 0.10, 0.12, 0.165})
        EXPECT_TRUE(
            newHoseMaterial(Material{0.02, BendLimit{BendLimit::Kind::MinBendRadius, radius}}, 0.02,
                            0.03)
                .presetKept)
            << radius;
}

TEST(NewHoseMaterial, GivesOwnValuesWithFiveDiametersWhenThePresetDoesNotSuit)
{
    const Material pvc{0.05, BendLimit{BendLimit::Kind::MinBendRadius, 0.10}};
    // A 6 mm hose with the 100 mm of a 20 mm PVC hose would be stiff as a rod.
    const NewHoseMaterial small = newHoseMaterial(pvc, 0.006, 0.015);
    EXPECT_FALSE(small.presetKept);
    EXPECT_DOUBLE_EQ(small.material.expansionCoefficient, 0.05) << "the preset's stretch band";
    EXPECT_EQ(small.material.bendLimit.kind, BendLimit::Kind::MinBendRadius);
    EXPECT_DOUBLE_EQ(small.material.bendLimit.value, 0.03);
    EXPECT_NO_THROW(small.material.validate());
    // A 50 mm hose with it would bend tighter than it can.
    EXPECT_DOUBLE_EQ(newHoseMaterial(pvc, 0.05, 0.03).material.bendLimit.value, 0.25);
    // "No limit" (radius 0) suits no diameter.
    EXPECT_FALSE(
        newHoseMaterial(Material{0.05, BendLimit{BendLimit::Kind::MinBendRadius, 0.0}}, 0.02, 0.03)
            .presetKept);
}

TEST(NewHoseMaterial, JudgesADeflectionAnglePresetAtTheNewHosesSegmentLength)
{
    // 0.3 rad per joint: bend radius 0.03 / (2 sin 0.15) = 100 mm with 3 cm segments (suits a
    // 20 mm hose), 25 mm with 7.5 mm segments (does not).
    const Material angle{0.05, BendLimit{BendLimit::Kind::DeflectionAngle, 0.3}};
    EXPECT_TRUE(newHoseMaterial(angle, 0.02, 0.03).presetKept);
    const NewHoseMaterial own = newHoseMaterial(angle, 0.02, 0.0075);
    EXPECT_FALSE(own.presetKept);
    EXPECT_EQ(own.material.bendLimit.kind, BendLimit::Kind::MinBendRadius);
    EXPECT_DOUBLE_EQ(own.material.bendLimit.value, 0.10);
}

/// Nearest point among infinite planes (point, unit normal) within maxDistance.
NearestSurfaceQuery planes(std::vector<std::pair<Vec3, Vec3>> list, int* queries = nullptr)
{
    return [list, queries](const Vec3& at, double maxDistance) {
        if (queries) ++*queries;
        NearestSurface best;
        double bestDistance = maxDistance;
        for (const auto& [onPlane, normal] : list) {
            const double signedDistance = normal.dot(at - onPlane);
            if (std::abs(signedDistance) < bestDistance) {
                bestDistance = std::abs(signedDistance);
                best.found = true;
                best.point = at - signedDistance * normal;
            }
        }
        return best;
    };
}

double nearestPlane(const std::vector<std::pair<Vec3, Vec3>>& list, const Vec3& at)
{
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [onPlane, normal] : list)
        best = std::min(best, std::abs(normal.dot(at - onPlane)));
    return best;
}

TEST(KeepClearOfSurfaces, APointClickedNextToAnInnerCornerGoesOutOfItInOnePush)
{
    // A floor y = 0 and a wall x = 0; clicked on the floor 3 mm from the wall, 10 mm wanted.
    const std::vector<std::pair<Vec3, Vec3>> corner = {{Vec3::Zero(), Vec3::UnitY()},
                                                       {Vec3::Zero(), Vec3::UnitX()}};
    const SurfaceOffset placed =
        offsetFromSurface(Vec3(0.003, 0.0, 0.5), Vec3::UnitY(), Vec3(0, -1, 0), 0.01);
    EXPECT_NEAR(nearestPlane(corner, placed.position), 0.003, 1e-15) << "the wall is too near";
    const ClearedRoutePoint cleared = keepClearOfSurfaces(placed, 0.01, planes(corner));
    EXPECT_TRUE(cleared.clear);
    EXPECT_EQ(cleared.pushes, 1);
    EXPECT_NEAR((cleared.position - Vec3(0.01, 0.01, 0.5)).norm(), 0.0, 1e-15);
    EXPECT_GE(nearestPlane(corner, cleared.position), 0.01 - 1e-15);
    EXPECT_NEAR(cleared.clearance, 0.01, 1e-15);
}

TEST(KeepClearOfSurfaces, AWedgeIsClearedWithinTheBoundedPushes)
{
    // A floor and a face leaning in at 60° over it (a 60° wedge), clicked near its apex.
    const Vec3 leaning(-std::sin(std::numbers::pi / 3), std::cos(std::numbers::pi / 3), 0.0);
    const std::vector<std::pair<Vec3, Vec3>> wedge = {{Vec3::Zero(), Vec3::UnitY()},
                                                      {Vec3::Zero(), -leaning}};
    int queries = 0;
    const SurfaceOffset placed =
        offsetFromSurface(Vec3(0.01, 0.0, 0.0), Vec3::UnitY(), Vec3(0, -1, 0), 0.01);
    const ClearedRoutePoint cleared = keepClearOfSurfaces(placed, 0.01, planes(wedge, &queries));
    EXPECT_TRUE(cleared.clear);
    EXPECT_GE(nearestPlane(wedge, cleared.position), 0.01 * (1 - 1e-9));
    EXPECT_GT(cleared.position.x(), 0.0);
    EXPECT_LE(cleared.pushes, 2) << "both faces solved at once";
    EXPECT_EQ(queries, cleared.pushes + 1);
}

TEST(KeepClearOfSurfaces, AGapTooNarrowForTheHoseIsReportedWithTheBestPointFound)
{
    // A slot 15 mm wide (x = 0 and x = 0.015) over a floor: 10 mm from both walls is impossible.
    const std::vector<std::pair<Vec3, Vec3>> slot = {{Vec3::Zero(), Vec3::UnitY()},
                                                     {Vec3::Zero(), Vec3::UnitX()},
                                                     {Vec3(0.015, 0, 0), -Vec3::UnitX()}};
    int queries = 0;
    const SurfaceOffset placed =
        offsetFromSurface(Vec3(0.004, 0.0, 0.0), Vec3::UnitY(), Vec3(0, -1, 0), 0.01);
    const ClearedRoutePoint cleared = keepClearOfSurfaces(placed, 0.01, planes(slot, &queries));
    EXPECT_FALSE(cleared.clear);
    EXPECT_EQ(cleared.pushes, kMaxClearingPushes);
    EXPECT_EQ(queries, kMaxClearingPushes + 1) << "the work is bounded";
    EXPECT_NEAR(cleared.clearance, nearestPlane(slot, cleared.position), 1e-15);
    EXPECT_GE(cleared.clearance, nearestPlane(slot, placed.position));
    EXPECT_LT(cleared.clearance, 0.0075 + 1e-12) << "half the slot at most";
    EXPECT_TRUE(cleared.position.allFinite());
}

TEST(KeepClearOfSurfaces, NothingNearOrNoQueryLeavesThePointWhereItIs)
{
    const SurfaceOffset placed =
        offsetFromSurface(Vec3(0.0, 0.0, 0.0), Vec3::UnitY(), Vec3(0, -1, 0), 0.01);
    const ClearedRoutePoint alone =
        keepClearOfSurfaces(placed, 0.01, planes({{Vec3::Zero(), Vec3::UnitY()}}));
    EXPECT_TRUE(alone.clear);
    EXPECT_EQ(alone.pushes, 0);
    EXPECT_EQ(alone.position, placed.position);
    const ClearedRoutePoint none = keepClearOfSurfaces(placed, 0.01, nullptr);
    EXPECT_TRUE(none.clear);
    EXPECT_EQ(none.position, placed.position);
    const ClearedRoutePoint nan = keepClearOfSurfaces(
        placed, std::numeric_limits<double>::quiet_NaN(), planes({{Vec3::Zero(), Vec3::UnitX()}}));
    EXPECT_EQ(nan.position, placed.position);
}

/// The nearest point on the surface of an axis-aligned box (from inside too), when nearer than
/// `within`.
NearestSurfaceQuery boxSurface(const Vec3& lo, const Vec3& hi, int* queries = nullptr)
{
    return [=](const Vec3& at, double within) {
        if (queries) ++*queries;
        NearestSurface near;
        Vec3 p = at.cwiseMax(lo).cwiseMin(hi);
        if (p == at) { // inside: the nearest face
            double best = std::numeric_limits<double>::infinity();
            for (int axis = 0; axis < 3; ++axis)
                for (const double face : {lo[axis], hi[axis]})
                    if (std::abs(at[axis] - face) < best) {
                        best = std::abs(at[axis] - face);
                        p = at;
                        p[axis] = face;
                    }
        }
        near.found = (p - at).norm() < within;
        near.point = p;
        return near;
    };
}

/// The polyline sampled at 5 mm: the hose "laid" along a route without rounding.
std::vector<Vec3> sampled(const std::vector<Vec3>& route)
{
    std::vector<Vec3> axis;
    for (size_t i = 0; i + 1 < route.size(); ++i) {
        const int steps = std::max(1, int(std::ceil((route[i + 1] - route[i]).norm() / 0.005)));
        for (int k = 0; k < steps; ++k)
            axis.push_back(route[i] + (route[i + 1] - route[i]) * (double(k) / steps));
    }
    axis.push_back(route.back());
    return axis;
}

TEST(KeepRouteClearOfSurfaces, ALegPastABoxGetsPointsThatTakeItRoundAndKeepsTheClickedOnes)
{
    // A 6 cm cube whose edge the straight leg passes 5 mm from; 15 mm wanted.
    const Vec3 lo(-0.03, 0.0, -0.03), hi(0.03, 0.06, 0.03);
    const std::vector<Vec3> route = {Vec3(-0.2, 0.03, 0.035), Vec3(0.2, 0.03, 0.035)};
    int queries = 0;
    const ClearedRoute cleared =
        keepRouteClearOfSurfaces(route, 0.015, 0.1, sampled, boxSurface(lo, hi, &queries));
    ASSERT_TRUE(cleared.clear);
    EXPECT_GE(cleared.added, 1);
    ASSERT_EQ(cleared.route.size(), cleared.given.size());
    EXPECT_EQ(cleared.route.front(), route.front());
    EXPECT_EQ(cleared.route.back(), route.back());
    EXPECT_EQ(cleared.given.front(), 0);
    EXPECT_EQ(cleared.given.back(), 1);
    for (size_t i = 1; i + 1 < cleared.given.size(); ++i)
        EXPECT_EQ(cleared.given[i], -1);
    const NearestSurfaceQuery box = boxSurface(lo, hi);
    const std::vector<Vec3> axis = sampled(cleared.route);
    for (const Vec3& p : axis)
        EXPECT_GE((box(p, 1.0).point - p).norm(), 0.015 * (1 - 1e-6)) << p.transpose();
    EXPECT_GE(cleared.clearance, 0.015 * (1 - 1e-6));
    // Bounded: at most kMaxAddedRoutePoints + 1 layouts, each a query per point and middle.
    EXPECT_LE(queries,
              (kMaxAddedRoutePoints + 1) * 2 * int(axis.size() + 8) * (kMaxClearingPushes + 2));
}

TEST(KeepRouteClearOfSurfaces, ARouteAlreadyClearIsLeftAsItIs)
{
    const std::vector<Vec3> route = {Vec3(-0.2, 0.03, 0.2), Vec3(0.2, 0.03, 0.2)};
    const ClearedRoute cleared = keepRouteClearOfSurfaces(
        route, 0.015, 0.1, sampled, boxSurface(Vec3(-0.03, 0, -0.03), Vec3(0.03, 0.06, 0.03)));
    EXPECT_TRUE(cleared.clear);
    EXPECT_EQ(cleared.added, 0);
    EXPECT_EQ(cleared.route, route);
    EXPECT_EQ(cleared.clearance, 0.015);
    const ClearedRoute none = keepRouteClearOfSurfaces(route, 0.015, 0.1, sampled, nullptr);
    EXPECT_EQ(none.route, route);
}

TEST(KeepRouteClearOfSurfaces, AGapNarrowerThanTheHoseIsReportedWithTheBestRouteFound)
{
    // Between two walls 2 cm apart (a 15 mm distance wants 3 cm): never clear, work bounded.
    auto walls = [](const Vec3& at, double within) {
        NearestSurface near;
        const double wall = at.z() < 0.0 ? -0.01 : 0.01;
        near.point = Vec3(at.x(), at.y(), wall);
        near.found = std::abs(at.z() - wall) < within && std::abs(at.x()) < 0.1;
        return near;
    };
    const std::vector<Vec3> route = {Vec3(-0.3, 0, 0.002), Vec3(0.3, 0, 0.002)};
    const ClearedRoute cleared = keepRouteClearOfSurfaces(route, 0.015, 0.1, sampled, walls);
    EXPECT_FALSE(cleared.clear);
    EXPECT_LE(cleared.added, kMaxAddedRoutePoints);
    EXPECT_LT(cleared.clearance, 0.015);
    EXPECT_GE(cleared.clearance, 0.008 - 1e-9) << "the best found: the middle of the gap or near";
}

} // namespace
} // namespace chaintube::editor
